"""Line contact: a rigid cylinder sliding on a Winkler foundation (paper section 4).

The problem
-----------
The cylinder's gap is ``s(x) = x^2/2`` (normalized units, radius 1), the
substrate a Winkler foundation ``w = -p/k``, and the film thickness

    d(x, t) = hc(t) + x^2/2 + p(x, t)/k           (d = h - w, w < 0 under p > 0)

obeys the 1-D normalized Reynolds equation, with the same conventions as the
2-D problem of :mod:`femehl.scene` (design.md sections 1-2):

    beta d/dx( d^3 dp/dx ) = -V(t) dd/dx + dd/dt      on -L < x < L,
    p(-L) = p(L) = 0,    p(x, 0) = 0  so  d(x, 0) = hc(0) + x^2/2.

The cylinder slides toward +x; in its frame the substrate moves toward -x,
so the inlet is at x > 0 and the exit constriction at x < 0.  hc > 0 is a
gap, hc < 0 an indentation.  Cavitation is not modeled: p may go negative
(at the exit), as in the 2-D solvers.  The paper checks its scheme on this
problem (Wu, Hui et al., JMPS 2022, section 4 and its SI) against the exact
steady sliding solution, which :mod:`femehl.line_steady` computes by
quadrature and shooting.

The scheme (paper section 3, femehl's FE form, design.md section 4)
------------------------------------------------------------------
P1 pressure on a scikit-fem :class:`~skfem.MeshLine` (uniform or graded),
the film on elements (P0): ``d_e = h(x_e) + (P p)_e / k`` with ``x_e`` the
centroid and ``P`` the element average of a P1 field.  With ``d^3`` lagged
one step, find p^{k+1} in P1, p = 0 at x = +-L, such that for every P1 test
function q vanishing at +-L

    beta int (d^k)^3 p' q'  +  V int d^{k+1} q'  +  int (d^{k+1} - d^k)/dt q  = 0

(the Couette term integrated by parts; its boundary term vanishes since
q(+-L) = 0).  With ``C = P/k`` (sparse: the Winkler foundation is local) this
is ONE sparse linear system per step,

    ( beta K(d^k) + V Bx C + M C/dt ) p = -V Bx h^{k+1} - M (h^{k+1} - d^k)/dt,

with the forms of :mod:`femehl.fe.forms` (K: ``film_diffusion``, Bx:
``couette``, M: ``squeeze``).  No dense matrix is built anywhere.

Imposed load per unit length ``F(t)`` instead of an imposed gap: hc^{k+1} is
one more unknown (its column is ``V Bx 1 + M 1/dt``) and the row
``int p dx = F(t^{k+1})`` borders the system; still one sparse solve per step,
and the load is met to solver precision at every step.  ``motion.gap`` then
only sets the initial clearance hc(0) (as for the 2-D solvers).

``scheme="bdf2"`` (see :data:`femehl.stepping.SCHEMES`) replaces the backward
Euler difference by BDF2 and the lagged d^k by the extrapolation
``2 d^k - d^{k-1}`` (variable-step forms); still one linear system per step.
At a steady state (d^{k+1} = d^k = d^{k-1}) either scheme reduces to the
steady weak form whatever dt, so long runs test the spatial discretization
alone.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, ElementLineP0, ElementLineP1, MeshLine, asm

from .errors import SceneError, SingularSystemError
from .fe.forms import couette, film_diffusion, squeeze
from .scene import (Constant, Motion, RampHold, Table, TanhStart, _as_time_function,
                    check_finite, check_positive)
from .stepping import State, get_scheme, march

__all__ = ["LineScene", "LineStepper", "LineResult", "line_nodes", "solve_line"]


def _default_motion() -> Motion:
    return Motion(gap=RampHold(0.1, -0.5, 1.0), velocity=TanhStart(1.0, 1.0))


# --------------------------------------------------------------------------
# scene
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class LineScene:
    """A rigid cylinder (gap ``x^2/2``) on a lubricated Winkler foundation, normalized.

    Parameters
    ----------
    k : float, default: 1.0
        Winkler stiffness, ``w = -p/k`` (> 0; a large k is a nearly rigid substrate).
    beta : float, default: 10.0
        The paper's film parameter multiplying ``d/dx(d^3 dp/dx)`` (> 0).
    motion : femehl.scene.Motion, default: ramp 0.1 -> -0.5 for t <= 1, then tanh(t - 1) sliding
        Tip clearance hc(t) and sliding velocity V(t) (cylinder moves toward +x).
        With an imposed load, ``motion.gap`` only gives the initial clearance hc(0).
    L : float, default: 2.0
        Half length of the domain ``[-L, L]``; p = 0 at both ends.
    load : callable or float or None, default: None
        Imposed load per unit length ``F(t) = int p dx``; None imposes the gap
        instead.  ``motion.load`` is accepted too (and moved here); give one of them.
    """

    k: float = 1.0
    beta: float = 10.0
    motion: Motion = field(default_factory=_default_motion)
    L: float = 2.0
    load: Callable[[float], float] | None = None

    def __post_init__(self):
        object.__setattr__(self, "k", check_positive(
            "Winkler stiffness k", self.k, "Use a large k for a nearly rigid substrate."))
        object.__setattr__(self, "beta", check_positive(
            "beta", self.beta, "beta multiplies d/dx(d^3 dp/dx) in the normalized equation."))
        object.__setattr__(self, "L", check_positive(
            "domain half length L", self.L, "The domain is [-L, L]; L = 2 suits hc >= -0.5."))
        if not isinstance(self.motion, Motion):
            raise SceneError(
                f"LineScene.motion must be a femehl.scene.Motion, got {type(self.motion).__name__}: "
                "wrap the gap and velocity as Motion(gap=..., velocity=...).")
        mload = getattr(self.motion, "load", None)
        if mload is not None:
            if self.load is not None:
                raise SceneError(
                    "the load is imposed twice (LineScene.load and Motion.load): give only one.")
            object.__setattr__(self, "load", mload)
        if self.load is not None:
            object.__setattr__(self, "load", _as_time_function("LineScene load F(t)", self.load))
            check_finite("load F(t=0)", self.load(0.0), "The load history must return finite values.")
        hc0 = self.motion.hc(0.0)
        if hc0 <= 0.0:
            raise SceneError(
                f"initial clearance hc(0) = {hc0:g} must be > 0: with p = 0 at t = 0 the film "
                "thickness d = hc + x^2/2 would be <= 0 at x = 0. Start with a positive gap and "
                "indent with a ramp, e.g. RampHold(h0=0.1, h_end=-0.5, t1=1.0).")
        a = self.contact_halfwidth()
        if a is not None and self.L < 1.5 * a:
            raise SceneError(
                f"domain half length L = {self.L:g} is too small to hold the contact: the dry "
                f"Winkler contact of this run reaches |x| = {a:.3g}, and the pressure must decay "
                f"before x = +-L. Use L >= {1.5 * a:.3g}.")

    @property
    def imposed_load(self) -> bool:
        """True when the load F(t) is imposed (hc is then an unknown)."""
        return self.load is not None

    @staticmethod
    def shape(x):
        """Rigid gap of the cylinder, ``x^2/2``."""
        x = np.asarray(x, dtype=float)
        return 0.5 * x * x

    def contact_halfwidth(self) -> float | None:
        """Largest dry (Hertz-Winkler) contact half width of the run, when it can be told.

        Imposed gap: ``a = sqrt(-2 hc_min)`` (0 if the gap stays open).  Imposed
        load: ``F = (2/3) k a^3``.  None for gap or load histories that are
        arbitrary callables.
        """
        if self.load is None:
            gap = self.motion.gap
            if isinstance(gap, RampHold):
                hmin = min(gap.h0, gap.h_end)
            elif isinstance(gap, Table):
                hmin = min(gap.values)
            elif isinstance(gap, Constant):
                hmin = gap.value
            else:
                return None
            return math.sqrt(2.0 * max(0.0, -hmin))
        F = self.load
        if isinstance(F, Constant):
            fmax = F.value
        elif isinstance(F, Table):
            fmax = max(F.values)
        else:
            return None
        return (1.5 * max(0.0, fmax) / self.k) ** (1.0 / 3.0)


# --------------------------------------------------------------------------
# mesh
# --------------------------------------------------------------------------
def line_nodes(L: float, n_elements: int, grading="uniform", fine: float | None = None):
    """Node coordinates of a 1-D mesh of ``[-L, L]`` with ``n_elements`` elements.

    Parameters
    ----------
    L : float
        Half length of the domain.
    n_elements : int
        Number of elements (>= 4).
    grading : "uniform", float or callable, default: "uniform"
        "uniform": equal elements.  A float ``r >= 1``: elements are ``r`` times
        smaller in ``|x| <= fine`` than near the ends, with a linear change of
        the node density over a width ``0.25 L`` outside that zone.  A callable
        ``rho(x) > 0``: node density (element size proportional to ``1/rho``).
        The nodes are the quantiles of the density, so doubling ``n_elements``
        halves every element (clean refinement studies).
    fine : float, optional
        Half width of the fine zone for a float ``grading``; default ``L/2``.

    Returns
    -------
    numpy.ndarray
        ``n_elements + 1`` increasing node coordinates, ``-L`` and ``L`` included.
    """
    L = check_positive("domain half length L", L)
    if isinstance(n_elements, bool) or not isinstance(n_elements, (int, np.integer)) or n_elements < 4:
        raise SceneError(f"n_elements must be an integer >= 4, got {n_elements!r}.")
    n = int(n_elements)
    if isinstance(grading, str):
        if grading != "uniform":
            raise SceneError(f"grading must be 'uniform', a size ratio >= 1 or a density "
                             f"function, got {grading!r}.")
        return np.linspace(-L, L, n + 1)
    if callable(grading):
        rho = grading
    else:
        r = check_finite("grading (size ratio)", grading,
                         "Give 'uniform', a ratio >= 1 or a density function rho(x).")
        if r < 1.0:
            raise SceneError(f"grading ratio must be >= 1 (fine/coarse element size), got {r:g}.")
        xf = 0.5 * L if fine is None else check_positive("fine zone half width", fine)
        width = 0.25 * L

        def rho(x):
            u = np.clip((np.abs(x) - xf) / width, 0.0, 1.0)
            return r + (1.0 - r) * u
    xs = np.linspace(-L, L, 200 * n + 1)
    try:
        dens = np.asarray(rho(xs), dtype=float) * np.ones_like(xs)
    except Exception as exc:  # noqa: BLE001 - a user callable may fail any way
        raise SceneError(f"the grading density rho(x) failed on an array of x: {exc}") from None
    if not (np.all(np.isfinite(dens)) and np.all(dens > 0.0)):
        raise SceneError("the grading density rho(x) must be finite and > 0 on [-L, L].")
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (dens[1:] + dens[:-1]) * np.diff(xs))])
    x = np.interp(np.linspace(0.0, cum[-1], n + 1), cum, xs)
    x[0], x[-1] = -L, L
    return x


# --------------------------------------------------------------------------
# stepper
# --------------------------------------------------------------------------
class LineStepper:
    """Advance the line-contact FE discretization by one lagged sparse linear step.

    Parameters
    ----------
    scene : LineScene
    n_elements : int, default: 400
        Number of P1 elements on ``[-L, L]``.
    grading : "uniform", float or callable, default: 3.0
        Mesh grading, see :func:`line_nodes`.  The default makes elements 3
        times smaller over the contact (``|x| <= fine``) than at the ends.
    fine : float, optional
        Half width of the fine zone; default ``min(L, a + 0.5)`` with ``a`` the
        dry contact half width (:meth:`LineScene.contact_halfwidth`), or ``L/2``.
    scheme : {"euler", "bdf2"}, default: "euler"
        "euler" is the paper's scheme (backward Euler, d^3 lagged one step);
        "bdf2" is second order in time (:data:`femehl.stepping.SCHEMES`) but
        less robust: for k = 1, beta = 10, hc = -0.5 it kept oscillating at
        dt = 0.2 (settled at dt <= 0.1), where "euler" settles up to dt = 0.5.

    Attributes
    ----------
    x, xc : numpy.ndarray
        Nodes and element centroids.
    free : numpy.ndarray
        Indices of the interior nodes (the pressure unknowns).
    matrix_format : str
        Sparse format of the step matrix ("csc").
    """

    method = "line"
    matrix_format = "csc"

    def __init__(self, scene: LineScene, n_elements: int = 400, grading=3.0, fine=None,
                 scheme: str = "euler"):
        t0 = time.perf_counter()
        if not isinstance(scene, LineScene):
            raise SceneError(f"scene must be a femehl.line.LineScene, got {type(scene).__name__}.")
        self.scene = scene
        self.scheme = get_scheme(scheme)
        if fine is None and not isinstance(grading, str):
            a = scene.contact_halfwidth()
            fine = 0.5 * scene.L if a is None else min(scene.L, a + 0.5)
        x = line_nodes(scene.L, n_elements, grading, fine)
        self.mesh = MeshLine(x)
        b1 = Basis(self.mesh, ElementLineP1())
        b0 = b1.with_element(ElementLineP0())
        self.basis, self.basis0 = b1, b0
        t = self.mesh.t
        self.x = self.mesh.p[0].copy()
        self.xc = self.x[t].mean(axis=0)
        ne, nn = t.shape[1], self.x.size
        self.nelements, self.nnodes = ne, nn
        # element average of a P1 field
        self.P = sp.csr_matrix((np.full(2 * ne, 0.5), (np.repeat(np.arange(ne), 2), t.T.ravel())),
                               shape=(ne, nn))
        self.free = np.setdiff1d(np.arange(nn), self.mesh.boundary_nodes())
        free = self.free
        self.beta, self.k = scene.beta, scene.k
        self.shape = scene.shape(self.xc)
        # unit-coefficient element stiffness; K(d) scales element e by d_e^3
        kcoo = film_diffusion.coo_data(b1, d3=b0.interpolate(np.ones(ne)))
        self._k_rows, self._k_cols = kcoo.indices
        self._k_data = kcoo.data.reshape(-1, ne)
        Mall = asm(squeeze, b0, b1).tocsr()
        self.Bx = asm(couette, b0, b1).tocsr()[free]               # (nfree, ne)
        self.M = Mall[free]
        self.node_weight = np.asarray(Mall.sum(axis=1)).ravel()    # int phi_q dx
        self.C = (self.P[:, free] / self.k).tocsr()                # (P p)/k on elements
        self.BxC = (self.Bx @ self.C).tocsr()
        self.MC = (self.M @ self.C).tocsr()
        ones = np.ones(ne)
        self._hc_col = (self.Bx @ ones, self.M @ ones)             # d(rows)/d(hc): V Bx1 + M1/dt
        self.info = {
            "method": self.method, "elements": ne, "nodes": nn, "unknowns": int(free.size)
            + int(scene.imposed_load), "grading": grading if not callable(grading) else "callable",
            "h_min": float(np.diff(self.x).min()), "h_max": float(np.diff(self.x).max()),
            "imposed_load": scene.imposed_load, "scheme": self.scheme.name,
            "setup_s": time.perf_counter() - t0,
        }

    # ---- operators ----------------------------------------------------------
    def stiffness(self, d: np.ndarray):
        """K(d)[q, p] = int d^3 p' q' on the free nodes (d element-constant)."""
        data = (self._k_data * (np.asarray(d, dtype=float) ** 3)[None, :]).ravel()
        n = self.nnodes
        K = sp.csr_matrix((data, (self._k_rows, self._k_cols)), shape=(n, n))
        return K[self.free][:, self.free]

    def assemble(self, state: State, t_new: float, dt: float):
        """The sparse system ``A u = b`` of the step from ``state`` to ``t_new``.

        ``u`` is the free nodal pressure, followed by hc^{k+1} under an imposed
        load.  ``A`` is a scipy sparse matrix in :attr:`matrix_format`.  With
        the scheme's coefficients (Euler: a0 = a1 = l0 = 1, a2 = l1 = 0)

            A = beta K(l0 d^k - l1 d^{k-1}) + V Bx C + (a0/dt) M C
            b = -V Bx h - M (a0 h - a1 d^k + a2 d^{k-1}) / dt.
        """
        sc = self.scene
        V = sc.motion.V(t_new)
        omega = None if state.d_prev is None or not state.dt_prev else dt / state.dt_prev
        a0, a1, a2, l0, l1 = self.scheme.coefficients(omega)
        if l1 == 0.0:
            d_lag, hist = state.d, state.d
        else:   # extrapolated coefficient, kept positive as in the FE solver
            d_lag = np.maximum(l0 * state.d - l1 * state.d_prev, 0.5 * state.d)
            hist = a1 * state.d - a2 * state.d_prev
        c = a0 / dt
        A = self.beta * self.stiffness(d_lag) + V * self.BxC + c * self.MC
        if not sc.imposed_load:
            h = sc.motion.hc(t_new) + self.shape
            b = -V * (self.Bx @ h) - self.M @ (a0 * h - hist) / dt
            return A.asformat(self.matrix_format), b
        F = check_finite(f"load F(t={t_new:g})", sc.load(t_new),
                         "The load history must return finite values.")
        col = V * self._hc_col[0] + c * self._hc_col[1]
        row = self.node_weight[self.free]
        A = sp.bmat([[A, sp.csr_matrix(col[:, None])], [sp.csr_matrix(row[None, :]), None]])
        b = np.concatenate([-V * (self.Bx @ self.shape) - self.M @ (a0 * self.shape - hist) / dt, [F]])
        return A.asformat(self.matrix_format), b

    # ---- stepping -----------------------------------------------------------
    def _state(self, step, t, hc, V, p_free, info=None, d_prev=None, dt_prev=None) -> State:
        p = np.zeros(self.nnodes)
        p[self.free] = p_free
        Pp = self.P @ p
        w = -Pp / self.k
        d = hc + self.shape - w
        i_min, i_max = int(np.argmin(d)), int(np.argmax(p))
        p0 = float(np.interp(0.0, self.x, p))
        return State(step=step, t=t, hc=float(hc), V=float(V), p=p, w=w, d=d,
                     load=float(self.node_weight @ p), film_center=float(hc) + p0 / self.k,
                     film_min=float(d[i_min]), film_min_at=(float(self.xc[i_min]), 0.0),
                     p_max=float(p[i_max]), p_max_at=(float(self.x[i_max]), 0.0),
                     info=info or {}, d_prev=d_prev, dt_prev=dt_prev)

    def initial_state(self) -> State:
        """p = 0 at t = 0, so d = hc(0) + x^2/2."""
        mo = self.scene.motion
        return self._state(0, 0.0, mo.hc(0.0), mo.V(0.0), np.zeros(self.free.size))

    def step(self, state: State, t_new: float, dt: float) -> State:
        """One lagged step: assemble the sparse system and solve it once."""
        A, b = self.assemble(state, t_new, dt)
        try:
            u = spla.splu(A).solve(b)
        except RuntimeError as exc:
            raise SingularSystemError(
                f"line step at t = {t_new:.6g}: the sparse system is singular ({exc}). "
                "Try a smaller dt or more elements.", t=t_new) from None
        if not np.all(np.isfinite(u)):
            raise SingularSystemError(
                f"line step at t = {t_new:.6g} produced non-finite values: the system is "
                "ill-conditioned. Try a smaller dt or more elements.", t=t_new)
        bn = float(np.linalg.norm(b))
        res = float(np.linalg.norm(A @ u - b)) / bn if bn > 0 else 0.0
        mo = self.scene.motion
        if self.scene.imposed_load:
            p_free, hc = u[:-1], float(u[-1])
        else:
            p_free, hc = u, mo.hc(t_new)
        return self._state(state.step + 1, t_new, hc, mo.V(t_new), p_free,
                           info={"residual": res}, d_prev=state.d, dt_prev=dt)


# --------------------------------------------------------------------------
# driver and result
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class LineResult:
    """Per-step arrays of a line-contact run, the stored states and the mesh.

    Attributes
    ----------
    t, hc, V, load, film_center, film_min, film_min_x, p_max : numpy.ndarray
        One entry per step (the initial state first).
    states : tuple of femehl.stepping.State
        Stored states (every ``store_every``-th step and the last one).
    x, xc : numpy.ndarray
        Mesh nodes (where ``State.p`` lives) and centroids (``State.d``, ``State.w``).
    """

    scene: LineScene
    t: np.ndarray
    hc: np.ndarray
    V: np.ndarray
    load: np.ndarray
    film_center: np.ndarray
    film_min: np.ndarray
    film_min_x: np.ndarray
    p_max: np.ndarray
    states: tuple
    x: np.ndarray
    xc: np.ndarray
    info: dict = field(default_factory=dict)

    @property
    def final(self) -> State:
        """The last state of the run."""
        return self.states[-1]

    def state_at(self, t: float) -> State:
        """The stored state closest in time to ``t``."""
        ts = np.array([s.t for s in self.states])
        return self.states[int(np.argmin(np.abs(ts - t)))]


def solve_line(scene: LineScene, t_end: float, dt: float, *, store_every: int = 1,
               callback: Callable[[State], None] | None = None, **opts) -> LineResult:
    """Run a line-contact scene from t = 0 to ``t_end`` with steps ``dt``.

    Parameters
    ----------
    scene : LineScene
    t_end, dt : float
        End time and time step (normalized; the last step is shortened to end at t_end).
    store_every : int, default: 1
        Keep the fields of every ``store_every``-th state (the last one always).
    callback : callable, optional
        Called with every state as it is produced.
    **opts
        Passed to :class:`LineStepper` (``n_elements``, ``grading``, ``fine``, ``scheme``).

    Returns
    -------
    LineResult
    """
    if isinstance(store_every, bool) or not isinstance(store_every, (int, np.integer)) or store_every < 1:
        raise SceneError(f"store_every must be an integer >= 1, got {store_every!r}.")
    t0 = time.perf_counter()
    stepper = LineStepper(scene, **opts)
    rows = {k: [] for k in ("t", "hc", "V", "load", "film_center", "film_min", "film_min_x", "p_max")}
    stored = []
    last = None
    for s in march(stepper, t_end, dt):
        for k in ("t", "hc", "V", "load", "film_center", "film_min", "p_max"):
            rows[k].append(getattr(s, k))
        rows["film_min_x"].append(s.film_min_at[0])
        if s.step % store_every == 0:
            stored.append(s)
        if callback is not None:
            callback(s)
        last = s
    if stored[-1] is not last:
        stored.append(last)
    info = dict(stepper.info)
    info.update(steps=last.step, dt=float(dt), run_s=time.perf_counter() - t0)
    return LineResult(scene=scene, states=tuple(stored), x=stepper.x.copy(), xc=stepper.xc.copy(),
                      info=info, **{k: np.asarray(v, dtype=float) for k, v in rows.items()})
