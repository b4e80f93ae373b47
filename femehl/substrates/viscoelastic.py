"""Viscoelastic substrate: a standard linear solid whose memory travels with the material.

Constitutive law
----------------
A standard linear solid (Zener) in shear, with constant Poisson ratio, relaxes from the
unrelaxed (instantaneous) modulus ``G0`` to the relaxed modulus ``G_inf`` with the
stress-relaxation time ``tau``:

    G(t) = G_inf + (G0 - G_inf) exp(-t / tau).

Its creep compliance (the response to a unit step of stress) is

    J(t) = J_inf - (J_inf - J0) exp(-t / tau_c),   J0 = 1/G0,  J_inf = 1/G_inf,
    tau_c = tau G0 / G_inf                         (the retardation time, >= tau).

Moduli are in units of the scene's shear modulus G (the one in ``beta``); ``G_inf = 1``
(the default) makes the slow limit the elastic scene itself.  By the correspondence
principle (constant Poisson ratio) every elastic substrate whose compliance is
proportional to 1/G has the viscoelastic surface response

    w(x, t) = -[ J0 u(X, t) + q(X, t) ],    u = C p  (the elastic operator at G = 1),
    tau_c Dq/Dt = (J_inf - J0) u - q,

with ``q`` the delayed (creep) part of the deflection, an internal variable on the film
points, and ``D/Dt`` the material derivative.  ``elastic`` is that substrate
(:class:`~femehl.substrates.HalfSpace` by default; any substrate of femehl's, e.g. a
Winkler foundation, whose stiffness then relaxes the same way).

Moving frame
------------
femehl works in the indenter's frame, where the substrate's material moves at ``-2 V(t)``
along x (the film's mean speed is ``-V``: the Couette term ``-V dd/dx`` of the normalized
Reynolds equation; docs/design.md section 2).  So the memory is carried with the
material: ``D/Dt = d/dt - 2 V d/dx``.  femehl integrates it along the characteristics
(semi-Lagrangian): the material at a film point ``x`` at ``t_{k+1}`` was at the
departure point ``x + 2 int_{t_k}^{t_{k+1}} V dt`` at ``t_k`` (trapezoidal rule in V),
and with the step's own backward difference (Euler or variable-step BDF2, coefficients
``a0, a1, a2``)

    a0 q^{k+1} - a1 q^k(x_dep1) + a2 q^{k-1}(x_dep2) = (dt/tau_c) [(J_inf - J0) u^{k+1} - q^{k+1}].

Solved for q^{k+1} this gives the step's deflection

    w^{k+1} = -[ J_eff u^{k+1} + H / (a0 + dt/tau_c) ],
    J_eff = J0 + (J_inf - J0) (dt/tau_c) / (a0 + dt/tau_c),   H = a1 q^k(x_dep1) - a2 q^{k-1}(x_dep2),

affine in the step's pressure: the elastic operator is scaled by ``J_eff`` and ``H`` is a
known film offset, so each step is still ONE linear system (the stepper's, unchanged).
``q`` lives on a uniform grid aligned with the sliding direction (:class:`CreepMemory`):
there the shift to the departure points is a cubic spline along x (no numerical diffusion
to speak of, unlike linear interpolation on the unstructured film points, which lost 7 %
of the memory in the test case), the source ``u`` arrives by linear interpolation from the
film points, and the history returns to the film points, the origin and the nodes by the
same spline.  A departure point beyond the grid (material entering the domain upstream)
takes the grid's edge value: the material entering at the rim has the memory of the rim
-- exact in the slow and fast limits, in between an error bounded by the rim deflection
(benchmarks/viscoelastic.md measures it against the domain size: use L >= 3 for friction).

Limits
------
``tau -> infinity``: the unrelaxed elastic solid (compliance J0); ``tau -> 0``: the relaxed
one (J_inf); ``G0 = G_inf``: the elastic solid itself, exactly (the internal variable
stays 0).  Under a constant load in the dry limit the Hertz contact radius creeps as
``a(t)^3 = a_H^3 J(t)/J0`` (Lee and Radok 1960, J. Appl. Mech. 27, 438).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..errors import SceneError
from ..tribology import ENERGETICS_COLUMNS
from ..validation import check_positive
from .base import Substrate, register_substrate, substrate_operators
from .halfspace import HalfSpace

__all__ = ["Viscoelastic", "CreepMemory", "StepMemory"]


@register_substrate
@dataclass(frozen=True)
class Viscoelastic:
    """Standard linear solid (unrelaxed ``G0``, relaxed ``G_inf``, relaxation time ``tau``).

    Parameters
    ----------
    G0 : float
        Unrelaxed (instantaneous, glassy) shear modulus, in units of the scene's G
        (``G0 >= G_inf``).
    tau : float
        Stress-relaxation time, in the normalized time of the scene.  The creep
        (retardation) time is ``tau_c = tau G0 / G_inf``.
    G_inf : float, default: 1.0
        Relaxed (rubbery, long-time) shear modulus, in units of the scene's G.
    elastic : Substrate, default: HalfSpace()
        The elastic substrate whose modulus relaxes (half space, layer, Winkler).

    Notes
    -----
    Equations, the moving-frame integration and its limits: :mod:`femehl.substrates.viscoelastic`.
    """

    G0: float
    tau: float
    G_inf: float = 1.0
    elastic: object = field(default_factory=HalfSpace)
    kind = "viscoelastic"
    #: per-step figures of its runs (summary.csv, Result): the sliding energy budget
    columns = ENERGETICS_COLUMNS

    @property
    def local(self) -> bool:
        """Sparse operators only when the relaxing solid's are (a Winkler foundation)."""
        return bool(getattr(self.elastic, "local", False))

    @property
    def operators(self) -> tuple:
        """The FE elastic operators of the relaxing solid (a layer: dense only)."""
        return substrate_operators(self.elastic)

    def __post_init__(self):
        G0 = check_positive("unrelaxed modulus G0", self.G0, "Give G0 in units of G.")
        Gi = check_positive("relaxed modulus G_inf", self.G_inf, "Give G_inf in units of G.")
        tau = check_positive("relaxation time tau", self.tau, "Give the relaxation time in normalized time.")
        if G0 < Gi:
            raise SceneError(
                f"the unrelaxed modulus G0 = {G0:g} is below the relaxed one G_inf = {Gi:g}: a "
                "standard linear solid stiffens under fast loading, so give G0 >= G_inf."
            )
        if isinstance(self.elastic, dict):
            from ..scenefile import substrate_from_mapping

            object.__setattr__(self, "elastic", substrate_from_mapping(self.elastic))
        if not isinstance(self.elastic, Substrate) or isinstance(self.elastic, Viscoelastic):
            raise SceneError(
                f"Viscoelastic(elastic=...) must be an elastic substrate such as femehl.HalfSpace() "
                f"or femehl.Winkler(k), got {type(self.elastic).__name__}."
            )
        object.__setattr__(self, "G0", G0)
        object.__setattr__(self, "G_inf", Gi)
        object.__setattr__(self, "tau", tau)

    @classmethod
    def from_si(cls, G0, tau, dim, G_inf=None, elastic=None) -> Viscoelastic:
        """From SI values: ``G0`` and ``G_inf`` [Pa] (default ``G_inf = dim.G``, the modulus
        in beta), ``tau`` [s]; ``dim`` a :class:`femehl.Dimensional` (its time scale)."""
        G = float(dim.G)
        G0 = check_positive("[si] G0 [Pa]", G0, "Give the unrelaxed shear modulus in Pa.")
        tau = check_positive("[si] tau [s]", tau, "Give the relaxation time in seconds.")
        Gi = G if G_inf is None else check_positive("[si] G_inf [Pa]", G_inf, "Give it in Pa.")
        return cls(G0=G0 / G, tau=tau / dim.time, G_inf=Gi / G, elastic=elastic or HalfSpace(dim.nu))

    # ---- the creep function ---------------------------------------------------------------
    @property
    def J0(self) -> float:
        """Unrelaxed compliance ``1/G0`` (units of 1/G)."""
        return 1.0 / self.G0

    @property
    def J_inf(self) -> float:
        """Relaxed compliance ``1/G_inf`` (units of 1/G)."""
        return 1.0 / self.G_inf

    @property
    def tau_creep(self) -> float:
        """Retardation (creep) time ``tau G0 / G_inf``."""
        return self.tau * self.G0 / self.G_inf

    def creep_compliance(self, t):
        """``J(t) = J_inf - (J_inf - J0) exp(-t / tau_c)`` for t >= 0."""
        t = np.asarray(t, dtype=float)
        return self.J_inf - (self.J_inf - self.J0) * np.exp(-t / self.tau_creep)

    def relaxation_modulus(self, t):
        """``G(t) = G_inf + (G0 - G_inf) exp(-t / tau)`` for t >= 0."""
        t = np.asarray(t, dtype=float)
        return self.G_inf + (self.G0 - self.G_inf) * np.exp(-t / self.tau)

    # ---- the substrate protocol: the elastic operator at unit modulus ---------------------
    def compliance_operator(self, disc):
        return self.elastic.compliance_operator(disc)

    def deflection_rows(self, disc, points):
        return self.elastic.deflection_rows(disc, points)

    def memory(self, disc) -> CreepMemory:
        """The internal variable's integrator on ``disc`` (used by the stepper)."""
        return CreepMemory(self, disc)


@dataclass(frozen=True)
class StepMemory:
    """One step's viscoelastic response: ``w = -(scale u + offset)`` with ``u = C p``.

    ``offset`` lives on the film points; :meth:`offset_at` gives it elsewhere (the origin,
    probed nodes); :meth:`creep` is the internal variable after the step (on the memory's
    grid).
    """

    scale: float
    offset: np.ndarray
    weight: float  # (dt/tau_c) (J_inf - J0) / (a0 + dt/tau_c): q^{k+1} = offset + weight u
    grid_offset: np.ndarray
    _at: object
    _to_grid: object
    _film: object

    def offset_at(self, points):
        return self._at(points)

    def creep(self, u):
        """The internal variable after the step (the state's ``creep`` array: grid values,
        then the film points' defects) from ``u^{k+1} = C p^{k+1}`` on the film points."""
        u = np.asarray(u, dtype=float)
        grid = self.grid_offset + self.weight * np.asarray(self._to_grid @ u).ravel()
        return self._film(grid, self.offset + self.weight * u)


class CreepMemory:
    """Semi-Lagrangian integrator of ``tau_c Dq/Dt = (J_inf - J0) u - q`` on a discretization.

    The internal variable lives on a uniform grid aligned with the sliding direction
    (spacing that of the film points in the finest part of the mesh -- the 5th
    percentile of nearest-neighbour distances --, at most :data:`MAX_COLUMNS` columns;
    twice that across, where nothing is transported), where the
    transport along x is a cubic-spline shift (error O(dx^4) per step: no numerical
    diffusion to speak of).  The step's source ``u = C p`` reaches the grid by linear
    interpolation from the film points (a Delaunay triangulation of them, mirrored for a
    half disk; an O(h^2) error that does not accumulate, since the grid keeps the master
    copy), and the grid's history reaches the film points, the origin and the nodes by
    the same cubic spline.  Beyond the grid (material entering upstream) the spline takes
    the edge value (mode "nearest").  The film points also keep their *defect*, their own value
    minus the grid's spline there (an O(h^2) round-trip error), kept in place (not shifted:
    carrying it by repeated linear interpolation went unstable near the rim with BDF2): at
    zero shift the history at a film point is then its own value exactly, so a step of any
    size continues the film points' memory without a jump (the adaptive step controller,
    which tests the film points, would otherwise meet an error floor that no step size
    removes).  The price is a larger transport error: 0.90 % instead of 0.52 % in the test
    case (medium mesh).  The origin and the nodes take the grid's value.
    """

    MAX_COLUMNS = 4096

    def __init__(self, solid: Viscoelastic, disc):
        from scipy.spatial import Delaunay, cKDTree

        self.solid = solid
        self.disc = disc
        P = np.asarray(disc.film_points, dtype=float)
        self.points = P
        self.one_d = getattr(disc, "dimension", 2) == 1
        self.half = bool(getattr(disc, "half", False))
        x0, x1 = float(P[:, 0].min()), float(P[:, 0].max())
        if self.one_d:
            gaps = np.diff(np.unique(P[:, 0]))
        else:  # the spacing of the film points: nearest-neighbour distances
            gaps = cKDTree(P).query(P, k=2)[0][:, 1]
        gaps = gaps[gaps > 0]
        h = float(np.percentile(gaps, 5)) if gaps.size else (x1 - x0)
        span = x1 - x0
        nx = int(min(self.MAX_COLUMNS, max(8, np.ceil(span / h) + 1)))
        self.dx = span / (nx - 1)
        self.x0 = x0
        if self.one_d:
            self.y0, self.dy, ny = 0.0, 1.0, 1
        else:
            y0 = 0.0 if self.half else float(P[:, 1].min())
            y1 = float(P[:, 1].max())
            ny = int(max(2, np.ceil((y1 - y0) / (2.0 * self.dx)) + 1))  # no transport along y
            self.y0, self.dy = y0, (y1 - y0) / (ny - 1)
        self.shape = (ny, nx)
        gx = x0 + self.dx * np.arange(nx)
        gy = self.y0 + self.dy * np.arange(ny)
        GX, GY = np.meshgrid(gx, gy)
        self.grid = np.column_stack([GX.ravel(), GY.ravel()])
        if self.one_d:
            self._order = np.argsort(P[:, 0])
        else:
            pts = np.vstack([P, P * np.array([1.0, -1.0])]) if self.half else P
            self._tri, self._tree = Delaunay(pts), cKDTree(pts)
        self.to_grid = self._linear(self.grid)  # film points -> grid

    def _linear(self, points) -> sp.csr_matrix:
        """Linear interpolation of film-point values at ``points`` (sparse); the nearest
        film point's value outside their hull."""
        P, X = self.points, np.asarray(points, dtype=float).reshape(-1, 2)
        m, n = X.shape[0], P.shape[0]
        if self.one_d:
            xs = P[self._order, 0]
            xg = np.clip(X[:, 0], xs[0], xs[-1])
            j = np.clip(np.searchsorted(xs, xg) - 1, 0, xs.size - 2)
            w1 = (xg - xs[j]) / (xs[j + 1] - xs[j])
            rows = np.repeat(np.arange(m), 2)
            cols = np.column_stack([self._order[j], self._order[j + 1]]).ravel()
            vals = np.column_stack([1.0 - w1, w1]).ravel()
        else:
            tri = self._tri
            simp = tri.find_simplex(X)
            k = np.flatnonzero(simp >= 0)
            T = tri.transform[simp[k]]
            b = np.einsum("kij,kj->ki", T[:, :2], X[k] - T[:, 2])
            out = np.flatnonzero(simp < 0)
            rows = np.concatenate([np.repeat(k, 3), out])
            cols = np.concatenate([tri.simplices[simp[k]].ravel(), self._tree.query(X[out])[1]])
            vals = np.concatenate([np.column_stack([b, 1.0 - b.sum(axis=1)]).ravel(), np.ones(out.size)])
            cols = np.where(cols >= n, cols - n, cols)
        return sp.csr_matrix((vals, (rows, cols)), shape=(m, n))

    @property
    def size(self) -> int:
        """Length of the internal variable's state: the grid values, then the film points'
        defects (see :meth:`step`)."""
        return self.grid.shape[0] + self.points.shape[0]

    def split(self, state_array):
        """``(grid values, film-point defects)`` of a state's ``creep`` array."""
        a = np.asarray(state_array, dtype=float)
        m = self.grid.shape[0]
        return a[:m], a[m:]

    # ---- the cubic spline of a grid field -------------------------------------------------
    def _spline(self, q):
        from scipy.ndimage import spline_filter

        Q = np.asarray(q, dtype=float).reshape(self.shape)
        return spline_filter(Q[0] if self.one_d else Q, order=3, mode="nearest")

    def _eval(self, coef, points, shift):
        from scipy.ndimage import map_coordinates

        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        col = (pts[:, 0] + shift - self.x0) / self.dx
        if self.one_d:
            coords = col[None, :]
        else:
            y = np.abs(pts[:, 1]) if self.half else pts[:, 1]
            coords = np.vstack([(y - self.y0) / self.dy, col])
        return map_coordinates(coef, coords, order=3, mode="nearest", prefilter=False)

    # ---- one step -----------------------------------------------------------------------
    def step(self, state, t_new: float, dt: float, a0: float, a1: float, a2: float, V) -> StepMemory:
        """The step's scale and offset from the material's history (``state.creep``).

        ``a0, a1, a2`` are the step's backward-difference coefficients; without the
        internal variable one step back (a restart without history) the step is Euler's.
        """
        solid = self.solid
        q, e = self.split(np.zeros(self.size) if state.creep is None else state.creep)
        qp, ep = self.split(state.creep_prev) if state.creep_prev is not None else (None, None)
        t = state.t
        s1 = dt * (V(t) + V(t_new))  # 2 int V dt over the step, trapezoidal
        two = a2 != 0.0 and qp is not None and bool(state.dt_prev)
        if two:
            s2 = s1 + state.dt_prev * (V(t - state.dt_prev) + V(t))
        else:
            a0, a1, a2, s2 = 1.0, 1.0, 0.0, 0.0
        r = dt / solid.tau_creep
        den = a0 + r
        dJ = solid.J_inf - solid.J0
        c1 = self._spline(q)
        c2 = self._spline(qp) if two else None

        def history(points, e1=0.0, e2=0.0):
            out = a1 * (self._eval(c1, points, s1) + e1)
            return (out - a2 * (self._eval(c2, points, s2) + e2) if two else out) / den

        return StepMemory(
            scale=solid.J0 + dJ * r / den,
            offset=history(self.points, e, ep),  # the film points' own values at zero shift
            weight=dJ * r / den,
            grid_offset=history(self.grid),
            _at=history,
            _to_grid=self.to_grid,
            _film=self._film_defect,
        )

    def _film_defect(self, grid_values, film_values):
        """The state array: the grid values and the film points' defect against them."""
        return np.concatenate(
            [grid_values, film_values - self._eval(self._spline(grid_values), self.points, 0.0)]
        )
