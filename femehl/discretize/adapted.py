"""Meshes adapted to a run: sizes from where its film and pressure curve most.

:func:`adapted_sizes` reads a finished FE run (every stored state) and returns an
:class:`AdaptedSizes`, a size field ``level * s(x)`` whose meshes (:meth:`AdaptedSizes.mesh`,
gmsh through :func:`femehl.discretize.mesh.sized_disk`) put their cells at the exit
constriction, the inlet and the contact rim.  The indicator, the calibration and the
measurements: docs/design.md section 4 ("Meshes adapted to a run").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from femehl.discretize.mesh import DiskMesh, LinearSizes, sized_disk
from femehl.errors import MeshError, SceneError

__all__ = ["AdaptedSizes", "adapted_sizes", "curvature_indicator"]

#: the sizes of neighbouring cells differ by at most this slope (|grad h| <= GRADE)
GRADE = 0.25
#: the indicator is capped at CAP times its area-weighted 99th percentile, so a singular
#: point (a punch's edge) does not take the cells a finite feature needs (sizes go at most
#: sqrt(CAP) = 4 times below the percentile's)
CAP = 16.0
#: a state's pressure curvature is relative to its peak, at least this fraction of the run's
PEAK_FLOOR = 0.01
#: no size above this fraction of the domain radius
H_MAX = 0.25
#: calibration passes of the size field's scale to the wanted cell count
PASSES = 4
#: cells of an area at size h: an equilateral triangle of side h has area sqrt(3)/4 h^2
_CELLS_PER_H2 = 4.0 / math.sqrt(3.0)


def _to_nodes(t: np.ndarray, n: int, areas: np.ndarray, ve: np.ndarray) -> np.ndarray:
    """Area-weighted average of the element values ``ve`` at the ``n`` nodes."""
    acc, w = np.zeros(n), np.zeros(n)
    for k in range(3):
        np.add.at(acc, t[k], areas * ve)
        np.add.at(w, t[k], areas)
    return acc / w


def _gradient(p: np.ndarray, t: np.ndarray, vn: np.ndarray) -> tuple:
    """The gradient of the linear interpolant of the nodal ``vn`` on each triangle."""
    x1, y1 = p[:, t[0]]
    x2, y2 = p[:, t[1]]
    x3, y3 = p[:, t[2]]
    det = (x2 - x1) * (y3 - y1) - (x3 - x1) * (y2 - y1)
    f1, f2, f3 = vn[t[0]], vn[t[1]], vn[t[2]]
    gx = ((f2 - f1) * (y3 - y1) - (f3 - f1) * (y2 - y1)) / det
    gy = ((f3 - f1) * (x2 - x1) - (f2 - f1) * (x3 - x1)) / det
    return gx, gy


def _hessian_norm(p, t, areas, vn) -> np.ndarray:
    """Per triangle, the largest |eigenvalue| of the recovered Hessian of ``vn``: the
    gradient of the nodal average of the elements' gradients."""
    n = p.shape[1]
    gx, gy = _gradient(p, t, vn)
    hxx, hxy = _gradient(p, t, _to_nodes(t, n, areas, gx))
    hyx, hyy = _gradient(p, t, _to_nodes(t, n, areas, gy))
    hxy = 0.5 * (hxy + hyx)
    half_trace = 0.5 * (hxx + hyy)
    root = np.sqrt(np.maximum(half_trace**2 - (hxx * hyy - hxy * hxy), 0.0))
    return np.abs(half_trace) + root


def curvature_indicator(disc, state, floor: float = 0.0) -> np.ndarray:
    """Per cell of an FE disk ``disc``: ``max(|H d| / d, |H p| / max(max|p|, floor))`` at
    ``state``, the recovered Hessians of the film (relative to the local film: a thin film's
    relative error is the one the minimum film shows) and of the pressure (relative to its
    peak, the load's error; at least ``floor``)."""
    mesh = disc.mesh
    p, t, areas = mesh.p, mesh.t, disc.areas
    n = p.shape[1]
    d = np.asarray(state.d, dtype=float)
    film = _hessian_norm(p, t, areas, _to_nodes(t, n, areas, d)) / np.maximum(d, 1e-300)
    pn = np.zeros(n)
    pv = np.asarray(state.p, dtype=float)
    if pv.size == n:
        pn = pv
    else:
        pn[disc.free] = pv
    peak = max(float(np.max(np.abs(pn))), float(floor))
    if not peak > 0.0:
        return film
    return np.maximum(film, _hessian_norm(p, t, areas, pn) / peak)


@dataclass(frozen=True, eq=False)
class AdaptedSizes:
    """The size field ``level * s(x)`` of meshes adapted to a run.

    ``s`` is given at the ``nodes`` of the run's mesh (linear on its ``triangles``),
    graded and scaled so that ``level = 1`` makes about ``cells`` cells.
    """

    L: float
    half: bool
    nodes: np.ndarray  # (2, n)
    triangles: np.ndarray  # (3, ne)
    s: np.ndarray  # (n,), level-1 sizes
    source: str = "a run"

    def cells(self, level: float) -> float:
        """The cells a mesh at ``level`` would have (no mesh is built)."""
        level = _check_level(level)
        return _cells(self.nodes, self.triangles, self.s * level)

    def size(self, level: float = 1.0) -> LinearSizes:
        """``h(x, y)`` at ``level``: the linear interpolant of ``level * s`` (its largest
        value outside the run's triangles)."""
        level = _check_level(level)
        return LinearSizes(self.nodes, self.triangles, self.s * level, float(np.max(self.s) * level))

    def record(self) -> dict:
        """The field as JSON-able lists (a run folder's plan), :meth:`from_record` reads it."""
        return {
            "L": self.L,
            "half": self.half,
            "nodes": self.nodes.tolist(),
            "triangles": self.triangles.tolist(),
            "s": self.s.tolist(),
            "source": self.source,
        }

    @classmethod
    def from_record(cls, rec: dict) -> AdaptedSizes:
        return cls(
            float(rec["L"]),
            bool(rec["half"]),
            np.asarray(rec["nodes"], dtype=float),
            np.asarray(rec["triangles"], dtype=np.int64),
            np.asarray(rec["s"], dtype=float),
            str(rec.get("source", "a run")),
        )

    def mesh(self, level: float = 1.0) -> DiskMesh:
        """The (half) disk meshed by gmsh at ``level``."""
        return sized_disk(
            self.L, self.half, self.size(level), name=f"adapted to {self.source}, level {level:.3g}"
        )


def _check_level(level) -> float:
    if isinstance(level, bool) or not isinstance(level, int | float) or not (0.0 < level < math.inf):
        raise SceneError(f"level must be a positive number (1: the calibrated cells), got {level!r}.")
    return float(level)


def _cells(p, t, h_nodes) -> float:
    x, y = p[:, t]
    a = 0.5 * np.abs((x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]))
    he = np.mean(h_nodes[t], axis=0)
    return float(np.sum(_CELLS_PER_H2 * a / he**2))


def _graded(p, t, s_nodes, grade) -> np.ndarray:
    """``s`` lowered until ``s_i <= s_j + grade |x_i - x_j|`` along every edge."""
    e = np.concatenate([t[[0, 1]], t[[1, 2]], t[[2, 0]]], axis=1)
    length = np.hypot(*(p[:, e[0]] - p[:, e[1]]))
    s = s_nodes.copy()
    for _ in range(10 * p.shape[1]):
        before = s.copy()
        np.minimum.at(s, e[0], s[e[1]] + grade * length)
        np.minimum.at(s, e[1], s[e[0]] + grade * length)
        if np.array_equal(before, s):
            break
    return s


def adapted_sizes(result, cells: float, *, grade: float = GRADE) -> AdaptedSizes:
    """The sizes of meshes adapted to ``result`` (an FE run), about ``cells`` cells at level 1.

    The indicator (:func:`curvature_indicator`) is the largest over the run's stored states
    (all of them: the features move, the mesh serves the whole run), capped at :data:`CAP`
    times its area-weighted 99th percentile.  A size ``s ~ indicator^(-1/2)`` equidistributes
    the linear interpolation error; it is graded (:data:`GRADE`), capped at :data:`H_MAX`
    ``L`` and scaled to ``cells``.
    """
    disc = getattr(result, "disc", None)
    if disc is None or not hasattr(disc, "mesh") or not hasattr(disc, "areas"):
        raise SceneError("adapted_sizes needs a finished FE disk run (method 'fe') with its discretization.")
    states = [s for s in result.states if s.t > 0.0]
    if not states:
        raise SceneError("adapted_sizes needs a run with stored states after t = 0 (store_every >= 1).")
    if not (isinstance(cells, int | float) and not isinstance(cells, bool) and cells >= 10):
        raise SceneError(f"cells must be a number >= 10, got {cells!r}.")
    mesh = disc.mesh
    p, t, areas = mesh.p, mesh.t, disc.areas
    # a state's pressure relative to its own peak, but at least PEAK_FLOOR of the run's: the
    # weak pressure of the first steps (the initial layer, t ~ 1e-6) does not shape the mesh
    floor = PEAK_FLOOR * max(float(np.max(np.abs(np.asarray(s.p, dtype=float)))) for s in states)
    m = np.zeros(t.shape[1])
    for state in states:
        m = np.maximum(m, curvature_indicator(disc, state, floor))
    if not np.all(np.isfinite(m)) or not np.any(m > 0.0):
        raise MeshError("the run's film and pressure give no finite curvature to adapt a mesh to.")
    order = np.argsort(m)
    share = np.cumsum(areas[order]) / np.sum(areas)
    p99 = float(m[order][np.searchsorted(share, 0.99)])
    m = np.clip(m, 1e-6 * p99, CAP * p99)
    s_elem = 1.0 / np.sqrt(m)
    s0 = np.full(p.shape[1], np.inf)
    for k in range(3):
        np.minimum.at(s0, t[k], s_elem)
    h_max = H_MAX * float(disc.L)
    scale = math.sqrt(_cells(p, t, s0) / cells)
    for _ in range(PASSES):
        s = _graded(p, t, np.minimum(scale * s0, h_max), grade)
        scale *= math.sqrt(_cells(p, t, s) / cells)
    s = _graded(p, t, np.minimum(scale * s0, h_max), grade)
    return AdaptedSizes(
        float(disc.L), bool(disc.half), p.copy(), t.copy(), s, source=f"a run on {t.shape[1]} cells"
    )
