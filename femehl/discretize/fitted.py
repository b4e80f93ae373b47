"""Meshes fitted to the scene: refined where the contact of *this* run is.

:func:`contact_extent` estimates the largest dry-contact semi-axes of the run,
:func:`fitted_sizes` turns them into a size field (a contact zone, an edge band of
half-width ``W(beta)``, a far field) and :func:`fitted_disk` meshes it with gmsh through
:func:`femehl.discretize.mesh.sized_disk` and caches it: ``femehl.solve(scene, t_end=5.0,
mesh=fitted_disk(scene, 5.0), scheme="bdf2")``.  The size field, the measurements behind
its constants and the accuracy against the mesh ladder: docs/design.md section 4
("Meshes fitted to the scene").
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
    """The size field of a fitted mesh (docs/design.md section 4).

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
