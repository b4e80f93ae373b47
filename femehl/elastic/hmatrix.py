"""A hierarchical (H^2) approximation of the Boussinesq operator: memory and work O(N log N).

The dense operator ``X[i, j] = int_{T_j} dA' / |c_i - x'|`` (:mod:`femehl.elastic.kernels`)
as an exact sparse near field plus Chebyshev-interpolated admissible blocks on two cluster
trees (the "black-box FMM" of Fong and Darve 2009), the far factors stored in single
precision at the default tolerance and used in double: :class:`FastCompliance`, whose near
field is also the fast path's preconditioner (:mod:`femehl.solver.linsolve`).  The format,
the one parameter ``operator_tol`` and the measurements behind its defaults:
docs/design.md section 10.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numba
import numpy as np
import scipy.sparse as sp

from femehl.elastic.kernels import _edge_log
from femehl.validation import (
    check_admissibility,
    check_chebyshev_order,
    check_int,
    check_operator_tol,
    check_svd_ratio,
)

__all__ = [
    "ClusterTree",
    "FastCompliance",
    "FastOptions",
    "H2Operator",
    "cluster_tree",
    "order_for",
    "pair_influence",
    "sampled_error",
]


# ---- small pieces -----------------------------------------------------------------------
def pair_influence(points, tri):
    """Exact ``int_{T_k} dA' / |A_k - x'|`` for paired field points and triangles (k = 0..m-1)."""
    points = np.ascontiguousarray(points, dtype=float)
    tri = np.ascontiguousarray(tri, dtype=float)
    k = np.arange(points.shape[0])
    return _pairs(points, tri, k, k)


@numba.njit(cache=True, boundscheck=False)
def _pairs(points, tri, I, J):  # pragma: no cover (compiled)
    """``int_{T_J[k]} dA' / |A_I[k] - x'|`` without gathered copies of the points and
    triangles: the edge terms of the dense operator (``kernels._edge_log``,
    nothing from an edge through A or of zero length), the three vertex distances shared."""
    out = np.empty(I.size)
    rho = np.empty(3)
    for k in range(I.size):
        ax, ay = points[I[k], 0], points[I[k], 1]
        t = tri[J[k]]
        for v in range(3):
            rho[v] = math.sqrt((t[v, 0] - ax) ** 2 + (t[v, 1] - ay) ** 2)
        acc = 0.0
        for e in range(3):
            f = (e + 1) % 3
            bx, by = t[e, 0] - ax, t[e, 1] - ay
            ex, ey = t[f, 0] - t[e, 0], t[f, 1] - t[e, 1]
            le = math.sqrt(ex * ex + ey * ey)
            if le > 0.0:
                ex, ey = ex / le, ey / le
                h = bx * ey - by * ex
                if abs(h) > 1e-14 * le:
                    sb = bx * ex + by * ey
                    acc += _edge_log(h, sb, sb + le, rho[e], rho[f])
        cross = (t[1, 0] - t[0, 0]) * (t[2, 1] - t[0, 1]) - (t[1, 1] - t[0, 1]) * (t[2, 0] - t[0, 0])
        out[k] = acc if cross > 0.0 else (-acc if cross < 0.0 else 0.0)
    return out


def _cheb(p):
    return np.cos((2.0 * np.arange(p) + 1.0) * np.pi / (2.0 * p))  # in (-1, 1)


def _lagrange(s, nodes):
    """``l_k(s)`` for scaled coordinates ``s`` (m,) and nodes (p,): (m, p).

    ``prod_{j != k} (s - x_j)`` as the product of the factors before ``k`` and after it
    (running products both ways): exact at a node too, and p passes instead of p^2."""
    p = nodes.size
    diff = s[None, :] - nodes[:, None]  # (p, m): rows contiguous
    before = np.empty_like(diff)
    after = np.empty_like(diff)
    before[0] = after[p - 1] = 1.0
    for k in range(1, p):
        np.multiply(before[k - 1], diff[k - 1], out=before[k])
        np.multiply(after[p - k], diff[p - k], out=after[p - 1 - k])
    denom = np.array([np.prod(nodes[k] - np.delete(nodes, k)) for k in range(p)])
    before *= after
    before /= denom[:, None]
    return before.T


def _triangle_rule(degree):
    """Collapsed Gauss-Legendre rule on the reference triangle, exact to ``degree``.

    Returns barycentric coordinates (q, 3) and weights (q,) summing to 1.
    """
    n = degree // 2 + 1
    x, w = np.polynomial.legendre.leggauss(n)
    u, v = (x + 1.0) / 2.0, w / 2.0
    U, V = np.meshgrid(u, u, indexing="ij")
    WU, WV = np.meshgrid(v, v, indexing="ij")
    # Duffy: (a, b) in the square -> (a, (1 - a) b); Jacobian (1 - a); one extra degree in a
    a, b = U.ravel(), V.ravel()
    lam1, lam2 = a, (1.0 - a) * b
    wts = (WU * WV).ravel() * (1.0 - a) * 2.0
    return np.column_stack([1.0 - lam1 - lam2, lam1, lam2]), wts / wts.sum()


# ---- cluster trees ----------------------------------------------------------------------
@dataclass
class ClusterTree:
    """Bisection tree: node ``k`` holds ``perm[start[k]:stop[k]]`` inside box ``lo[k]..hi[k]``."""

    perm: np.ndarray
    start: np.ndarray
    stop: np.ndarray
    lo: np.ndarray  # (nodes, 2)
    hi: np.ndarray
    left: np.ndarray  # -1 at a leaf
    right: np.ndarray
    parent: np.ndarray
    depth: np.ndarray

    @property
    def size(self):
        return self.stop - self.start

    @property
    def leaf(self):
        return self.left < 0

    @property
    def diam(self):
        return np.hypot(*(self.hi - self.lo).T)


def cluster_tree(centers, lo_items, hi_items, leaf: int = 32) -> ClusterTree:
    """Split at the median of the centres along the longest side until ``<= leaf`` items."""
    n = centers.shape[0]
    perm = np.arange(n)
    start, stop, parent, depth = [0], [n], [-1], [0]
    left, right = [-1], [-1]
    k = 0
    while k < len(start):
        s, e = start[k], stop[k]
        if e - s > leaf:
            idx = perm[s:e]
            c = centers[idx]
            axis = int(np.argmax(c.max(axis=0) - c.min(axis=0)))
            half = (e - s) // 2
            order = np.argpartition(c[:, axis], half)
            perm[s:e] = idx[order]
            for a, b in ((s, s + half), (s + half, e)):
                start.append(a)
                stop.append(b)
                parent.append(k)
                depth.append(depth[k] + 1)
                left.append(-1)
                right.append(-1)
            left[k], right[k] = len(start) - 2, len(start) - 1
        k += 1
    start, stop = np.array(start), np.array(stop)
    # boxes of the items (sources: whole triangles), by a reduction over the permuted order
    lo_p, hi_p = lo_items[perm], hi_items[perm]
    lo = np.array([lo_p[a:b].min(axis=0) for a, b in zip(start, stop, strict=True)])
    hi = np.array([hi_p[a:b].max(axis=0) for a, b in zip(start, stop, strict=True)])
    # a box of zero width (points on a line): widen it a little; interpolation is exact in any box
    scale = float(np.max(hi[0] - lo[0])) or 1.0
    thin = (hi - lo) < 1e-9 * scale
    mid = 0.5 * (hi + lo)
    lo = np.where(thin, mid - 0.5e-9 * scale, lo)
    hi = np.where(thin, mid + 0.5e-9 * scale, hi)
    return ClusterTree(
        perm, start, stop, lo, hi, np.array(left), np.array(right), np.array(parent), np.array(depth)
    )


#: admissible blocks whose couplings are compressed at a time (a chunk's kernel matrices
#: take FAR_CHUNK x p^4 x 8 bytes: 15 MB at p = 11, reused by the allocator; chunks of
#: 2,048 blocks, 240 MB fresh each, spent a quarter of the far field's set-up in page
#: faults on the benchmark machine)
FAR_CHUNK = 128
#: columns of the random range finder of the couplings (:func:`_low_rank`) at first, and
#: the margin kept above the largest rank found: at p = 11 and 3e-7 the ranks are 7-22
RANGE_WIDTH, RANGE_MARGIN = 32, 10


def _low_rank(K, tol, width):
    """Leading singular triplets of each coupling block ``K[b]`` (n x n), down to ``tol``.

    Yields ``(blocks, u, s, vt)`` (``K[blocks] ~ u diag(s) vt`` with at least the singular
    values above ``tol * s[:, 0]``).  A random range finder of ``width`` columns (Halko,
    Martinsson and Tropp 2011, with a fixed seed): ``Q = orth(K Omega)``, the SVD of
    ``Q^T K`` (width x n).  Its residual ``||K - Q Q^T K||_F`` is computed; a block where it
    exceeds ``0.1 tol s_0`` gets the full SVD instead.  So every block's truncation error
    is at most 1.1 times that of its own full SVD, at a quarter of its cost (1.5 ms for
    121 x 121 on the benchmark machine).
    """
    b, n, _ = K.shape
    if width >= n:
        u, s, vt = np.linalg.svd(K)
        yield np.arange(b), u, s, vt
        return
    omega = np.random.default_rng(20261206).standard_normal((n, width))
    Q = np.linalg.qr((K.reshape(-1, n) @ omega).reshape(b, n, width))[0]
    B = np.matmul(Q.transpose(0, 2, 1), K)
    R = K - np.matmul(Q, B)
    residual = np.sqrt(np.einsum("bij,bij->b", R, R))
    ub, s, vt = np.linalg.svd(B, full_matrices=False)
    ok = residual <= 0.1 * tol * s[:, 0]
    good = np.flatnonzero(ok)
    if good.size:
        yield good, np.matmul(Q[good], ub[good]), s[good], vt[good]
    bad = np.flatnonzero(~ok)
    if bad.size:
        u, s, vt = np.linalg.svd(K[bad])
        yield bad, u, s, vt


def _box_distance(lo1, hi1, lo2, hi2):
    gap = np.maximum(0.0, np.maximum(lo1 - hi2, lo2 - hi1))
    return np.hypot(gap[:, 0], gap[:, 1])


def _partition(T, S, eta):
    """Admissible (far) and near leaf pairs of the block tree, level by level (vectorized)."""
    pt, ps = np.array([0]), np.array([0])
    far_t, far_s, near_t, near_s = [], [], [], []
    dT, dS = T.diam, S.diam
    while pt.size:
        dist = _box_distance(T.lo[pt], T.hi[pt], S.lo[ps], S.hi[ps])
        adm = np.maximum(dT[pt], dS[ps]) <= eta * dist
        far_t.append(pt[adm])
        far_s.append(ps[adm])
        pt, ps = pt[~adm], ps[~adm]
        lt, ls = T.leaf[pt], S.leaf[ps]
        both = lt & ls
        near_t.append(pt[both])
        near_s.append(ps[both])
        split_t = ~lt & (ls | (dT[pt] >= dS[ps]))
        split_s = ~both & ~split_t
        a, b = pt[split_t], ps[split_t]
        c, d = pt[split_s], ps[split_s]
        pt = np.concatenate([T.left[a], T.right[a], c, c])
        ps = np.concatenate([b, b, S.left[d], S.right[d]])
    cat = np.concatenate
    return cat(far_t), cat(far_s), cat(near_t), cat(near_s)


def _grid(lo, hi, nodes):
    """Chebyshev grid points of boxes: (boxes, p, 2) per axis positions."""
    return lo[:, None, :] + (hi - lo)[:, None, :] * (nodes[None, :, None] + 1.0) / 2.0


def _scaled(x, lo, hi):
    return (2.0 * x - (lo + hi)) / (hi - lo)


@numba.njit(cache=True, boundscheck=False)
def _kernel_blocks(gt, gs):  # pragma: no cover (compiled)
    """``1 / |x - y|`` between the Chebyshev grids of paired boxes: (blocks, p^2, p^2).

    ``gt``, ``gs`` (blocks, p, 2): each box's nodes per axis; grid point ``a p + b`` is
    ``(g[a, 0], g[b, 1])`` (the order of the moments and local expansions)."""
    nb, p = gt.shape[0], gt.shape[1]
    K = np.empty((nb, p * p, p * p))
    for k in range(nb):
        for a in range(p):
            for b in range(p):
                i = a * p + b
                for c in range(p):
                    dx = gt[k, a, 0] - gs[k, c, 0]
                    for d in range(p):
                        dy = gt[k, b, 1] - gs[k, d, 1]
                        K[k, i, c * p + d] = 1.0 / np.sqrt(dx * dx + dy * dy)
    return K


@numba.njit(cache=True, fastmath={"reassoc", "contract"}, boundscheck=False)
def _couple(L, Mf, ft, fs, Ut, V):  # pragma: no cover (compiled)
    """``L[ft[b]] += Ut[b]^T (V[b] Mf[fs[b]])`` for every admissible block ``b``.

    One fused pass over the factors: they are read once, in their storage precision,
    and every product and sum is in double precision (``float32 * float64`` is a
    double), so the operator is the same linear map at every call.  It replaces two
    einsums and a sparse scatter: 21.1 -> 9.5 ms on 44,792 elements (single-precision
    factors; 16.2 ms in double).
    """
    nb, r, k = V.shape
    m = np.empty(k)
    for b in range(nb):
        s, d = fs[b], ft[b]
        for j in range(k):
            m[j] = Mf[s, j]
        for i in range(r):
            acc = 0.0
            for j in range(k):
                acc += V[b, i, j] * m[j]
            for j in range(k):
                L[d, j] += Ut[b, i, j] * acc


@numba.njit(cache=True, fastmath={"reassoc", "contract"}, boundscheck=False)
def _couple_columns(L, Mf, ft, fs, Ut, V, blocks):  # pragma: no cover (compiled)
    """:func:`_couple` of k columns at once (``L``, ``Mf``: clusters x p^2 x k), over the
    admissible blocks ``blocks`` only (those whose source cluster has moments)."""
    r, pp, k = V.shape[1], V.shape[2], Mf.shape[2]
    t = np.empty((r, k))
    for b in blocks:
        s, d = fs[b], ft[b]
        t[:] = 0.0
        for i in range(r):
            for a in range(pp):
                v = V[b, i, a]
                for j in range(k):
                    t[i, j] += v * Mf[s, a, j]
        for i in range(r):
            for a in range(pp):
                w = Ut[b, i, a]
                for j in range(k):
                    L[d, a, j] += w * t[i, j]


# ---- the operator -----------------------------------------------------------------------
class H2Operator:
    """``X u`` for element values ``u``: near field exact, far field interpolated.

    Parameters
    ----------
    targets : (n, 2) array
        Field points (element centroids).
    tri : (m, 3, 2) array
        Source triangles (mirror images included).
    source_element : (m,) int array
        Which unknown each source triangle carries (its own element, or the element it is
        the image of): ``X u`` sums ``int_{T_j} / |c_i - x'| u[source_element[j]]``.
    n_unknowns : int
        Length of ``u``.
    p : int, default: 9
        Chebyshev points per axis (:func:`order_for` gives it for a relative error).
    eta : float, default: 2.0
        Admissibility: ``max(diam) <= eta dist`` (the fast compliance uses :data:`ETA`).
    leaf : int, default: 64
        Items per leaf cluster (64 and eta = 2 were the fastest and smallest of the
        tried (leaf, eta, p) = (32, 2, 9), (48, 2, 9), (32, 1.5, 8), (96, 2.5, 10) at the
        same random-vector error; for the films' error eta = 2.5 at p = 11, :data:`ETA`).
    svd_tol : float, default: 1e-9
        Relative singular-value truncation of the interpolated blocks.
    rank_step : int, default: :data:`RANK_STEP`
        The blocks' ranks rounded up to a multiple of this (blocks of one rank are
        grouped for the product).
    factor_dtype : numpy dtype, default: float64
        Storage of the blocks' low-rank factors (``float32``: half the memory and half
        the far field's time; a relative rounding of about 6e-8 of each factor, measured
        5.3e-8 of the far part; the products and sums stay in double, see
        :func:`_couple`).
    keep : callable, optional
        ``keep(i, j) -> mask`` of near-field entries (target ``i``, source ``j``) to return
        also in :attr:`kept` as ``(rows, element columns, values)``.
    fold : sparse matrix (n_unknowns, m), optional
        Act on ``z`` with ``u = fold @ z`` instead (``X fold``): the near field is stored
        with ``fold`` multiplied in, a group of rows at a time (for the FE disk ``fold``
        is the element average ``P`` of the P1 pressure: about half the entries).
    """

    def __init__(
        self,
        targets,
        tri,
        source_element,
        n_unknowns,
        p=9,
        eta=2.0,
        leaf=64,
        svd_tol=1e-9,
        keep=None,
        fold=None,
        factor_dtype=np.float64,
        rank_step=None,
    ):
        t0 = time.perf_counter()
        self.p, self.eta, self.leaf = int(p), float(eta), int(leaf)
        self.rank_step = RANK_STEP if rank_step is None else int(rank_step)
        self.factor_dtype = np.dtype(factor_dtype)
        targets = np.asarray(targets, dtype=float)
        tri = np.asarray(tri, dtype=float)
        self.n_targets, self.n_sources = targets.shape[0], tri.shape[0]
        self.n_unknowns = int(n_unknowns)
        self.source_element = np.asarray(source_element)
        fold = None if fold is None else sp.csr_matrix(fold)
        self.n_cols = self.n_unknowns if fold is None else fold.shape[1]
        # gather the unknowns to the sources (sparse so a mirror image sums with its element)
        G = sp.csr_matrix(
            (np.ones(self.n_sources), (np.arange(self.n_sources), self.source_element)),
            shape=(self.n_sources, self.n_unknowns),
        )
        cen = tri.mean(axis=1)
        T = cluster_tree(targets, targets, targets, leaf)
        S = cluster_tree(cen, tri.min(axis=1), tri.max(axis=1), leaf)
        self.T, self.S = T, S
        t1 = time.perf_counter()
        ft, fs, nt, ns = _partition(T, S, self.eta)
        self.n_far, self.n_near = ft.size, nt.size
        t2 = time.perf_counter()
        nodes = _cheb(self.p)
        self._near_perm, self.kept = self._near_field(targets, tri, T, S, nt, ns, keep, fold)
        t3 = time.perf_counter()
        self._build_bases(targets, tri, nodes)
        # the gather to the sources and the fold go into the leaf moments: one sparse
        # product from the columns of z (fewer entries: a leaf's triangles share nodes,
        # 7.26 -> 5.63 million on 44,792 elements, 5.0 -> 3.1 ms)
        self._P2M = (self._P2M @ (G if fold is None else G @ fold)).tocsr()
        self._build_far(nodes, ft, fs, svd_tol)
        t4 = time.perf_counter()
        self.info = {
            "p": self.p,
            "eta": self.eta,
            "leaf": self.leaf,
            "rank_step": self.rank_step,
            "far_blocks": int(self.n_far),
            "near_blocks": int(self.n_near),
            "near_nnz": int(self._near_perm.nnz),
            "far_rank_mean": float(self._rank_mean),
            "tree_s": t1 - t0,
            "partition_s": t2 - t1,
            "near_s": t3 - t2,
            "far_s": t4 - t3,
            "bytes": int(self.nbytes),
        }

    # -- set-up ---------------------------------------------------------------------------
    def _near_field(self, targets, tri, T, S, nt, ns, keep=None, fold=None):
        """Exact entries of every near leaf pair: sparse, rows in the target tree's order.

        Built a group of target leaves at a time (a contiguous row range), so the peak
        memory is the matrix plus one group.  ``keep(i, j_source)`` -> bool mask selects
        the entries also returned as ``(rows, element columns, values)`` (the
        preconditioner's), in natural row order.  ``fold`` (sparse, unknowns x columns)
        is multiplied into each group.
        """
        order = np.argsort(T.start[nt], kind="stable")
        nt, ns = nt[order], ns[order]
        mt, ms = T.size[nt], S.size[ns]
        sizes = mt * ms
        leaf_start = np.flatnonzero(np.r_[True, nt[1:] != nt[:-1]]) if nt.size else np.zeros(0, int)
        csum = np.cumsum(sizes)
        chunks, kept = [], []
        budget = 1_000_000
        lo = 0
        while lo < nt.size:
            # extend to whole target leaves, about `budget` entries
            base = csum[lo - 1] if lo else 0
            hi = int(np.searchsorted(csum, base + budget, side="right"))
            hi = max(hi, lo + 1)
            nxt = leaf_start[leaf_start >= hi]
            hi = int(nxt[0]) if nxt.size else nt.size
            bt, bs, bm, bsz = nt[lo:hi], ns[lo:hi], ms[lo:hi], sizes[lo:hi]
            blk = np.repeat(np.arange(hi - lo), bsz)
            k = np.arange(blk.size) - np.repeat(np.cumsum(bsz) - bsz, bsz)
            row = T.start[bt][blk] + k // bm[blk]  # position in T.perm
            J = S.perm[S.start[bs][blk] + k % bm[blk]]
            I = T.perm[row]
            v = _pairs(targets, tri, I, J)
            r0 = int(T.start[bt].min())
            r1 = int((T.start[bt] + T.size[bt]).max())
            M = sp.csr_matrix((v, (row - r0, self.source_element[J])), shape=(r1 - r0, self.n_unknowns))
            chunks.append((r0, M if fold is None else (M @ fold).tocsr()))
            if keep is not None:
                m = keep(I, J)
                kept.append((I[m], self.source_element[J[m]], v[m]))
            lo = hi
        # stack the row ranges (they tile 0..n_targets in order; empty ranges are zero rows)
        blocks, at = [], 0
        for r0, M in chunks:
            if r0 > at:
                blocks.append(sp.csr_matrix((r0 - at, self.n_cols)))
            blocks.append(M)
            at = r0 + M.shape[0]
        if at < self.n_targets:
            blocks.append(sp.csr_matrix((self.n_targets - at, self.n_cols)))
        near = sp.vstack(blocks, format="csr") if blocks else sp.csr_matrix((self.n_targets, self.n_cols))
        if keep is None:
            return near, None
        cat = np.concatenate
        trio = tuple(cat([k[i] for k in kept]) if kept else np.zeros(0) for i in range(3))
        return near, trio

    def _build_bases(self, targets, tri, nodes):
        p, T, S = self.p, self.T, self.S
        pp = p * p
        # leaf evaluation S: Lagrange basis of each target's leaf at the target
        leaves = np.flatnonzero(T.leaf)
        owner = np.empty(self.n_targets, dtype=np.int64)
        for k in leaves:
            owner[T.perm[T.start[k] : T.stop[k]]] = k
        sx = _scaled(targets[:, 0], T.lo[owner, 0], T.hi[owner, 0])
        sy = _scaled(targets[:, 1], T.lo[owner, 1], T.hi[owner, 1])
        vals = (_lagrange(sx, nodes)[:, :, None] * _lagrange(sy, nodes)[:, None, :]).reshape(-1, pp)
        cols = owner[:, None] * pp + np.arange(pp)[None, :]  # pp entries per row: CSR directly
        self._L2P = sp.csr_matrix(
            (vals.ravel(), cols.ravel(), np.arange(0, self.n_targets * pp + 1, pp)),
            shape=(self.n_targets, T.start.size * pp),
        )
        # leaf moments Q: int_T l_b(y) dA, Gauss rule exact for degree 2 (p - 1)
        lam, w = _triangle_rule(2 * (p - 1))
        owner_s = np.empty(self.n_sources, dtype=np.int64)
        for k in np.flatnonzero(S.leaf):
            owner_s[S.perm[S.start[k] : S.stop[k]]] = k
        e1 = tri[:, 1] - tri[:, 0]
        e2 = tri[:, 2] - tri[:, 0]
        area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        Qv = np.zeros((self.n_sources, pp))
        chunk = max(1, 2_000_000 // (lam.shape[0] * p))
        for s in range(0, self.n_sources, chunk):
            sl = slice(s, min(s + chunk, self.n_sources))
            q = np.einsum("qk,ekd->eqd", lam, tri[sl])  # (e, q, 2)
            o = owner_s[sl]
            ax = _lagrange(_scaled(q[:, :, 0], S.lo[o, None, 0], S.hi[o, None, 0]).ravel(), nodes)
            ay = _lagrange(_scaled(q[:, :, 1], S.lo[o, None, 1], S.hi[o, None, 1]).ravel(), nodes)
            ax = ax.reshape(q.shape[0], q.shape[1], p) * w[None, :, None]
            ay = ay.reshape(q.shape[0], q.shape[1], p)
            Qv[sl] = np.einsum("eqa,eqb->eab", ax, ay).reshape(-1, pp) * area[sl, None]
        rows = owner_s[:, None] * pp + np.arange(pp)[None, :]  # pp entries per column: CSC
        # then stored as CSR: its product gathers instead of scattering, 7.3 -> 4.5 ms on
        # 45,156 elements (C @ z 50.7 -> 47.4 ms), the same sums
        self._P2M = sp.csc_matrix(
            (Qv.ravel(), rows.ravel(), np.arange(0, self.n_sources * pp + 1, pp)),
            shape=(S.start.size * pp, self.n_sources),
        ).tocsr()
        # transfer matrices (1-D, per child): parent's Lagrange basis at the child's nodes
        self._levels_S = self._transfers(S, nodes)
        self._levels_T = self._transfers(T, nodes)

    def _transfers(self, tree, nodes):
        """Per depth (deepest first): children, their parents, Wx, Wy (p x p each)."""
        out = []
        kids = np.flatnonzero(tree.parent >= 0)
        is_left = np.zeros(tree.start.size, dtype=bool)
        is_left[tree.left[tree.left >= 0]] = True
        for d, side in sorted({(int(tree.depth[k]), bool(is_left[k])) for k in kids}, reverse=True):
            # one side at a time: every parent appears once (fancy-index += is then exact)
            c = kids[(tree.depth[kids] == d) & (is_left[kids] == side)]
            par = tree.parent[c]
            g = _grid(tree.lo[c], tree.hi[c], nodes)  # (c, p, 2)
            wx = _lagrange(_scaled(g[:, :, 0], tree.lo[par, None, 0], tree.hi[par, None, 0]).ravel(), nodes)
            wy = _lagrange(_scaled(g[:, :, 1], tree.lo[par, None, 1], tree.hi[par, None, 1]).ravel(), nodes)
            # W[c][a_child, b_parent] = l^parent_b(node^child_a)
            out.append((c, par, wx.reshape(c.size, self.p, self.p), wy.reshape(c.size, self.p, self.p)))
        return out

    def _build_far(self, nodes, ft, fs, svd_tol):
        pp = self.p * self.p
        T, S = self.T, self.S
        order = np.argsort(ft, kind="stable")
        ft, fs = ft[order], fs[order]
        gt = _grid(T.lo[ft], T.hi[ft], nodes)  # (b, p, 2)
        gs = _grid(S.lo[fs], S.hi[fs], nodes)
        groups: dict[int, list] = {}  # rank bucket -> [(block index, U, V)] per chunk
        ranks = []
        width = min(pp, RANGE_WIDTH)
        for s in range(0, ft.size, FAR_CHUNK):
            sl = slice(s, min(s + FAR_CHUNK, ft.size))
            K = _kernel_blocks(gt[sl], gs[sl])
            for sel, u, sv, vt in _low_rank(K, svd_tol, width):
                r = np.maximum(1, (sv > svd_tol * sv[:, :1]).sum(axis=1))
                ranks.append(r)
                width = min(pp, max(width, int(r.max()) + RANGE_MARGIN))
                bucket = np.minimum(-(-r // self.rank_step) * self.rank_step, sv.shape[1])
                for rb in np.unique(bucket):
                    i = np.flatnonzero(bucket == rb)
                    # U^T (rank x pp) and V (rank x pp): both read along their last axis
                    Ub = (
                        (u[i, :, :rb] * sv[i, None, :rb])
                        .transpose(0, 2, 1)
                        .astype(self.factor_dtype, order="C")
                    )
                    groups.setdefault(int(rb), []).append(
                        (s + sel[i], Ub, vt[i, :rb, :].astype(self.factor_dtype))
                    )
        ranks = np.concatenate(ranks) if ranks else np.zeros(0, int)
        self._rank_mean = float(ranks.mean()) if ranks.size else 0.0
        self._far_groups = []
        for rb in sorted(groups):
            idx = np.concatenate([g[0] for g in groups[rb]])
            U_r = np.concatenate([g[1] for g in groups[rb]])
            V_r = np.concatenate([g[2] for g in groups[rb]])
            groups[rb] = None
            # (target cluster, source cluster, U^T, V) of each block of this rank
            self._far_groups.append((ft[idx].astype(np.int64), fs[idx].astype(np.int64), U_r, V_r))
        self.n_nodes_T, self.n_nodes_S = T.start.size, S.start.size

    @property
    def nbytes(self) -> int:
        n = 0
        for M in (self._near_perm, self._L2P, self._P2M):
            n += M.data.nbytes + M.indices.nbytes + M.indptr.nbytes
        for ft, fs, U, V in getattr(self, "_far_groups", []):
            n += U.nbytes + V.nbytes + fs.nbytes + ft.nbytes
        return int(n)

    @property
    def near(self):
        """The exact near-field part (sparse, targets x columns of ``z``, natural row order)."""
        inv = np.empty_like(self.T.perm)
        inv[self.T.perm] = np.arange(self.T.perm.size)
        return self._near_perm[inv]

    # -- application ----------------------------------------------------------------------
    #: columns per blocked product (a block's moments take n_nodes x p^2 x BLOCK x 8 bytes)
    BLOCK = 32

    def __matmul__(self, u):
        if sp.issparse(u) or np.ndim(u) == 2:
            return self._columns(u)
        u = np.asarray(u, dtype=float)
        y = self.far(u)
        y[self.T.perm] += self._near_perm @ u
        return y

    def _columns(self, u):
        """``X @ u`` of the columns of ``u`` (n x k), :data:`BLOCK` at a time through
        :meth:`far_block`.  A sparse ``u`` (coarse hat functions) stays sparse in the near
        product, and its blocks leave the far blocks of vanishing sources skipped."""
        sparse = sp.issparse(u)
        u = sp.csc_matrix(u, dtype=float) if sparse else np.asarray(u, dtype=float)
        dense = (lambda a: a.toarray()) if sparse else np.asarray
        out = np.empty((self.T.perm.size, u.shape[1]))
        work = np.empty((self.n_nodes_S + self.n_nodes_T) * self.p**2 * min(self.BLOCK, u.shape[1]))
        for s in range(0, u.shape[1], self.BLOCK):
            ub = u[:, s : s + self.BLOCK]
            y = self.far_block(ub, work)
            y[self.T.perm] += dense(self._near_perm @ ub)
            out[:, s : s + self.BLOCK] = y
        return out

    def far_block(self, u, work=None):
        """:meth:`far` of the columns of ``u`` (n x k, dense or sparse) at once: the same
        passes, k wide.  ``work``: a buffer of at least (source + target clusters) x p^2 x
        k doubles for the moments and local expansions, reused from block to block by
        :meth:`_columns` (fresh memory costs its page faults, 40 ms a block of 32 columns
        on 17,678 elements).

        A cluster with no moment (every column of ``u`` vanishes on it: columns of
        compact support, as a coarse space sorted in space) is skipped in the upward pass
        and in the couplings: its products are zero.
        """
        p, pp, k = self.p, self.p * self.p, u.shape[1]
        if work is None:
            work = np.empty((self.n_nodes_S + self.n_nodes_T) * pp * k)
        nM = self.n_nodes_S * pp * k
        M, L = work[:nM].reshape(-1, k), work[nM : nM + self.n_nodes_T * pp * k].reshape(-1, pp, k)
        if sp.issparse(u):
            M[...] = 0.0  # toarray(out=) adds into it
            (self._P2M @ u).toarray(out=M)
        else:
            M[...] = self._P2M @ u
        M = M.reshape(self.n_nodes_S, p, p, k)
        live = np.any(M.reshape(self.n_nodes_S, -1) != 0.0, axis=1)
        for c, par, wx, wy in self._levels_S:  # M_parent += Wx^T M_child Wy, per column
            m = live[c]  # only the children with moments (a parent's others add zeros)
            if m.any():
                M[par[m]] += np.einsum("nba,nbck,ncd->nadk", wx[m], M[c[m]], wy[m], optimize=True)
                live[par[m]] = True
        L[...] = 0.0
        Mf = M.reshape(-1, pp, k)
        for ft, fs, Ut, V in self._far_groups:
            _couple_columns(L, Mf, ft, fs, Ut, V, np.flatnonzero(live[fs]))
        L = L.reshape(self.n_nodes_T, p, p, k)
        for c, par, wx, wy in reversed(self._levels_T):  # L_child += Wx L_parent Wy^T
            L[c] += np.einsum("nab,nbck,ndc->nadk", wx, L[par], wy, optimize=True)
        return np.asarray(self._L2P @ L.reshape(-1, k))

    def far(self, u):
        """The interpolated (admissible) part of ``X u`` only (``X fold u`` with a fold)."""
        p, pp = self.p, self.p * self.p
        M = (self._P2M @ u).reshape(self.n_nodes_S, p, p)
        for c, par, wx, wy in self._levels_S:  # upward: M_parent += Wx^T M_child Wy
            M[par] += np.matmul(np.matmul(wx.transpose(0, 2, 1), M[c]), wy)
        L = np.zeros((self.n_nodes_T, pp))
        Mf = M.reshape(-1, pp)
        for ft, fs, Ut, V in self._far_groups:
            _couple(L, Mf, ft, fs, Ut, V)
        L = L.reshape(self.n_nodes_T, p, p)
        for c, par, wx, wy in reversed(self._levels_T):  # downward: L_child += Wx L_parent Wy^T
            L[c] += np.matmul(np.matmul(wx, L[par]), wy.transpose(0, 2, 1))
        return self._L2P @ L.reshape(-1)


# ---- the compliance of a disk mesh ------------------------------------------------------
#: relative operator error of the interpolation at p = 5 and its factor per extra order
#: (admissibility :data:`ETA` = 2.5, couplings at :data:`SVD_RATIO`):
#: ``_ERR_P5 / _ERR_FACTOR**(p - 5)`` is the error of random vectors (the Frobenius ratio
#: over 64, :func:`sampled_error`) against exact rows of the fitted paper-sphere half
#: disks: 5.0e-7, 1.9e-7 and 1.1e-7 at p = 10, 11, 12 on 11,450 elements (side runs);
#: at p = 11 9.4e-8 (2,988) to 4.9e-7 (514,644, ``benchmarks/fast_operator.md``).  A
#: smooth vector (a Hertz-like pressure) is 10 to 40 times more accurate.
_ERR_P5, _ERR_FACTOR = 6e-5, 2.6

#: orders added to the law's for the films: the minimum film's relative error is the
#: deflection's error at the thinnest film over the film there (about 0.02 against a
#: deflection of order 1 in the paper case), so it magnifies the operator's error in those
#: few rows.  Measured over the whole paper case at the default rtol against the dense
#: operator solved to rtol 1e-10 (2,988 / 11,450 / 27,640 elements,
#: ``benchmarks/fast_operator.md``, agreement): p = 11 at eta = 2.5 6.4e-7 / 4.8e-7 /
#: 7.2e-7 (side runs of the same: 8.7e-7 / 7.5e-7 / 7.9e-7, the preconditioner's refreshes
#: follow measured times); p = 10 at eta = 2 with couplings at tol (the default until
#: 2026-12-04) 1.5e-6 / 1.9e-6 / 2.2e-6
FILM_ORDERS = 1


def order_for(tol: float) -> int:
    """Chebyshev points per axis for a relative operator error ``tol`` with films to about
    ``tol`` (:data:`FILM_ORDERS` above the law's order; at most 14)."""
    need = math.log(max(_ERR_P5 / tol, 1.0)) / math.log(_ERR_FACTOR)
    return int(min(14, 5 + math.ceil(need - 1e-9) + FILM_ORDERS))


#: the couplings' singular values are truncated at ``SVD_RATIO * operator_tol`` relative to
#: each block's largest.  The truncation, not the interpolation, set the minimum film's
#: error at 1e-6 (side runs, 2026-12-04; p = 10, eta = 2, whole paper case, default rtol):
#: on 11,450 elements 1.6e-6, 8.5e-7 and 9.0e-7 at ratios 1, 0.3 and 0.1 (27,640
#: elements: 2.1e-6 at 1, 1.5e-6 at 0.3), while a product ``C z`` on 47,296 elements costs
#: the same at 1 and 0.3 (40.2 and 41.4 ms, interleaved; mean ranks 11.3 and 12.9)
SVD_RATIO = 0.3

#: admissibility of the fast compliance: a block is far when ``max(diam) <= ETA dist``.
#: At p = 11 (couplings at 0.3 tol) on 47,296 elements (side runs), eta = 2 / 2.5 / 3
#: keep 18.4 / 14.8 / 12.7 million near entries and a product costs 43.6 / 38.9 / 36.8 ms
#: against the 37.8 ms of the former default (p = 10, eta = 2, couplings at tol); the
#: minimum film on 27,640 elements is 6.5e-7 / 7.9e-7 / 6.5e-6 (eta = 3 needs p = 12:
#: 8.2e-7, 41.4 ms)
ETA = 2.5

#: the couplings' ranks are rounded up to a multiple of this, blocks of one rank grouped
#: (4 until 2026-12-04: 3 % more far-field bytes, the same time)
RANK_STEP = 1

#: the default ``operator_tol`` of the fast path (``femehl.solve(..., operator_tol=...)``)
DEFAULT_OPERATOR_TOL = 1e-6

#: operator tolerances from which the far factors are stored in single precision (their
#: relative rounding, about 6e-8, is then at most 6 % of the tolerance)
SINGLE_FACTORS_TOL = 1e-6

#: preconditioner: the near-field entries with ``|c_i - c_j| <= PRECOND_RADIUS sqrt(area_j)``
PRECOND_RADIUS = 4.0


#: coarse space of the preconditioner (:mod:`femehl.elastic.coarse`): about one coarse node per
#: COARSE_RATIO free nodes, between COARSE_MIN and COARSE_MAX (``C P`` costs
#: elements x COARSE_MAX x 4 bytes: 2.4 GB at 1,000,000 elements)
COARSE_RATIO, COARSE_MIN, COARSE_MAX = 12, 100, 600


@dataclass(frozen=True)
class FastOptions:
    """How :class:`FastCompliance` is built: one tolerance, and the overrides of experiments.

    ``femehl.solve(..., operator_tol=x)`` is ``FastOptions(tol=x)``; a ``FastOptions``
    may be given as ``operator_tol`` instead to build another operator (benchmarks and
    experiments: ``benchmarks/fast_operator.py agree --variant``).

    Parameters
    ----------
    tol : float, default: :data:`DEFAULT_OPERATOR_TOL`
        Relative operator error; gives the Chebyshev order (:func:`order_for`) and the
        far factors' precision (single from :data:`SINGLE_FACTORS_TOL`).
    p : int, optional
        Chebyshev points per axis instead of ``order_for(tol)`` (2 to 16).
    eta : float, default: :data:`ETA`
        Admissibility: a block is far when ``max(diam) <= eta dist``.
    svd_ratio : float, default: :data:`SVD_RATIO`
        The couplings are truncated at ``svd_ratio * tol``.
    rank_step : int, default: :data:`RANK_STEP`
        The couplings' ranks rounded up to a multiple of this.
    """

    tol: float = DEFAULT_OPERATOR_TOL
    p: int | None = None
    eta: float = ETA
    svd_ratio: float = SVD_RATIO
    rank_step: int = RANK_STEP

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "tol", check_operator_tol(self.tol))
        set_(self, "p", None if self.p is None else check_chebyshev_order(self.p))
        set_(self, "eta", check_admissibility(self.eta))
        set_(self, "svd_ratio", check_svd_ratio(self.svd_ratio))
        set_(self, "rank_step", check_int("rank_step", self.rank_step, 1, "Ranks are rounded up to it."))

    @classmethod
    def of(cls, value) -> FastOptions:
        """``value`` if it is a FastOptions, else ``FastOptions(tol=value)``."""
        return value if isinstance(value, cls) else cls(tol=value)

    @property
    def order(self) -> int:
        """The Chebyshev order: ``p``, or what ``tol`` gives (:func:`order_for`)."""
        return order_for(self.tol) if self.p is None else self.p

    @property
    def factor_dtype(self):
        """The far factors' storage: single precision when their rounding (6e-8) is far
        below ``tol`` (from :data:`SINGLE_FACTORS_TOL`)."""
        return np.float32 if self.tol >= SINGLE_FACTORS_TOL else np.float64


class FastCompliance:
    """``C = factor * X P`` of a disk mesh with ``X`` as an :class:`H2Operator` (never dense).

    Behaves as the dense ``C`` where the stepper needs it: ``C @ z`` (vector or columns),
    ``shape``, ``C *= factor``, ``nbytes``; and gives the sparse approximation the fast
    path's preconditioner factors, :attr:`preconditioner` (the near-field entries within
    :data:`PRECOND_RADIUS` element sizes, times ``P``).

    ``options``: a :class:`FastOptions`, or its tolerance alone (a number).
    """

    is_fast = True

    def __init__(self, disc, options=None, factor: float = 1.0, coarse: bool = True):
        options = FastOptions() if options is None else FastOptions.of(options)
        t0 = time.perf_counter()
        ne = disc.nelements
        tri = disc.tri
        src_el = np.arange(ne)
        if disc.half:  # mirror images carry the same element values
            img = tri * np.array([1.0, -1.0])
            tri = np.concatenate([tri, img])
            src_el = np.concatenate([src_el, src_el])
        self.options = options
        cen = disc.centroids
        radius = PRECOND_RADIUS * np.sqrt(np.abs(disc.areas))

        def keep(i, j):  # near entries within a few element sizes of the source element
            e = src_el[j]
            return np.hypot(*(cen[i] - cen[e]).T) <= radius[e]

        # the far factors in single precision when their rounding (6e-8) is far below tol
        # (FastOptions.factor_dtype): half the far field's memory and time.  Products and
        # sums stay in double (_couple), so the operator is one fixed linear map: no
        # rounding floor under the Krylov residual (single-precision *arithmetic* put one
        # at about 1e-7).
        # The element average P folded into the near field: about half the entries of
        # X_near (an element's ~800 near elements share ~400 nodes), so half the work
        P = disc.P[:, disc.free].tocsr()
        self.H = H2Operator(
            cen,
            tri,
            src_el,
            ne,
            p=options.order,
            svd_tol=options.svd_ratio * options.tol,
            keep=keep,
            fold=P,
            eta=options.eta,
            factor_dtype=options.factor_dtype,
            rank_step=options.rank_step,
        )
        self.factor = float(factor)
        rows, cols, vals = self.H.kept
        self.H.kept = None
        self._pre = sp.csr_matrix((vals, (rows, cols)), shape=(ne, ne)) @ P
        self.shape = (ne, P.shape[1])
        #: ``(P, C P)`` of the preconditioner's coarse space (:mod:`femehl.elastic.coarse`; C P
        #: elements x coarse nodes, single precision: it serves the preconditioner only),
        #: None on meshes too small for one
        self.coarse = None
        if coarse and P.shape[1] > 2 * COARSE_MIN:
            t1 = time.perf_counter()
            m = min(COARSE_MAX, max(COARSE_MIN, P.shape[1] // COARSE_RATIO))
            self.coarse = self._coarse_space(disc, m)
            self.H.info.update(coarse_nodes=int(self.coarse[0].shape[1]), coarse_s=time.perf_counter() - t1)
        build_s = time.perf_counter() - t0
        self.info = dict(self.H.info, operator_tol=options.tol, svd_ratio=options.svd_ratio, build_s=build_s)

    def _coarse_space(self, disc, m: int) -> tuple:
        """``(P, C P)`` of about ``m`` coarse nodes, ``C P`` by blocked products (set-up)."""
        from femehl.elastic.coarse import coarse_prolongation

        Pc, verts = coarse_prolongation(disc.mesh, disc.areas, disc.free, m)
        # columns in space order (leaves of a bisection tree of the coarse vertices): a
        # block of nearby hat functions touches few source clusters (H2Operator.far_block)
        xy = disc.nodes[verts]
        order = cluster_tree(xy, xy, xy, leaf=H2Operator.BLOCK // 2).perm
        Pc = Pc[:, order].tocsr()
        Pcsc, blk = Pc.tocsc(), H2Operator.BLOCK
        CP = np.empty((self.shape[0], Pc.shape[1]), dtype=np.float32)
        for s in range(0, Pc.shape[1], blk):  # a block of columns at a time
            CP[:, s : s + blk] = self @ Pcsc[:, s : s + blk]
        return Pc, CP

    def __imul__(self, factor):
        self.factor *= float(factor)
        if self.coarse is not None:
            self.coarse[1][...] *= np.float32(factor)
        return self

    @property
    def preconditioner(self):
        """Sparse approximation of ``C`` (near field within a few element sizes)."""
        return self.factor * self._pre

    @property
    def near(self):
        """The exact near-field part of ``C / factor`` (sparse, elements x free nodes)."""
        return self.H.near

    @property
    def nbytes(self) -> int:
        n = self.H.nbytes + self._pre.data.nbytes + self._pre.indices.nbytes + self._pre.indptr.nbytes
        if self.coarse is not None:
            Pc, CP = self.coarse
            n += CP.nbytes + Pc.data.nbytes + Pc.indices.nbytes + Pc.indptr.nbytes
        return int(n)

    def __matmul__(self, z):
        return self.factor * (self.H @ z)


def sampled_error(disc, C, vectors: dict, rows: int = 384, seed: int = 2026) -> dict:
    """Relative error of ``C @ v`` for each of ``vectors`` against exact rows of ``disc``.

    The exact rows are :meth:`~femehl.discretize.fe_disk.FEDisc.boussinesq_rows`
    (the triangle integrals, O(N) a row, mirror images included) at ``rows`` elements
    drawn uniformly with ``seed``, so the error is measured where the dense operator does
    not fit: ``||(C v - X v)_S|| / ||(X v)_S||`` over the sampled rows S (Frobenius over
    the columns of a 2-D ``v``).  ``C`` is unscaled (``factor = 1``).

    For random vectors give many columns: the error of one random vector is dominated by
    the few rows of largest error and scatters by a factor of 5 between vectors (2.5e-7
    and 1.3e-6 for two on 11,450 elements, order 9); 64 columns estimate the Frobenius
    ratio ``||E_S||_F / ||X_S||_F`` to about 10 %.
    """
    rng = np.random.default_rng(seed)
    sample = np.sort(rng.choice(disc.nelements, size=min(rows, disc.nelements), replace=False))
    exact = {k: np.empty((sample.size,) + np.shape(v)[1:]) for k, v in vectors.items()}
    for s in range(0, sample.size, 8):  # 8 rows at a time: 8 x (2 N) triangle terms
        R = disc.boussinesq_rows(disc.centroids[sample[s : s + 8]])
        for k, v in vectors.items():
            exact[k][s : s + 8] = R @ v
    return {
        k: float(np.linalg.norm((C @ v)[sample] - exact[k]) / np.linalg.norm(exact[k]))
        for k, v in vectors.items()
    }
