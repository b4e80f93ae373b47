"""Exact Boussinesq integrals of a uniform pressure over triangles and polar cells.

``I(A, T) = int_T dA' / |A - x'|`` exactly for any field point A (inside, on or outside the
triangle T), one ``asinh`` term per edge (paper Eq. 24), vectorized over field points and
triangles in row blocks; and radial kernels ``a/r - R(r)`` (an elastic layer,
:mod:`femehl.elastic.layer_kernel`), their smooth part by the 7-point rule or the polar
edge integrals, assembled sparse, dense, low-rank or by an FFT on a grid.  The formulas:
docs/design.md section 4 ("Exact influence of a uniform pressure on a triangle") and
section 14.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from femehl.elastic.dense import in_rows

__all__ = [
    "triangle_influence",
    "influence_matrix",
    "quad_influence",
    "mesh_edges",
    "edge_terms",
    "edge_products",
    "radial_influence",
    "sparse_radial_influence",
    "radial_triangle_pairs",
    "smooth_matrix",
    "smooth_pairs",
    "singular_pairs",
    "near_pairs",
    "pair_fraction",
]

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


def edge_terms(points, nodes, edges, out=None, mirror=False):
    """``T[i, k] = h (asinh(sC/|h|) - asinh(sB/|h|))`` for A = points[i], edge k = (B, C).

    The same quantity as the per-edge term of :func:`triangle_influence`,
    written with the vertex distances rho = |B - A|, |C - A| as
    ``h * log((sC + rhoC)/(sB + rhoB))`` (or its mirror form when the foot of
    A lies beyond C, to avoid cancellation), so each term costs one log.
    ``mirror``: minus the term of the edge mirrored in ``y = 0`` (a half disk's image),
    which is the term seen from A mirrored, ``(x, -y)``.
    """
    pts, nodes, B, C = _edge_arrays(points, nodes, edges)
    if out is None:
        out = np.empty((pts.shape[0], B.shape[0]))
    return _edge_rows(pts, nodes, B, C, bool(mirror), out)


def edge_products(points, nodes, edges, SP, mirror=False):
    """``T SP`` (:func:`edge_terms` times a sparse ``SP``, nedges x m) without forming ``T``.

    Each row of T lives in one scratch row while it is contracted with the columns of SP
    (CSC), so an n x nedges T is never written: the dense influence ``X P = T (S P)`` of a
    mesh (:meth:`femehl.discretize.fe_disk.FEDisk.boussinesq`) in one pass.
    """
    import scipy.sparse as sp

    pts, nodes, B, C = _edge_arrays(points, nodes, edges)
    SP = sp.csc_matrix(SP)
    if SP.shape[0] != B.shape[0]:
        raise ValueError(f"SP has {SP.shape[0]} rows for {B.shape[0]} edges")
    SP.sort_indices()
    out = np.empty((pts.shape[0], SP.shape[1]))
    indptr, indices = SP.indptr.astype(np.int64), SP.indices.astype(np.int64)
    args = (pts, nodes, B, C, bool(mirror), indptr, indices, SP.data, out)
    in_rows(lambda i0, i1: _edge_products(*args, i0, i1), pts.shape[0])
    return out


def _edge_arrays(points, nodes, edges):
    pts = np.ascontiguousarray(np.asarray(points, dtype=float).reshape(-1, 2))
    nodes = np.ascontiguousarray(np.asarray(nodes, dtype=float))
    edges = np.asarray(edges, dtype=np.int64)
    return pts, nodes, *(np.ascontiguousarray(edges[:, k]) for k in (0, 1))


@numba.njit(cache=True, boundscheck=False)
def _edge_frames(nodes, B, C):  # pragma: no cover - compiled
    """Per edge: its length, unit direction and first vertex, as contiguous arrays."""
    nE = B.shape[0]
    frame = np.empty((5, nE))
    for k in range(nE):
        x = nodes[C[k], 0] - nodes[B[k], 0]
        y = nodes[C[k], 1] - nodes[B[k], 1]
        le = math.hypot(x, y)
        frame[0, k], frame[1, k], frame[2, k] = le, x / le, y / le
        frame[3, k], frame[4, k] = nodes[B[k], 0], nodes[B[k], 1]
    return frame


@numba.njit(cache=True, inline="always")
def _edge_log(h, sb, sc, rho_b, rho_c):  # pragma: no cover - compiled
    """An edge B -> C seen from A: ``h log((s_C + rho_C) / (s_B + rho_B))``, ``h`` the signed
    distance of A from the edge's line, ``s`` the vertices' positions along it from A's
    foot, ``rho`` their distances from A.  Each factor in the form that adds two positive
    numbers (``s + rho = h^2 / (rho - s)``): no cancellation wherever the foot lies (the
    former form, ``s + rho`` as it comes, lost up to 4e-10 relative near an edge's line
    and divided by zero a hair from the inside of an edge)."""
    num = sc + rho_c if sc >= 0.0 else h * h / (rho_c - sc)
    den = sb + rho_b if sb >= 0.0 else h * h / (rho_b - sb)
    return h * math.log(num / den)


@numba.njit(cache=True, boundscheck=False)
def _edge_row(ax, ay, nodes, B, C, frame, mirror, rho, row):  # pragma: no cover - compiled
    """``row[k]``: the term of edge k seen from A = (ax, ay), minus the mirrored edge's
    (``mirror``), which is the term seen from A mirrored, (ax, -ay).  ``rho`` (2, nodes):
    scratch for the vertex distances from A and from its mirror image."""
    le, ex, ey, xb, yb = frame[0], frame[1], frame[2], frame[3], frame[4]
    images = 2 if mirror else 1
    for m in range(images):
        ay_m = ay if m == 0 else -ay
        for j in range(nodes.shape[0]):
            dx = nodes[j, 0] - ax
            dy = nodes[j, 1] - ay_m
            rho[m, j] = math.sqrt(dx * dx + dy * dy)
    for k in range(B.shape[0]):
        val = 0.0
        for m in range(images):
            bx = xb[k] - ax
            by = yb[k] - (ay if m == 0 else -ay)
            h = bx * ey[k] - by * ex[k]  # signed distance of A from the edge's line
            if abs(h) > 1e-14 * le[k]:
                sb = bx * ex[k] + by * ey[k]  # positions of B and C along the edge from A's foot
                val += _edge_log(h, sb, sb + le[k], rho[m, B[k]], rho[m, C[k]])
        row[k] = val


@numba.njit(cache=True, boundscheck=False)
def _edge_rows(pts, nodes, B, C, mirror, out):  # pragma: no cover - compiled
    frame = _edge_frames(nodes, B, C)
    rho = np.empty((2, nodes.shape[0]))
    for i in range(pts.shape[0]):
        _edge_row(pts[i, 0], pts[i, 1], nodes, B, C, frame, mirror, rho, out[i])
    return out


@numba.njit(cache=True, nogil=True, boundscheck=False)
def _edge_products(pts, nodes, B, C, mirror, indptr, indices, data, out, i0, i1):  # pragma: no cover
    """Rows ``i0:i1`` of :func:`edge_products` (no GIL held: rows split among threads)."""
    frame = _edge_frames(nodes, B, C)
    rho = np.empty((2, nodes.shape[0]))
    row = np.empty(B.shape[0])
    for i in range(i0, i1):
        _edge_row(pts[i, 0], pts[i, 1], nodes, B, C, frame, mirror, rho, row)
        for j in range(out.shape[1]):
            acc = 0.0
            for q in range(indptr[j], indptr[j + 1]):
                acc += data[q] * row[indices[q]]
            out[i, j] = acc
    return out


# --------------------------------------------------------------------------
# radial kernels g(r) = a/r - R(r), R smooth (an elastic layer, femehl.elastic.layer_kernel)
# --------------------------------------------------------------------------
#: Dunavant's 7-point rule on the triangle, exact for degree 5: barycentric points, weights
_G7_A1, _G7_B1 = 0.059715871789770, 0.470142064105115
_G7_A2, _G7_B2 = 0.797426985353087, 0.101286507323456
_G7_BARY = np.array(
    [
        [1 / 3, 1 / 3, 1 / 3],
        [_G7_A1, _G7_B1, _G7_B1],
        [_G7_B1, _G7_A1, _G7_B1],
        [_G7_B1, _G7_B1, _G7_A1],
        [_G7_A2, _G7_B2, _G7_B2],
        [_G7_B2, _G7_A2, _G7_B2],
        [_G7_B2, _G7_B2, _G7_A2],
    ]
)
_G7_W = np.array([0.225, *[0.132394152788506] * 3, *[0.125939180544827] * 3])

#: a triangle whose diameter is at most this times the kernel's ``scale`` is integrated by
#: the 7-point rule (error about 4e-5 (diameter/scale)^6 of area / scale: 1e-8 at the limit,
#: 4e-11 at scale/10, against subdivided rules), a larger one by the polar edge integrals
SMALL_TRIANGLE = 0.25
#: polar edge integrals: Gauss-Legendre points per piece, pieces at most this times ``scale``
#: (<= 5e-13 of area / scale against 16 points on pieces of scale / 4, tests/test_layer.py)
EDGE_GAUSS = 8
EDGE_PIECE = 2.0
_GL_X, _GL_W = np.polynomial.legendre.leggauss(EDGE_GAUSS)


def triangle_diameters(tri):
    """Longest edge of each triangle (m, 3, 2) -> (m,)."""
    tri = np.asarray(tri, dtype=float).reshape(-1, 3, 2)
    d = [np.hypot(*(tri[:, (k + 1) % 3] - tri[:, k]).T) for k in range(3)]
    return np.maximum(np.maximum(d[0], d[1]), d[2])


def triangle_areas(tri):
    tri = np.asarray(tri, dtype=float).reshape(-1, 3, 2)
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    return 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])


def singular_pairs(points, tri, i, j):
    """Exact ``int_{T_j} dA'/|A_i - x'|`` for the pairs (i[k], j[k])."""
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    tri = np.asarray(tri, dtype=float).reshape(-1, 3, 2)
    ax, ay = pts[i, 0], pts[i, 1]
    v = tri[j]
    acc = _edge_term(ax, ay, v[:, 0, 0], v[:, 0, 1], v[:, 1, 0], v[:, 1, 1])
    acc += _edge_term(ax, ay, v[:, 1, 0], v[:, 1, 1], v[:, 2, 0], v[:, 2, 1])
    acc += _edge_term(ax, ay, v[:, 2, 0], v[:, 2, 1], v[:, 0, 0], v[:, 0, 1])
    return acc * _orientation(v)


def _smooth_gauss(pts, tri, i, j, kernel):
    v = tri[j]  # (k, 3, 2)
    x = np.einsum("qa,kac->kqc", _G7_BARY, v)  # (k, 7, 2)
    rho = np.hypot(x[..., 0] - pts[i, 0, None], x[..., 1] - pts[i, 1, None])
    return triangle_areas(v) * (kernel.smooth(rho) @ _G7_W)


def _smooth_edge(ax, ay, bx, by, cx, cy, kernel):
    """``hA int_{sB}^{sC} F(rho(s)) ds`` of edge B -> C seen from A (1-D arrays)."""
    ex, ey = cx - bx, cy - by
    le = np.hypot(ex, ey)
    with np.errstate(invalid="ignore", divide="ignore"):
        ex, ey = ex / le, ey / le
    dbx, dby = bx - ax, by - ay
    h = dbx * ey - dby * ex
    sb = dbx * ex + dby * ey
    sc = sb + le
    ah = np.abs(h)
    cut = kernel.cutoff
    with np.errstate(invalid="ignore"):
        sig = np.sqrt(np.maximum(cut * cut - h * h, 0.0)) if np.isfinite(cut) else np.full_like(h, np.inf)
    s1 = np.clip(sb, -sig, sig)
    s2 = np.clip(sc, -sig, sig)
    out = np.zeros_like(h)
    ok = (ah > 1e-300) & (le > 0.0)
    # far parts [sb, s1] and [s2, sc]: F = a/rho - tail/rho^2 exactly
    far = ok & ((sb < s1) | (s2 < sc))
    if far.any():
        a, tail = kernel.singular, kernel.tail
        hf, ahf = h[far], ah[far]

        def prim(s):
            return hf * (a * np.arcsinh(s / ahf)) - tail * np.sign(hf) * np.arctan(s / ahf)

        out[far] = prim(s1[far]) - prim(sb[far]) + prim(sc[far]) - prim(s2[far])
    # near part [s1, s2]: composite Gauss-Legendre, pieces <= EDGE_PIECE * scale
    near = np.flatnonzero(ok & (s2 > s1))
    if near.size:
        length = s2[near] - s1[near]
        m = np.maximum(1, np.ceil(length / (EDGE_PIECE * kernel.scale))).astype(np.int64)
        # group by the power of two >= m so that each group is one array operation
        groups = np.ceil(np.log2(m)).astype(np.int64)
        for gpow in np.unique(groups):
            sel = near[groups == gpow]
            mm = 1 << int(gpow)
            lo, w = s1[sel], (s2[sel] - s1[sel]) / mm
            for start in range(0, sel.size, max(1, 2**21 // (mm * EDGE_GAUSS))):
                sl = slice(start, start + max(1, 2**21 // (mm * EDGE_GAUSS)))
                k = np.arange(mm)[None, :, None]
                s = lo[sl, None, None] + w[sl, None, None] * (k + 0.5 * (_GL_X[None, None, :] + 1.0))
                rho = np.hypot(h[sel][sl, None, None], s)
                val = kernel.smooth_edge(rho.ravel()).reshape(rho.shape)
                out[sel[sl]] += h[sel][sl] * 0.5 * w[sl] * np.einsum("kmq,q->k", val, _GL_W)
    return out


def _smooth_polar(pts, tri, i, j, kernel):
    v = tri[j]
    ax, ay = pts[i, 0], pts[i, 1]
    acc = np.zeros(i.size)
    for a, b in ((0, 1), (1, 2), (2, 0)):
        acc += _smooth_edge(ax, ay, v[:, a, 0], v[:, a, 1], v[:, b, 0], v[:, b, 1], kernel)
    return acc * _orientation(v)


def smooth_pairs(points, tri, i, j, kernel, small=None):
    """``int_{T_j} R(|A_i - x'|) dA'`` of the kernel's smooth part R for the pairs (i, j).

    A triangle of diameter <= ``SMALL_TRIANGLE * kernel.scale`` takes the 7-point Gauss
    rule (R is analytic), a larger one the polar form about A: the triangle (A, B, C) of
    each edge B -> C contributes ``hA int_{sB}^{sC} F(sqrt(hA^2 + s^2)) ds`` with
    ``F(r) = (1/r^2) int_0^r s R(s) ds`` (the exact polar integral of R, a smooth function
    of r^2; ``F = 1/r`` gives the ``asinh`` terms of :func:`triangle_influence`), by
    composite Gauss-Legendre on pieces of at most ``EDGE_PIECE * scale`` within the
    cut-off and in closed form beyond it.  Exact whatever the triangle's size.

    Parameters
    ----------
    points : array_like, shape (n, 2)
    tri : array_like, shape (m, 3, 2)
    i, j : array_like of int, shape (k,)
        The pairs (field point, triangle).
    kernel : object
        ``scale``, ``cutoff``, ``singular``, ``tail``, ``smooth(r)``, ``smooth_edge(r)``
        (see :class:`femehl.elastic.layer_kernel.LayerKernel`).
    small : numpy.ndarray of bool, shape (m,), optional
        Which triangles take the Gauss rule (default: by diameter as above).

    Returns
    -------
    numpy.ndarray, shape (k,)
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    tri = np.asarray(tri, dtype=float).reshape(-1, 3, 2)
    i, j = np.asarray(i, dtype=np.intp), np.asarray(j, dtype=np.intp)
    if small is None:
        small = triangle_diameters(tri) <= SMALL_TRIANGLE * kernel.scale
    out = np.empty(i.size)
    g = small[j]
    if g.any():
        out[g] = _smooth_gauss(pts, tri, i[g], j[g], kernel)
    if (~g).any():
        out[~g] = _smooth_polar(pts, tri, i[~g], j[~g], kernel)
    return out


def radial_triangle_pairs(points, tri, i, j, kernel):
    """``int_{T_j} g(|A_i - x'|) dA'`` for ``g = singular/r - R``: the exact 1/r part minus
    :func:`smooth_pairs`."""
    return kernel.singular * singular_pairs(points, tri, i, j) - smooth_pairs(points, tri, i, j, kernel)


def near_pairs(points, tri, radius):
    """Pairs (i, j) with triangle j possibly within ``radius`` of point i (KD-tree).

    A triangle is kept when its centroid lies within ``radius`` plus its largest
    centroid-to-vertex distance, so every triangle that reaches into the disk is found.
    """
    from scipy.spatial import cKDTree

    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    tri = np.asarray(tri, dtype=float).reshape(-1, 3, 2)
    cen = tri.mean(axis=1)
    reach = np.max(np.hypot(*(tri - cen[:, None, :]).transpose(2, 0, 1)), axis=1)
    big = float(reach.max()) if reach.size else 0.0
    D = cKDTree(pts).sparse_distance_matrix(cKDTree(cen), radius + big, output_type="ndarray")
    i, j = D["i"].astype(np.intp), D["j"].astype(np.intp)
    keep = D["v"] <= radius + reach[j]  # (zero distances are kept: output_type ndarray)
    return i[keep], j[keep]


def pair_fraction(points, tri, radius, sample=256):
    """Estimated fraction of the (point, triangle) pairs :func:`near_pairs` would return."""
    from scipy.spatial import cKDTree

    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    tri = np.asarray(tri, dtype=float).reshape(-1, 3, 2)
    cen = tri.mean(axis=1)
    reach = float(np.max(np.hypot(*(tri - cen[:, None, :]).transpose(2, 0, 1)))) if tri.size else 0.0
    sel = np.random.default_rng(0).choice(pts.shape[0], min(sample, pts.shape[0]), replace=False)
    counts = cKDTree(cen).query_ball_point(pts[sel], radius + reach, return_length=True)
    return float(np.mean(counts)) / max(cen.shape[0], 1)


def smooth_matrix(points, tri, kernel, mirror_y=False):
    """Dense ``X_R[i, j] = int_{T_j} R(|A_i - x'|) dA'`` (plus the mirror image y -> -y).

    Small triangles (see :func:`smooth_pairs`) by the 7-point rule for a block of rows at
    once, the others by the polar edge integrals.
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    tri = np.asarray(tri, dtype=float).reshape(-1, 3, 2)
    n, m = pts.shape[0], tri.shape[0]
    out = np.zeros((n, m))
    sources = [tri]
    if mirror_y:
        sources.append(tri * np.array([1.0, -1.0]))
    for src in sources:
        small = triangle_diameters(src) <= SMALL_TRIANGLE * kernel.scale
        js = np.flatnonzero(small)
        jl = np.flatnonzero(~small)
        if js.size:
            x = np.einsum("qa,kac->kqc", _G7_BARY, src[js])  # (ms, 7, 2)
            wa = triangle_areas(src[js])[:, None] * _G7_W[None, :]  # (ms, 7)
            xs, ys = x[..., 0].ravel(), x[..., 1].ravel()
            rows = max(1, _BLOCK_BYTES // (8 * 6 * xs.size))
            for s in range(0, n, rows):
                sl = slice(s, min(s + rows, n))
                rho = np.hypot(xs[None, :] - pts[sl, 0:1], ys[None, :] - pts[sl, 1:2])
                val = kernel.smooth(rho.ravel()).reshape(rho.shape[0], js.size, 7)
                out[sl, js] += np.einsum("rkq,kq->rk", val, wa)
        if jl.size:
            i = np.repeat(np.arange(n), jl.size)
            j = np.tile(jl, n)
            out[i, j] += _smooth_polar(pts, src, i, j, kernel)
    return out


def sparse_radial_influence(points, tri, kernel, mirror_y=False, dense_fraction=0.25):
    """The matrix of :func:`radial_influence` as CSR, or None where it is not sparse.

    None when the kernel has no finite cut-off, or when the pairs within its reach (a
    KD-tree) are at least ``dense_fraction`` of all pairs.
    """
    import scipy.sparse as sp

    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    tri = np.asarray(tri, dtype=float).reshape(-1, 3, 2)
    n, m = pts.shape[0], tri.shape[0]
    if not np.isfinite(kernel.cutoff):
        return None
    allp = np.vstack([pts, tri.reshape(-1, 2)])
    if kernel.cutoff >= 2.0 * np.hypot(*(allp.max(axis=0) - allp.min(axis=0))):
        return None  # every pair (mirror images included) is within reach
    sources = [tri] + ([tri * np.array([1.0, -1.0])] if mirror_y else [])
    if pair_fraction(pts, tri, kernel.cutoff) >= 1.2 * dense_fraction:
        return None  # (the estimate, before the pairs are found)
    pairs = [near_pairs(pts, src, kernel.cutoff) for src in sources]
    if sum(p[0].size for p in pairs) >= dense_fraction * n * m * len(sources):
        return None
    X = sp.csr_matrix((n, m))
    for src, (i, j) in zip(sources, pairs, strict=True):
        vals = radial_triangle_pairs(pts, src, i, j, kernel)
        X = X + sp.csr_matrix((vals, (i, j)), shape=(n, m))
    return X.tocsr()


def radial_influence(points, tri, kernel, mirror_y=False, dense_fraction=0.25):
    """``X[i, j] = int_{T_j} g(|A_i - x'|) dA'`` for a radial kernel ``g = singular/r - R``.

    Sparse (CSR) when the kernel's cut-off leaves fewer than ``dense_fraction`` of the
    pairs (the others are zero to the kernel's tolerance, see :mod:`femehl.elastic.layer_kernel`):
    the pairs within reach by a KD-tree, each by :func:`radial_triangle_pairs`
    (:func:`sparse_radial_influence`).  Otherwise dense: ``singular * influence_matrix -
    smooth_matrix``.  The mirror images (``mirror_y``) add to the same columns.

    Returns
    -------
    numpy.ndarray or scipy.sparse.csr_matrix, shape (n, m)
    """
    X = sparse_radial_influence(points, tri, kernel, mirror_y, dense_fraction)
    if X is not None:
        return X
    X = influence_matrix(points, tri, mirror_y=mirror_y)
    if kernel.singular != 1.0:
        X *= kernel.singular
    X -= smooth_matrix(points, tri, kernel, mirror_y=mirror_y)
    return X


def _cheb_nodes(lo, hi, p):
    k = np.arange(p)
    return 0.5 * (lo + hi) + 0.5 * (hi - lo) * np.cos(np.pi * (2 * k + 1) / (2 * p))


def _lagrange(x, nodes):
    """Lagrange basis of the Chebyshev ``nodes`` (first kind) at ``x``: (len(x), p), barycentric."""
    p = nodes.size
    k = np.arange(p)
    w = (-1.0) ** k * np.sin(np.pi * (2 * k + 1) / (2 * p))
    d = x[:, None] - nodes[None, :]
    exact = d == 0.0
    d[exact] = 1.0
    L = w[None, :] / d
    L /= L.sum(axis=1, keepdims=True)
    rows = np.flatnonzero(exact.any(axis=1))
    if rows.size:
        L[rows] = exact[rows].astype(float)
    return L


def _mirrored_source_points(tri, kernel, mirror_y):
    """:func:`_source_points`, with their mirror images in y = 0 appended when ``mirror_y``."""
    xq, wq, owner = _source_points(tri, kernel)
    if mirror_y:
        xq = np.vstack([xq, xq * np.array([1.0, -1.0])])
        wq, owner = np.r_[wq, wq], np.r_[owner, owner]
    return xq, wq, owner


def _source_points(tri, kernel):
    """Gauss points (7 per piece) and weights of triangles, each split into k^2 congruent
    pieces of diameter <= SMALL_TRIANGLE * scale: (points (q, 2), weights (q,), triangle (q,))."""
    diam = triangle_diameters(tri)
    k = np.maximum(1, np.ceil(diam / (SMALL_TRIANGLE * kernel.scale))).astype(np.int64)
    xs, ws, owner = [], [], []
    for kk in np.unique(k):
        sel = np.flatnonzero(k == kk)
        v = tri[sel]
        # barycentric coordinates of the pieces' vertices: the k^2 sub-triangles
        sub = []
        for a in range(kk):
            for b in range(kk - a):
                sub.append([(a, b), (a + 1, b), (a, b + 1)])
                if a + b < kk - 1:
                    sub.append([(a + 1, b), (a + 1, b + 1), (a, b + 1)])
        sub = np.array(sub, dtype=float) / kk  # (k^2, 3, 2): coordinates along e1, e2
        lam = np.concatenate([1.0 - sub.sum(axis=2, keepdims=True), sub], axis=2)  # (k^2, 3, 3)
        bary = np.einsum("qa,sab->sqb", _G7_BARY, lam).reshape(-1, 3)  # (k^2 * 7, 3)
        xs.append(np.einsum("qb,tbc->tqc", bary, v).reshape(-1, 2))
        area = triangle_areas(v)
        ws.append((area[:, None] * np.tile(_G7_W, sub.shape[0])[None, :] / sub.shape[0]).ravel())
        owner.append(np.repeat(sel, bary.shape[0]))
    return np.concatenate(xs), np.concatenate(ws), np.concatenate(owner)


#: the low-rank smooth part is used up to this many Chebyshev points per direction
LOWRANK_MAX_P = 40


def smooth_lowrank(points, tri, kernel, mirror_y=False, tol=1e-9, max_p=LOWRANK_MAX_P):
    """``X_R ~ S K Q`` by tensor Chebyshev interpolation of ``R(|x - y|)`` on one box.

    R is analytic on the kernel's ``scale``; on a box of half-width W about the points and
    sources, ``p`` points per direction interpolate it to about ``(a + sqrt(1 + a^2))^-p``,
    ``a = 2 scale / W``.  ``p`` starts from that estimate and grows until 400 random
    (point, source) pairs agree with the direct ``R`` to ``tol * R(0)``; None when that
    needs more than ``max_p`` (the direct :func:`smooth_matrix` is then cheaper).  The
    sources are the 7-point rule on each triangle split into pieces of diameter <=
    ``SMALL_TRIANGLE * scale``, so ``S K Q`` is :func:`smooth_matrix` up to the
    interpolation error.

    Returns
    -------
    (S, K, Q) with shapes (n, p^2), (p^2, p^2), (p^2, m), or None
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    tri = np.asarray(tri, dtype=float).reshape(-1, 3, 2)
    xq, wq, owner = _mirrored_source_points(tri, kernel, mirror_y)
    allp = np.vstack([pts, xq])
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    W = 0.5 * float(np.max(hi - lo))
    a = 2.0 * kernel.scale / max(W, 1e-300)
    p = int(np.ceil(np.log(1.0 / tol) / np.log(a + np.sqrt(1.0 + a * a))))
    p = max(p, 4)
    rng = np.random.default_rng(0)
    ti = rng.integers(0, pts.shape[0], 400)
    si = rng.integers(0, xq.shape[0], 400)
    ref = kernel.smooth(np.hypot(*(pts[ti] - xq[si]).T))
    scale0 = float(kernel.smooth(np.zeros(1))[0])
    while p <= max_p:
        nx, ny = _cheb_nodes(lo[0], hi[0], p), _cheb_nodes(lo[1], hi[1], p)
        gx, gy = np.meshgrid(nx, ny, indexing="ij")
        g = np.column_stack([gx.ravel(), gy.ravel()])

        def basis(x, nx=nx, ny=ny):
            Lx, Ly = _lagrange(x[:, 0], nx), _lagrange(x[:, 1], ny)
            return (Lx[:, :, None] * Ly[:, None, :]).reshape(x.shape[0], -1)

        K = kernel.smooth(np.hypot(g[:, None, 0] - g[None, :, 0], g[:, None, 1] - g[None, :, 1]))
        approx = np.einsum("ia,ab,ib->i", basis(pts[ti]), K, basis(xq[si]))
        if np.max(np.abs(approx - ref)) <= tol * scale0:
            import scipy.sparse as sp

            S = basis(pts)
            Q = np.zeros((p * p, tri.shape[0]))
            block = max(1, 2**22 // (p * p))
            for s in range(0, xq.shape[0], block):
                sl = slice(s, s + block)
                B = basis(xq[sl]) * wq[sl, None]
                agg = sp.csr_matrix(
                    (np.ones(B.shape[0]), (owner[sl], np.arange(B.shape[0]))),
                    shape=(tri.shape[0], B.shape[0]),
                )
                Q += (agg @ B).T
            return S, K, Q
        p = int(np.ceil(1.25 * p))
    return None


def _local_lagrange(u, q):
    """Weights and first index of the degree-q Lagrange interpolation on the integer grid.

    For each coordinate ``u`` (in grid units) the q + 1 nodes ``i0 .. i0 + q`` around it
    (``u`` in the middle cell) and their Lagrange weights: (i0 (k,), W (k, q + 1)).
    """
    i0 = np.floor(u).astype(np.intp) - (q // 2)
    s = u - i0  # in [q//2, q//2 + 1)
    W = np.ones((u.size, q + 1))
    for k in range(q + 1):
        for m in range(q + 1):
            if m != k:
                W[:, k] *= (s - m) / (k - m)
    return i0, W


#: grid smooth part: spacing ``scale / GRID_PER_SCALE``, local Lagrange degree GRID_DEGREE
GRID_PER_SCALE = 6.0
GRID_DEGREE = 11


def smooth_grid_apply(points, tri, kernel, columns, mirror_y=False, batch=64):
    """``X_R @ columns`` by a uniform grid: ``R(|x - y|)`` interpolated in x and in y by local
    Lagrange polynomials (degree :data:`GRID_DEGREE`, spacing ``scale/GRID_PER_SCALE``), the
    grid-to-grid part a discrete convolution (FFT).  The sources are the 7-point rule on the
    triangles split into pieces of diameter <= ``SMALL_TRIANGLE * scale``.

    Parameters
    ----------
    points : (n, 2) targets; tri : (m, 3, 2) source triangles
    columns : sparse or dense (m, k): the element values to apply X_R to (e.g. ``P``)

    Returns
    -------
    numpy.ndarray, shape (n, k)
    """
    import scipy.sparse as sp

    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    tri = np.asarray(tri, dtype=float).reshape(-1, 3, 2)
    xq, wq, owner = _mirrored_source_points(tri, kernel, mirror_y)
    q = GRID_DEGREE
    d = kernel.scale / GRID_PER_SCALE
    allp = np.vstack([pts, xq])
    lo = allp.min(axis=0) - (q // 2 + 1) * d
    hi = allp.max(axis=0) + (q // 2 + 2) * d
    nx, ny = (np.ceil((hi - lo) / d).astype(int) + 1).tolist()

    def interp(x):
        ix, Wx = _local_lagrange((x[:, 0] - lo[0]) / d, q)
        iy, Wy = _local_lagrange((x[:, 1] - lo[1]) / d, q)
        k = np.arange(q + 1)
        cols = (ix[:, None, None] + k[None, :, None]) * ny + (iy[:, None, None] + k[None, None, :])
        vals = Wx[:, :, None] * Wy[:, None, :]
        rows = np.repeat(np.arange(x.shape[0]), (q + 1) ** 2)
        return sp.csr_matrix((vals.ravel(), (rows, cols.ravel())), shape=(x.shape[0], nx * ny))

    LT = interp(pts)
    # anterpolation: grid weights of every triangle (sum over its points)
    A = sp.csr_matrix(
        (np.ones(xq.shape[0]), (owner, np.arange(xq.shape[0]))), shape=(tri.shape[0], xq.shape[0])
    )
    A = (A @ (interp(xq).multiply(wq[:, None]).tocsr())).T.tocsr()  # (grid, m)
    Y = A @ columns
    Y = Y.toarray() if sp.issparse(Y) else np.asarray(Y)
    # the kernel on grid offsets, for a linear convolution of an (nx, ny) grid
    from scipy import fft

    fx, fy = fft.next_fast_len(2 * nx - 1, real=True), fft.next_fast_len(2 * ny - 1, real=True)
    ox = np.arange(fx, dtype=float)
    ox[ox >= nx] -= fx  # circular offsets: every offset in (-nx, nx) once
    oy = np.arange(fy, dtype=float)
    oy[oy >= ny] -= fy
    Kf = fft.rfft2(kernel.smooth(d * np.hypot(ox[:, None], oy[None, :])))
    out = np.empty((pts.shape[0], Y.shape[1]))
    for s in range(0, Y.shape[1], batch):
        blk = Y[:, s : s + batch].T.reshape(-1, nx, ny)
        conv = fft.irfft2(fft.rfft2(blk, s=(fx, fy)) * Kf[None], s=(fx, fy))[:, :nx, :ny]
        out[:, s : s + batch] = LT @ conv.reshape(conv.shape[0], -1).T
    return out


def smooth_cost_estimates(points, tri, kernel, mirror_y=False, ncols=None):
    """Estimated seconds of the direct (:func:`smooth_matrix`) and the grid
    (:func:`smooth_grid_apply`) smooth part on this machine class (measured constants:
    180 ns per kernel evaluation, 5 ns per grid point and log2 per column FFT pair)."""
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    tri = np.asarray(tri, dtype=float).reshape(-1, 3, 2)
    diam = triangle_diameters(tri)
    small = diam <= SMALL_TRIANGLE * kernel.scale
    evals = np.where(
        small, 7.0, 3.0 * EDGE_GAUSS * np.maximum(1.0, np.ceil(diam / (EDGE_PIECE * kernel.scale)))
    )
    mult = 2.0 if mirror_y else 1.0
    direct = 180e-9 * pts.shape[0] * mult * float(evals.sum())
    allp = np.vstack([pts, tri.reshape(-1, 2)] + ([tri.reshape(-1, 2) * [1.0, -1.0]] if mirror_y else []))
    ext = allp.max(axis=0) - allp.min(axis=0)
    g = (ext / (kernel.scale / GRID_PER_SCALE) + GRID_DEGREE + 4) * 2.0
    npts = float(g[0] * g[1])
    grid = 5e-9 * npts * np.log2(npts) * (tri.shape[0] if ncols is None else ncols)
    return direct, grid
