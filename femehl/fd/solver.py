"""The paper-faithful polar finite-difference solver (Wu, Hui et al. 2022, section 3).

Discretization (Eqs. 13-26)
---------------------------
The Reynolds equation in polar form (Eq. 13a),

    beta [ p_r N + p_rr d^3 + (p_thth d^3 + M p_th) / r^2 ]
        = -V (cos(th) d_r - sin(th)/r d_th) + d_t,
    N = d^2 (d/r + 3 d_r),   M = 3 d^2 d_th                      (Eq. 13b)

is written at every interior node (0 < i < m-1, 0 < j < n-1) with forward
first differences and central second differences (Eq. 19), the coefficients
d^3, N, M taken from step k (lagged), and d = h - w at step k+1 on the right:
the derivatives of d^{k+1} are forward differences of h^{k+1} - w^{k+1}
(Eq. 19c,d) and d_t = (d^{k+1} - d^k)/dt (Eq. 19e).

Eq. 20 of the paper is garbled in the text (F appears twice; F, G, H are
printed as multiplying pressure neighbours while they are the w-coefficients
of Eq. 22).  femehl rebuilds it from Eq. 15 term by term instead of copying
Eqs. 20-23: the pressure stencil is

    p_{i,j+1}: N/dr + d^3/dr^2          p_{i,j-1}: d^3/dr^2
    p_{i+1,j}: d^3/(r^2 dth^2) + M/(r^2 dth)   p_{i-1,j}: d^3/(r^2 dth^2)
    p_{i,j}:   -(N/dr + 2 d^3/dr^2 + 2 d^3/(r^2 dth^2) + M/(r^2 dth))

(which is Eq. 21 divided by dr^2) and the w terms are moved to the left with
the signs Eq. 15 gives them.  Two further choices, both first order like the
paper's own differences: d_r and d_th in N and M are forward differences of
d^k (backward at the outer row), not r - w_r with the exact r, so any
indenter shape works; and d_t uses (h^{k+1} - h^k)/dt for the rigid part,
which equals the paper's -(1 + h0) on the ramp.

Boundary conditions: p_{i,0} = p_{i,1} (Eq. 17a), p_{0,j} = p_{1,j} and
p_{m-1,j} = p_{m-2,j} (Eq. 17b), p_{i,n-1} = 0 (Eq. 18a); they are imposed by
eliminating the boundary nodes (an expansion matrix E from the free interior
unknowns to all nodes).  Elasticity w = -c chi p (Eq. 25) with chi the polar
cell influence of Eq. 24 including the mirror half theta in [pi, 2 pi].

Stability (measured, paper case beta = 200, h0 = 0.1): the forward differences
are downwind on the exit side (theta > pi/2, where the substrate carries the
film toward growing r and theta), so where the film is thin the discrete
operator loses its sign structure and the film ruptures.  Grids dr = 0.05
(t = 1.64), dr = 0.025 with dtheta = pi/24 (t = 2.57) or pi/36 (t = 2.62) stop
with FilmRuptureError during the sliding start-up; dr = 0.0125, dtheta = pi/36
runs to t = 5.  The paper itself used dr = 0.01, dtheta = pi/60.

The monolithic (p, w) system of Eq. 26 is solved with w eliminated
(w = -W p substituted into the Reynolds rows), which is the same linear
system, half the size; a dense LU per step, as in the paper.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import SceneError, SingularSystemError
from ..kernels import quad_influence
from ..scene import HalfSpace, Rigid, Scene, Winkler
from ..stepping import State
from .grid import PolarGrid

__all__ = ["FDStepper", "compliance_operator", "COMPLIANCE"]


def _expansion(grid: PolarGrid):
    """Sparse E (m*n, nfree): full node values from the free interior unknowns."""
    m, n = grid.m, grid.n
    fi = np.arange(1, m - 1)
    fj = np.arange(1, n - 1)
    nfree = fi.size * fj.size
    I, J = np.meshgrid(np.arange(m), np.arange(n), indexing="ij")
    src_i = np.clip(I, 1, m - 2)              # mirror rows theta = 0, pi (Eq. 17b)
    src_j = np.maximum(J, 1)                  # centre p_{i,0} = p_{i,1}  (Eq. 17a)
    keep = (J < n - 1).ravel()                # p = 0 on r = L            (Eq. 18a)
    rows = np.arange(m * n)[keep]
    cols = ((src_i - 1) * (n - 2) + (src_j - 1)).ravel()[keep]
    E = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(m * n, nfree))
    interior = ((I > 0) & (I < m - 1) & (J > 0) & (J < n - 1)).ravel()
    return E, np.flatnonzero(interior)


def _forward_diff(grid: PolarGrid, rows):
    """Sparse forward differences d/dr and d/dtheta at node indices ``rows``."""
    n = grid.n
    k = rows.size
    ar = np.arange(k)
    one = np.ones(k)
    Dr = sp.csr_matrix((np.r_[one, -one] / grid.dr, (np.r_[ar, ar], np.r_[rows + 1, rows])),
                       shape=(k, grid.m * n))
    Dt = sp.csr_matrix((np.r_[one, -one] / grid.dtheta, (np.r_[ar, ar], np.r_[rows + n, rows])),
                       shape=(k, grid.m * n))
    return Dr, Dt


def _halfspace(substrate: HalfSpace, grid: PolarGrid, E):
    """Dense W = c chi E: polar cells and their mirror images (Eq. 24-25)."""
    pts = grid.xy()
    cells = grid.cells()
    chi = quad_influence(pts, cells)
    mirror = cells.copy()
    mirror[..., 1] *= -1.0
    chi += quad_influence(pts, mirror)
    return substrate.compliance * np.asarray(E.T @ chi.T).T


def _winkler(substrate: Winkler, grid: PolarGrid, E):
    return (E / substrate.k).tocsr()


def _rigid(substrate: Rigid, grid: PolarGrid, E):
    return sp.csr_matrix(E.shape)


#: substrate type -> builder of W with w = -W p_free on all nodes
COMPLIANCE = {HalfSpace: _halfspace, Winkler: _winkler, Rigid: _rigid}


def compliance_operator(substrate, grid, E):
    """W such that the deflection at every node is ``w = -W p_free``."""
    try:
        build = COMPLIANCE[type(substrate)]
    except KeyError:
        raise NotImplementedError(
            f"the FD solver has no elastic operator for {type(substrate).__name__}; "
            f"registered: {[c.__name__ for c in COMPLIANCE]}") from None
    return build(substrate, grid, E)


class FDStepper:
    """Advance the polar FD discretization of a scene by one lagged linear step.

    Parameters
    ----------
    scene : femehl.scene.Scene
    dr : float, default: 0.0125
        Radial step (L/dr must be an integer).  The default is the coarsest grid found
        to carry the paper case through its sliding start-up (see the module notes).
    dtheta : float, default: pi/36
        Azimuthal step (pi/dtheta must be an integer).
    """

    method = "fd"

    def __init__(self, scene: Scene, dr: float = 0.0125, dtheta: float = math.pi / 36):
        if not getattr(scene.indenter, "symmetric_y", False):
            raise SceneError(
                "the FD solver computes the half plane y >= 0 and mirrors it (paper Eq. 17b), so "
                f"it needs an indenter symmetric in y; {type(scene.indenter).__name__} is not. "
                "Use method='fe' (it meshes the full disk for such shapes).")
        self.scene = scene
        self.grid = grid = PolarGrid(scene.domain.L, dr, dtheta)
        self.disc = grid
        m, n = grid.m, grid.n
        self.E, self.rows = _expansion(grid)
        th, rr = grid.mesh()
        self.r = rr.ravel()
        self.theta = th.ravel()
        xy = grid.xy()
        self.xy = xy
        self.shape = np.asarray(scene.indenter.gap(xy[:, 0], xy[:, 1]), dtype=float)
        self.area = grid.cell_areas().ravel()
        Dr, Dt = _forward_diff(grid, self.rows)
        ri = self.r[self.rows]
        # Couette operator on d: cos(th) d_r - sin(th)/r d_th at interior rows
        self.G = (sp.diags(np.cos(self.theta[self.rows])) @ Dr
                  - sp.diags(np.sin(self.theta[self.rows]) / ri) @ Dt).tocsr()
        self.S = sp.csr_matrix((np.ones(self.rows.size), (np.arange(self.rows.size), self.rows)),
                               shape=(self.rows.size, m * n))
        self.W = compliance_operator(scene.substrate, grid, self.E)
        self.dense = isinstance(self.W, np.ndarray)
        # products that depend on the grid alone (formed once)
        self.GW = self.G @ self.W
        self.SW = self.S @ self.W
        if not self.dense:
            self.GW = sp.csr_matrix(self.GW)
            self.SW = sp.csr_matrix(self.SW)
        self.beta = scene.fluid.beta
        self._centre = 0  # node (0, 0) is r = 0

    # ---- Reynolds operator with lagged coefficients (Eq. 15, 21) --------------
    def reynolds_matrix(self, d_full: np.ndarray):
        """Sparse L(d^k): interior rows x free unknowns."""
        g = self.grid
        m, n = g.m, g.n
        D = d_full.reshape(m, n)
        d_r = np.empty_like(D)
        d_r[:, :-1] = (D[:, 1:] - D[:, :-1]) / g.dr
        d_r[:, -1] = d_r[:, -2]
        d_t = np.empty_like(D)
        d_t[:-1, :] = (D[1:, :] - D[:-1, :]) / g.dtheta
        d_t[-1, :] = d_t[-2, :]
        rows = self.rows
        d = D.ravel()[rows]
        r = self.r[rows]
        d3 = d ** 3
        N = d * d * (d / r + 3.0 * d_r.ravel()[rows])          # Eq. 13b
        M = 3.0 * d * d * d_t.ravel()[rows]
        cr2 = 1.0 / g.dr ** 2
        ct2 = 1.0 / (r * r * g.dtheta ** 2)
        c_jp = N / g.dr + d3 * cr2
        c_jm = d3 * cr2
        c_ip = d3 * ct2 + M / (r * r * g.dtheta)
        c_im = d3 * ct2
        c_0 = -(c_jp + c_jm + c_ip + c_im)
        k = rows.size
        ar = np.arange(k)
        Lfull = sp.csr_matrix(
            (np.concatenate([c_0, c_jp, c_jm, c_ip, c_im]),
             (np.tile(ar, 5), np.concatenate([rows, rows + 1, rows - 1, rows + n, rows - n]))),
            shape=(k, m * n))
        return Lfull @ self.E

    # ---- stepping --------------------------------------------------------------
    def _state(self, step, t, hc, V, p_free, dt=None, info=None):
        p = self.E @ p_free
        Wp = self.W @ p_free
        w = -np.asarray(Wp).ravel()
        d = hc + self.shape - w
        load = 2.0 * float(np.sum(p * self.area))
        i_min = int(np.argmin(d))
        i_max = int(np.argmax(p))
        return State(step=step, t=t, hc=hc, V=V, p=p, w=w, d=d, load=load,
                     film_center=float(d[self._centre]), film_min=float(d[i_min]),
                     film_min_at=tuple(self.xy[i_min]), p_max=float(p[i_max]),
                     p_max_at=tuple(self.xy[i_max]), info=info or {})

    def initial_state(self) -> State:
        mo = self.scene.motion
        return self._state(0, 0.0, mo.hc(0.0), mo.V(0.0), np.zeros(self.E.shape[1]))

    def step(self, state: State, t_new: float, dt: float) -> State:
        """One lagged step: ONE linear system (bordered by one row under imposed load).

        Under imposed load F(t) the clearance hc^{k+1} is one more unknown with
        the row ``load(p) = F(t^{k+1})``: since the right-hand side is affine in
        hc, ``p = x1 + hc x2`` with ``A x1 = rhs(h = shape)`` and
        ``A x2 = d rhs / d hc = S 1 / dt`` (``G 1 = 0``), both from one LU.
        """
        mo = self.scene.motion
        V = mo.V(t_new)
        L = self.reynolds_matrix(state.d)
        if self.dense:
            A = self.beta * L.toarray()
            A += V * self.GW
            A -= self.SW / dt
            try:
                lu = sla.lu_factor(A, check_finite=True)
            except (np.linalg.LinAlgError, ValueError) as exc:
                raise SingularSystemError(
                    f"FD step at t = {t_new:.6g}: the linear system is singular ({exc}). "
                    "Try a smaller dt or a finer grid.", t=t_new) from None
            if np.any(np.diag(lu[0]) == 0.0):
                raise SingularSystemError(
                    f"FD step at t = {t_new:.6g}: the linear system is singular (zero pivot). "
                    "Try a smaller dt or a finer grid.", t=t_new)

            def solve(b):
                return sla.lu_solve(lu, b)
        else:
            A = (self.beta * L + V * self.GW - self.SW / dt).tocsc()
            try:
                lu = spla.splu(A)
            except RuntimeError as exc:
                raise SingularSystemError(
                    f"FD step at t = {t_new:.6g}: the sparse system is singular ({exc}). "
                    "Try a smaller dt or a finer grid.", t=t_new) from None
            solve = lu.solve

        def rhs_for(h):
            return -V * (self.G @ h) + self.S @ (h - state.d) / dt

        if mo.load_controlled:
            F = mo.F(t_new)
            x1 = solve(rhs_for(self.shape))
            x2 = solve(self.S @ np.full(self.shape.size, 1.0 / dt))
            g = 2.0 * (self.E.T @ self.area)              # load = g . p_free (whole plane)
            den = float(g @ x2)
            if not np.isfinite(den) or den == 0.0:
                raise SingularSystemError(f"FD step at t = {t_new:.6g}: the load row is singular "
                                          "(the film does not respond to hc).", t=t_new)
            hc = (F - float(g @ x1)) / den
            p = x1 + hc * x2
        else:
            hc = mo.hc(t_new)
            p = solve(rhs_for(hc + self.shape))
        if not (np.all(np.isfinite(p)) and np.isfinite(hc)):
            raise SingularSystemError(
                f"FD step at t = {t_new:.6g} produced non-finite pressure: the system is singular "
                "or ill-conditioned. Try a smaller dt or a finer grid.", t=t_new)
        return self._state(state.step + 1, t_new, hc, V, p)
