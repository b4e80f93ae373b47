"""Viscoelastic substrate: a standard linear solid whose memory travels with the material.

:class:`Viscoelastic` (unrelaxed and relaxed shear moduli ``G0``, ``G_inf`` in units of the
scene's G, stress-relaxation time ``tau``) relaxes any elastic substrate by the
correspondence principle: ``w = -(J0 C p + q)``, the creep ``q`` an internal variable that
:class:`CreepMemory` carries with the material (``D/Dt = d/dt - 2 U d/dx``, ``U`` the
substrate surface's speed, :meth:`femehl.Motion.substrate_speed`) by an exact
exponential integrator on a uniform grid, so that each step is still one linear system.
The constitutive law, the scheme, its step limit and the limits: docs/design.md section 15.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from femehl.elastic.base import Substrate, register_substrate, substrate_operators
from femehl.elastic.halfspace import HalfSpace
from femehl.errors import SceneError
from femehl.validation import check_positive

__all__ = ["Viscoelastic", "CreepMemory", "StepMemory", "ENERGETICS_COLUMNS"]

#: the sliding energy budget a viscoelastic run reports (:mod:`femehl.solver.energetics`)
ENERGETICS_COLUMNS = ("friction", "dissipation_film", "power_sliding")


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
    Equations, the moving-frame integration and its limits: :mod:`femehl.elastic.viscoelastic`.
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

    #: the material crosses the film domain in at least this many adaptive steps
    TRANSIT_STEPS = 4

    def step_limit(self, scene, disc, t_end: float) -> float:
        """The largest step the memory's integrator resolves: the moving material crosses
        the film domain (its extent along x) in at least :attr:`TRANSIT_STEPS` steps at the
        largest speed of the run, ``span / (2 U_max TRANSIT_STEPS)`` (``U`` the substrate's
        surface speed); math.inf while the substrate's surface is still.

        Each step integrates the memory exactly along the characteristic for a source frozen
        in time and takes the source's increment over the step at the arrival point: exact
        in a steady state whatever dt, second order in a transient while the step's shift
        ``2 U dt`` is a fraction of the length over which the source varies (the contact).
        Beyond that the memory of the whole domain is rebuilt each step from the previous
        step's source, an error the adaptive steps' film-based estimate does not scale with;
        a quarter of the domain keeps it a fraction of the contact for L >= 2 a.
        """
        pts = np.asarray(disc.film_points, dtype=float)
        span = float(np.ptp(pts[:, 0])) if pts.size else 0.0
        motion = getattr(scene, "motion", None)
        if motion is None or span <= 0.0:
            return math.inf
        ts = np.union1d(np.linspace(0.0, float(t_end), 2001), getattr(motion, "breakpoints", ()) or ())
        v = max(abs(float(motion.substrate_speed(t))) for t in ts[(ts >= 0.0) & (ts <= t_end)])
        return math.inf if v == 0.0 else span / (2.0 * v * self.TRANSIT_STEPS)

    def memory(self, disc) -> CreepMemory:
        """The internal variable's integrator on ``disc`` (used by the stepper)."""
        return CreepMemory(self, disc)

    def dry_contact(self, shape):
        """The relaxed solid's (``G_inf``: the softest, so the deepest under a load), with the
        geometric overlap as its extent (a sliding contact's hysteresis shifts it)."""
        from femehl.elastic.contact import DryContact, _dry_contact

        relaxed = _dry_contact(self.elastic, shape).load
        load = None if relaxed is None else (lambda delta: self.G_inf * relaxed(delta))
        return DryContact(shape.overlap_axes, load, "the viscoelastic substrate")


@dataclass(frozen=True)
class StepMemory:
    """One step's viscoelastic response: ``w = -(scale u + offset)`` with ``u = C p``.

    ``offset`` lives on the film points; :meth:`offset_at` gives it elsewhere (the origin,
    probed nodes); :meth:`creep` is the internal variable's state after the step.
    """

    scale: float
    offset: np.ndarray
    weight: float  # q^{k+1} = offset + weight u^{k+1}
    grid_offset: np.ndarray
    _at: object
    _to_grid: object
    _state: object

    def offset_at(self, points):
        return self._at(points)

    def creep(self, u):
        """The internal variable's state after the step (the state's ``creep`` array, see
        :meth:`CreepMemory.split`) from ``u^{k+1} = C p^{k+1}`` on the film points."""
        u = np.asarray(u, dtype=float)
        ug = np.asarray(self._to_grid @ u).ravel()
        return self._state(self.grid_offset + self.weight * ug, self.offset + self.weight * u, ug, u)

    def own(self, u) -> dict:
        """The memory's own variables after the step (``state.own``), from ``u = C p``."""
        return {"creep": self.creep(u)}


def _phi(r):
    """``(a, b) = (int_0^1 r e^{-r s} (1 - s) ds, int_0^1 r e^{-r s} s ds)``: the exact
    weights of a source linear in s over an interval of r relaxation times (a + b = 1 - e^{-r})."""
    r = np.asarray(r, dtype=float)
    small = r < 1e-4
    rs = np.where(small, 1.0, r)
    b = np.where(small, r / 2 - r * r / 3 + r**3 / 8, (-np.expm1(-rs) - rs * np.exp(-rs)) / rs)
    return -np.expm1(-r) - b, b


class CreepMemory:
    """Exponential integrator of ``tau_c Dq/Dt = (J_inf - J0) u - q`` along the characteristics.

    State.  The internal variable lives on a uniform grid aligned with the sliding
    direction (spacing that of the film points in the finest part of the mesh -- the 5th
    percentile of nearest-neighbour distances --, at most :data:`MAX_COLUMNS` columns;
    twice that across, where nothing is transported); the state also keeps the source
    ``u = C p`` of the last step on the grid and on the film points, and the film points'
    *defect* (their own q minus the grid's cubic spline there: an O(h^2) round trip,
    kept so that a step of any size continues the film points' memory without a jump).

    Step (exact along the characteristic, for any dt).  The material at ``x`` at
    ``t_{k+1}`` was at ``x + sigma(theta)`` a time ``theta`` earlier, ``sigma = 2 int U``
    (the substrate's surface speed U linear over the step).  With the source linear in time
    between ``u^k`` (on the path) and ``u^{k+1}`` (its increment taken at the arrival point ``x``: an
    ``O(dt^2 U du/dx)`` error, second order, zero in a steady state)::

        q^{k+1}(x) = e^{-r} q^k(x + s) + (dJ/tau_c) int_0^dt e^{-theta/tau_c} u^k(x + sigma) dtheta
                     + w [u^{k+1}(x) - u^k(x)],       r = dt/tau_c,  s = sigma(dt),
        w = dJ int_0^1 r e^{-r s} (1 - s) ds      (-> dJ r/2 for small r, dJ for large r),

    affine in the step's own ``u^{k+1}``: the step's film is ``d = h + offset + J_eff C p``
    with ``J_eff = J0 + w``, ONE linear system (the stepper's).  The integral is a
    quadrature on sub-steps that shift the material by at most one grid spacing (``u^k``
    by the grid's cubic spline, linear in between, exact exponential weights), so the
    spatial integration is the grid's, not the step's: in a steady state
    (``u^{k+1} = u^k``, ``q^{k+1} = q^k``) this is the exact characteristic relation of
    the steady memory for every ``dt``, and the steady state does not depend on dt.
    Material (and source) beyond the grid's upstream edge has no creep: q = 0 and u = 0
    there (it has not been loaded yet; exact for a Winkler foundation, whose deflection
    vanishes at the rim), reached linearly over one grid spacing beyond the edge (so a
    step continues the memory without a jump however small its shift).  Points beyond
    the grid at zero shift (the rim nodes) take the edge value.  The film points' defect
    follows the material out over one grid spacing of travel (factor ``e^{-|s|/dx}``:
    kept at rest, forgotten once its material is gone).
    """

    MAX_COLUMNS = 4096
    #: at most this many sub-steps of the source's quadrature along a path
    MAX_SUBSTEPS = 100_000

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
        """Length of the internal variable's state (see :meth:`split`)."""
        return 2 * (self.grid.shape[0] + self.points.shape[0])

    def split(self, state_array):
        """``(q on the grid, film points' defects, u on the grid, u on the film points)`` of
        a state's ``creep`` array (u: the last step's source ``C p``)."""
        a = np.asarray(state_array, dtype=float)
        m, n = self.grid.shape[0], self.points.shape[0]
        return a[:m], a[m : m + n], a[m + n : 2 * m + n], a[2 * m + n :]

    def _state(self, q, q_film, u, u_film):
        """The state array: grid values, the film points' defects, the source."""
        defect = q_film - self._eval(self._spline(q), self.points, 0.0)
        return np.concatenate([q, defect, u, u_film])

    # ---- the cubic spline of a grid field -------------------------------------------------
    def _spline(self, q):
        from scipy.ndimage import spline_filter

        Q = np.asarray(q, dtype=float).reshape(self.shape)
        return spline_filter(Q[0] if self.one_d else Q, order=3, mode="nearest")

    def _columns(self, points, shift):
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        return pts, (pts[:, 0] + shift - self.x0) / self.dx

    def _eval(self, coef, points, shift):
        """The grid field at ``points + (shift, 0)``; 0 where the shift leaves the grid by
        more than a grid spacing (material not yet in the domain: no creep), linear in
        between (so continuous in the shift), the edge value at zero shift."""
        from scipy.ndimage import map_coordinates

        pts, col = self._columns(points, shift)
        if self.one_d:
            coords = col[None, :]
        else:
            y = np.abs(pts[:, 1]) if self.half else pts[:, 1]
            coords = np.vstack([(y - self.y0) / self.dy, col])
        out = map_coordinates(coef, coords, order=3, mode="nearest", prefilter=False)
        if shift != 0.0:  # beyond the upstream edge: down to 0 over one grid spacing of travel
            edge = self.shape[1] - 1.0
            start = col - shift / self.dx
            beyond = col - np.maximum(edge, start) if shift > 0.0 else np.minimum(0.0, start) - col
            out *= np.clip(1.0 - beyond, 0.0, 1.0)
        return out

    def _path(self, dt, V0, V1):
        """Sub-step shifts ``sigma_j`` (a time ``theta_j = j dt/M`` before arrival) and the
        exact weights ``W_j`` of a source linear between them (sum: dJ (1 - e^{-dt/tau_c}))."""
        tc = self.solid.tau_creep
        dJ = self.solid.J_inf - self.solid.J0
        s = dt * (V0 + V1)
        m = int(min(self.MAX_SUBSTEPS, max(1, np.ceil(abs(s) / self.dx))))
        th = dt * np.arange(m + 1) / m
        sig = 2.0 * (V1 * th + (V0 - V1) * th * th / (2.0 * dt))
        a, b = _phi(dt / m / tc)
        decay = np.exp(-th / tc)
        W = np.zeros(m + 1)
        W[:-1] += a * decay[:-1]
        W[1:] += b * decay[:-1]
        keep = np.abs(sig) <= (self.shape[1] + 1) * self.dx  # beyond: no source there
        return sig[keep], dJ * W[keep]

    # ---- its part in the step (femehl.solver.parts) ------------------------------------------
    def initial(self, stepper, state):
        """The material at rest, unloaded: ``state.own["creep"] = 0``."""
        return state.with_own(creep=np.zeros(self.size))

    def lagged(self, state, free_index):
        return None

    def rows(self, stepper, system, rhs_list, state, ctx):
        return system, rhs_list, None

    def rest_film(self, stepper) -> StepMemory:
        """A load put on at rest at t = 0 (:meth:`LaggedStepper.at_rest`): the glassy
        response ``J0 u``, no creep yet, the load the memory's source from then on."""
        zeros = lambda points: np.zeros(np.asarray(points).reshape(-1, 2).shape[0])  # noqa: E731
        return StepMemory(
            scale=self.solid.J0,
            offset=zeros(self.points),
            weight=0.0,
            grid_offset=zeros(self.grid),
            _at=zeros,
            _to_grid=self.to_grid,
            _state=self._state,
        )

    def film(self, stepper, state, t_new: float, dt: float) -> StepMemory:
        return self.step(state, t_new, dt, stepper.scene.motion.substrate_speed)

    def finish(self, stepper, solved, new):
        """The internal variable after the step, from the step's ``u = C p``."""
        return new.with_own(creep=solved.film.creep(solved.Cp))

    # ---- one step -----------------------------------------------------------------------
    def step(self, state, t_new: float, dt: float, V) -> StepMemory:
        """The step's scale and offset from the material's history (``state.own["creep"]``);
        ``V(t)`` is the substrate's surface speed (:meth:`femehl.Motion.substrate_speed`, the
        material moving at ``-2 V``).

        Exact along the characteristic whatever the step (class docstring).
        """
        solid = self.solid
        q, e, ug, uf = self.split(state.own.get("creep", np.zeros(self.size)))
        V0, V1 = float(V(state.t)), float(V(t_new))
        s = dt * (V0 + V1)  # 2 int V dt over the step
        r = dt / solid.tau_creep
        decay = np.exp(-r)
        w = (solid.J_inf - solid.J0) * float(_phi(r)[0])
        sig, W = self._path(dt, V0, V1)
        cq, cu = self._spline(q), self._spline(ug)
        keep_defect = decay * np.exp(-abs(s) / self.dx)

        def offset(points, film=False):
            out = decay * self._eval(cq, points, s)
            if film:  # the film points: their own u^k and defect at the arrival point
                u0 = self._eval(cu, points, 0.0)
                out += keep_defect * e + (W.sum() - w) * uf
                for sj, Wj in zip(sig, W, strict=True):
                    if Wj != 0.0 and sj != 0.0:
                        out += Wj * (self._eval(cu, points, sj) - u0)
                return out
            for sj, Wj in zip(sig, W, strict=True):
                out += Wj * self._eval(cu, points, sj)
            return out - w * self._eval(cu, points, 0.0)

        return StepMemory(
            scale=solid.J0 + w,
            offset=offset(self.points, film=True),
            weight=w,
            grid_offset=offset(self.grid),
            _at=offset,
            _to_grid=self.to_grid,
            _state=self._state,
        )
