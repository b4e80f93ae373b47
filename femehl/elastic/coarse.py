"""A coarse P1 space on any triangle mesh: the second level of the fast path's preconditioner.

The fast elastic operator's preconditioner is a sparse LU of the near field
(:class:`femehl.elastic.hmatrix.FastCompliance`): it misses the smooth far-field part of the
compliance, which is what left 13-19 fresh Krylov iterations per solve at 11,450 elements
(paper sphere).  A coarse space ``P`` (fine free nodes x coarse free nodes, the P1
interpolation from a coarse mesh) carries exactly those smooth modes; the coarse
correction (:class:`femehl.solver.linsolve.TwoLevel`) solves them on a small dense Galerkin
system ``P^T A P``.

The coarse mesh is made from the fine mesh alone (any mesh: fitted, ladder, a user's
file): a subset of its nodes, spaced ``c`` times the local element size (greedy
Poisson-disk selection, finest regions first, so the coarse mesh keeps the fine mesh's
grading), with its rim nodes kept at the same spacing so that the coarse Delaunay
triangulation covers the domain; ``c`` is chosen for about ``m`` coarse free nodes.
Coarse rim nodes carry the fine mesh's Dirichlet condition (no column), and the coarse
functions vanish on fine nodes outside the coarse triangulation (between a coarse rim
chord and the rim).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.spatial import Delaunay, cKDTree

__all__ = ["coarse_prolongation", "node_sizes", "boundary_corners"]


def node_sizes(mesh, areas: np.ndarray) -> np.ndarray:
    """Local element size at every node of ``mesh`` (skfem): sqrt of the mean of the
    ``areas`` (:func:`femehl.discretize.mesh.areas`) of the elements around it."""
    t = mesh.t.ravel()
    total = np.bincount(t, weights=np.tile(np.abs(areas), 3), minlength=mesh.p.shape[1])
    count = np.bincount(t, minlength=mesh.p.shape[1])
    return np.sqrt(total / np.maximum(count, 1))


def boundary_corners(mesh, angle: float = np.radians(20.0)) -> np.ndarray:
    """Boundary nodes of ``mesh`` (skfem) where the boundary turns by more than ``angle``
    (a half disk's two ends of the symmetry axis): kept in the coarse mesh, so that it
    covers the domain."""
    nodes = mesh.p.T
    b = mesh.facets[:, mesh.boundary_facets()].T  # boundary edges (node pairs)
    if b.size == 0:
        return np.zeros(0, dtype=np.int64)
    node = np.concatenate([b[:, 0], b[:, 1]])  # (node, boundary neighbour) both ways
    nbr = np.concatenate([b[:, 1], b[:, 0]])
    o = np.argsort(node, kind="stable")
    node, nbr = node[o], nbr[o]
    k, first, count = np.unique(node, return_index=True, return_counts=True)
    two = count == 2  # a node on one boundary curve: its two neighbours
    k, first = k[two], first[two]
    d1 = nodes[k] - nodes[nbr[first]]
    d2 = nodes[nbr[first + 1]] - nodes[k]
    cos = np.einsum("ij,ij->i", d1, d2) / (np.linalg.norm(d1, axis=1) * np.linalg.norm(d2, axis=1))
    return k[cos < np.cos(angle)]


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


def coarse_prolongation(mesh, areas: np.ndarray, free: np.ndarray, m: int) -> tuple:
    """``(P, vertices)``: P1 interpolation from a coarse mesh, and its free vertices.

    ``mesh`` the fine skfem mesh, ``areas`` its element areas, ``free`` the free
    (non-Dirichlet) nodes, in the order of the unknowns.  ``P`` (sparse CSR, fine free
    nodes x about ``m`` coarse free nodes) interpolates values at the coarse free
    vertices (0 at the coarse rim vertices); ``vertices`` are those vertices' indices
    into the mesh's nodes.  A row of ``P`` sums to 1 where the coarse triangle has no
    rim vertex.
    """
    nodes = mesh.p.T
    free = np.asarray(free, dtype=np.int64)
    h = node_sizes(mesh, areas)
    is_free = np.zeros(nodes.shape[0], dtype=bool)
    is_free[free] = True
    key = h.copy()
    key[boundary_corners(mesh)] = -1.0  # corners first: always kept
    order = np.argsort(key, kind="stable")  # then finest first: the grading survives
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
    s = dl.find_simplex(pts, tol=1e-10)
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
    # a fine node outside the coarse triangulation (between a coarse rim chord and the
    # rim) gets a zero row: the coarse functions vanish there, as at the coarse rim
    if rows:
        rows, cols, vals = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    P = sp.csr_matrix((vals, (rows, cols)), shape=(free.size, keep_in.size))
    return P, keep_in
