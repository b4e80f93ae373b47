"""Exact Boussinesq integrals of a uniform pressure over triangles and polar cells.

Conventions (docs/design.md, section 4; paper Eq. 24-25)
--------------------------------------------------------
The normalized deflection of an elastic half space under pressure p is
``w(x) = -c * int p(x') / |x - x'| dA'`` (Eq. 10b; c = 2(1 - nu), 1 for the
incompressible case).  This module computes the *kernel* part

    I(A, T) = int_T dA' / |A - x'|

exactly for a field point A and a triangle T, whatever A's position (inside,
on an edge, on a vertex, outside).  Split T into the three triangles
(A, P_i, P_i+1).  For an edge B -> C with unit vector e, signed distance
``hA = (B - A) x e`` of A from the line and positions ``sB = (B - A).e``,
``sC = (C - A).e`` along it, the triangle (A, B, C) contributes

    hA * ( asinh(sC/|hA|) - asinh(sB/|hA|) )

(the integral of 1/rho in polar coordinates about A, signed by the orientation
of (A, B, C), which is the sign of hA).  The sum over the three edges, times
the orientation sign of T, is I(A, T); an edge with hA = 0 contributes 0.
The paper's quadrilateral BCDE (Eq. 24) is two such triangles.

All functions are vectorized over field points and triangles and work in
row blocks so that memory stays at the size of the output matrix.
"""

from __future__ import annotations

import numpy as np

__all__ = ["triangle_influence", "influence_matrix", "quad_influence", "mesh_edges", "edge_terms"]

_BLOCK_BYTES = 64 * 2**20  # temporaries per block of rows


def _edge_term(ax, ay, bx, by, cx, cy):
    """Signed contribution of edge B -> C seen from A; arrays broadcast."""
    ex = cx - bx
    ey = cy - by
    le = np.hypot(ex, ey)
    # (overflow: A at a subnormal distance from the line BC; masked below like h = 0)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        ex = ex / le
        ey = ey / le
        dbx = bx - ax
        dby = by - ay
        h = dbx * ey - dby * ex  # signed distance of A from line BC
        sb = dbx * ex + dby * ey  # positions along e from the foot of A
        sc = (cx - ax) * ex + (cy - ay) * ey
        ah = np.abs(h)
        val = h * (np.arcsinh(sc / ah) - np.arcsinh(sb / ah))
    # an edge through A (h = 0) or of zero length contributes nothing
    return np.where((ah > 1e-300) & (le > 0.0), val, 0.0)


def triangle_influence(points, tri):
    """Exact ``int_T dA'/|A - x'|`` for every field point A and triangle T.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Field points A.
    tri : array_like, shape (m, 3, 2)
        Triangle vertices, any orientation.

    Returns
    -------
    numpy.ndarray, shape (n, m)
        Non-negative integrals (zero for a degenerate triangle).
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    tri = np.asarray(tri, dtype=float).reshape(-1, 3, 2)
    out = np.empty((pts.shape[0], tri.shape[0]))
    _fill(out, pts, tri, np.ones(tri.shape[0]))
    return out


def _orientation(tri):
    p0, p1, p2 = tri[:, 0], tri[:, 1], tri[:, 2]
    cross = (p1[:, 0] - p0[:, 0]) * (p2[:, 1] - p0[:, 1]) - (p1[:, 1] - p0[:, 1]) * (p2[:, 0] - p0[:, 0])
    return np.sign(cross)


def _fill(out, pts, tri, weight, accumulate=False):
    """out[i, j] (+)= weight[j] * I(pts[i], tri[j]), in row blocks."""
    m = tri.shape[0]
    sgn = _orientation(tri) * weight
    rows = max(1, _BLOCK_BYTES // (8 * 8 * max(m, 1)))
    vx = [tri[None, :, k, 0] for k in range(3)]
    vy = [tri[None, :, k, 1] for k in range(3)]
    for start in range(0, pts.shape[0], rows):
        stop = min(start + rows, pts.shape[0])
        ax = pts[start:stop, 0:1]
        ay = pts[start:stop, 1:2]
        acc = _edge_term(ax, ay, vx[0], vy[0], vx[1], vy[1])
        acc += _edge_term(ax, ay, vx[1], vy[1], vx[2], vy[2])
        acc += _edge_term(ax, ay, vx[2], vy[2], vx[0], vy[0])
        acc *= sgn[None, :]
        if accumulate:
            out[start:stop] += acc
        else:
            out[start:stop] = acc


def influence_matrix(points, tri, mirror_y=False, out=None):
    """Influence matrix ``X[i, j] = int_{T_j} dA'/|points_i - x'|`` (plus mirror image).

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Field points (element centroids for the FE solver).
    tri : array_like, shape (m, 3, 2)
        Source triangles carrying a uniform unit pressure.
    mirror_y : bool, default: False
        Add the image of every triangle in the line y = 0 (half-domain scenes
        that are symmetric in y: the pressure on the other half is the mirror).
    out : numpy.ndarray, optional
        Preallocated (n, m) float64 array to fill (avoids a second copy).

    Returns
    -------
    numpy.ndarray, shape (n, m)
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    tri = np.asarray(tri, dtype=float).reshape(-1, 3, 2)
    if out is None:
        out = np.empty((pts.shape[0], tri.shape[0]))
    _fill(out, pts, tri, np.ones(tri.shape[0]))
    if mirror_y:
        img = tri.copy()
        img[:, :, 1] *= -1.0
        _fill(out, pts, img, np.ones(tri.shape[0]), accumulate=True)
    return out


def quad_influence(points, quad):
    """Exact influence of uniform pressure on quadrilaterals (paper Eq. 24).

    Parameters
    ----------
    points : array_like, shape (n, 2)
    quad : array_like, shape (m, 4, 2)
        Vertices B, C, D, E of simple (convex) quadrilaterals, in order around
        the boundary; a repeated vertex (a triangle, as at r = 0) is allowed.

    Returns
    -------
    numpy.ndarray, shape (n, m)
    """
    q = np.asarray(quad, dtype=float).reshape(-1, 4, 2)
    t1 = q[:, [0, 1, 2], :]
    t2 = q[:, [0, 2, 3], :]
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    out = np.empty((pts.shape[0], q.shape[0]))
    # each half is signed by its own orientation, so it adds a non-negative
    # integral; a degenerate half (zero area) adds 0.
    w = np.ones(q.shape[0])
    _fill(out, pts, t1, w)
    _fill(out, pts, t2, w, accumulate=True)
    return out


# --------------------------------------------------------------------------
# fast path for meshes: one term per unique edge, shared by its two triangles
# --------------------------------------------------------------------------
def mesh_edges(t, nodes):
    """Unique edges of a triangulation and their signed incidence.

    Parameters
    ----------
    t : array_like of int, shape (3, ne)
        Triangle node indices (any orientation).
    nodes : array_like, shape (nn, 2)

    Returns
    -------
    edges : numpy.ndarray of int, shape (nedges, 2)
        Node pairs (B, C), each edge once.
    S : scipy.sparse.csr_matrix, shape (nedges, ne)
        ``I(A, T_j) = sum_k S[k, j] * edge_term(A, edge_k)``: the triangle's
        orientation sign times +1 where the triangle's cycle runs B -> C.
    """
    import scipy.sparse as sp

    t = np.asarray(t)
    nodes = np.asarray(nodes, dtype=float)
    ne = t.shape[1]
    tri = np.transpose(nodes[t], (1, 0, 2))
    sgn = _orientation(tri)
    a = np.concatenate([t[0], t[1], t[2]])
    b = np.concatenate([t[1], t[2], t[0]])
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = lo.astype(np.int64) * (nodes.shape[0] + 1) + hi
    uniq, inv = np.unique(key, return_inverse=True)
    edges = np.column_stack([uniq // (nodes.shape[0] + 1), uniq % (nodes.shape[0] + 1)]).astype(np.int64)
    direction = np.where(a == edges[inv, 0], 1.0, -1.0)
    cols = np.tile(np.arange(ne), 3)
    S = sp.csr_matrix((direction * np.tile(sgn, 3), (inv, cols)), shape=(edges.shape[0], ne))
    return edges, S


def edge_terms(points, nodes, edges, out=None):
    """``T[i, k] = h (asinh(sC/|h|) - asinh(sB/|h|))`` for A = points[i], edge k = (B, C).

    The same quantity as the per-edge term of :func:`triangle_influence`,
    written with the vertex distances rho = |B - A|, |C - A| as
    ``h * log((sC + rhoC)/(sB + rhoB))`` (or its mirror form when the foot of
    A lies beyond C, to avoid cancellation), so each term costs one log.
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    nodes = np.asarray(nodes, dtype=float)
    edges = np.asarray(edges)
    B, C = edges[:, 0], edges[:, 1]
    e = nodes[C] - nodes[B]
    le = np.hypot(e[:, 0], e[:, 1])
    ex, ey = e[:, 0] / le, e[:, 1] / le
    nE = edges.shape[0]
    if out is None:
        out = np.empty((pts.shape[0], nE))
    rows = max(1, _BLOCK_BYTES // (8 * 6 * max(nE, nodes.shape[0])))
    for s in range(0, pts.shape[0], rows):
        sl = slice(s, min(s + rows, pts.shape[0]))
        dx = nodes[None, :, 0] - pts[sl, 0:1]  # (rows, nn): vertex - A
        dy = nodes[None, :, 1] - pts[sl, 1:2]
        rho = np.hypot(dx, dy)
        bx, by = dx[:, B], dy[:, B]
        h = bx * ey - by * ex
        sb = bx * ex + by * ey
        sc = sb + le
        rb, rc = rho[:, B], rho[:, C]
        flip = (sb + sc) < 0.0
        num = np.where(flip, rb - sb, sc + rc)
        den = np.where(flip, rc - sc, sb + rb)
        with np.errstate(divide="ignore", invalid="ignore"):
            val = h * np.log(num / den)
        val[~(np.abs(h) > 1e-14 * le)] = 0.0
        out[sl] = val
    return out
