"""The finite-element soft-EHL solver: P1 pressure, P0 film, exact Boussinesq (design.md s. 4).

Per step (paper section 3, lagged coefficients: ONE linear system):

    beta K(d^k) p - (V Bx + M/dt) w = -V Bx h^{k+1} - M (h^{k+1} - d^k)/dt
    w + C p = 0

with C = c X P for the elastic half space (X the exact triangle influence at
element centroids, mirrored for a half disk; P the element average of P1),
C = P/k for a Winkler foundation and C = 0 for a rigid substrate.  With w
eliminated the system in the free pressure unknowns is

    A p = ( beta K(d^k) + V Bx C + M C / dt ) p = -V Bx h - M (h - d^k)/dt

and only K changes from step to step: Bx C and M C depend on the mesh alone
and are formed once.  ``d^{k+1} = h^{k+1} + C p^{k+1}`` on elements.

Linear algebra (the step must still solve A p = b to a stated tolerance;
``rtol`` is the relative residual ||b - A p|| / ||b||, default 1e-8; over the
whole paper case that moves the films by < 4e-6 relative to a direct LU at every
step, three orders below the finest discretization error):
``A z = beta K z + (V Bx + c M)(C z)`` needs ONE dense product (C z) and
sparse work, and any vector z whose C z is known can be re-applied with a
new K and V for sparse work only.  Each step therefore minimizes the
residual (GCR, equivalent to flexible GMRES) first over *recycled*
directions -- the last solutions and the last steps' search directions,
kept with their C z -- and then over new directions z = LU^{-1} r, with the
LU of a recent A as the preconditioner (one triangular-solve pair + one
dense C product each).  The true residual b - A p is checked (sparse work,
from the tracked C p) before a step is accepted; otherwise the step is
solved directly.  The LU is refreshed by cost balancing: when the
preconditioned iterations of the last solve cost more than the average
cost per solve since the last factorization (factorization included), or
when a0/dt changed by more than 10 %.  ``refactor_after=n`` instead
refreshes when a solve needed more than n preconditioned iterations.
``linear_solver="lu"`` refactorizes at every step (the paper's direct
solve).  The dense A is formed in place (no dense temporaries) and its
transpose, which is Fortran-ordered, is LU-factorized in place.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, ElementTriP0, ElementTriP1, asm

from ..errors import SceneError, SingularSystemError
from ..kernels import edge_terms, mesh_edges, triangle_influence
from ..scene import HalfSpace, Rigid, Scene, Winkler
from ..stepping import State, get_scheme
from .forms import couette, film_diffusion, squeeze
from .mesh import DiskMesh, areas, centroids, load_mesh

__all__ = ["FEStepper", "FEDisc", "COMPLIANCE", "compliance_operator"]


class FEDisc:
    """A disk mesh with the P1/P0 bases and interpolation of stored fields."""

    def __init__(self, dm: DiskMesh):
        self.dm = dm
        self.mesh = dm.mesh
        self.half = dm.half
        self.L = dm.L
        self.basis = Basis(self.mesh, ElementTriP1())
        self.basis0 = self.basis.with_element(ElementTriP0())
        p, t = self.mesh.p, self.mesh.t
        self.nodes = p.T.copy()
        self.tri = np.transpose(p[:, t], (2, 1, 0))            # (ne, 3, 2)
        self.centroids = centroids(dm)
        self.areas = areas(dm)
        ne, nn = t.shape[1], p.shape[1]
        # element average of a P1 field: (P p)_e = mean of its 3 nodal values
        self.P = sp.csr_matrix((np.full(3 * ne, 1.0 / 3.0),
                                (np.repeat(np.arange(ne), 3), t.T.ravel())), shape=(ne, nn))
        r = np.hypot(p[0], p[1])
        self.free = np.flatnonzero(r < self.L * (1.0 - 1e-9))
        self._tri = None

    @property
    def nelements(self) -> int:
        return self.mesh.t.shape[1]

    @property
    def nnodes(self) -> int:
        return self.mesh.p.shape[1]

    def _finder(self):
        if self._tri is None:
            import matplotlib.tri as mtri
            self._tri = mtri.Triangulation(self.mesh.p[0], self.mesh.p[1], self.mesh.t.T)
            self._finder_ = self._tri.get_trifinder()
        return self._finder_

    def _locate(self, points):
        pts = np.asarray(points, dtype=float).copy()
        if self.half:
            pts[:, 1] = np.abs(pts[:, 1])
        return pts, self._finder()(pts[:, 0], pts[:, 1])

    def pressure_at(self, p, points):
        """P1 interpolation; 0 outside the mesh (p = 0 beyond r = L)."""
        import matplotlib.tri as mtri
        pts, _ = self._locate(points)
        self._finder()
        f = mtri.LinearTriInterpolator(self._tri, np.asarray(p, dtype=float), trifinder=self._finder_)
        v = f(pts[:, 0], pts[:, 1])
        return np.ma.filled(v.astype(float), 0.0)

    def _cell_value(self, values, points):
        pts, e = self._locate(points)
        out = np.full(pts.shape[0], np.nan)
        ok = e >= 0
        out[ok] = np.asarray(values)[e[ok]]
        return out

    def film_at(self, d, points):
        """Element-constant film thickness (NaN outside the mesh)."""
        return self._cell_value(d, points)

    def deflection_at(self, w, points):
        return self._cell_value(w, points)

    def vtk_geometry(self):
        """Points (z = 0), triangles, and False: film fields live on elements."""
        p = self.mesh.p
        pts = np.column_stack([p[0], p[1], np.zeros(p.shape[1])])
        return pts, [("triangle", self.mesh.t.T.astype(np.int64))], False

    def centreline(self, n: int = 401):
        x = np.linspace(-self.L, self.L, n)
        return np.column_stack([x, np.zeros_like(x)])


# ---- elastic operators: w = -C p on elements ---------------------------------
def _halfspace(substrate: HalfSpace, disc: FEDisc, free):
    """Dense C[:, free] = c X P[:, free], built in row blocks.

    X[i, j] = I(c_i, T_j) is never stored: with the signed edge incidence S
    of :func:`femehl.kernels.mesh_edges`, X = T S where T holds one exact
    term per unique edge, so a block of rows of C is T_block (S P).  For a
    half disk the mirror images (orientation reversed) add -T_mirror S.
    """
    ne = disc.nelements
    edges, S = mesh_edges(disc.mesh.t, disc.nodes)
    SP = (S @ disc.P[:, free]).tocsc()                 # (nedges, nfree), sparse
    mirror = disc.nodes * np.array([1.0, -1.0])
    C = np.empty((ne, free.size))
    block = max(1, int(2**26 // (8 * edges.shape[0])))
    for s in range(0, ne, block):
        e = slice(s, min(s + block, ne))
        T = edge_terms(disc.centroids[e], disc.nodes, edges)
        if disc.half:
            T -= edge_terms(disc.centroids[e], mirror, edges)
        C[e] = (SP.T @ T.T).T
    C *= substrate.compliance
    return C


def _winkler(substrate: Winkler, disc: FEDisc, free):
    return (disc.P[:, free] / substrate.k).tocsr()


def _rigid(substrate: Rigid, disc: FEDisc, free):
    return sp.csr_matrix((disc.nelements, free.size))


#: substrate type -> builder of C (elements x free nodes), w = -C p
COMPLIANCE = {HalfSpace: _halfspace, Winkler: _winkler, Rigid: _rigid}


def compliance_operator(substrate, disc, free):
    try:
        build = COMPLIANCE[type(substrate)]
    except KeyError:
        raise NotImplementedError(
            f"the FE solver has no elastic operator for {type(substrate).__name__}; "
            f"registered: {[c.__name__ for c in COMPLIANCE]}") from None
    return build(substrate, disc, free)


@dataclass
class _Factor:
    lu: tuple           # LAPACK LU of A^T (A C-ordered = A^T Fortran-ordered: no copy)
    key: float          # a0/dt of the factorized matrix
    cost: float         # wall time of forming and factorizing A (s)
    total: float = 0.0  # cost of this factor's cycle: factorization + preconditioned iterations
    solves: int = 0     # solves of this cycle (the factorizing one included)
    stale: bool = False # refresh at the next solve


class FEStepper:
    """Advance the FE discretization of a scene by one lagged linear step.

    Parameters
    ----------
    scene : femehl.scene.Scene
    mesh : str, path, skfem.MeshTri or DiskMesh, default: "medium"
        A ladder name ("coarse", "medium", "fine", "xfine") or any mesh meshio reads.
    half : bool, optional
        Use the half disk y >= 0; default: True when the indenter is symmetric in y.
    scheme : {"euler", "bdf2"}, default: "euler"
        "euler" is the paper's first-order scheme; "bdf2" is second order and
        still one linear system per step (see :data:`femehl.stepping.SCHEMES`).
    linear_solver : {"gmres", "lu"}, default: "gmres"
        "gmres": minimal residual (flexible GMRES / GCR) over recycled directions
        and directions preconditioned by the LU of a recent step; "lu": a new
        dense LU at every step.
    rtol : float, default: 1e-8
        Relative residual ||b - A p|| / ||b|| every step is solved to.
    refactor_after : int, optional
        Refresh the LU when a solve needed more than this many preconditioned
        iterations; default (None): refresh by cost balancing (see module doc).
    recycle : int, default: 8
        Number of recycled directions kept between solves (0: none).
    """

    method = "fe"

    def __init__(self, scene: Scene, mesh="medium", half: bool | None = None,
                 scheme: str = "euler", linear_solver: str = "gmres", rtol: float = 1e-8,
                 refactor_after: int | None = None, recycle: int = 8):
        t0 = time.perf_counter()
        self.scene = scene
        self.scheme = get_scheme(scheme)
        symmetric = bool(getattr(scene.indenter, "symmetric_y", False))
        if half is not None and not isinstance(half, (bool, np.bool_)):
            raise SceneError(f"half must be True, False or None (automatic), got {half!r}.")
        if not isinstance(linear_solver, str):
            raise SceneError(f"linear_solver must be 'gmres' or 'lu', got {linear_solver!r}.")
        if half is None:
            half = symmetric if isinstance(mesh, str) and not _looks_like_path(mesh) else None
        if half and not symmetric:
            raise SceneError("a half-disk mesh needs an indenter symmetric in y; use half=False "
                             "or a full-disk mesh.")
        dm = load_mesh(mesh, L=scene.domain.L, half=half)
        if dm.half and not symmetric:
            raise SceneError(f"mesh {dm.name!r} is a half disk but the indenter is not symmetric "
                             "in y: use a full-disk mesh.")
        if linear_solver not in ("gmres", "lu"):
            raise SceneError(f"linear_solver must be 'gmres' or 'lu', got {linear_solver!r}.")
        try:
            rtol = float(rtol)
        except (TypeError, ValueError):
            rtol = float("nan")
        if not (0.0 < rtol < 1e-2):
            raise SceneError(f"rtol must be in (0, 1e-2), got {rtol!r}.")
        self.linear_solver = linear_solver
        self.rtol = rtol
        if refactor_after is not None and (isinstance(refactor_after, bool)
                                           or not isinstance(refactor_after, int) or refactor_after < 1):
            raise SceneError(f"refactor_after must be an integer >= 1 or None, got {refactor_after!r}.")
        if isinstance(recycle, bool) or not isinstance(recycle, int) or recycle < 0:
            raise SceneError(f"recycle must be an integer >= 0, got {recycle!r}.")
        self.refactor_after = refactor_after
        self.recycle = recycle
        self._solutions: list = []     # recent (x, C x) of the Krylov path
        self._directions: list = []    # recent preconditioned (z, C z)
        self.max_krylov = 30           # preconditioned iterations before a direct solve
        self.precond_dtype = np.float32  # the LU is a preconditioner only: single precision
        self.disc = disc = FEDisc(dm)
        free = disc.free
        self.free = free
        self.beta = scene.fluid.beta
        self.shape = np.asarray(scene.indenter.gap(disc.centroids[:, 0], disc.centroids[:, 1]), float)
        if self.shape.shape != (disc.nelements,) or not np.all(np.isfinite(self.shape)):
            raise SceneError("the indenter's gap(x, y) must return finite values of the same shape "
                             "as x; check the shape function.")
        b1, b0 = disc.basis, disc.basis0
        # element stiffness with unit coefficient; K(d) scales each element by d^3
        kcoo = film_diffusion.coo_data(b1, d3=b0.interpolate(np.ones(disc.nelements)))
        self._k_rows, self._k_cols = kcoo.indices
        self._k_data = kcoo.data.reshape(-1, disc.nelements)       # (9, ne), element last
        Mfull = asm(squeeze, b0, b1).tocsr()
        self.M = Mfull[free]                                         # (nfree, ne)
        self.node_weight = np.asarray(Mfull.sum(axis=1)).ravel()     # int phi_q dA
        self.mult = 2.0 if disc.half else 1.0
        t1 = time.perf_counter()
        self.C = compliance_operator(scene.substrate, disc, free)
        self.dense = isinstance(self.C, np.ndarray)
        t2 = time.perf_counter()
        self.MC = np.asarray(self.M @ self.C) if self.dense else sp.csr_matrix(self.M @ self.C)
        self._Bx = None        # Couette operators: built the first time V != 0
        self._BxC = None
        self._centre_row = self._centre_operator()
        self._factor: _Factor | None = None
        self.info = {
            "method": "fe", "mesh": dm.name, "half": dm.half, "elements": disc.nelements,
            "nodes": disc.nnodes, "unknowns": int(free.size), "scheme": self.scheme.name,
            "substrate": type(scene.substrate).__name__,
            "setup_s": time.perf_counter() - t0, "elastic_build_s": t2 - t1,
            "operator_bytes": int(_nbytes(self.C) + _nbytes(self.MC)),
            "factorizations": 0, "krylov_iterations": 0, "couette_assembled": False,
        }

    def _centre_operator(self):
        """Row r with w(0, 0) = -r . p_free (exact kernel for the element-average pressure)."""
        if self.dense:
            x0 = triangle_influence(np.zeros((1, 2)), self.disc.tri)[0]
            x0 = x0 * (2.0 if self.disc.half else 1.0)       # mirror image at y = 0 is symmetric
            return self.scene.substrate.compliance * (self.disc.P[:, self.free].T @ x0)
        return None

    # ---- operators ----------------------------------------------------------
    def couette(self):
        """(Bx, Bx C): assembled once, the first time the scene slides."""
        if self._Bx is None:
            self._Bx = asm(couette, self.disc.basis0, self.disc.basis).tocsr()[self.free]
            self._BxC = (np.asarray(self._Bx @ self.C) if self.dense
                         else sp.csr_matrix(self._Bx @ self.C))
            self.info["couette_assembled"] = True
            self.info["operator_bytes"] += _nbytes(self._BxC)
        return self._Bx, self._BxC

    def stiffness(self, d: np.ndarray):
        """K(d) on the free nodes, element coefficient d^3."""
        data = (self._k_data * (d ** 3)[None, :]).ravel()
        n = self.disc.nnodes
        K = sp.csr_matrix((data, (self._k_rows, self._k_cols)), shape=(n, n))
        return K[self.free][:, self.free]

    def _matrix(self, K, V, c, dtype=np.float64):
        """A = beta K + V Bx C + c M C, with c = a0/dt.

        Dense: formed in place in ``dtype`` (row blocks, no dense temporary), C-ordered.
        """
        if self.dense:
            n = self.MC.shape[0]
            A = np.empty((n, n), dtype=dtype)
            BxC = self.couette()[1] if V != 0.0 else None
            blk = max(1, (1 << 21) // max(n, 1))
            for s in range(0, n, blk):
                e = min(s + blk, n)
                rows = c * self.MC[s:e]
                if BxC is not None:
                    rows += V * BxC[s:e]
                A[s:e] = rows
            Kc = K.tocoo()
            np.add.at(A, (Kc.row, Kc.col), (self.beta * Kc.data).astype(dtype))
            return A
        A = self.beta * K + c * self.MC
        if V != 0.0:
            A = A + V * self.couette()[1]
        return A.tocsc()

    def _coupling(self, V, c):
        """G = V Bx + c M (sparse, free nodes x elements): A z = beta K z + G (C z)."""
        G = self.M * c
        if V != 0.0:
            G = G + self.couette()[0] * V
        return G.tocsr()

    def _solve(self, K, V, c, rhs, t_new):
        self._last_Cx = None
        bnorm = float(np.linalg.norm(rhs))
        if bnorm == 0.0:
            return np.zeros_like(rhs), 0
        if not self.dense:
            try:
                return spla.splu(self._matrix(K, V, c)).solve(rhs), 0
            except RuntimeError as exc:
                raise SingularSystemError(
                    f"FE step at t = {t_new:.6g}: the sparse system is singular ({exc}). "
                    "Try a smaller dt or a finer mesh.", t=t_new) from None
        if self.linear_solver == "lu":
            return self._direct(K, V, c, rhs, t_new), 0
        f = self._factor
        fresh = f is None or f.stale or abs(f.key - c) > 0.1 * c
        if fresh:
            f = self._refactor(K, V, c, t_new)
        t0 = time.perf_counter()
        x, Cx, its, dirs = self._krylov(K, self._coupling(V, c), rhs, bnorm, f)
        dt_solve = time.perf_counter() - t0
        self.info["krylov_iterations"] += its
        self.info["krylov_s"] = self.info.get("krylov_s", 0.0) + dt_solve
        if x is None:
            if fresh:        # even a fresh preconditioner failed: solve directly in double
                return self._direct(K, V, c, rhs, t_new), its
            f.stale = True
            return self._solve(K, V, c, rhs, t_new)[0], its
        self._remember(x, Cx, dirs)
        self._last_Cx = (x, Cx)
        # Refresh policy.  Cost balancing: a cycle costs the factorization plus the
        # preconditioned iterations of its solves; refresh when the last solve's iterations
        # cost more than the cycle's average per solve (the average then stops falling).
        if self.refactor_after is not None:
            f.stale = its > self.refactor_after
        else:
            marginal = its * self._t_iter
            f.total += marginal
            f.solves += 1
            f.stale = marginal > f.total / f.solves
        return x, its

    def _refactor(self, K, V, c, t_new):
        """LU of the current A as the Krylov preconditioner (``precond_dtype``, in place)."""
        self._factor = None                  # free the old factor before forming the new A
        t0 = time.perf_counter()
        A = self._matrix(K, V, c, dtype=self.precond_dtype)
        lu = self._lu(A, t_new)
        cost = time.perf_counter() - t0
        self.info["factorizations"] += 1
        self.info["factor_s"] = self.info.get("factor_s", 0.0) + cost
        self._factor = _Factor(lu, c, cost, total=cost, solves=0)
        return self._factor

    @staticmethod
    def _lu(A, t_new):
        try:
            # A is C-ordered, so A.T is Fortran-ordered: LAPACK factors it in place (LU of A^T)
            lu = sla.lu_factor(A.T, overwrite_a=True, check_finite=True)
        except (ValueError, np.linalg.LinAlgError) as exc:
            raise SingularSystemError(f"FE step at t = {t_new:.6g}: cannot factor the system "
                                      f"({exc}). Try a smaller dt or a finer mesh.", t=t_new) from None
        if np.any(np.abs(np.diag(lu[0])) == 0.0):
            raise SingularSystemError(
                f"FE step at t = {t_new:.6g}: the linear system is singular (zero pivot). "
                "Try a smaller dt or a finer mesh.", t=t_new)
        return lu

    def _direct(self, K, V, c, rhs, t_new):
        """The paper's direct solve: a new dense LU (double) of A."""
        t0 = time.perf_counter()
        lu = self._lu(self._matrix(K, V, c), t_new)
        self.info["factorizations"] += 1
        self.info["factor_s"] = self.info.get("factor_s", 0.0) + time.perf_counter() - t0
        return sla.lu_solve(lu, rhs, trans=1)

    def _precondition(self, f, r):
        lu = f.lu[0]
        return sla.lu_solve(f.lu, r.astype(lu.dtype, copy=False), trans=1,
                            check_finite=False).astype(np.float64, copy=False)

    def _krylov(self, K, G, b, bnorm, f):
        """Minimal residual (GCR) over recycled + LU-preconditioned directions.

        Every stored direction z carries its exact C z (one dense product when it was made),
        so re-applying it with the new K and V is sparse work.  The result's C x is formed
        with one dense product and the TRUE residual b - beta K x - G (C x) is checked.
        Returns ``(x, C x, preconditioned iterations, new directions)``, or ``x = None``
        when ``rtol`` was not reached in ``max_krylov`` iterations.
        """
        beta, C = self.beta, self.C
        tol = self.rtol * bnorm
        rec = self._solutions + self._directions
        m = len(rec) + self.max_krylov
        n, ne = b.size, C.shape[0]
        Z = np.empty((m, n))            # row j: direction z_j
        CZ = np.empty((m, ne))          # row j: C z_j
        Q = np.empty((m, n))            # row j: orthonormal basis of A span(Z)
        R = np.zeros((m, m))
        g = np.zeros(m)
        k = 0
        r = b.copy()
        if rec:
            Zr = np.array([z for z, _ in rec])
            CZr = np.array([cz for _, cz in rec])
            AZ = beta * (K @ Zr.T) + G @ CZr.T                   # sparse work only
            scale = np.linalg.norm(AZ, axis=0)
            scale[scale == 0.0] = 1.0
            q, rr, piv = sla.qr(AZ / scale, mode="economic", pivoting=True)
            d = np.abs(np.diag(rr))
            k = int(np.count_nonzero(d > 1e-8 * d[0])) if d.size and d[0] > 0 else 0
            sel = piv[:k]
            Z[:k] = Zr[sel] / scale[sel, None]
            CZ[:k] = CZr[sel] / scale[sel, None]
            Q[:k] = q[:, :k].T
            R[:k, :k] = rr[:k, :k]
            for _ in range(2):                      # r = b - Q Q^T b, reorthogonalized
                h = Q[:k] @ r
                r -= h @ Q[:k]
                g[:k] += h
        its = 0
        k_rec = k
        hist = [float(np.linalg.norm(r)) / bnorm]
        while True:
            if hist[-1] <= 0.5 * self.rtol or its >= self.max_krylov:
                if k == 0:
                    return None, None, its, []
                y = sla.solve_triangular(R[:k, :k], g[:k])
                x = y @ Z[:k]
                Cx = C @ x                                      # exact, for the state and the check
                rt = b - beta * (K @ x) - G @ Cx                # the TRUE residual
                res = float(np.linalg.norm(rt))
                hist.append(res / bnorm)
                self._last_history = hist
                if np.isfinite(res) and res <= tol:
                    return x, Cx, its, [(Z[j].copy(), CZ[j].copy()) for j in range(k_rec, k)]
                if its >= self.max_krylov or not np.isfinite(res):
                    return None, None, its, []
                r = rt - (Q[:k] @ rt) @ Q[:k]          # continue from the true residual
            t0 = time.perf_counter()
            z = self._precondition(f, r)
            cz = C @ z                                          # the one dense product
            q = beta * (K @ z) + G @ cz
            h = np.zeros(k)
            for _ in range(2):
                hh = Q[:k] @ q
                q -= hh @ Q[:k]
                h += hh
            nq = float(np.linalg.norm(q))
            its += 1
            if not np.isfinite(nq) or nq == 0.0:
                return None, None, its, []
            Q[k] = q / nq
            R[:k, k] = h
            R[k, k] = nq
            Z[k] = z
            CZ[k] = cz
            g[k] = Q[k] @ r
            r -= g[k] * Q[k]
            k += 1
            hist.append(float(np.linalg.norm(r)) / bnorm)
            self._t_iter = time.perf_counter() - t0

    _t_iter = 0.0

    def _remember(self, x, Cx, dirs):
        """Keep the newest solutions and preconditioned directions (with C z) for recycling."""
        if self.recycle <= 0:
            return
        nsol = min(4, self.recycle)
        self._solutions = ([(x, Cx)] + self._solutions)[:nsol]
        self._directions = (dirs + self._directions)[:max(0, self.recycle - len(self._solutions))]

    # ---- stepping -----------------------------------------------------------
    def _state(self, step, t, hc, V, p_free, d_prev=None, dt_prev=None, info=None, Cp=None):
        disc = self.disc
        p = np.zeros(disc.nnodes)
        p[self.free] = p_free
        if Cp is None:                      # the Krylov path hands over its exact C p
            Cp = np.asarray(self.C @ p_free).ravel()
        w = -Cp
        d = hc + self.shape + Cp
        load = self.mult * float(self.node_weight @ p)
        if self._centre_row is not None:
            w0 = -float(self._centre_row @ p_free)
        else:
            w0 = float(disc.deflection_at(w, np.zeros((1, 2)))[0])
        s0 = float(self.scene.indenter.gap(0.0, 0.0))
        i_min = int(np.argmin(d))
        i_max = int(np.argmax(p))
        return State(step=step, t=t, hc=hc, V=V, p=p, w=w, d=d, load=load,
                     film_center=hc + s0 - w0, film_min=float(d[i_min]),
                     film_min_at=tuple(disc.centroids[i_min]), p_max=float(p[i_max]),
                     p_max_at=tuple(disc.nodes[i_max]), info=info or {},
                     d_prev=d_prev, dt_prev=dt_prev)

    def initial_state(self) -> State:
        mo = self.scene.motion
        return self._state(0, 0.0, mo.hc(0.0), mo.V(0.0), np.zeros(self.free.size))

    def step(self, state: State, t_new: float, dt: float) -> State:
        """One lagged step: ONE linear system (bordered by one row under imposed load)."""
        mo = self.scene.motion
        V = mo.V(t_new)
        omega = None if state.d_prev is None else dt / state.dt_prev
        a0, a1, a2, l0, l1 = self.scheme.coefficients(omega)
        d_lag = state.d if l1 == 0.0 else np.maximum(l0 * state.d - l1 * state.d_prev, 0.5 * state.d)
        hist = a1 * state.d - (a2 * state.d_prev if a2 else 0.0)   # a1 d^k - a2 d^{k-1}
        K = self.stiffness(d_lag)
        c = a0 / dt
        Bx = self.couette()[0] if V != 0.0 else None

        def rhs_for(h):
            r = -self.M @ (a0 * h - hist) / dt
            if Bx is not None:
                r -= V * (Bx @ h)
            return r

        if mo.load_controlled:
            # A p + col hc = rhs(s);  g . p = F   ->  p = x1 - hc x2
            F = mo.F(t_new)
            x1, its1 = self._solve(K, V, c, rhs_for(self.shape), t_new)
            cx1 = self._known_Cx(x1)
            col = c * (self.M @ np.ones(self.disc.nelements))
            if Bx is not None:
                col += V * (Bx @ np.ones(self.disc.nelements))
            x2, its2 = self._solve(K, V, c, col, t_new)
            cx2 = self._known_Cx(x2)
            g = self.mult * self.node_weight[self.free]
            den = float(g @ x2)
            if not np.isfinite(den) or den == 0.0:
                raise SingularSystemError(f"FE step at t = {t_new:.6g}: the load row is singular "
                                          "(the film does not respond to hc).", t=t_new)
            hc = (float(g @ x1) - F) / den
            p = x1 - hc * x2
            Cp = None if cx1 is None or cx2 is None else cx1 - hc * cx2
            its = its1 + its2
        else:
            hc = mo.hc(t_new)
            p, its = self._solve(K, V, c, rhs_for(hc + self.shape), t_new)
            Cp = self._known_Cx(p)
        if not (np.all(np.isfinite(p)) and np.isfinite(hc)):
            raise SingularSystemError(
                f"FE step at t = {t_new:.6g} produced non-finite pressure: the system is singular "
                "or ill-conditioned. Try a smaller dt or a finer mesh.", t=t_new)
        return self._state(state.step + 1, t_new, hc, V, p, d_prev=state.d, dt_prev=dt,
                           info={"krylov_iterations": its}, Cp=Cp)

    def _known_Cx(self, x):
        """C x if the last solve that returned ``x`` already formed it, else None."""
        last = getattr(self, "_last_Cx", None)
        return last[1] if last is not None and last[0] is x else None


def _nbytes(a) -> int:
    if isinstance(a, np.ndarray):
        return a.nbytes
    if sp.issparse(a):
        a = a.tocsr()
        return a.data.nbytes + a.indices.nbytes + a.indptr.nbytes
    return 0


def _looks_like_path(s: str) -> bool:
    return any(ch in s for ch in "/\\.")
