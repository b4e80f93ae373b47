"""Indenter shapes: the rigid gap ``s(x, y)`` added to the tip clearance, ``h = hc(t) + s``.

Every indenter is a frozen dataclass with

- ``gap(x, y)``: the rigid gap shape on numpy arrays (broadcast), ``s >= 0`` and
  ``s(0, 0) = 0`` at the tip, so that ``hc`` is the tip clearance;
- ``symmetric_y``: True when ``s(x, -y) = s(x, y)``.  The FE solver then runs on
  the half disk ``y >= 0`` with mirror images (ladder meshes choose this
  automatically); otherwise on the full disk;
- ``axisymmetric``: True when ``s`` depends on ``r`` alone.

All lengths are in the paper's normalized units (in-plane lengths in units of
``sqrt(R* h_inf)``, gaps in units of ``h_inf``, radii of curvature in units of
the normalizing radius ``R*``; docs/design.md, section 2), so ``Sphere(1.0)`` is the
paper's sphere.  :data:`INDENTERS` maps the scene-file names to the classes;
:func:`si_indenter` builds an indenter from SI values for a
:class:`~femehl.Dimensional` experiment.

Shapes
------
=============================  ============================================================
``Sphere(R)``                  ``s = (x^2 + y^2) / (2 R)`` (the paraboloid of the tip)
``Ellipsoid(Rx, Ry)``          ``s = x^2/(2 Rx) + y^2/(2 Ry)`` (elliptic paraboloid); the
                               indenter slides along x, so ``Rx < Ry`` puts the long
                               axis of the contact across the sliding direction
``FlatPunch(a, edge_radius)``  flat for ``r < a``, then ``s = (r - a)^2 / (2 edge_radius)``
                               (a C1 rounded edge)
``Shape(func)``                any user callable ``func(x, y)`` on numpy arrays
``HeightMap(x, y, z)``         samples ``z[i, j] = s(x[i], y[j])`` on a regular grid,
                               interpolated bilinearly; must cover the disk ``r <= L``
=============================  ============================================================
"""

from __future__ import annotations

import math
import pathlib
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from femehl.errors import SceneError
from femehl.validation import check_finite, check_positive, check_shape_values

__all__ = [
    "INDENTERS",
    "Ellipsoid",
    "FlatPunch",
    "HeightMap",
    "Shape",
    "Sphere",
    "si_indenter",
]


_positive = check_positive  # the historic local name


def _radius_range(L: float, rise: tuple) -> tuple:
    """Radii R for which L^2 / (2 R) lies in ``rise`` = (lo, hi)."""
    return L * L / (2.0 * rise[1]), L * L / (2.0 * rise[0])


def _xy(x, y):
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    return np.broadcast_arrays(x, y)


# --------------------------------------------------------------------------
# analytic shapes
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class Sphere:
    """A rigid sphere (paraboloid near its tip): ``s(x, y) = (x^2 + y^2) / (2 R)``.

    Parameters
    ----------
    R : float, default: 1.0
        Radius in units of the normalizing radius R*; the paper's
        normalization makes it 1.
    """

    R: float = 1.0
    symmetric_y = True
    axisymmetric = True
    #: how each parameter converts from SI (see :func:`si_indenter`)
    si_units: ClassVar[dict] = {"R": "curvature"}

    def __post_init__(self):
        object.__setattr__(
            self, "R", _positive("Sphere radius R", self.R, "Use R = 1 in the paper's normalization.")
        )

    def gap(self, x, y):
        """Rigid gap shape s(x, y) (>= 0, zero at the tip), broadcast over arrays."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        return (x * x + y * y) / (2.0 * self.R)

    def curvature_radii(self) -> tuple[float, float]:
        """Principal radii of curvature ``(Rx, Ry)`` at the tip: ``(R, R)`` (Hertz contact)."""
        return self.R, self.R

    def domain_hint(self, L: float, rise: tuple) -> str:
        """How to choose R so that the gap's rise L^2/(2R) on the domain r <= L lies in ``rise``."""
        lo, hi = _radius_range(L, rise)
        return (
            f"Use a radius {lo:.3g} <= R <= {hi:.3g} for the domain radius L = {L:g} "
            f"(s(L) = L^2/(2R) must lie in [{rise[0]:g}, {rise[1]:g}]; R = 1 in the paper's "
            "normalization), or change L."
        )


@dataclass(frozen=True)
class Ellipsoid:
    """An elliptic paraboloid ``s = x'^2 / (2 Rx) + y'^2 / (2 Ry)`` in its own axes ``(x', y')``,
    turned by ``angle`` from the motion's x axis.

    The film is entrained along x (the indenter slides along +x).  ``Rx < Ry`` makes the
    contact an ellipse elongated across the motion (the long axis along y), as in a
    ball-on-groove or a crowned roller; ``Rx > Ry`` elongates it along x; an ``angle``
    inclines its axes to the motion (a skewed roller), on the full disk.

    Parameters
    ----------
    Rx, Ry : float
        Radii of curvature along its own axes, in units of the normalizing radius R* (> 0);
        at ``angle = 0`` along the motion (x) and across it (y).
    angle : float, default: 0.0
        The angle in degrees from the motion's x axis to the ``Rx`` axis, counterclockwise.
    """

    Rx: float = 1.0
    Ry: float = 1.0
    angle: float = field(default=0.0, metadata={"describe": "omit_default"})
    si_units: ClassVar[dict] = {"Rx": "curvature", "Ry": "curvature", "angle": "angle"}

    def __post_init__(self):
        hint = "Give positive radii of curvature, e.g. Ellipsoid(Rx=0.5, Ry=2.0)."
        object.__setattr__(self, "Rx", _positive("Ellipsoid radius of curvature Rx", self.Rx, hint))
        object.__setattr__(self, "Ry", _positive("Ellipsoid radius of curvature Ry", self.Ry, hint))
        object.__setattr__(
            self, "angle", check_finite("Ellipsoid angle", self.angle, "Give the angle in degrees, e.g. 30.")
        )

    @property
    def axisymmetric(self) -> bool:
        """True only for Rx == Ry (a sphere)."""
        return self.Rx == self.Ry

    @property
    def _quarter_turns(self):
        """The angle in quarter turns when it is a whole number of them (None otherwise)."""
        q = self.angle / 90.0
        return int(round(q)) % 4 if q == round(q) else None

    @property
    def symmetric_y(self) -> bool:
        """Symmetric about the motion's axis: its axes along x and y (or a sphere)."""
        return self.axisymmetric or self._quarter_turns is not None

    def gap(self, x, y):
        """Rigid gap shape s(x, y) (>= 0, zero at the tip), broadcast over arrays."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        Rx, Ry = self.curvature_radii() if self._quarter_turns is not None else (self.Rx, self.Ry)
        if self._quarter_turns is None:  # the coordinates along its own axes
            a = math.radians(self.angle)
            c, s = math.cos(a), math.sin(a)
            x, y = c * x + s * y, c * y - s * x
        return x * x / (2.0 * Rx) + y * y / (2.0 * Ry)

    def curvature_radii(self) -> tuple[float, float] | None:
        """The radii of curvature ``(Rx, Ry)`` along x and y when they are principal (Hertz
        elliptic contact); None for axes inclined to the motion."""
        q = self._quarter_turns
        if q is None:
            return None
        return (self.Rx, self.Ry) if q % 2 == 0 else (self.Ry, self.Rx)

    def domain_hint(self, L: float, rise: tuple) -> str:
        """How to choose Rx, Ry so that the gap's rise on the domain r <= L lies in ``rise``."""
        lo, hi = _radius_range(L, rise)
        return (
            f"Use radii of curvature with {lo:.3g} <= min(Rx, Ry) and max(Rx, Ry) <= {hi:.3g} "
            f"for the domain radius L = {L:g} (the rise L^2/(2R) must lie in "
            f"[{rise[0]:g}, {rise[1]:g}]), or change L."
        )


@dataclass(frozen=True)
class FlatPunch:
    """A flat punch of radius ``a`` with a rounded edge of radius ``edge_radius``.

    ``s = 0`` for ``r <= a`` and ``s = (r - a)^2 / (2 edge_radius)`` beyond: the
    gap and its slope are continuous (C1), so the film stays smooth at the edge.

    Parameters
    ----------
    a : float, default: 0.5
        Radius of the flat face (> 0; use :class:`Sphere` for a = 0).
    edge_radius : float, default: 0.5
        Radius of curvature of the rounded edge (> 0: a sharp edge makes the
        pressure singular).
    """

    a: float = 0.5
    edge_radius: float = 0.5
    symmetric_y = True
    axisymmetric = True
    si_units: ClassVar[dict] = {"a": "length", "edge_radius": "curvature"}

    def __post_init__(self):
        object.__setattr__(
            self,
            "a",
            _positive(
                "FlatPunch radius a",
                self.a,
                "Give the radius of the flat face; for a = 0 use Sphere(R=edge_radius).",
            ),
        )
        object.__setattr__(
            self,
            "edge_radius",
            _positive(
                "FlatPunch edge_radius",
                self.edge_radius,
                "A sharp edge makes the pressure singular: use a rounded edge, edge_radius > 0 (e.g. 0.2).",
            ),
        )

    def gap(self, x, y):
        """Rigid gap shape s(x, y) (>= 0, zero on the flat face), broadcast over arrays."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        e = np.maximum(np.hypot(x, y) - self.a, 0.0)
        return e * e / (2.0 * self.edge_radius)

    def domain_hint(self, L: float, rise: tuple) -> str:
        """How to choose a and edge_radius so that the rise (L - a)^2/(2 edge_radius) lies in ``rise``."""
        if self.a >= L:
            return (
                f"The flat face (a = {self.a:g}) covers the whole domain r <= L = {L:g}: use "
                f"a < L, or a domain radius L > a (the paper's rule: L about 2 contact radii)."
            )
        lo, hi = _radius_range(L - self.a, rise)
        return (
            f"Use {lo:.3g} <= edge_radius <= {hi:.3g} for a = {self.a:g} and L = {L:g} "
            f"(the rise (L - a)^2/(2 edge_radius) must lie in [{rise[0]:g}, {rise[1]:g}]), "
            "or change L."
        )


# --------------------------------------------------------------------------
# user shapes
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class Shape:
    """Any shape from a Python function ``func(x, y) -> s`` on numpy arrays.

    ``func`` receives two float arrays of the same shape and must return an
    array of that shape (or a scalar, broadcast), finite, ``>= 0`` with
    ``s(0, 0) = 0`` at the tip (so that ``hc`` is the tip clearance).  It is
    called once on a small sample grid at construction to catch mistakes
    early.

    Parameters
    ----------
    func : callable
        ``func(x, y)``, vectorized over numpy arrays.
    symmetric_y : bool, default: False
        Declare ``func(x, -y) == func(x, y)``: the FE solver may then use the
        half disk.  Leave False (the full disk) when unsure.
    name : str, default: "custom"
        A label for logs and plots.

    Examples
    --------
    A sphere with a ripple across the sliding direction::

        Shape(lambda x, y: (x**2 + y**2) / 2 + 0.05 * (1 - np.cos(6 * x)))
    """

    func: Callable = None
    symmetric_y: bool = False
    name: str = "custom"
    axisymmetric = False

    def __post_init__(self):
        if not callable(self.func):
            raise SceneError(
                f"Shape func must be a callable func(x, y) on numpy arrays, got "
                f"{type(self.func).__name__}; in a scene file use kind = "
                "'heightmap' or an analytic kind instead."
            )
        object.__setattr__(self, "symmetric_y", bool(self.symmetric_y))
        g = np.linspace(-1.0, 1.0, 5)
        X, Y = np.meshgrid(g, g, indexing="ij")
        s = self.gap(X, Y)
        if self.symmetric_y:
            s_m = self.gap(X, -Y)
            tol = 1e-9 * max(float(np.ptp(s)), float(np.max(np.abs(s))), np.finfo(float).tiny)
            if np.any(np.abs(s_m - s) > tol):
                k = np.unravel_index(int(np.argmax(np.abs(s_m - s))), s.shape)
                raise SceneError(
                    f"Shape {self.name!r} declares symmetric_y=True, but func(x, -y) != func(x, y): "
                    f"func({X[k]:.3g}, {Y[k]:.3g}) = {s[k]:.6g}, func({X[k]:.3g}, {-Y[k]:.3g}) = "
                    f"{s_m[k]:.6g}. Pass symmetric_y=False (the solver then uses the full disk)."
                )

    def gap(self, x, y):
        """``func(x, y)`` checked: real, finite, same shape as the broadcast inputs."""
        x, y = _xy(x, y)
        try:
            with np.errstate(all="ignore"):  # NaN / inf results are refused below
                s = self.func(x.copy(), y.copy())
        except Exception as exc:  # noqa: BLE001 - the user's code: report what failed
            raise SceneError(
                f"Shape {self.name!r}: func(x, y) raised {type(exc).__name__}: {exc}. "
                "It must accept numpy arrays (use np.sin, np.hypot, ...)."
            ) from None
        s = check_shape_values(f"Shape {self.name!r}: func(x, y)", s, x.shape)
        if not np.all(np.isfinite(s)):
            bad = np.flatnonzero(~np.isfinite(s.ravel()))[0]
            raise SceneError(
                f"Shape {self.name!r}: func(x, y) is not finite (NaN or inf) at "
                f"(x, y) = ({x.ravel()[bad]:.3g}, {y.ravel()[bad]:.3g}): fix the "
                "function so that it returns finite gaps over the whole domain."
            )
        return s


@dataclass(frozen=True, eq=False)
class HeightMap:
    """A gap shape sampled on a regular grid, interpolated bilinearly.

    Parameters
    ----------
    x : (nx,) array
        Strictly increasing grid abscissae (at least 2).
    y : (ny,) array
        Strictly increasing grid ordinates (at least 2).
    z : (nx, ny) array
        ``z[i, j] = s(x[i], y[j])``, finite; ``s >= 0`` with ``s = 0`` at the tip
        (x, y) = (0, 0).
    symmetric_y : bool, optional
        Whether ``s(x, -y) = s(x, y)``.  Default: detected from the data (the
        y grid symmetric about 0 and ``z[:, ::-1] == z`` to 1e-12 of max ``|z|``).

    Notes
    -----
    The grid must cover the computational disk ``r <= L``: a scene whose
    domain reaches outside the map is rejected at construction, and any point
    outside the grid raises :class:`~femehl.errors.SceneError` (no
    extrapolation).  Load a map from an ``.npz`` file with arrays ``x``, ``y``,
    ``z`` with :meth:`from_file`.
    """

    x: np.ndarray = None
    y: np.ndarray = None
    z: np.ndarray = None
    symmetric_y: bool | None = None
    axisymmetric = False
    _interp: object = field(default=None, init=False, repr=False)

    def __post_init__(self):
        axes = []
        for name in ("x", "y"):
            try:
                a = np.array(getattr(self, name), dtype=float)
            except (TypeError, ValueError):
                raise SceneError(f"HeightMap {name} must be a 1-D array of numbers.") from None
            if a.ndim != 1 or a.size < 2:
                raise SceneError(
                    f"HeightMap {name} must be a 1-D array of at least 2 grid "
                    f"coordinates, got shape {a.shape}."
                )
            if not np.all(np.isfinite(a)):
                raise SceneError(f"HeightMap {name} contains NaN or inf: give finite grid coordinates.")
            if np.any(np.diff(a) <= 0):
                raise SceneError(
                    f"HeightMap {name} must be strictly increasing (monotonic grid): "
                    f"sort the axis and the matching axis of z."
                )
            a.setflags(write=False)
            axes.append(a)
        x, y = axes
        try:
            z = np.array(self.z, dtype=float)
        except (TypeError, ValueError):
            raise SceneError("HeightMap z must be a 2-D array of numbers.") from None
        if z.shape != (x.size, y.size):
            raise SceneError(
                f"HeightMap z has shape {z.shape} but the grid needs "
                f"(len(x), len(y)) = ({x.size}, {y.size}): z[i, j] = s(x[i], y[j]) "
                "(transpose z if it is indexed [y, x])."
            )
        if not np.all(np.isfinite(z)):
            raise SceneError(
                "HeightMap z contains NaN or inf values: fill the gaps in the map "
                "(e.g. by interpolation) before using it."
            )
        z.setflags(write=False)
        sym = self.symmetric_y
        if sym is None:
            tol = 1e-12 * max(1.0, float(np.abs(z).max()))
            sym = bool(
                np.allclose(y, -y[::-1], rtol=0.0, atol=1e-12 * max(1.0, abs(y).max()))
                and np.allclose(z, z[:, ::-1], rtol=0.0, atol=tol)
            )
        from scipy.interpolate import RegularGridInterpolator

        interp = RegularGridInterpolator((x, y), z, method="linear", bounds_error=False, fill_value=np.nan)
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "z", z)
        object.__setattr__(self, "symmetric_y", bool(sym))
        object.__setattr__(self, "_interp", interp)

    def __repr__(self):
        return (
            f"HeightMap(x=[{self.x[0]:g} .. {self.x[-1]:g}] ({self.x.size}), "
            f"y=[{self.y[0]:g} .. {self.y[-1]:g}] ({self.y.size}), "
            f"z=[{self.z.min():g} .. {self.z.max():g}], symmetric_y={self.symmetric_y})"
        )

    @classmethod
    def from_file(cls, path, symmetric_y: bool | None = None) -> HeightMap:
        """Read a map from an ``.npz`` file holding arrays ``x``, ``y`` and ``z``."""
        path = pathlib.Path(path)
        try:
            with np.load(path) as data:
                missing = {"x", "y", "z"} - set(data.files)
                if missing:
                    raise SceneError(
                        f"height map file {str(path)!r} lacks arrays {sorted(missing)}; "
                        "save it with np.savez(path, x=x, y=y, z=z)."
                    )
                x, y, z = data["x"], data["y"], data["z"]
        except FileNotFoundError:
            raise SceneError(
                f"height map file {str(path)!r} does not exist: check the path "
                "(relative paths are relative to the scene file)."
            ) from None
        except (OSError, ValueError) as exc:
            raise SceneError(
                f"cannot read height map file {str(path)!r} ({exc}); save it with "
                "np.savez(path, x=x, y=y, z=z)."
            ) from None
        return cls(x, y, z, symmetric_y)

    @property
    def extent(self) -> float:
        """Radius of the largest disk about the origin inside the grid (0 if none)."""
        return max(0.0, min(-self.x[0], self.x[-1], -self.y[0], self.y[-1]))

    def check_domain(self, L: float) -> None:
        """Raise SceneError unless the grid covers the disk ``r <= L``."""
        ext = self.extent
        if ext < L * (1.0 - 1e-12):
            raise SceneError(
                f"HeightMap grid [{self.x[0]:g}, {self.x[-1]:g}] x [{self.y[0]:g}, {self.y[-1]:g}] "
                f"does not cover the domain r <= L = {L:g}: extend the map to |x|, |y| >= {L:g} "
                f"or use a smaller domain radius L <= {ext:g}."
            )

    def gap(self, x, y):
        """Bilinear interpolation of the map; SceneError for points outside the grid."""
        x, y = _xy(x, y)
        pts = np.column_stack([x.ravel(), y.ravel()])
        # points on the grid boundary up to round-off are inside
        span = max(self.x[-1] - self.x[0], self.y[-1] - self.y[0])
        tol = 1e-12 * span
        pts[:, 0] = np.where((pts[:, 0] < self.x[0]) & (pts[:, 0] > self.x[0] - tol), self.x[0], pts[:, 0])
        pts[:, 0] = np.where((pts[:, 0] > self.x[-1]) & (pts[:, 0] < self.x[-1] + tol), self.x[-1], pts[:, 0])
        pts[:, 1] = np.where((pts[:, 1] < self.y[0]) & (pts[:, 1] > self.y[0] - tol), self.y[0], pts[:, 1])
        pts[:, 1] = np.where((pts[:, 1] > self.y[-1]) & (pts[:, 1] < self.y[-1] + tol), self.y[-1], pts[:, 1])
        s = self._interp(pts)
        if not np.all(np.isfinite(s)):
            bad = int(np.flatnonzero(~np.isfinite(s))[0])
            raise SceneError(
                f"HeightMap asked for the gap at (x, y) = ({pts[bad, 0]:.3g}, {pts[bad, 1]:.3g}), "
                f"outside its grid [{self.x[0]:g}, {self.x[-1]:g}] x [{self.y[0]:g}, {self.y[-1]:g}]: "
                "extend the map to cover the whole domain r <= L."
            )
        return s.reshape(x.shape)


#: scene-file name -> indenter class (``[indenter] kind = ...``)
INDENTERS: dict[str, type] = {
    "sphere": Sphere,
    "ellipsoid": Ellipsoid,
    "flat_punch": FlatPunch,
    "heightmap": HeightMap,
    "shape": Shape,
}


def si_indenter(kind: str, params: dict, dim) -> object:
    """Build the indenter ``kind`` from SI parameters for the experiment ``dim``.

    Each class lists in ``si_units`` whether a parameter is a radius of
    curvature (divided by the normalizing radius ``dim.R``) or an in-plane
    length (divided by ``dim.length = sqrt(R h_inf)``).

    Parameters
    ----------
    kind : str
        A key of :data:`INDENTERS` with SI support (sphere, ellipsoid, flat_punch).
    params : dict
        The indenter's parameters in metres.
    dim : femehl.Dimensional
        The experiment whose scales normalize them.

    Returns
    -------
    Indenter
        An instance of ``INDENTERS[kind]`` in normalized units.
    """
    if not isinstance(kind, str) or kind not in INDENTERS:
        raise SceneError(f"indenter kind {kind!r} is not known; use one of {sorted(INDENTERS)}.")
    cls = INDENTERS[kind]
    units = getattr(cls, "si_units", None)
    if units is None:
        raise SceneError(
            f"indenter kind {kind!r} cannot be given in SI units; use a normalized "
            f"scene (no [si] table) or one of "
            f"{sorted(k for k, c in INDENTERS.items() if hasattr(c, 'si_units'))}."
        )
    extra = set(params) - set(units)
    if extra:
        raise SceneError(f"indenter kind {kind!r} does not take {sorted(extra)}; it takes {sorted(units)}.")
    scale = {"curvature": dim.R, "length": dim.length}
    out = {}
    for k, v in params.items():
        if units[k] == "angle":  # degrees, the same in SI
            out[k] = check_finite(f"{kind} {k} [degrees]", v)
        else:
            out[k] = _positive(f"{kind} {k} [m]", v) / scale[units[k]]
    return cls(**out)
