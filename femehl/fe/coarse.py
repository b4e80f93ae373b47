"""A coarse P1 space on any triangle mesh: the second level of the fast path's preconditioner.

The fast elastic operator's preconditioner is a sparse LU of the near field
(:class:`femehl.hmatrix.FastCompliance`): it misses the smooth far-field part of the
compliance, which is what left 13-19 fresh Krylov iterations per solve at 11,450 elements
(paper sphere).  A coarse space ``P`` (fine free nodes x coarse free nodes, the P1
interpolation from a coarse mesh) carries exactly those smooth modes; the coarse
correction (:class:`femehl.core.linsolve.TwoLevel`) solves them on a small dense Galerkin
system ``P^T A P``.

The coarse mesh is made from the fine mesh alone (any mesh: fitted, ladder, a user's
file): a subset of its nodes, spaced ``c`` times the local element size (greedy
Poisson-disk selection, finest regions first, so the coarse mesh keeps the fine mesh's
grading), with its rim nodes kept at the same spacing so that the coarse Delaunay
triangulation covers the domain; ``c`` is chosen for about ``m`` coarse free nodes.
Coarse rim nodes carry the fine mesh's Dirichlet condition (no column); a fine node the
coarse triangulation does not cover (rounding on the hull) takes its nearest coarse node.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.spatial import Delaunay, cKDTree

__all__ = ["coarse_prolongation", "node_sizes"]


def node_sizes(nodes: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Local element size at every node: sqrt of the mean area of the elements around it."""
    X = nodes[tri]  # (ne, 3, 2)
    area = 0.5 * np.abs(
        (X[:, 1, 0] - X[:, 0, 0]) * (X[:, 2, 1] - X[:, 0, 1])
        - (X[:, 2, 0] - X[:, 0, 0]) * (X[:, 1, 1] - X[:, 0, 1])
    )
    total = np.zeros(nodes.shape[0])
    count = np.zeros(nodes.shape[0])
    np.add.at(total, tri.ravel(), np.repeat(area, 3))
    np.add.at(count, tri.ravel(), 1.0)
    return np.sqrt(total / np.maximum(count, 1.0))


def _select(points: np.ndarray, radius: np.ndarray, order: np.ndarray) -> np.ndarray:
    """Greedy Poisson-disk subset: in ``order``, keep a point not within a kept one's radius."""
    tree = cKDTree(points)
    covered = np.zeros(points.shape[0], dtype=bool)
    kept = []
    for i in order:
        if covered[i]:
            continue
        kept.append(i)
        covered[tree.query_ball_point(points[i], radius[i])] = True
    return np.asarray(kept, dtype=np.int64)


def coarse_prolongation(nodes: np.ndarray, tri: np.ndarray, free: np.ndarray, m: int) -> tuple:
    """``(P, vertices)``: P1 interpolation from a coarse mesh, and its free vertices.

    ``nodes`` (nn, 2), ``tri`` (ne, 3) node indices, ``free`` the free (non-Dirichlet)
    nodes, in the order of the unknowns.  ``P`` (sparse CSR, fine free nodes x about
    ``m`` coarse free nodes) interpolates values at the coarse free vertices (0 at the
    coarse rim vertices); ``vertices`` are those vertices' indices into ``nodes``.  A
    row of ``P`` sums to 1 where the coarse triangle has no rim vertex.
    """
    nodes = np.asarray(nodes, dtype=float)
    free = np.asarray(free, dtype=np.int64)
    nn = nodes.shape[0]
    h = node_sizes(nodes, np.asarray(tri))
    is_free = np.zeros(nn, dtype=bool)
    is_free[free] = True
    order = np.argsort(h, kind="stable")  # finest first: the grading survives
    rim = order[~is_free[order]]
    inner = order[is_free[order]]
    c = max(2.0, np.sqrt(free.size / max(m, 1)))
    for _ in range(5):  # the spacing for about m coarse free nodes
        keep_in = _select(nodes[inner], c * h[inner], np.arange(inner.size))
        if abs(keep_in.size - m) <= 0.15 * m or free.size <= m:
            break
        c *= np.sqrt(keep_in.size / m)
    keep_in = inner[keep_in]
    keep_rim = rim[_select(nodes[rim], c * h[rim], np.arange(rim.size))] if rim.size else rim
    verts = np.concatenate([keep_in, keep_rim])
    col = np.full(verts.size, -1, dtype=np.int64)  # coarse vertex -> column (rim: none)
    col[: keep_in.size] = np.arange(keep_in.size)
    dl = Delaunay(nodes[verts])
    pts = nodes[free]
    s = dl.find_simplex(pts)
    rows, cols, vals = [], [], []
    ok = np.flatnonzero(s >= 0)
    if ok.size:
        T = dl.transform[s[ok]]  # barycentric coordinates
        b = np.einsum("nij,nj->ni", T[:, :2], pts[ok] - T[:, 2])
        bary = np.column_stack([b, 1.0 - b.sum(axis=1)])
        v = dl.simplices[s[ok]]
        cc = col[v]
        use = (cc >= 0) & (np.abs(bary) > 1e-14)
        rows.append(np.repeat(ok, 3)[use.ravel()])
        cols.append(cc[use])
        vals.append(bary[use])
    out = np.flatnonzero(s < 0)
    if out.size:  # on the hull within rounding: the nearest coarse vertex
        _, j = cKDTree(nodes[verts]).query(pts[out])
        cj = col[j]
        use = cj >= 0
        rows.append(out[use])
        cols.append(cj[use])
        vals.append(np.ones(int(use.sum())))
    P = sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(free.size, keep_in.size)
    )
    return P, keep_in
