"""The dry contact a substrate predicts for a scene's indenter: depth, load and extent.

Each substrate answers :meth:`dry_contact` with a :class:`DryContact` built from the
helpers here (Hertz / Sneddon for an elastic half space, the geometric overlap for a local
foundation); :func:`dry_contact_extent` is the one place that turns a scene's motion into
the deepest indentation and the largest contact semi-axes of its run.  The automatic
mode's fitted meshes and the scene's domain check both ask it (docs/design.md section 8).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from femehl.errors import SceneError

__all__ = [
    "DryContact",
    "SampledShape",
    "LineShape",
    "dry_contact_extent",
    "indentation",
    "elastic_contact",
    "overlap_contact",
    "hertz_ellipse",
    "sample_shape",
]

# polar sampling of the gap: rays, radial samples, Gauss points of the Sneddon integrals
_NTH, _NR, _NPHI = 96, 801, 48


# ---------------------------------------------------------------------------
# contact extent


def _run_times(f, t_end: float) -> np.ndarray:
    """Times in [0, t_end] at which a history is sampled: a fine grid plus its knots."""
    extra = [float(t) for t in (getattr(f, "times", ()) or ())]
    t1 = getattr(f, "t1", None)
    if isinstance(t1, (int, float)):
        extra.append(float(t1))
    extra = [t for t in extra if math.isfinite(t) and 0.0 <= t <= t_end]
    return np.unique(np.concatenate([np.linspace(0.0, t_end, 2001), extra]))


def _polar_gap(scene):
    """The gap on a full polar grid: ``th (nth,)``, ``r (nr,)``, ``S (nth, nr)`` (inf where undefined)."""
    L = scene.domain.L
    rmax = min(1.5 * L, max(float(getattr(scene.indenter, "extent", math.inf)), L))
    th = np.linspace(0.0, 2.0 * math.pi, _NTH, endpoint=False)
    r = np.linspace(0.0, rmax, _NR)
    TH, RR = np.meshgrid(th, r, indexing="ij")
    try:
        with np.errstate(all="ignore"):
            S = np.asarray(scene.indenter.gap(RR * np.cos(TH), RR * np.sin(TH)), dtype=float)
    except Exception as exc:  # noqa: BLE001 - the user's shape: name the failure
        raise SceneError(
            f"contact_extent: the indenter's gap(x, y) failed on r <= {rmax:g} "
            f"({type(exc).__name__}: {exc}); fix the shape function"
        ) from None
    S = np.where(np.isfinite(S), S, np.inf)
    return th, r, S


def _overlap_radius(r, S, depth) -> np.ndarray:
    """Per ray, the largest radius where ``s < depth`` (linear between samples; 0 if none)."""
    g = S - depth
    neg = g < 0.0
    out = np.zeros(S.shape[0])
    rows = np.flatnonzero(neg.any(axis=1))
    if rows.size == 0:
        return out
    last = S.shape[1] - 1 - np.argmax(neg[rows, ::-1], axis=1)
    if np.any(last == S.shape[1] - 1):
        raise SceneError(
            f"contact_extent: an indentation {depth:.3g} deep overlaps the indenter beyond the "
            f"sampled radius {r[-1]:.3g}; use a larger domain radius L"
        )
    g0, g1 = g[rows, last], g[rows, last + 1]
    with np.errstate(all="ignore"):
        frac = np.where(np.isfinite(g1), g0 / (g0 - g1), 1.0)
    out[rows] = r[last] + frac * (r[last + 1] - r[last])
    return out


def _axes_of(th, radius) -> tuple[float, float]:
    return float(np.max(np.abs(radius * np.cos(th)))), float(np.max(np.abs(radius * np.sin(th))))


class _RaySneddon:
    """Sneddon's axisymmetric contact, applied ray by ray to the profile ``f(r) = s(r, theta)``.

    For an axisymmetric profile on a half space the contact radius ``c`` at depth
    ``delta`` solves ``delta = c int_0^{pi/2} f'(c sin phi) dphi`` and the load is
    ``F = (2 / (pi cc)) c^2 int_0^{pi/2} sin^2 phi f'(c sin phi) dphi`` in femehl's
    units (``cc = 2 (1 - nu)``; for the unit sphere ``c = sqrt(delta)``,
    ``F = 4 c^3 / (3 pi cc)``, design.md section 2).  Exact for every axisymmetric
    indenter (Sphere, FlatPunch); for other shapes each ray is treated as if the
    indenter were the body of revolution of that ray's profile (a heuristic: the
    contact of an elliptic paraboloid is less eccentric than this gives).
    """

    def __init__(self, r, S, cc):
        self.r, self.cc = r, cc
        fp = np.gradient(np.where(np.isfinite(S), S, np.nan), r, axis=1)
        self.fp = np.nan_to_num(fp, nan=0.0, posinf=0.0, neginf=0.0)
        x, w = np.polynomial.legendre.leggauss(_NPHI)
        self.phi = 0.25 * math.pi * (x + 1.0)
        self.w = 0.25 * math.pi * w
        dr = r[1] - r[0]
        idx = r[:, None] * np.sin(self.phi)[None, :] / dr  # (nc, nphi) fractional indices
        i0 = np.minimum(idx.astype(int), r.size - 2)
        f = idx - i0
        vals = self.fp[:, i0] * (1.0 - f) + self.fp[:, i0 + 1] * f  # (nth, nc, nphi)
        self.depth = r[None, :] * (vals @ self.w)  # delta(c) per ray
        self.load = (2.0 / (math.pi * cc)) * r[None, :] ** 2 * (vals @ (self.w * np.sin(self.phi) ** 2))

    def radius(self, delta) -> np.ndarray:
        """Per ray, the first contact radius ``c`` with ``delta(c) >= delta``."""
        D = self.depth
        hit = D >= delta
        if not hit.any(axis=1).all():
            raise SceneError(
                f"contact_extent: an indentation {delta:.3g} deep spreads the contact beyond the "
                f"sampled radius {self.r[-1]:.3g}; use a larger domain radius L"
            )
        k = np.argmax(hit, axis=1)
        k0 = np.maximum(k - 1, 0)
        rows = np.arange(D.shape[0])
        d0, d1 = D[rows, k0], D[rows, k]
        with np.errstate(all="ignore"):
            frac = np.where(d1 > d0, (delta - d0) / (d1 - d0), 1.0)
        return self.r[k0] + np.clip(frac, 0.0, 1.0) * (self.r[k] - self.r[k0])

    def force(self, delta) -> float:
        """Ray-averaged Sneddon load at depth ``delta``."""
        c = self.radius(delta)
        F = [np.interp(ci, self.r, row) for ci, row in zip(c, self.load, strict=True)]
        return float(np.mean(F))


def hertz_ellipse(Rx: float, Ry: float, delta: float) -> tuple[float, float, float]:
    """Hertz contact of the elliptic paraboloid ``x^2/(2 Rx) + y^2/(2 Ry)`` pressed ``delta`` deep.

    Returns ``(ax, ay, m)``: the semi-axes along x and y and ``m = e^2 = 1 -
    (short/long)^2``.  With curvatures ``A <= B`` (``A`` along the long axis),
    ``B/A = (E(m)/(1 - m) - K(m)) / (K(m) - E(m))`` fixes ``m`` and
    ``a_long^2 = delta (K - E) / (A K m)`` (Johnson, Contact Mechanics, section 3.5,
    with ``delta = cc pi b p0 K`` in femehl's units); a sphere (``m -> 0``) gives
    ``a = sqrt(R delta)``.  Independent of the substrate's compliance.
    """
    from scipy.optimize import brentq
    from scipy.special import ellipe, ellipk

    A, B = 1.0 / (2.0 * Rx), 1.0 / (2.0 * Ry)
    lo, hi = min(A, B), max(A, B)
    q = hi / lo
    if q < 1.0 + 1e-9:
        a = math.sqrt(delta / (2.0 * lo))
        return a, a, 0.0

    def f(m):
        K, E = ellipk(m), ellipe(m)
        return (E / (1.0 - m) - K) / (K - E) - q

    m = brentq(f, 1e-12, 1.0 - 1e-15, xtol=1e-15)
    K, E = ellipk(m), ellipe(m)
    a = math.sqrt(delta * (K - E) / (lo * K * m))
    b = a * math.sqrt(1.0 - m)
    return ((a, b) if A < B else (b, a)) + (float(m),)


def _hertz_ellipse_load(Rx, Ry, delta, cc) -> float:
    """Hertz load ``F = (2/3) a_long delta / (cc K(m))`` (unit sphere: ``4 delta^(3/2) / (3 pi cc)``)."""
    from scipy.special import ellipk

    ax, ay = hertz_ellipse(Rx, Ry, delta)[:2]
    along = max(ax, ay)
    m = 1.0 - (min(ax, ay) / along) ** 2
    return (2.0 / 3.0) * along * delta / (cc * float(ellipk(m)))


def _invert(F_of, F, what) -> float:
    """Depth ``delta`` with ``F_of(delta) = F`` (monotone), by doubling then bisection."""
    lo, hi = 0.0, 1e-3
    while F_of(hi) < F:
        lo, hi = hi, 2.0 * hi
        if hi > 1e6:
            raise SceneError(f"contact_extent: {what} cannot carry the load {F:g}; check the load history")
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if F_of(mid) < F else (lo, mid)
    return hi


@dataclass(frozen=True)
class SampledShape:
    """The indenter's gap ``S (nth, nr)`` on a full polar grid ``th``, ``r`` (inf where
    undefined), out to ``min(1.5 L, map extent)``; ``radii``: ``(Rx, Ry)`` of a
    paraboloid indenter (Sphere, Ellipsoid), else None."""

    th: np.ndarray
    r: np.ndarray
    S: np.ndarray
    radii: tuple | None

    def overlap_axes(self, depth: float) -> tuple[float, float]:
        """Semi-axes of the geometric overlap ``s < depth``."""
        return _axes_of(self.th, _overlap_radius(self.r, self.S, depth))

    def overlap_radius(self, depth: float) -> float:
        """The largest radius of the geometric overlap ``s < depth`` (over every ray)."""
        return float(np.max(_overlap_radius(self.r, self.S, depth)))

    def overlap_volume(self, depth: float) -> float:
        """``int (depth - s)+ dA`` over the sampled disk."""
        area = (self.r[1] - self.r[0]) * self.r * (2.0 * math.pi / self.th.size)
        return float(np.sum(np.maximum(depth - self.S, 0.0) @ area))


@dataclass(frozen=True)
class LineShape:
    """A line contact's cylinder of radius ``R``, per unit length: the 1-D shape a local
    foundation's :meth:`dry_contact` reads (``overlap_axes``, ``overlap_volume``)."""

    R: float = 1.0
    radii = None

    def overlap_axes(self, depth: float) -> tuple[float, float]:
        """``(a, 0)``: the overlap ``x^2/(2R) < depth`` is ``|x| < a = sqrt(2 R depth)``."""
        return math.sqrt(2.0 * self.R * max(depth, 0.0)), 0.0

    def overlap_volume(self, depth: float) -> float:
        """``int (depth - x^2/(2R))+ dx = (2/3) a^3 / R``."""
        a = self.overlap_axes(depth)[0]
        return (2.0 / 3.0) * a**3 / self.R


def sample_shape(scene) -> SampledShape:
    """The scene's indenter sampled on the polar grid (96 rays, 801 radii)."""
    th, r, S = _polar_gap(scene)
    radii = getattr(scene.indenter, "curvature_radii", None)
    radii = radii() if callable(radii) else None  # None: not a paraboloid with axes along x, y
    return SampledShape(th, r, S, None if radii is None else tuple(float(v) for v in radii))


@dataclass(frozen=True)
class DryContact:
    """A substrate's dry contact with one indenter: ``axes(depth) -> (ax, ay)`` and
    ``load(depth) -> F`` (None: the substrate is never indented under a load, a rigid one)."""

    axes: Callable[[float], tuple[float, float]]
    load: Callable[[float], float] | None
    #: names the substrate in messages
    what: str = "the substrate"

    def depth(self, F: float) -> float:
        """The depth at which the dry contact carries ``F`` (monotone inversion)."""
        return _invert(self.load, F, self.what)


def elastic_contact(shape: SampledShape, compliance: float, what: str = "the half space") -> DryContact:
    """An elastic half space of ``compliance`` (``2 (1 - nu)``): Hertz for a paraboloid
    (:func:`hertz_ellipse`; sphere ``a = sqrt(R delta)``, ``F = 4 a^3/(3 pi cc)``), else
    Sneddon's axisymmetric solution ray by ray (exact for FlatPunch; a heuristic for a
    shape without axial symmetry), the load the ray average."""
    cc = float(compliance)
    if shape.radii is not None:
        Rx, Ry = shape.radii
        return DryContact(
            lambda delta: hertz_ellipse(Rx, Ry, delta)[:2],
            lambda delta: _hertz_ellipse_load(Rx, Ry, delta, cc),
            what,
        )
    rs = _RaySneddon(shape.r, shape.S, cc)
    return DryContact(lambda delta: _axes_of(shape.th, rs.radius(delta)), rs.force, what)


def overlap_contact(shape: SampledShape, k: float | None, what: str = "the foundation") -> DryContact:
    """A local foundation of stiffness ``k`` (no lateral spreading): the geometric overlap,
    ``F = k int (delta - s)+ dA``; ``k = None``: never indented under a load."""
    load = None if k is None else (lambda delta: float(k) * shape.overlap_volume(delta))
    return DryContact(shape.overlap_axes, load, what)


def _dry_contact(substrate, shape: SampledShape) -> DryContact:
    """The substrate's own :class:`DryContact`; one without ``dry_contact`` (a user's) is
    taken as a half space of its ``compliance`` (default 1)."""
    own = getattr(substrate, "dry_contact", None)
    if callable(own):
        return own(shape)
    return elastic_contact(
        shape, float(getattr(substrate, "compliance", 1.0)), f"the {type(substrate).__name__}"
    )


def indentation(scene, *, load: float | None = None, depth: float | None = None, shape=None):
    """``(ax, ay, delta)``: the dry contact's semi-axes and depth under ``load`` (the
    substrate's :meth:`dry_contact` inverted) or at ``depth``; zeros when it does not touch.
    ``shape``: the scene's :func:`sample_shape`, if the caller has it already."""
    if (depth if load is None else load) is None or (depth if load is None else load) <= 0.0:
        return 0.0, 0.0, 0.0
    dry = _dry_contact(scene.substrate, sample_shape(scene) if shape is None else shape)
    if load is not None:
        if dry.load is None:
            return 0.0, 0.0, 0.0
        depth = dry.depth(load)
    ax, ay = dry.axes(depth)
    return float(ax), float(ay), float(depth)


def dry_contact_extent(scene, t_end: float) -> tuple[float, float, float]:
    """``(ax, ay, delta)``: the largest dry-contact semi-axes of a run to ``t_end`` and its
    deepest indentation (:func:`indentation` at the largest load ``F(t)``, or at
    ``-min hc(t)``, or a free indenter's :func:`free_fall_depth`; ``t`` on 2001 points of
    ``[0, t_end]`` plus the history's knots)."""
    motion = scene.motion
    if motion.free:
        F = max(float(motion.applied_force(float(t))) for t in _run_times(motion.force, t_end))
        return indentation(scene, depth=free_fall_depth(scene, F))
    if motion.load_controlled:
        F = max(float(motion.F(float(t))) for t in _run_times(motion.load, t_end))
        return indentation(scene, load=F)
    return indentation(scene, depth=-min(float(motion.hc(float(t))) for t in _run_times(motion.gap, t_end)))


def free_fall_depth(scene, force: float) -> float:
    """The deepest dry indentation a free indenter can reach under a constant ``force``:
    the depth where the dry contact's stored energy ``int_0^delta load`` equals the work of
    ``force`` from the initial gap ``hc(0)`` plus the initial kinetic energy ``m hc'(0)^2 / 2``
    (no film, no damping: an upper bound; the film only slows it).  0 when it does not
    touch (a rigid substrate, or nothing pushes it down)."""
    motion = scene.motion
    gap0 = max(0.0, float(motion.hc(0.0)))
    kinetic = 0.5 * float(motion.mass) * float(motion.hc_dot0) ** 2
    if force <= 0.0 and kinetic == 0.0:
        return 0.0
    dry = _dry_contact(scene.substrate, sample_shape(scene))
    if dry.load is None:
        return 0.0

    def surplus(delta: float) -> float:
        s = np.linspace(0.0, delta, 65)
        stored = float(np.trapezoid([0.0] + [dry.load(float(x)) for x in s[1:]], s))  # no load at 0
        return stored - max(force, 0.0) * (delta + gap0) - kinetic

    lo, hi = 0.0, 1e-3
    while surplus(hi) < 0.0:
        lo, hi = hi, 2.0 * hi
        if hi > 1e6:
            raise SceneError(f"contact_extent: {dry.what} cannot stop the free indenter; check its force")
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if surplus(mid) < 0.0 else (lo, mid)
    return hi
