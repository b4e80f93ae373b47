"""Meshes fitted to the scene: refined where the contact of *this* run is.

The mesh ladder (:data:`femehl.discretize.mesh.LADDER`) is graded for the paper sphere's
contact annulus ``0.8 <= r <= 1.2``.  Another indenter puts its contact edge
elsewhere: the shipped ellipsoid (``Rx = 0.5, Ry = 2, hc = -0.5``) has a contact
semi-axis 0.44 along x and its exit minimum film near ``x = -0.5``, inside the
ladder's coarse contact zone, and the ``medium`` rung is 11-13 % low in the
minimum film at ``t = 3``.  This module meshes the disk from the scene itself::

    from femehl.discretize.fitted import fitted_disk
    res = femehl.solve(scene, t_end=5.0, mesh=fitted_disk(scene, 5.0), scheme="bdf2")

Two steps
---------
:func:`contact_extent` estimates the largest dry-contact semi-axes ``(ax, ay)``
of the run (Hertz / Sneddon / Winkler, see there).  :func:`fitted_sizes` turns
them into a size field, :func:`fitted_disk` meshes it with gmsh through
:func:`femehl.discretize.mesh.sized_disk` (the ladder's mesher and options) and caches
the result on disk.

The size field
--------------
The contact is modelled as the ellipse ``rho(x, y) = 1`` with
``rho = sqrt((x/ax)^2 + (y/ay)^2)``.  Its local normal length scale is
``ell(x, y) = 1/|grad rho|`` (constant along rays; ``ax`` on the x axis, ``ay``
on the y axis, in ``[min(ax, ay), max(ax, ay)]``), and ``dn = (rho - 1) ell``
approximates the signed distance to the contact edge (exact on the axes).
With ``a_min = min(ax, ay)`` and sizes multiplied by ``level``:

* contact zone ``rho <= 1.3``: ``h_contact = min(0.095, 2.4 * 0.2035 W(beta))
  a_min`` (the ``medium`` rung's 0.095 for the unit sphere; ``a_min`` because
  the triangles are isotropic and must resolve the short axis; at most 2.4 times
  the edge size, see "Thin films" below);
* edge band ``|dn| <= w``, ``w = W(beta) ell``: ``h_edge = 0.2035 w`` (about
  ten elements across the band ``2 w``; ``0.0407`` at ``beta = 200``, the
  ``medium`` rung's edge size), growing linearly to ``h_contact`` over
  ``0.15 ell`` on either side (the ladder's transition);
* far field: linear along each ray from ``h_contact`` on ``rho = 1.3`` to
  ``h_far = 0.152 L`` at ``r = L`` (the ``medium`` rung's 0.303 for ``L = 2``).

So for the paper sphere at ``beta = 200`` and ``level = 1`` the field is the
``medium`` rung's, and ``level = 1/1.45`` divides every size by 1.45 like one
ladder rung (about twice the elements).

Edge-band width
---------------
``W(beta) = max(0.05, 1.17 beta^(-1/3))``: 0.2 at ``beta = 200`` (the
ladder's annulus half-width, tuned on the paper sphere).  The band must hold
the exit zone: the film's exit minimum sits past the Hertz edge and the film
then opens.  Measured on the paper sphere (``benchmarks/fitted_mesh.md``,
fine ladder mesh, ``t = 3``, centreline): the distance ``e`` from the Hertz
edge to where the film past its exit minimum has doubled is 0.366, 0.165,
0.083 at ``beta = 20, 200, 2000``, i.e. ``e ~ beta^(-0.32)``; ``W`` is 1.1-1.2
times ``e`` at all three.  (A Hertzian boundary-layer argument, gap opening
like ``(x/ell)^(3/2)`` and films ``h ~ beta^(-0.6)``, predicts ``beta^(-0.4)``
for the constriction itself; the measured zone, which includes the opening,
shrinks more slowly.)  The floor 0.05 keeps the band resolvable on a mesh for
``beta >~ 10^4``.

Thin films: the contact zone
----------------------------
Up to 2026-12-03 the contact zone was ``0.095 a_min`` at every beta, 9.3 times the
edge size at ``beta = 20000``.  There, during the approach, the minimum film is on
the rim of the trapped dimple, which crosses the contact zone (r ~ 0.2 to the edge):
on the ``sphere_b20000_approach`` scene of ``benchmarks/auto_scenes.py`` (BDF2,
dt = 0.0025, to t = 1; ``benchmarks/fitted_thin.md``) the uncapped levels 1 and 0.7
(10,846 and 21,842 elements) are 27 % and 11 % off the finest capped mesh (level 0.7,
50,120 elements) in the minimum film (central film 3.8 % and 2.0 %), the capped
levels 1.4 and 1 (12,778 and 24,736 elements) 2.0 % and 1.25 % (0.33 % and 0.11 %).
The cap ``C_CONTACT_EDGE = 2.4`` keeps every
mesh of ``beta <= 218`` as it was (their ratio is at most 2.33).

Accuracy (``benchmarks/fitted_mesh.md``, before the cap for beta = 2000): on the shipped ellipsoid (both
orientations) a fitted mesh with the element count of the ``medium`` rung
(``level = 1.45``) is within 1 % of the extrapolated minimum film at
``t = 3``, where the ``medium`` rung is 11-13 % low (``xfine``, four times the
elements: about 2 %); on the paper sphere the fitted ``level = 1`` mesh is the
``medium`` rung's field (both within 1 %).  At ``beta = 2000`` the narrower
band makes the fitted mesh at the medium count 3.7 % low (``medium``: 8.7 %,
``fine``: 6.2 %); ``level = 1`` (the fine count) is within 1 %.
"""

from __future__ import annotations

import hashlib
import json
import math
import pathlib
from dataclasses import asdict, dataclass, replace

import numpy as np

from femehl.discretize.mesh import (
    MAX_GMSH_ELEMENTS,
    DiskMesh,
    _write_msh,
    check_mesh_memory,
    load_mesh,
    sized_disk,
)
from femehl.elastic.contact import dry_contact_extent, hertz_ellipse
from femehl.errors import MeshError, SceneError

__all__ = [
    "CACHE_DIR",
    "hertz_ellipse",
    "FittedSizes",
    "contact_extent",
    "fitted_disk",
    "fitted_sizes",
]

#: Bump when the size field or the mesher changes: it is part of the cache key.
FITTED_VERSION = 1
#: Default mesh cache folder (``cache_dir=`` of :func:`fitted_disk` overrides it).
CACHE_DIR = pathlib.Path("~/.cache/femehl/meshes")

#: h_contact / a_min at level 1 (the medium rung's 0.138 / 1.45 for the unit sphere).
C_CONTACT = 0.095
#: h_edge / w: about ten elements across the band 2 w (medium rung: 0.0407 / 0.2).
C_EDGE = 0.2035
#: h_contact is at most this many times the edge size on the short axis (the medium
#: rung's ratio 0.095 / 0.0407 = 2.33 at beta = 200: the cap acts from beta ~ 218 on)
C_CONTACT_EDGE = 2.4
#: Band half-width / ell = max(W_MIN, C_WIDTH * beta**WIDTH_EXPONENT).
C_WIDTH = 1.17
WIDTH_EXPONENT = -1.0 / 3.0
W_MIN = 0.05
#: Width (in units of ell) over which h goes from h_edge to h_contact (ladder: 0.15).
TRANSITION = 0.15
#: The contact zone (size h_contact) is rho <= RHO_CONTACT (ladder: r_contact = 1.3).
RHO_CONTACT = 1.3
#: h_far / L (medium rung: 0.303 for L = 2).
C_FAR = 0.152
#: Smallest contact semi-axis used for sizes, in units of L (a scene with no
#: indentation still gets its tip region resolved).
A_FLOOR = 0.05


def contact_extent(scene, t_end: float) -> tuple[float, float]:
    """The largest dry-contact semi-axes ``(ax, ay)`` along x and y over a run to ``t_end``:
    :func:`femehl.elastic.contact.dry_contact_extent` on the run's times (2001 points of
    ``[0, t_end]`` plus the history's knots); ``(0.0, 0.0)`` if the indenter never touches.
    """
    if not (isinstance(t_end, (int, float)) and math.isfinite(t_end) and t_end > 0):
        raise SceneError(f"contact_extent: t_end = {t_end!r} must be a positive finite time")
    return dry_contact_extent(scene, t_end)[:2]


# ---------------------------------------------------------------------------
# size field


@dataclass(frozen=True)
class FittedSizes:
    """The size field of a fitted mesh (see the module docstring).

    Attributes
    ----------
    ax, ay : float
        Contact semi-axes used (``contact_extent``, floored at ``A_FLOOR * L``).
    h_contact : float
        Size in the contact zone ``rho <= RHO_CONTACT``.
    edge_coef : float
        Edge size / ``ell`` (``h_edge = edge_coef * ell``).
    width : float
        Edge-band half-width / ``ell``.
    h_far : float
        Size at ``r = L``.
    L : float
        Disk radius.
    beta : float
        The scene's beta (sets ``width``).
    level : float
        The factor all sizes were multiplied by.
    """

    ax: float
    ay: float
    h_contact: float
    edge_coef: float
    width: float
    h_far: float
    L: float
    beta: float
    level: float

    def size(self, x: float, y: float) -> float:
        """The mesh size at ``(x, y)`` (scalar, pure Python: gmsh calls it per point)."""
        ax, ay, L = self.ax, self.ay, self.L
        u, v = x / ax, y / ay
        rho = math.sqrt(u * u + v * v)
        g = math.hypot(u / ax, v / ay)
        ell = rho / g if g > 0.0 else min(ax, ay)
        h_c = self.h_contact
        h_e = self.edge_coef * ell
        dn = abs(rho - 1.0) * ell
        # from h_e at the edge toward h_c, growing beyond it (zone then rules); an edge size
        # above the contact size (wide exit zones at small beta, ellipses) grows from h_e
        band = h_e + abs(h_c - h_e) * max(dn - self.width * ell, 0.0) / (TRANSITION * ell)
        if rho <= RHO_CONTACT:
            zone = h_c
        else:
            r = math.hypot(x, y)
            rc = RHO_CONTACT * r / rho
            frac = min((r - rc) / (L - rc), 1.0) if rc < L else 0.0
            zone = h_c + (self.h_far - h_c) * frac
        return min(band, zone)

    def sizes(self, x, y) -> np.ndarray:
        """:meth:`size` at arrays of points: the same formula, vectorized."""
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        ax, ay, L = self.ax, self.ay, self.L
        u, v = x / ax, y / ay
        rho = np.sqrt(u * u + v * v)
        g = np.hypot(u / ax, v / ay)
        ell = np.where(g > 0.0, rho / np.where(g > 0.0, g, 1.0), min(ax, ay))
        h_c = self.h_contact
        h_e = self.edge_coef * ell
        dn = np.abs(rho - 1.0) * ell
        band = h_e + np.abs(h_c - h_e) * np.maximum(dn - self.width * ell, 0.0) / (TRANSITION * ell)
        r = np.hypot(x, y)
        rc = RHO_CONTACT * r / np.where(rho > 0.0, rho, 1.0)
        far = rc < L
        frac = np.where(far, np.minimum((r - rc) / np.where(far, L - rc, 1.0), 1.0), 0.0)
        zone = np.where(rho <= RHO_CONTACT, h_c, h_c + (self.h_far - h_c) * frac)
        return np.minimum(band, zone)

    def at_level(self, level: float) -> FittedSizes:
        """These sizes at another ``level`` (the contact extent kept, nothing recomputed):
        what :func:`fitted_sizes` gives at ``level``, to rounding."""
        level = _check_level(level)
        k = level / self.level
        return replace(
            self,
            h_contact=self.h_contact * k,
            edge_coef=self.edge_coef * k,
            h_far=min(C_FAR * self.L * level, self.L),
            level=level,
        )

    def estimate_elements(self, half: bool) -> float:
        """About how many triangles gmsh makes: ``int 4 / (sqrt(3) h^2) dA`` (polar midpoint rule)."""
        nr, nt = 500, 240
        r = (np.arange(nr) + 0.5) * self.L / nr
        span = math.pi if half else 2.0 * math.pi
        th = (np.arange(nt) + 0.5) * span / nt
        R, T = np.meshgrid(r, th)
        tot = float(np.sum(R / self.sizes(R * np.cos(T), R * np.sin(T)) ** 2))
        return tot * (self.L / nr) * (span / nt) * 4.0 / math.sqrt(3.0)

    def key(self, half: bool) -> dict:
        """Everything the mesh depends on (the cache key)."""
        import gmsh

        d = {k: float(f"{v:.12g}") for k, v in asdict(self).items() if k not in ("beta", "level")}
        d.update(
            half=bool(half),
            gmsh=gmsh.__version__,
            version=FITTED_VERSION,
            consts=[C_CONTACT, C_EDGE, TRANSITION, RHO_CONTACT],
        )
        if self.edge_coef * max(self.ax, self.ay) > self.h_contact:
            d["edge_band"] = 2  # the band grows from h_e (before: it shrank, down to 0)
        return d


def _check_level(level) -> float:
    if not (isinstance(level, (int, float, np.number)) and math.isfinite(level) and level > 0):
        raise MeshError(
            f"fitted mesh: level = {level!r} must be a positive finite number (1: default sizes, "
            "1/1.45: about twice the elements)"
        )
    return float(level)


def fitted_sizes(scene, t_end: float, level: float = 1.0) -> FittedSizes:
    """The size field fitted to ``scene`` over a run to ``t_end`` (every size times ``level``)."""
    level = _check_level(level)
    L = float(scene.domain.L)
    ax, ay = contact_extent(scene, t_end)
    floor = A_FLOOR * L
    ax, ay = max(ax, floor), max(ay, floor)
    beta = float(scene.fluid.beta)
    width = max(W_MIN, C_WIDTH * beta**WIDTH_EXPONENT)
    return FittedSizes(
        ax=ax,
        ay=ay,
        h_contact=min(C_CONTACT, C_CONTACT_EDGE * C_EDGE * width) * min(ax, ay) * level,
        edge_coef=C_EDGE * width * level,
        width=width,
        h_far=min(C_FAR * L * level, L),
        L=L,
        beta=beta,
        level=level,
    )


# ---------------------------------------------------------------------------
# mesh and cache


def _cache_path(sizes: FittedSizes, half: bool, cache_dir) -> pathlib.Path:
    key = json.dumps(sizes.key(half), sort_keys=True).encode()
    tag = hashlib.sha256(key).hexdigest()[:16]
    folder = pathlib.Path(CACHE_DIR if cache_dir is None else cache_dir).expanduser()
    return folder / f"fitted_{'half' if half else 'full'}-{tag}.msh"


def _renamed(dm: DiskMesh, name: str) -> DiskMesh:
    return DiskMesh(dm.mesh, dm.L, dm.half, name)


def fitted_disk(
    scene, t_end: float, level: float = 1.0, half: bool | None = None, *, cache: bool = True, cache_dir=None
) -> DiskMesh:
    """A gmsh mesh of the scene's disk refined at the contact of a run to ``t_end``.

    Parameters
    ----------
    scene : femehl.Scene
        The scene (indenter, substrate, motion, fluid beta, domain radius L).
    t_end : float
        End time of the run (the contact is the largest one in ``[0, t_end]``).
    level : float, default 1.0
        Multiplies every mesh size; ``1/1.45`` gives about twice the elements
        (one ladder rung), for convergence studies.
    half : bool or None, default None
        Half disk ``y >= 0``; None: the indenter's ``symmetric_y``.
    cache : bool, default True
        Look the mesh up in, and store it to, the cache folder.
    cache_dir : path, optional
        Cache folder, default :data:`CACHE_DIR` (``~/.cache/femehl/meshes``).
        The file name is a hash of the sizes, contact axes, L, half, the gmsh
        version and :data:`FITTED_VERSION`: a second call is a load.

    Returns
    -------
    DiskMesh
        Checked as by :func:`~femehl.discretize.mesh.load_mesh`; ``name`` is
        ``"fitted-<hash>"``.  Pass it as ``femehl.solve(scene, mesh=dm, ...)``.

    Raises
    ------
    MeshError
        For a bad ``level``, a half disk for an indenter not symmetric in y, or
        sizes that would make more than ``MAX_GMSH_ELEMENTS`` elements.
    """
    sym = bool(getattr(scene.indenter, "symmetric_y", False))
    half = sym if half is None else bool(half)
    if half and not sym:
        raise MeshError(
            "fitted_disk: half=True needs an indenter symmetric in y (symmetric_y); pass "
            "half=False (or None) for the full disk"
        )
    sizes = fitted_sizes(scene, t_end, level)
    path = _cache_path(sizes, half, cache_dir)
    name = f"fitted-{path.stem.split('-')[-1]}"
    if cache and path.is_file():
        try:
            return _renamed(load_mesh(path, L=sizes.L, half=half), name)
        except MeshError:
            pass  # a damaged cache file: regenerate it below
    ne = sizes.estimate_elements(half)
    if not ne <= MAX_GMSH_ELEMENTS:
        raise MeshError(
            f"fitted_disk: level = {sizes.level:g} would make about {ne:.3g} elements, more than "
            f"{MAX_GMSH_ELEMENTS:.0e}; pass a larger level"
        )
    check_mesh_memory(
        int(ne), int(ne / 2), f"fitted_disk(level={sizes.level:g}) (estimated)", operator="fast"
    )
    dm = sized_disk(sizes.L, half, sizes.size, name)
    if cache:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            _write_msh(dm, path)
        except OSError:
            pass  # an unwritable cache only costs the next call a remesh
    return dm
