"""Rough surfaces: asperity contact and the mean gap of a film between rough surfaces.

A :class:`Roughness` on the scene (``Scene(roughness=...)``, TOML ``[roughness]``) makes the
step's pressure unknown the total pressure ``P`` (what deflects the substrate and carries the
load), shared between the film and the asperities::

    P = p_film + p_a(d),      p_a(d) = K F_{5/2}(d / sigma)      (Greenwood-Tripp 1970)

on the mean separation ``d = hc + s + C P``.  The Reynolds equation acts on ``p_film`` with
the mean gap ``h_T(d) = sigma (t Phi(t) + phi(t))``, ``t = d / sigma`` (the expected local gap
over Gaussian heights of rms ``sigma``) as the film's content and ``h_T^3`` as its mobility.
Both are linearized about the step's lagged film, as the film coefficients are, so the step
stays ONE linear system.  The derivation, the energy budget and what is left out (flow
factors): docs/design.md section 18.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.interpolate import CubicHermiteSpline
from scipy.special import gammaln, ndtr, pbdv

from femehl.errors import SceneError, SolverError
from femehl.solver.parts import StepPart
from femehl.validation import check_positive

logger = logging.getLogger("femehl")

__all__ = ["Roughness", "AsperityContact", "greenwood_tripp", "mean_gap", "RESIDUAL", "ROUGH_COLUMNS"]

#: the per-step figures a run with a roughness reports (summary.csv, the Result)
ROUGH_COLUMNS = ("asperity_load", "asperity_share", "asperity_friction")

#: F_n(t) below this t is continued by its tangent (d < -38 sigma: far past any contact the
#: model describes; D_{-n-1} overflows beyond it); above _T_ZERO it is below 1e-300
_T_LOW, _T_ZERO = -38.0, 38.0
#: the lowest mean separation a step may reach, in sigma: the asperities press with
#: ``K F_{5/2}(-10) = 320 K`` there, far beyond any contact; below it a step overshot (a long
#: step's runaway: the adaptive steps retry it shorter, fixed steps raise FilmRuptureError)
FILM_LIMIT = 10.0
#: the start's static asperity contact (:meth:`AsperityContact.initial`): Newton steps at
#: most, and the largest pressure change, relative to the largest pressure, it converged at
#: (the linear solves' own residual is 1e-8 relative)
_STATIC_ITERATIONS, _STATIC_RTOL = 60, 1e-8
#: the residual film where the surfaces are in full contact, over sigma (:func:`mean_gap`)
RESIDUAL = 0.02
#: where the asperities and the gap's roughness correction are negligible: F_{5/2}(8.5) < 1e-18
#: and 1 - Phi(8.5) < 1e-17 of their scale
_T_CONTACT = 8.5


#: :func:`greenwood_tripp` interpolates ``log F_n`` and ``log F_{n-1}`` (cubic Hermite splines
#: with their exact slopes at knots this far apart over [_T_LOW, _T_ZERO]): against the
#: Gauss-Legendre reference, relative errors below 3e-10 on [-30, 30] but near t = 5.8,
#: where scipy's ``pbdv`` (the knots' values) is itself 3.4e-9 off (tests/test_roughness.py).
#: ``pbdv`` at every element took 23 ms a call on the 10,786 elements of the PDMS ball's
#: fitted level 1, 8 % of its run (25 s of 316 s, two calls a step); the two splines 3 ms
_GT_KNOT = 0.01


def _log_gt(t, n):
    """``log F_n(t)``, from the parabolic cylinder function (no underflow on [-38, 38])."""
    return gammaln(n + 1.0) - 0.25 * t * t + np.log(pbdv(-n - 1.0, t)[0]) - 0.5 * math.log(2.0 * math.pi)


@functools.cache
def _gt_spline(n: float) -> CubicHermiteSpline:
    """The spline of ``log F_n`` on [_T_LOW, _T_ZERO] (:data:`_GT_KNOT`), built once per ``n``."""
    t = np.linspace(_T_LOW, _T_ZERO, int(round((_T_ZERO - _T_LOW) / _GT_KNOT)) + 1)
    log_f = _log_gt(t, n)
    return CubicHermiteSpline(t, log_f, -n * np.exp(_log_gt(t, n - 1.0) - log_f))


def greenwood_tripp(t, n: float = 2.5):
    """``(F_n(t), dF_n/dt)``: the n-th moment of a unit Gaussian above ``t``,
    ``Gamma(n+1) exp(-t^2/4) D_{-n-1}(t) / sqrt(2 pi)``, and its slope ``-n F_{n-1}(t)``
    (interpolated, :data:`_GT_KNOT`); continued by its tangent below t = -38.  Vectorized."""
    t = np.asarray(t, dtype=float)
    tc = np.clip(t, _T_LOW, _T_ZERO)
    F = np.exp(_gt_spline(float(n))(tc))
    # F_{n-1} by its own spline: the slope of the interpolant of log F_n carries the knots'
    # rounding (1e-10) over the knot distance, 3e-8 on [-10, -3]
    dF = -n * np.exp(_gt_spline(float(n) - 1.0)(tc))
    low = t < _T_LOW
    if np.any(low):
        F = np.where(low, F + dF * (t - _T_LOW), F)
    return F, dF


def mean_gap(d, sigma: float):
    """``(h, dh/dd, Phi)``: the film's mean gap at mean separation ``d`` and its slope, and
    the wetted fraction ``Phi(t)`` (``t = d/sigma``)::

        h = sigma (t Phi(t) + phi(t) + RESIDUAL (1 - Phi(t))),    dh/dd = Phi(t) - RESIDUAL phi(t)

    ``sigma (t Phi + phi)`` is the expected local gap over Gaussian heights; the residual
    film ``RESIDUAL sigma`` that remains where the surfaces are in full contact (``t << 0``)
    keeps the film's mobility, and so the step's system, regular there. ``h -> d`` for
    ``d >> sigma`` (``1 - Phi(8.5) < 1e-17``)."""
    t = np.clip(np.asarray(d, dtype=float) / sigma, _T_LOW, None)
    Phi = ndtr(t)
    phi = np.exp(-0.5 * t * t) / math.sqrt(2.0 * math.pi)
    return sigma * (t * Phi + phi + RESIDUAL * (1.0 - Phi)), Phi - RESIDUAL * phi, Phi


@dataclass(frozen=True)
class Roughness:
    """The combined roughness of the two surfaces and its asperity contact (normalized units).

    Parameters
    ----------
    sigma : float
        The combined rms roughness over ``h_inf`` (``sqrt(sigma_1^2 + sigma_2^2)``).
    stiffness : float
        ``K``, the Greenwood-Tripp asperity stiffness over the pressure scale ``p0``:
        ``p_a = K F_{5/2}(d/sigma)``;
        :func:`femehl.reference.rough_contact.gt_stiffness` computes it from the asperity
        density, radius and the summits' rms height.
    friction : float, default 0
        The boundary friction coefficient of the asperities: their shear is ``friction``
        times their pressure, against the sliding (0: frictionless asperities).
    aspect : float, optional
        ``sqrt(h_inf/R)``, femehl's height scale over its length scale, needed with a
        ``friction``: friction forces are in units of ``p0 h_inf sqrt(R h_inf)``, loads in
        units of ``p0 R h_inf``, so the asperities' friction is ``friction * asperity_load
        / aspect`` (docs/design.md section 15). An SI scene gives it.
    """

    sigma: float
    stiffness: float
    friction: float = 0.0
    aspect: float | None = None

    def __post_init__(self):
        hint = "give the combined rms roughness over h_inf (a positive number)"
        object.__setattr__(self, "sigma", check_positive("roughness sigma", self.sigma, hint))
        hint = "give the Greenwood-Tripp stiffness K over p0 (gt_stiffness computes it)"
        object.__setattr__(self, "stiffness", check_positive("roughness stiffness", self.stiffness, hint))
        mu = self.friction
        if isinstance(mu, bool) or not isinstance(mu, (int, float)) or not (math.isfinite(mu) and mu >= 0):
            raise SceneError(
                f"roughness friction = {mu!r} must be a finite number >= 0 (the asperities' boundary "
                "friction coefficient, e.g. 0.1)."
            )
        object.__setattr__(self, "friction", float(mu))
        if self.aspect is not None:
            hint = "it is sqrt(h_inf/R), e.g. 0.03 for h_inf = 10 um and R = 10 mm"
            object.__setattr__(self, "aspect", check_positive("roughness aspect", self.aspect, hint))
        elif mu > 0.0:
            raise SceneError(
                f"roughness friction = {mu:g} needs aspect = sqrt(h_inf/R) (femehl's friction force "
                "and load have different units): give Roughness(..., friction=mu, aspect=sqrt(h_inf/R)), "
                "or state the scene in SI units, which knows it."
            )

    columns = ROUGH_COLUMNS

    def solid_friction(self, load, sliding):
        """The asperities' friction force (femehl's friction unit) at asperity load ``load``
        and sliding speed ``sliding`` (``U_s - U_i``): against the sliding."""
        return 0.0 if self.friction == 0.0 else self.friction * float(np.sign(sliding)) * load / self.aspect

    @property
    def lowest_film(self) -> float:
        """The lowest film a run may reach, ``-FILM_LIMIT sigma``: a scene may start there
        too (its start is on the asperities, :meth:`AsperityContact.initial`)."""
        return -FILM_LIMIT * self.sigma

    def pressure(self, d):
        """``(p_a, dp_a/dd)`` at mean separation ``d``."""
        F, dF = greenwood_tripp(np.asarray(d, dtype=float) / self.sigma, 2.5)
        return self.stiffness * F, (self.stiffness / self.sigma) * dF

    def mean_gap(self, d):
        """``(h, dh/dd, wetted fraction)`` at mean separation ``d``: :func:`mean_gap`."""
        return mean_gap(d, self.sigma)

    def check_scene(self, scene) -> None:
        cavitation = getattr(scene, "cavitation", None)
        if cavitation not in (None, "reynolds"):
            raise SceneError(
                f"a rough scene takes cavitation = 'reynolds' (the film's pressure >= 0, the "
                f"asperities' apart), not {cavitation!r}: its content and clipping are not written "
                "for a mean gap. Use cavitation = 'reynolds', or leave it out (full Sommerfeld)."
            )

    @staticmethod
    def point_fields(disc, state) -> dict:
        """The asperity pressure on every mesh node (the VTK series' ``asperity_pressure``)."""
        p_a = state.own.get("p_asperity")
        return {} if p_a is None else {"asperity_pressure": disc.expand(p_a)}

    def part(self, disc) -> AsperityContact:
        """The step part that puts this roughness into each lagged step."""
        return AsperityContact(self, disc)


def check_roughness(value):
    """``value`` if None or a :class:`Roughness`, else SceneError naming the fix."""
    if value is None or isinstance(value, Roughness):
        return value
    raise SceneError(
        f"roughness must be None (smooth surfaces) or a femehl.Roughness(sigma, stiffness), got "
        f"{type(value).__name__}."
    )


class AsperityContact(StepPart):
    """The roughness in each lagged step (:class:`femehl.solver.parts.StepPart`).

    About the lagged film ``d*`` (the terms' ``d_lag``), on the film points::

        p_a(d) ~ a + b d,            a = p_a(d*) - b d*,        b = p_a'(d*) <= 0
        h_T(d) ~ Phi* d + r,         r = h_T(d*) - Phi* d*

    The terms see the mean gap (their context's films are ``h_T``); their matrix ``D`` acts
    on the film pressure ``P - N p_a`` (``N``: the film points' values averaged to the
    nodes) and their film operator ``G`` on ``h_T``. Both corrections are sparse film
    operators on the step's ``d^{k+1}``, nonzero only on the elements near contact
    (``d* < 8.5 sigma``): ``-D N diag(b)`` and ``-G diag(1 - Phi*)``.
    """

    def __init__(self, roughness: Roughness, disc):
        self.rough = roughness
        self.disc = disc
        N = getattr(disc, "node_average", None)
        free = disc.free_index
        if N is None:  # the film points are the nodes
            nf = disc.film_points.shape[0]
            N = sp.identity(nf, format="csr")
        self.N = sp.csr_matrix(N)[free]  # free nodes x film points
        self._lin = None

    # ---- the step ----------------------------------------------------------------------
    def context(self, stepper, state, ctx):
        """The terms' context in mean gaps; the linearization point kept for :meth:`operator`."""
        rough = self.rough
        hT_star = self._linearize(ctx.d_lag)[1]
        hT = rough.mean_gap(state.d)[0]
        if ctx.a2 != 0.0 and state.d_prev is not None:
            history = ctx.a1 * hT - ctx.a2 * rough.mean_gap(state.d_prev)[0]
        else:
            history = hT
        return dataclasses.replace(ctx, d=hT, d_lag=hT_star, history=history)

    def _linearize(self, d_star):
        """Keep the linearization point ``(d*, h_T*, Phi*, p_a*, p_a'*)`` and return it."""
        d_star = np.asarray(d_star, dtype=float)
        hT_star, Phi, _ = self.rough.mean_gap(d_star)
        pa, slope = self.rough.pressure(d_star)
        self._lin = (d_star, hT_star, Phi, pa, slope)
        return self._lin

    def _near(self):
        """The film points near contact and the asperity pressure's ``a``, ``b`` there."""
        d_star, _, _, pa, slope = self._lin
        near = np.flatnonzero(d_star < _T_CONTACT * self.rough.sigma)
        b = slope[near]
        return near, pa[near] - b * d_star[near], b

    def _to_all(self, F, near):
        """``F`` on the columns ``near`` as a film operator on every film point."""
        k = near.size
        pick = sp.csr_matrix((np.ones(k), (np.arange(k), near)), shape=(k, self._lin[0].size))
        return sp.csr_matrix(F @ pick)

    def operator(self, stepper, ctx, D, G):
        """``[(F, rhs)]``: film operators on ``d^{k+1}`` and right-hand sides the roughness adds."""
        _, hT_star, Phi, _, _ = self._lin
        near, a, b = self._near()
        if near.size == 0:
            return []
        # on the elements near contact only (columns ``near`` of the film operators)
        c, r = 1.0 - Phi[near], hT_star[near] - Phi[near] * self._lin[0][near]
        DN, Gn = sp.csr_matrix(D @ self.N[:, near]), sp.csr_matrix(G)[:, near]
        # the asperities' share of the pressure: D acts on P - N (a + b d); the film's
        # content h_T = Phi* d + r
        Fn = -(DN @ sp.diags(b)) - Gn @ sp.diags(c)
        rhs = DN @ a - Gn @ r
        return [(self._to_all(Fn, near), np.asarray(rhs).ravel())]

    def held_rows(self, stepper, ctx, held):
        """What the rows ``held`` at ``p = 0`` (a cavitated node) add: they hold the film's
        pressure, ``P - N (a + b d) = 0``: the film operator ``-N diag(b)`` and the
        right-hand side ``N a`` on those rows."""
        near, a, b = self._near()
        n = self.N.shape[0]
        rows = sp.csr_matrix((np.ones(held.size), (held, held)), shape=(n, n))
        Nn = rows @ self.N[:, near]
        return self._to_all(-(Nn @ sp.diags(b)), near), np.asarray(Nn @ a).ravel()

    def solid_pressure(self, state):
        """The asperities' share of ``state``'s pressure unknowns (free nodes)."""
        return state.own["p_asperity"]

    def finish(self, stepper, solved, new):
        """The asperity pressure the step solved for (its linearization at the new film)."""
        d_star, _, _, pa, slope = self._lin
        pa_new = np.where(d_star < _T_CONTACT * self.rough.sigma, pa + slope * (new.d - d_star), 0.0)
        return self._report(stepper, new, pa_new)

    def initial(self, stepper, state):
        """The start at rest: the film at ambient pressure and the substrate in equilibrium
        with the asperities, ``P = N p_a(h + C P)`` (the static rough contact, by Newton's
        method from ``P = 0``; nothing to do where no asperity touches).  Under an imposed
        load it carries the load ``F(0)``: hc is one more unknown, and at ``F(0) = 0`` the
        indenter starts where the asperities no longer touch.  A viscoelastic substrate
        answers with its glassy response, the load put on at t = 0 (then it creeps)."""
        if np.any(state.d < _T_CONTACT * self.rough.sigma):
            if stepper.gap.rest_load(stepper, state.t) == 0.0:
                state = self._lifted(stepper, state)
            else:
                state = self._static_contact(stepper, state)
        return self._report(stepper, state, self.rough.pressure(state.d)[0])

    def _lifted(self, stepper, rest):
        """``rest`` with hc raised until no film is within ``8.5 sigma`` (logged)."""
        lift = _T_CONTACT * self.rough.sigma - float(np.min(rest.d))
        logger.info(
            "femehl: the imposed load is 0 at t = %g and the asperities touched at hc(0) = %g: "
            "the indenter starts at hc = %g, where they do not",
            rest.t,
            rest.hc,
            rest.hc + lift,
        )
        return stepper.at_rest(dataclasses.replace(rest, hc=rest.hc + lift))

    def _static_contact(self, stepper, rest):
        """``rest`` (``P = 0``) moved to the static rough contact.  Each Newton step holds
        every row at the film's pressure zero (:meth:`held_rows`), ``P - N (a + b d) = 0``
        with ``d = h + C P``; from ``P = 0`` the iterates rise monotonically to the root
        (``p_a`` is convex and falling in ``d``), quadratically near it."""
        held = np.arange(self.N.shape[0])
        state, change, solver = rest, np.inf, stepper.linear_solver()
        for _ in range(_STATIC_ITERATIONS):
            self._linearize(state.d)
            F, r = self.held_rows(stepper, None, held)
            new = stepper.at_rest(rest, F, r, solver)
            change = max(float(np.max(np.abs(new.p - state.p))), abs(new.hc - state.hc))
            state = new
            if change <= _STATIC_RTOL * max(float(np.max(np.abs(state.p))), abs(state.hc)):
                return state
        raise SolverError(
            f"the static asperity contact at t = {rest.t:g} (where the run starts: the asperities "
            f"already press) did not converge in {_STATIC_ITERATIONS} Newton steps (last change "
            f"{change:.3g} of the pressure). Start the run with the surfaces further apart (a larger "
            "initial gap), or give a softer asperity stiffness."
        )

    def _report(self, stepper, state, pa_points):
        p_a = np.asarray(self.N @ pa_points).ravel()  # on the free nodes
        load_a = float(stepper.g @ p_a)
        Ui, Us = stepper.scene.motion.surface_speeds(state.t)
        info = dict(state.info)
        info.update(
            film_limit=-FILM_LIMIT * self.rough.sigma,  # the asperities carry the load through contact
            film_error_floor=self.rough.sigma,  # the film's scale for the step error: d, at least sigma
            asperity_load=load_a,
            asperity_share=load_a / state.load if state.load != 0.0 else float("nan"),
            asperity_friction=self.rough.solid_friction(load_a, Us - Ui),
        )
        return dataclasses.replace(state, info=info).with_own(p_asperity=p_a)

    # ---- what the run reports ------------------------------------------------------------
    def budget(self, state) -> dict:
        """What :func:`femehl.solver.energetics.sliding_energetics` needs of the roughness."""
        p_a = state.own.get("p_asperity")
        h, _, wetted = self.rough.mean_gap(state.d)
        return {
            "p_solid": p_a,
            "gap": h,
            # the Couette shear on the wetted fraction, through its mean gap h/wetted
            "liquid": wetted * wetted,
            "solid_friction": state.info.get("asperity_friction", 0.0),
        }
