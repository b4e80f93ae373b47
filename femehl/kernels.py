"""Exact Boussinesq integrals of a uniform pressure over triangles and polar cells.

Conventions (design.md section 4; paper Eq. 24-25)
-------------------------------------------------
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

__all__ = ["triangle_influence", "influence_matrix", "quad_influence"]

_BLOCK_BYTES = 64 * 2**20  # temporaries per block of rows


def _edge_term(ax, ay, bx, by, cx, cy):
    """Signed contribution of edge B -> C seen from A; arrays broadcast."""
    ex = cx - bx
    ey = cy - by
    le = np.hypot(ex, ey)
    with np.errstate(invalid="ignore", divide="ignore"):
        ex = ex / le
        ey = ey / le
        dbx = bx - ax
        dby = by - ay
        h = dbx * ey - dby * ex                # signed distance of A from line BC
        sb = dbx * ex + dby * ey               # positions along e from the foot of A
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
