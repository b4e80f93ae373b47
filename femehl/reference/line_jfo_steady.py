"""Exact steady sliding of line contact: the one steady line reference (any rigid gap, rigid or Winkler).

Full film (:func:`steady_full_film`), mass-conserving JFO (:func:`steady_jfo`) or Reynolds
(:func:`steady_reynolds`) cavitation, by quadrature and shooting in the pressure, independent of
the FE solver of :mod:`femehl.problem.line`; :mod:`femehl.reference.line_steady` presents its
cylinder case.  The equations (numbered (1)-(7) in the docstrings), the method, the reference
configurations and the independent checks: docs/design.md section 17.

Rough surfaces (:class:`RoughSurfaces`, the mean-gap model of docs/design.md section 18) for the
full film and Reynolds: ``d`` is then the separation of the mean planes, the total pressure
``P = p + p_a(d)`` deflects the foundation, ``d = hc + s + P/k``, and (5) acts on the film's
pressure ``p`` with the mean gap ``h_T(d)`` as the film; :func:`steady_under_load` finds ``hc``
for an imposed load.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq, minimize_scalar
from scipy.special import ndtr

from femehl.errors import SceneError, SolverError
from femehl.problem.scene import check_finite, check_positive
from femehl.reference.rough_contact import greenwood_tripp, greenwood_tripp_derivative
from femehl.validation import check_int

__all__ = [
    "Region",
    "RoughSurfaces",
    "SteadyJFO",
    "pocket_slider",
    "steady_full_film",
    "steady_jfo",
    "steady_reynolds",
    "steady_under_load",
]

log = logging.getLogger(__name__)

#: the configurations a solution reports (:attr:`SteadyJFO.case`)
CASES = ("full", "outlet-cavity", "reformation")


def _cylinder(x):
    x = np.asarray(x, dtype=float)
    return 0.5 * x * x


def pocket_slider(
    depth: float = 0.3,
    width: float = 1.0,
    center: float = -1.0,
    slope: float = 0.2,
    ramp_start: float = 1.0,
    blend: float = 0.5,
):
    """A slider with an inlet ramp and a cosine-squared pocket; and where its s'' jumps.

    ``s(x) = slope r(x - ramp_start) + depth cos^2(pi (x - center)/width)`` for
    ``|x - center| < width/2`` (the pocket; 0 elsewhere), with the ramp
    ``r(u) = 0`` (u <= 0), ``u^2/(2 b)`` (0 < u < b), ``u - b/2`` (u >= b), ``b = blend``:
    flat from the outlet to ``ramp_start``, then rising toward the inlet +L
    (converging in the flow direction); ``blend = 0`` is a sharp corner, and
    ``ramp_start <= -L`` a plain linear slider.  The pocket and the blended ramp are C^1.
    The default is the "reformation" reference geometry of docs/design.md section 17.5 (with
    ``hc = 0.1``: film 0.1 on the land, pocket 3 films deep, 0.25 at the inlet).

    Returns
    -------
    profile : callable
        Vectorized ``s(x)``.
    kinks : tuple of float
        The points where s'' jumps (pass them as ``kinks``).
    """
    depth = check_finite("pocket depth", depth)
    width = check_positive("pocket width", width)
    center = check_finite("pocket center", center)
    slope = check_finite("slider slope", slope)
    ramp_start = check_finite("ramp start", ramp_start)
    b = float(blend)
    if not (math.isfinite(b) and b >= 0.0):
        raise SceneError(f"blend must be a finite number >= 0 (0: a sharp ramp corner), got {blend!r}.")

    def profile(x):
        x = np.asarray(x, dtype=float)
        u = x - ramp_start
        if b > 0.0:
            ramp = np.where(u <= 0.0, 0.0, np.where(u < b, 0.5 * u * u / max(b, 1e-300), u - 0.5 * b))
        else:
            ramp = np.maximum(u, 0.0)
        v = (x - center) / width
        bump = np.where(np.abs(v) < 0.5, np.cos(math.pi * v) ** 2, 0.0)
        return slope * ramp + depth * bump

    kinks = {ramp_start, center - 0.5 * width, center + 0.5 * width}
    if b > 0.0:
        kinks.add(ramp_start + b)
    return profile, tuple(sorted(kinks))


# --------------------------------------------------------------------------
# rough surfaces
# --------------------------------------------------------------------------
#: above this ``c/sigma`` (c the separation without the asperities) the asperities and the gap's
#: roughness correction are below double precision of the film: ``F_{5/2}(12) < 1e-33``,
#: ``phi(12) < 6e-32``, so ``d = c`` and ``h_T = d`` there
_T_SMOOTH = 12.0
_SQRT_2PI = math.sqrt(2.0 * math.pi)


@dataclass(frozen=True)
class RoughSurfaces:
    """Gaussian rough surfaces (the mean-gap model of docs/design.md section 18), normalized.

    ``sigma`` the combined rms roughness, ``stiffness`` the Greenwood-Tripp ``K``, ``eps`` the
    residual film in full contact, over sigma.  At mean separation ``d``, ``t = d / sigma``::

        p_a(d) = K F_{5/2}(t)                                    asperity pressure
        h_T(d) = sigma (t Phi(t) + phi(t) + eps (1 - Phi(t)))    the film's mean gap

    ``F_n`` by :func:`femehl.reference.rough_contact.greenwood_tripp` (quadrature), ``Phi`` by
    :func:`scipy.special.ndtr` (what ``scipy.stats.norm.cdf`` evaluates, without its per-call
    argument handling: ten times faster on the one point the integrator asks for).  A
    :class:`femehl.Roughness` or a tuple ``(sigma, stiffness[, eps])`` is taken where a
    roughness is asked for.
    """

    sigma: float
    stiffness: float
    eps: float = 0.02

    def __post_init__(self):
        object.__setattr__(self, "sigma", check_positive("roughness sigma", self.sigma))
        object.__setattr__(self, "stiffness", check_positive("roughness stiffness K", self.stiffness))
        eps = check_finite("roughness residual film eps", self.eps)
        if not 0.0 < eps < 1.0:
            raise SceneError(f"roughness eps = {eps:g} must be in (0, 1) (the residual film over sigma).")
        object.__setattr__(self, "eps", eps)

    @classmethod
    def of(cls, roughness):
        """None, a RoughSurfaces, a tuple ``(sigma, stiffness[, eps])`` or an object with
        ``sigma`` and ``stiffness`` (and optionally ``eps``) -> None or a RoughSurfaces."""
        if roughness is None or isinstance(roughness, cls):
            return roughness
        if isinstance(roughness, (tuple, list)):
            if len(roughness) not in (2, 3):
                raise SceneError(
                    f"roughness must be (sigma, stiffness) or (sigma, stiffness, eps), got {roughness!r}."
                )
            return cls(*roughness)
        if hasattr(roughness, "sigma") and hasattr(roughness, "stiffness"):
            return cls(roughness.sigma, roughness.stiffness, getattr(roughness, "eps", 0.02))
        raise SceneError(
            f"roughness must be None, a RoughSurfaces, a (sigma, stiffness[, eps]) tuple or an object "
            f"with sigma and stiffness (femehl.Roughness), got {type(roughness).__name__}."
        )

    def asperity_pressure(self, d):
        """``p_a(d) = K F_{5/2}(d / sigma)``."""
        return self.stiffness * greenwood_tripp(np.asarray(d, dtype=float) / self.sigma, 2.5)

    def asperity_slope(self, d):
        """``dp_a/dd = (K / sigma) F_{5/2}'(d / sigma) <= 0``."""
        return (self.stiffness / self.sigma) * greenwood_tripp_derivative(
            np.asarray(d, dtype=float) / self.sigma, 2.5
        )

    def mean_gap(self, d):
        """``h_T(d) = sigma (t Phi(t) + phi(t) + eps (1 - Phi(t)))``, ``t = d / sigma``."""
        t = np.asarray(d, dtype=float) / self.sigma
        Phi = ndtr(t)
        return self.sigma * (t * Phi + np.exp(-0.5 * t * t) / _SQRT_2PI + self.eps * (1.0 - Phi))

    def mean_gap_slope(self, d):
        """``dh_T/dd = Phi(t) - eps phi(t) > 0``."""
        t = np.asarray(d, dtype=float) / self.sigma
        return ndtr(t) - self.eps * np.exp(-0.5 * t * t) / _SQRT_2PI

    def separation(self, c, k, guess=None, full=False):
        """The separation ``d`` with ``d = c + p_a(d) / k`` (``c = hc + s + p/k``); vectorized.

        ``g(d) = d - p_a(d)/k`` is increasing (``g' >= 1``) and concave (p_a is convex), so
        Newton's iterates from any start reach the root from below after the first step and
        converge monotonically; ``guess`` (an estimate of d) only saves iterations.  The
        iteration stops when a chord step (the last slope) at the new iterate is below 1e-13
        of ``max(|d|, sigma)``.  ``k = inf``: d = c.  ``full``: also return ``p_a(d)`` and
        ``g'(d)`` (``p_a`` at the converged d, to the chord step's square).
        """
        c = np.asarray(c, dtype=float)
        if math.isinf(k):
            d = c.copy()
            return (d, self.asperity_pressure(d), np.ones(d.shape)) if full else d
        d = np.array(c if guess is None else np.broadcast_to(guess, c.shape), dtype=float)
        pa, gp = np.zeros(c.shape), np.ones(c.shape)
        live = c < _T_SMOOTH * self.sigma  # elsewhere d = c to double precision
        d[~live] = c[~live]
        if np.any(live):
            cl, dl = c[live], d[live]
            pl = self.asperity_pressure(dl)
            for _ in range(100):
                gl = 1.0 - self.asperity_slope(dl) / k
                dl = dl - (dl - cl - pl / k) / gl
                pl = self.asperity_pressure(dl)
                chord = (dl - cl - pl / k) / gl
                if np.all(np.abs(chord) <= 1e-13 * np.maximum(np.abs(dl), self.sigma)):
                    dl, pl = dl - chord, pl + k * (1.0 - gl) * chord
                    break
            else:
                raise SolverError("RoughSurfaces.separation: Newton did not converge (non-finite input?).")
            d[live], pa[live], gp[live] = dl, pl, gl
        return (d, pa, gp) if full else d


# --------------------------------------------------------------------------
# the solution
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class Region:
    """One full or cavitated interval ``[a, b]`` of a steady solution.

    Attributes
    ----------
    kind : {"full", "cavity"}
    a, b : float
        Its ends, ``a < b`` (the flow goes from b to a).
    q : float
        Flux film thickness, ``J = -V q`` (full region); in a cavity the liquid
        content ``theta d = q`` carried from the rupture.
    """

    kind: str
    a: float
    b: float
    q: float
    _sol: object = field(default=None, repr=False, compare=False)


@dataclass(frozen=True)
class SteadyJFO:
    """A steady cavitating solution (:func:`steady_jfo`, :func:`steady_reynolds`).

    Attributes
    ----------
    model : {"jfo", "reynolds", "full-film"}
        The cavitation condition (``"full-film"``: none, p may be negative).
    case : {"full", "outlet-cavity", "reformation"}
        No cavity; one cavity opening to the outlet ``-L`` (rupture only); rupture and
        reformation inside the domain.
    hc, V, beta, k, L : float
        The problem (``k = inf``: rigid).
    x, p, theta, d : ndarray
        The solution on the points ``x`` (the free boundaries included); with a roughness
        ``p`` is the film's pressure and ``d`` the separation of the mean planes.
    rupture, reformation : tuple of float
        Rupture points (full -> cavity toward -x) and reformation points (cavity ->
        full), in decreasing x (the flow's order).
    J : float
        Mass flux (4) of the inlet region, ``-V q`` (< 0: toward -x).  For JFO the flux
        everywhere.
    fluxes : tuple of float
        The flux of every full region, inlet first (JFO: all equal to J).
    mass_source : float
        Reynolds: the liquid created per unit time at reformation, ``J_in - J_out``
        (0 for JFO and without cavity).
    load : float
        ``int_{-L}^{L} P dx``, P the total pressure (``p`` without a roughness).
    film_min, film_min_at : float
        Minimum film thickness (the separation ``d``) and where.
    regions : tuple of Region
        The full and cavitated intervals, from the outlet to the inlet.
    end_error : float
        ``p(L)`` of the final shot (the missed inlet boundary condition).
    uncertainty : dict
        Absolute change of ``J``, ``load``, ``film_min``, ``rupture``, ``reformation``
        (largest over the points) and ``p`` (largest over x) when the solution is redone
        at 100 times the ``rtol``: an upper estimate of its own numerical error.
    roughness : RoughSurfaces or None
        The surfaces' roughness (None: smooth).
    P, h_T : ndarray
        The total pressure ``p + p_a(d)`` and the mean gap on the points ``x`` (smooth:
        ``p`` and ``d``).
    asperity_load : float
        ``int_{-L}^{L} p_a(d) dx``, the asperities' share of ``load`` (smooth: 0).
    """

    model: str
    case: str
    hc: float
    V: float
    beta: float
    k: float
    L: float
    x: np.ndarray
    p: np.ndarray
    theta: np.ndarray
    d: np.ndarray
    rupture: tuple
    reformation: tuple
    J: float
    fluxes: tuple
    mass_source: float
    load: float
    film_min: float
    film_min_at: float
    regions: tuple
    end_error: float
    uncertainty: dict
    roughness: RoughSurfaces | None
    P: np.ndarray
    h_T: np.ndarray
    asperity_load: float
    _problem: object = field(repr=False, compare=False)

    def _region_of(self, x):
        x = np.asarray(x, dtype=float)
        idx = np.zeros(x.shape, dtype=int)
        for i, r in enumerate(self.regions):
            idx[(x >= r.a) & (x <= r.b)] = i
        return idx

    def pressure(self, x):
        """Pressure p(x) (dense output of the integrator; 0 in a cavity)."""
        x = np.asarray(x, dtype=float)
        out = np.zeros(x.shape)
        idx = self._region_of(x)
        for i, r in enumerate(self.regions):
            m = idx == i
            if r.kind == "full" and np.any(m):
                out[m] = r._sol(x[m])[0]
        return out

    def film(self, x):
        """Film thickness ``d = hc + s(x) + p/k`` (rough: the separation, ``d = hc + s + P/k``)."""
        x = np.asarray(x, dtype=float)
        return self._problem.film(x, self.pressure(x))

    def mean_gap(self, x):
        """The film of the Reynolds equation: the mean gap ``h_T(d)`` (smooth: ``d``)."""
        x = np.asarray(x, dtype=float)
        return self._problem.gap(x, self.pressure(x))

    def asperity_pressure(self, x):
        """``p_a(d)`` (smooth: 0)."""
        x = np.asarray(x, dtype=float)
        if self.roughness is None:
            return np.zeros(x.shape)
        return self.roughness.asperity_pressure(self.film(x))

    def total_pressure(self, x):
        """``P = p + p_a(d)``, what deflects the foundation and carries the load (smooth: p)."""
        return self.pressure(x) + self.asperity_pressure(x)

    def fraction(self, x):
        """Liquid fraction theta(x): 1 in a full region, ``q / d`` in a cavity (rough: ``q / h_T``)."""
        x = np.asarray(x, dtype=float)
        out = np.ones(x.shape)
        idx = self._region_of(x)
        for i, r in enumerate(self.regions):
            m = idx == i
            if r.kind == "cavity" and np.any(m):
                out[m] = r.q / self._problem.gap(x[m], 0.0)
        return out

    def pressure_gradient(self, x):
        """``p'`` from (5) at the solution (0 in a cavity): the full-film ODE's right side."""
        x = np.asarray(x, dtype=float)
        out = np.zeros(x.shape)
        idx = self._region_of(x)
        pb = self._problem
        for i, r in enumerate(self.regions):
            m = idx == i
            if r.kind == "full" and np.any(m):
                d = pb.gap(x[m], r._sol(x[m])[0])
                out[m] = pb.V * (r.q - d) / (pb.beta * d**3)
        return out

    def friction(self, sliding=None, asperity_friction=0.0, epsrel=1e-10):
        """The friction force along x on the indenter per unit length, and its parts, by adaptive
        quadrature over the regions (split at the profile's kinks).

        The forces of :func:`femehl.solver.energetics.sliding_energetics`, written for the exact
        solution::

            shear_couette    = S/(6 beta) int c / h_T dx
            shear_poiseuille = int (h_T / 2) p' dx
            pressure_drag    = int P s'(x) dx      (= -int (hc + s) P' dx, P = 0 at x = +-L)

        ``c`` the liquid the Couette shear acts on: the JFO filling ``theta`` (1 in a Reynolds
        or full-Sommerfeld film, whose cavity's content the model does not say), and with a
        roughness the wetted fraction squared ``Phi(d/sigma)^2`` (the shear on the wetted part
        through its gap ``h_T / Phi``).  ``friction`` adds
        ``asperity_friction * asperity_load sign(S)``.

        Parameters
        ----------
        sliding : float, optional
            ``S = U_s - U_i``, the sliding speed; default ``V`` (pure sliding of the substrate).
        asperity_friction : float, default: 0
            The asperities' friction coefficient in femehl's force unit
            (``Roughness.friction / Roughness.aspect``).
        epsrel : float
            The quadrature's relative tolerance per interval.

        Returns
        -------
        dict
            ``friction``, ``shear_couette``, ``shear_poiseuille``, ``pressure_drag``,
            ``asperity_friction``.
        """
        pb = self._problem
        S = pb.V if sliding is None else float(sliding)
        rough = self.roughness
        eps = 1e-6

        def slope(x):  # s'(x), central differences (error ~1e-12 s''')
            return (float(pb._s(np.array([x + eps]))[0]) - float(pb._s(np.array([x - eps]))[0])) / (2 * eps)

        def couette(x):
            xa = np.array([x])
            c = float(self.fraction(xa)[0]) if self.model == "jfo" else 1.0
            if rough is not None:
                c *= float(ndtr(self.film(xa)[0] / rough.sigma)) ** 2
            return c / float(self.mean_gap(xa)[0])

        def poiseuille(x):
            xa = np.array([x])
            return 0.5 * float(self.mean_gap(xa)[0]) * float(self.pressure_gradient(xa)[0])

        def drag(x):
            return float(self.total_pressure(np.array([x]))[0]) * slope(x)

        cuts = sorted({-pb.L, pb.L, *pb.kinks.tolist(), *(e for r in self.regions for e in (r.a, r.b))})
        pieces = [(a, b) for a, b in zip(cuts[:-1], cuts[1:], strict=True) if b > a]

        def integral(f):
            return sum(quad(f, a, b, epsrel=epsrel, epsabs=0.0, limit=200)[0] for a, b in pieces)

        out = {
            "shear_couette": S / (6.0 * pb.beta) * integral(couette),
            "shear_poiseuille": integral(poiseuille),
            "pressure_drag": integral(drag),
            "asperity_friction": float(asperity_friction) * float(np.sign(S)) * self.asperity_load,
        }
        out["friction"] = sum(out.values())
        return out


# --------------------------------------------------------------------------
# the problem and its full-region integrator
# --------------------------------------------------------------------------
class _Piecewise:
    """Dense output of an integration split at kinks: ``self(x) -> [p, load(, asperity load)]``."""

    def __init__(self, pieces, m=2):
        self.pieces = pieces  # list of (a, b, OdeSolution)
        self.edges = np.array([pc[0] for pc in pieces] + [pieces[-1][1]])
        self.m = m  # components: [p, film load] (and the asperity load with a roughness)

    def __call__(self, x):
        x = np.atleast_1d(np.asarray(x, dtype=float))
        out = np.empty((self.m, x.size))
        j = np.clip(np.searchsorted(self.edges, x, side="right") - 1, 0, len(self.pieces) - 1)
        for i, (_, _, sol) in enumerate(self.pieces):
            m = j == i
            if np.any(m):
                out[:, m] = sol(x[m])
        return out


#: the default integrator is Radau when ``2 L V / (beta k max(hc + s)^3)``, an estimate of (5)'s
#: decay rate times the domain's length, exceeds this (a film soft everywhere; design.md 17.3)
_SOFT = 300.0


class _Problem:
    """Profile, parameters and the integrator of (5) toward +x."""

    def __init__(self, profile, hc, V, beta, k, L, kinks, rtol, method, rough=None, hint=None):
        self.profile, self.hc, self.V, self.beta, self.k, self.L = profile, hc, V, beta, k, L
        self.rigid = math.isinf(k)
        self.rough = rough
        self.hint = hint or {}  # q and rupture of a solution at a nearby hc: where to look first
        self.kinks = np.array(sorted(float(c) for c in kinks if -L < c < L))
        self.rtol = rtol
        xs = np.linspace(-L, L, 4001)
        self.grid, self.h_grid = xs, hc + self._s(xs)
        # the flux film at p = 0 (a rupture's q, a cavity's film): the rigid gap, or with a
        # roughness the mean gap at the separation the asperities alone hold
        self.g_grid = self.h_grid if rough is None else self.gap0(xs)
        if method is None:  # Radau where DOP853 is held to tiny steps by stability alone
            soft = not self.rigid and 2.0 * L * V / (beta * k * float(self.h_grid.max()) ** 3) > _SOFT
            method = "Radau" if soft else "DOP853"
        self.method = method

    def _s(self, x):
        return np.asarray(self.profile(np.asarray(x, dtype=float)), dtype=float)

    def h(self, x):
        """The film without deflection, ``hc + s(x)``."""
        return self.hc + self._s(x)

    def film(self, x, p):
        """The film ``d`` at film pressure ``p`` (rough: the separation of the mean planes)."""
        h = self.h(x)
        if self.rough is not None:
            return self.rough.separation(h if self.rigid else h + np.asarray(p) / self.k, self.k)
        return h if self.rigid else h + np.asarray(p) / self.k

    def gap(self, x, p):
        """The film of (5): ``d``, or with a roughness the mean gap ``h_T(d)``."""
        d = self.film(x, p)
        return d if self.rough is None else self.rough.mean_gap(d)

    def gap0(self, x):
        """The film of (5) where ``p = 0`` (smooth: ``hc + s``)."""
        return self.h(x) if self.rough is None else self.gap(x, 0.0)

    def _h1(self, x):
        return self.hc + float(self.profile(np.array([x]))[0])

    def _g1(self, x):
        """:meth:`gap0` at one point, a float."""
        return self._h1(x) if self.rough is None else float(self.gap0(np.array([x]))[0])

    def asperity_load(self, a, b, rtol):
        """``int_a^b p_a(d) dx`` at ``p = 0`` (a cavity), by adaptive quadrature split at the kinks."""
        if self.rough is None or b <= a:
            return 0.0
        pts = [c for c in self.kinks if a < c < b]
        cuts = [a, *pts, b]
        total = 0.0
        for lo, hi in zip(cuts[:-1], cuts[1:], strict=True):
            val, _ = quad(
                lambda x: float(self.rough.asperity_pressure(self.film(np.array([x]), 0.0))[0]),
                lo,
                hi,
                epsabs=1e-3 * rtol * self.rough.stiffness * (hi - lo),
                epsrel=max(rtol, 1e-13),
                limit=500,
            )
            total += val
        return total

    def _rough_point(self, q):
        """``(x, p) -> (d, h_T, p_a)`` at one point, the separation's Newton warm-started from the
        previous point's (the integrator's calls are close), the last results remembered (the
        events ask again at the points the right side was evaluated at)."""
        rough, k, rigid = self.rough, self.k, self.rigid
        last = {"c": None, "d": None, "g": 1.0}
        memo = {}

        def point(x, p):
            key = (x, p)
            if key in memo:
                return memo[key]
            c = self._h1(x) if rigid else self._h1(x) + p / k
            guess = None if last["d"] is None else last["d"] + (c - last["c"]) / last["g"]
            d, pa, gp = (float(v[0]) for v in rough.separation(np.array([c]), k, guess, full=True))
            last.update(c=c, d=d, g=gp)
            out = (d, float(rough.mean_gap(d)), pa)
            if len(memo) > 64:
                memo.clear()
            memo[key] = out
            return out

        return point

    def integrate(self, q, x0, x1, rtol=None, stop=None, dense=False):
        """(5) from x0 (p = 0) toward x1 > x0 with flux film q.

        ``stop``: None, "zero" (stop where p comes down to 0) or "tangent" (stop at the
        local minimum of p after its maximum, ``d`` coming down through q).
        Returns (x_end, p_end, load_end, reason, dense) with reason "end", "zero",
        "tangent" or "closed" (the film thickness reached ~0).  With a roughness ``d`` is the
        mean gap ``h_T``, ``load_end`` the film pressure's, and the dense output has a third
        component, the asperities' load ``int p_a dx``.
        """
        rtol = self.rtol if rtol is None else rtol
        V, beta, k, rigid = self.V, self.beta, self.k, self.rigid
        pscale = V * max(x1 - x0, 1e-3) / (beta * q * q)
        atol = [rtol * 1e-3 * pscale, rtol * 1e-3 * pscale * max(x1 - x0, 1e-3)]
        jac = None
        if self.rough is None:

            def film1(x, p):
                h = self._h1(x)
                return h if rigid else h + p / k

            def f(x, y):
                d = film1(x, y[0])
                return [V * (q - d) / (beta * d**3), y[0]]

            if not rigid and self.method in ("Radau", "BDF"):

                def jac(x, y):
                    d = film1(x, y[0])
                    return [[V * (2.0 * d - 3.0 * q) / (beta * k * d**4), 0.0], [1.0, 0.0]]

        else:
            rough, point = self.rough, self._rough_point(q)
            atol.append(rtol * 1e-3 * max(pscale, rough.stiffness) * max(x1 - x0, 1e-3))

            def film1(x, p):
                return point(x, p)[1]

            def f(x, y):
                _, hT, pa = point(x, y[0])
                return [V * (q - hT) / (beta * hT**3), y[0], pa]

            if not rigid and self.method in ("Radau", "BDF"):

                def jac(x, y):
                    d, hT, _ = point(x, y[0])
                    slope = float(rough.asperity_slope(d))
                    dd = 1.0 / (k - slope)  # dd/dp: d - p_a(d)/k = h + p/k
                    a = V * (2.0 * hT - 3.0 * q) / (beta * hT**4) * float(rough.mean_gap_slope(d)) * dd
                    return [[a, 0.0, 0.0], [1.0, 0.0, 0.0], [slope * dd, 0.0, 0.0]]

        def closed(x, y):
            return film1(x, y[0]) - 1e-6 * q

        closed.terminal, closed.direction = True, -1
        events = [closed]
        if stop == "zero":

            def zero(x, y):
                return y[0]

            zero.terminal, zero.direction = True, -1
            events.append(zero)
        elif stop == "tangent":

            def tangent(x, y):
                return film1(x, y[0]) - q

            tangent.terminal, tangent.direction = True, -1
            events.append(tangent)
        cuts = [x0, *[c for c in self.kinks if x0 < c < x1], x1]
        y = np.zeros(len(atol))
        pieces, reason, xe = [], "end", x1
        kw = {"jac": jac} if jac is not None else {}
        for a, b in zip(cuts[:-1], cuts[1:], strict=True):
            sol = solve_ivp(
                f,
                (a, b),
                y,
                method=self.method,
                rtol=rtol,
                atol=atol,
                events=events,
                dense_output=dense,
                **kw,
            )
            if sol.status == -1:
                raise SolverError(
                    f"steady_jfo: the integration of (5) failed on [{a:g}, {b:g}] ({sol.message})."
                )
            if dense:
                pieces.append((a, float(sol.t[-1]), sol.sol))
            y = sol.y[:, -1].copy()
            if sol.status == 1:
                for i, name in enumerate(("closed", stop)):
                    if i < len(sol.t_events) and sol.t_events[i].size:
                        reason, xe = name, float(sol.t_events[i][0])
                        y = sol.y_events[i][0].copy()
                        break
                break
        if reason == "end":
            xe = x1
        return xe, float(y[0]), float(y[1]), reason, (_Piecewise(pieces, y.size) if dense else None)


# --------------------------------------------------------------------------
# the regions
# --------------------------------------------------------------------------
_SCAN_RTOL = 1e-6


def _root(fun, a, b, rtol, scale):
    """Root of ``fun(v, tol)`` in [a, b] (a sign change): brentq at a loose tol, then at rtol.

    The loose root brackets the tight one closely, so the costly integrations at ``rtol``
    are few (brentq's interpolation converges in a handful of steps on a smooth miss).
    """
    v0 = brentq(lambda v: fun(v, _SCAN_RTOL), a, b, xtol=1e-10 * scale, rtol=1e-12, maxiter=200)
    memo = {}

    def tight(v):
        if v not in memo:
            memo[v] = fun(v, rtol)
        return memo[v]

    delta = 1e-6 * scale
    while True:
        lo, hi = max(a, v0 - delta), min(b, v0 + delta)
        if (tight(lo) > 0.0) != (tight(hi) > 0.0):
            break
        if lo == a and hi == b:
            raise SolverError(
                f"steady_jfo: the root in [{a:.6g}, {b:.6g}] is lost at rtol = {rtol:g}; try method='Radau'."
            )
        delta *= 30.0
    return brentq(tight, lo, hi, xtol=1e-15 * scale, rtol=1e-15, maxiter=200)


def _full_film(pb, rtol):
    """Step 1: (5) on [-L, L] with p(-L) = p(L) = 0, shooting on q."""
    L = pb.L

    def G(q, tol=_SCAN_RTOL):
        xe, pe, _, reason, _ = pb.integrate(q, -L, L, tol)
        return pe if reason == "end" else -1.0 - (L - xe)  # the film closed: q far too small

    near = _near_bracket(G, pb.hint.get("q"), lambda a, b: a < 0.0 <= b) if pb.hint else None
    if near is not None:  # a solution at a nearby hc (steady_under_load) brackets q at once
        lo, hi = near
        glo, ghi = -1.0, 0.0
    else:
        hi = float(pb.g_grid.max())
        ghi = G(hi)
        lo, glo = 0.5 * hi, G(0.5 * hi)
    while glo >= 0.0 and lo > 1e-8 * hi:
        hi, ghi, lo = lo, glo, 0.5 * lo
        glo = G(lo)
    if not (glo < 0.0 <= ghi):
        raise SolverError(
            f"steady_full_film: cannot bracket the flux film q in ({lo:.3g}, {hi:.3g}) (p(L) = "
            f"{glo:.3g}, {ghi:.3g}); check hc and the profile (the film must open toward x = +-L)."
        )
    q = _root(G, lo, hi, rtol, hi)
    pb.q_full = q
    xe, pe, load, reason, sol = pb.integrate(q, -L, L, rtol, dense=True)
    if reason != "end":
        raise SolverError(f"steady_full_film: the film closes at x = {xe:.4g} (the solution needs contact).")
    return [Region("full", -L, L, q, sol)], pe


def _inlet_F(pb, xr, rtol):
    """Step 2's miss: p(L) from a rupture at xr, or -(distance left) if p came back to 0 first."""
    L = pb.L
    q = pb._g1(xr)
    if q <= 0.0:
        return -1.0 - (L - xr)
    xe, pe, _, reason, _ = pb.integrate(q, xr, L, rtol, stop="zero")
    return pe if reason == "end" else -(L - xe) - (1.0 if reason == "closed" else 0.0)


def _near_bracket(fun, v, changes):
    """A bracket ``(v - e, v + e)`` of a root of ``fun`` near a hint ``v`` (``changes(f(a), f(b))``
    tells a root), ``e = 1e-4 |v|`` widened to ``1e-2 |v|``; None without one."""
    if v is None:
        return None
    for rel in (1e-4, 1e-3, 1e-2):
        e = rel * max(abs(v), 1e-3)
        a, b = v - e, v + e
        if changes(fun(a), fun(b)):
            return a, b
    return None


def _inlet_brackets(pb):
    """Step 2's scan of x_r (cached on the problem): brackets of sign changes, inlet first.

    With a hint (the rupture of a solution at a nearby hc, :func:`steady_under_load`) a bracket
    about it is tried first, alone; :func:`_solve` scans when it gives no solution."""
    if getattr(pb, "_brackets", None) is None and pb.hint.get("rupture") is not None:
        near = _near_bracket(
            lambda x: _inlet_F(pb, x, _SCAN_RTOL),
            pb.hint.get("rupture"),
            lambda a, b: (a > 0.0) != (b > 0.0) and max(a, b) > 0.0,
        )
        if near is not None and -pb.L < near[0] and near[1] < pb.L:
            pb._brackets, pb._hinted = [near], True
            return pb._brackets
    if getattr(pb, "_brackets", None) is None:
        L = pb.L
        xs = np.linspace(-L, L, 61)[1:-1]
        Fs = np.array([_inlet_F(pb, x, _SCAN_RTOL) for x in xs])
        out = []
        for i in range(xs.size - 2, -1, -1):
            a, b = Fs[i], Fs[i + 1]
            if (a > 0.0) != (b > 0.0) and max(a, b) > 0.0:
                out.append((float(xs[i]), float(xs[i + 1])))
        pb._brackets = out
        log.debug("steady_jfo: rupture brackets %s", out)
    return pb._brackets


def _first_below(pb, q, a, b):
    """First x in (a, b) where ``hc + s(x) < q`` going toward +x (a rupture), or None."""
    n = max(200, int(4000 * (b - a) / (2 * pb.L)))
    xs = np.linspace(a, b, n + 1)
    g = pb.gap0(xs) - q
    span = 1e-7 * pb.L
    ok = (xs > a + span) & (xs < b - span)
    below = np.flatnonzero(ok & (g < 0.0))
    if below.size == 0:
        return None
    i = int(below[0])
    lo = xs[i - 1] if g[i - 1] >= 0.0 else a + span

    return brentq(lambda x: pb._g1(x) - q, lo, xs[i], xtol=1e-15 * pb.L, rtol=1e-15, maxiter=200)


def _march_jfo(pb, q, xr, rtol):
    """Step 3: the regions downstream of the inlet's rupture xr, with the one flux q."""
    L = pb.L
    regions, x0 = [], -L
    state = "full" if pb._g1(-L) < q else "cavity"
    for _ in range(200):
        if state == "full":
            xe, _, _, reason, sol = pb.integrate(q, x0, xr, rtol, stop="zero", dense=True)
            if reason != "zero":
                return None  # the pressure does not come back to 0 before the inlet's rupture
            regions.append(Region("full", x0, xe, q, sol))
            x0, state = xe, "cavity"
        else:
            xn = _first_below(pb, q, x0, xr)
            if xn is None:
                regions.append(Region("cavity", x0, xr, q))
                return regions
            regions.append(Region("cavity", x0, xn, q))
            x0, state = xn, "full"
    raise SolverError("steady_jfo: more than 100 cavities; check the profile.")


def _march_reynolds(pb, q, xr, rtol):
    """Step 4: Reynolds downstream of xr: the outlet's full region has its own flux."""
    L = pb.L
    h0 = pb._g1(-L)
    inside = pb.grid <= xr
    hmax = float(pb.g_grid[inside].max())

    def H(q2, tol):
        xe, pe, _, reason, _ = pb.integrate(q2, -L, xr, tol, stop="tangent")
        return pe if reason != "closed" else -1.0 - (xr - xe)

    bracket = getattr(pb, "_reynolds_bracket", False)
    if bracket is False:  # the scan is cached: the solution at a looser rtol reuses it
        bracket = None
        if hmax > h0:
            qs = h0 + (hmax - h0) * np.linspace(0.0, 1.0, 41)[1:]
            Hs = [H(v, _SCAN_RTOL) for v in qs]
            for i in range(len(qs) - 1):
                if Hs[i] < 0.0 <= Hs[i + 1]:
                    bracket = (float(qs[i]), float(qs[i + 1]))
                    break
        pb._reynolds_bracket = bracket
    if bracket is None:
        xf = -L  # the outlet is cavitated: one cavity [-L, xr]
        regions = []
    else:
        q2 = _root(H, *bracket, rtol, hmax)
        xf, _, _, reason, sol = pb.integrate(q2, -L, xr, rtol, stop="tangent", dense=True)
        if reason != "tangent" or xf >= xr:
            return None
        regions = [Region("full", -L, xf, q2, sol)]
    # a Reynolds cavity holds p = 0 only where the gap diverges toward -x (residual >= 0)
    xs = np.linspace(xf, xr, 401)
    hs = pb.gap0(xs)
    if np.any(np.diff(hs) > 1e-9 * hs.max()):
        raise SolverError(
            "steady_reynolds: the cavity would cover a converging part of the gap: more than one "
            "cavity (or an outlet cavity reforming), which this reference does not handle."
        )
    regions.append(Region("cavity", xf, xr, q))
    return regions


def _solve(pb, model, rtol):
    """The regions (outlet first), the case and the inlet shot's miss."""
    regions, miss = _full_film(pb, rtol)
    r = regions[0]
    xs = np.linspace(-pb.L, pb.L, 4001)
    ps = r._sol(xs)[0]
    if model == "full-film" or ps.min() >= -1e-12 * max(ps.max(), 0.0):
        return regions, "full", miss
    pscale = max(ps.max(), -ps.min())
    L = pb.L
    for a, b in _inlet_brackets(pb):
        xr = _root(lambda x, tol: _inlet_F(pb, x, tol), a, b, rtol, L)
        miss = _inlet_F(pb, xr, rtol)
        if abs(miss) > 1e-6 * pscale:
            continue  # a jump of the miss (p touching 0 inside), not a root
        q = pb._g1(xr)
        _, _, _, _, sol = pb.integrate(q, xr, L, rtol, dense=True)
        inlet = Region("full", xr, L, q, sol)
        down = _march_jfo(pb, q, xr, rtol) if model == "jfo" else _march_reynolds(pb, q, xr, rtol)
        if down is None:
            continue
        case = "outlet-cavity" if len(down) == 1 else "reformation"
        return [*down, inlet], case, miss
    if getattr(pb, "_hinted", False):  # the hint's bracket gave no solution: scan
        pb._brackets, pb._hinted, pb.hint = None, False, {}
        return _solve(pb, model, rtol)
    raise SolverError(
        f"steady_{model}: no rupture point found that makes a consistent solution; the profile "
        "may need a cavity at the inlet or contact, which this reference does not handle."
    )


# --------------------------------------------------------------------------
# the public functions
# --------------------------------------------------------------------------
_METHODS = ("DOP853", "Radau", "BDF", "RK45")  # LSODA: its dense output misplaces events


def _check(profile, hc, V, beta, k, L, kinks, rtol, method, rough=None):
    if profile is None:
        profile = _cylinder
    if not callable(profile):
        raise SceneError(
            f"profile must be a callable s(x) (the rigid gap), got {type(profile).__name__}: pass e.g. "
            "lambda x: 0.5 * x**2, or None for the cylinder."
        )
    hc = check_finite("hc", hc)
    V = check_positive("sliding velocity V", V, "For V = 0 the steady film carries no load: no solution.")
    beta = check_positive("beta", beta)
    if k is None or (isinstance(k, (int, float)) and not isinstance(k, bool) and k == math.inf):
        k = math.inf
    else:
        k = check_positive("Winkler stiffness k", k, "Use k = math.inf for a rigid substrate.")
    L = check_positive("domain half length L", L)
    rtol = check_positive("rtol", rtol)
    if not 1e-14 <= rtol <= 1e-6:
        raise SceneError(f"rtol = {rtol:g} must be in [1e-14, 1e-6]: the reference is meant to be exact.")
    if method is not None and method not in _METHODS:
        raise SceneError(f"method must be one of {_METHODS} or None (automatic), got {method!r}.")
    kinks = tuple(check_finite("kink position", c) for c in kinks)
    xs = np.linspace(-L, L, 4001)
    try:
        s = np.asarray(profile(xs), dtype=float)
    except Exception as exc:  # noqa: BLE001 - the user's code: say which function failed
        raise SceneError(
            f"profile s(x) raised {type(exc).__name__} on an array of x ({exc}): it must accept a numpy "
            "array and return one value per point."
        ) from None
    if s.shape != xs.shape or not np.all(np.isfinite(s)):
        raise SceneError(
            f"profile s(x) must return one finite value per point of [-L, L] (got shape {s.shape}); "
            "vectorize it with numpy."
        )
    h = hc + s
    if min(h[0], h[-1]) <= 0.0:
        raise SceneError(
            f"hc + s(+-L) = ({h[0]:g}, {h[-1]:g}) must be > 0: p = 0 at the ends, so the film there is "
            "hc + s; use a larger L or hc."
        )
    if math.isinf(k) and h.min() <= 0.0 and rough is None:  # rough: the asperities carry it
        i = int(np.argmin(h))
        raise SceneError(
            f"rigid slider: hc + s(x) = {h[i]:g} <= 0 at x = {xs[i]:.4g}, the film is closed; use hc > "
            f"{hc - h[i]:g} or a finite Winkler stiffness k."
        )
    return profile, hc, V, beta, k, L, kinks, rtol, method


def _build(pb, model, regions, case, miss, n, x, rtol) -> dict:
    L = pb.L
    rupture, reformation = [], []
    for lo, hi in zip(regions[:-1], regions[1:], strict=True):
        if lo.kind == "cavity" and hi.kind == "full":
            rupture.append(lo.b)
        elif lo.kind == "full" and hi.kind == "cavity":
            reformation.append(lo.b)
    rupture, reformation = tuple(rupture[::-1]), tuple(reformation[::-1])
    full = [r for r in regions if r.kind == "full"]
    fluxes = tuple(-pb.V * r.q for r in full[::-1])
    load = float(sum(r._sol(r.b)[1, 0] for r in full))
    asperity_load = 0.0
    if pb.rough is not None:  # the full regions' third component; the cavities by quadrature
        for r in regions:
            if r.kind == "full":
                asperity_load += float(r._sol(r.b)[2, 0])
            else:
                asperity_load += pb.asperity_load(r.a, r.b, rtol)
        load += asperity_load
    edges = [r.a for r in regions] + [L]
    xs = np.linspace(-L, L, int(n)) if x is None else np.array(x, dtype=float)  # a copy
    if x is None:
        xs = np.union1d(xs, edges)
    sol = {
        "model": model,
        "case": case,
        "regions": tuple(regions),
        "rupture": rupture,
        "reformation": reformation,
        "J": fluxes[0],
        "fluxes": fluxes,
        "mass_source": fluxes[0] - fluxes[-1] if model == "reynolds" and reformation else 0.0,
        "load": load,
        "asperity_load": asperity_load,
        "end_error": float(miss),
        "x": xs,
    }
    # the minimum film: on a fine sample, refined by a bounded search
    tmp = _result(pb, sol, {})
    xf = np.union1d(np.linspace(-L, L, 20001), edges)
    df = tmp.film(xf)
    i = int(np.argmin(df))
    a, b = xf[max(i - 1, 0)], xf[min(i + 1, xf.size - 1)]
    res = minimize_scalar(
        lambda t: float(tmp.film(np.array([t]))[0]),
        bounds=(a, b),
        method="bounded",
        options={"xatol": 1e-12 * L},
    )
    if res.fun < df[i]:
        sol["film_min"], sol["film_min_at"] = float(res.fun), float(res.x)
    else:
        sol["film_min"], sol["film_min_at"] = float(df[i]), float(xf[i])
    return sol


def _result(pb, sol, uncertainty) -> SteadyJFO:
    shell = SteadyJFO(
        model=sol["model"],
        case=sol["case"],
        hc=pb.hc,
        V=pb.V,
        beta=pb.beta,
        k=pb.k,
        L=pb.L,
        x=sol["x"],
        p=np.zeros(0),
        theta=np.zeros(0),
        d=np.zeros(0),
        rupture=sol["rupture"],
        reformation=sol["reformation"],
        J=sol["J"],
        fluxes=sol["fluxes"],
        mass_source=sol["mass_source"],
        load=sol["load"],
        film_min=sol.get("film_min", math.nan),
        film_min_at=sol.get("film_min_at", math.nan),
        regions=sol["regions"],
        end_error=sol["end_error"],
        uncertainty=uncertainty,
        roughness=pb.rough,
        P=np.zeros(0),
        h_T=np.zeros(0),
        asperity_load=sol["asperity_load"],
        _problem=pb,
    )
    xs = sol["x"]
    p, d = shell.pressure(xs), shell.film(xs)
    if pb.rough is None:
        P, hT = p, d
    else:
        P, hT = p + pb.rough.asperity_pressure(d), pb.rough.mean_gap(d)
    return dataclasses.replace(shell, p=p, theta=shell.fraction(xs), d=d, P=P, h_T=hT)


def _difference(a: dict, b: dict) -> dict:
    def pts(u, v):
        if len(u) != len(v):
            return math.inf
        return max((abs(s - t) for s, t in zip(u, v, strict=True)), default=0.0)

    out = {name: abs(a[name] - b[name]) for name in ("J", "load", "film_min")}
    if a["asperity_load"] or b["asperity_load"]:
        out["asperity_load"] = abs(a["asperity_load"] - b["asperity_load"])
    out["rupture"] = pts(a["rupture"], b["rupture"])
    out["reformation"] = pts(a["reformation"], b["reformation"])
    return out


def _steady(
    model, profile, hc, V, beta, k, L, kinks, x, n, rtol, method, estimate_error, roughness=None, hint=None
):
    rough = RoughSurfaces.of(roughness)
    if rough is not None and model == "jfo":
        raise SceneError(
            "steady_jfo takes no roughness (the JFO content of a mean gap is not written here): use "
            "steady_reynolds or steady_full_film."
        )
    profile, hc, V, beta, k, L, kinks, rtol, method = _check(
        profile, hc, V, beta, k, L, kinks, rtol, method, rough
    )
    n = check_int("n", n, 2)
    if x is not None:
        xa = np.asarray(x, dtype=float)
        if xa.ndim != 1 or not np.all(np.isfinite(xa)) or np.abs(xa).max(initial=0.0) > L:
            raise SceneError(f"x must be a 1-D array of finite points of [-L, L] = [-{L:g}, {L:g}].")
    pb = _Problem(profile, hc, V, beta, k, L, kinks, rtol, method, rough, hint)
    regions, case, miss = _solve(pb, model, rtol)
    sol = _build(pb, model, regions, case, miss, n, x, rtol)
    unc = {}
    if estimate_error:
        loose = min(100.0 * rtol, 1e-6)
        r2, c2, m2 = _solve(pb, model, loose)
        s2 = _build(pb, model, r2, c2, m2, n, sol["x"], loose)
        if c2 != case:
            raise SolverError(
                f"steady_{model}: the configuration changes with the tolerance ({case} at rtol = {rtol:g}, "
                f"{c2} at {loose:g}): the problem is too close to a change of configuration."
            )
        unc = _difference(sol, s2)
        tmp, ref = _result(pb, s2, {}), _result(pb, sol, {})
        unc["p"] = float(np.abs(tmp.pressure(sol["x"]) - ref.pressure(sol["x"])).max())
        if rough is not None:
            unc["P"] = float(np.abs(tmp.P - ref.P).max())
        unc["rtol"] = loose
    out = _result(pb, sol, unc)
    log.info(
        "steady_%s: %s, rupture %s, reformation %s, J = %.12g, load = %.12g, film_min = %.12g",
        model,
        case,
        out.rupture,
        out.reformation,
        out.J,
        out.load,
        out.film_min,
    )
    return out


_COMMON = """
    Parameters
    ----------
    profile : callable or None
        Rigid gap ``s(x)`` of the slider, vectorized (an array of x -> one finite value per
        point); None: the cylinder ``x^2/2`` of :class:`femehl.problem.line.LineScene`.
    hc : float
        Imposed clearance (< 0: indentation, possible with a finite k).
    V : float, default: 1.0
        Sliding velocity (> 0; the substrate moves toward -x, the inlet is x = +L).
    beta : float, default: 10.0
        Film parameter of (1).
    k : float, default: math.inf
        Winkler stiffness (2); ``math.inf`` (or None): rigid, ``d = hc + s``.
    L : float, default: 2.0
        Domain half length, p(+-L) = 0.
    kinks : sequence of float, default: ()
        Points where s'' jumps (the integration is split there; :func:`pocket_slider`
        returns its pocket's edges).
    x : array_like, optional
        Where to return p, theta, d; default ``n`` equally spaced points on [-L, L] with
        the free boundaries added.
    n : int, default: 2001
        Number of the default points.
    rtol : float, default: 1e-12
        Relative tolerance of the integrations (the root finding goes to machine precision).
    method : str, optional
        :func:`scipy.integrate.solve_ivp` method (DOP853, Radau, BDF, RK45); default DOP853, or
        Radau for a Winkler film soft everywhere (``2 L V / (beta k max(hc + s)^3) > 300``).
    estimate_error : bool, default: True
        Solve again at ``100 rtol`` and report the differences as ``uncertainty``.

    Returns
    -------
    SteadyJFO
"""


def steady_jfo(
    profile,
    hc: float,
    V: float = 1.0,
    beta: float = 10.0,
    k: float = math.inf,
    L: float = 2.0,
    *,
    kinks=(),
    x=None,
    n: int = 2001,
    rtol: float = 1e-12,
    method: str | None = None,
    estimate_error: bool = True,
) -> SteadyJFO:
    return _steady("jfo", profile, hc, V, beta, k, L, kinks, x, n, rtol, method, estimate_error)


def steady_reynolds(
    profile,
    hc: float,
    V: float = 1.0,
    beta: float = 10.0,
    k: float = math.inf,
    L: float = 2.0,
    *,
    kinks=(),
    x=None,
    n: int = 2001,
    rtol: float = 1e-12,
    method: str | None = None,
    estimate_error: bool = True,
    roughness=None,
) -> SteadyJFO:
    return _steady(
        "reynolds", profile, hc, V, beta, k, L, kinks, x, n, rtol, method, estimate_error, roughness
    )


def steady_full_film(
    profile,
    hc: float,
    V: float = 1.0,
    beta: float = 10.0,
    k: float = math.inf,
    L: float = 2.0,
    *,
    kinks=(),
    x=None,
    n: int = 2001,
    rtol: float = 1e-12,
    method: str | None = None,
    estimate_error: bool = True,
    roughness=None,
) -> SteadyJFO:
    return _steady(
        "full-film", profile, hc, V, beta, k, L, kinks, x, n, rtol, method, estimate_error, roughness
    )


_ROUGH = """    roughness : RoughSurfaces, tuple or femehl.Roughness, optional
        Rough surfaces (docs/design.md section 18; a ``(sigma, stiffness[, eps])`` tuple or an
        object with ``sigma`` and ``stiffness``): ``d`` is the separation of the mean planes,
        ``d = hc + s + (p + p_a(d))/k``, (5) holds with the mean gap ``h_T(d)`` for ``d``, the
        cavitation condition acts on the film's pressure ``p``, and ``load`` is the total
        pressure's (``asperity_load`` the asperities' share).  None: smooth.
"""
_COMMON_ROUGH = _COMMON.replace("\n\n    Returns\n", "\n" + _ROUGH + "\n    Returns\n")

steady_jfo.__doc__ = (
    """Steady sliding with JFO (mass-conserving) cavitation: exact, by quadrature and shooting.

    The flux (4) is one constant; free boundaries by (6) and (7) (docs/design.md section 17).
    No cavity (case "full"), one cavity open to the outlet ("outlet-cavity") or cavities
    with reformation inside the domain ("reformation") are found automatically.
"""
    + _COMMON
)
steady_reynolds.__doc__ = (
    """Steady sliding with the Reynolds (Swift-Stieber) condition: p = p' = 0 at every free boundary.

    The comparison solution for :func:`steady_jfo`: the same inlet region, but the outlet's
    full region has its own flux (mass is not conserved at reformation); one cavity at most.
"""
    + _COMMON_ROUGH
)
steady_full_film.__doc__ = (
    """Steady sliding without a cavitation condition (full Sommerfeld: p may be < 0).

    On the cylinder (``profile=None``) :func:`femehl.reference.line_steady.steady_line` presents it
    in the names of the paper's section 4.
"""
    + _COMMON_ROUGH
)


_MODELS = ("full-film", "reynolds", "jfo")


def steady_under_load(
    model: str,
    profile,
    F: float,
    V: float = 1.0,
    beta: float = 10.0,
    k: float = math.inf,
    L: float = 2.0,
    *,
    hc_bracket=None,
    roughness=None,
    kinks=(),
    x=None,
    n: int = 2001,
    rtol: float = 1e-12,
    method: str | None = None,
    estimate_error: bool = True,
) -> SteadyJFO:
    """Steady sliding under an imposed load per unit width ``F = int P dx``: ``hc`` by brentq.

    ``model`` is ``"full-film"``, ``"reynolds"`` or ``"jfo"`` (:func:`steady_full_film`,
    :func:`steady_reynolds`, :func:`steady_jfo`; the roughness as there); the other arguments
    are theirs.  The load falls as ``hc`` grows; ``hc`` is found in ``hc_bracket`` to
    ``max(10 rtol, 1e-13)`` (the load is computed to about ``rtol``), each solve's shootings
    started about the previous solve's flux film and rupture point.  The default bracket is
    the cylinder's on a finite ``k`` (``profile=None``): from the dry contact ``F = (2/3) k a^3``,
    ``(max(-a^2/2 - 1, -0.49 L^2), L^2/4)``, as :func:`femehl.reference.line_steady.steady_line_load`;
    otherwise pass one.  Returns the solution at that ``hc`` (``.hc``).
    """
    if model not in _MODELS:
        raise SceneError(f"model must be one of {tuple(_MODELS)}, got {model!r}.")
    F = check_positive("load F", F)
    if hc_bracket is None:
        if profile is not None or k is None or k == math.inf:
            raise SceneError(
                "steady_under_load: pass hc_bracket=(lo, hi) (the default is the cylinder's on a finite "
                "Winkler k)."
            )
        k = check_positive("Winkler stiffness k", k)
        L = check_positive("domain half length L", L)
        a = (1.5 * F / k) ** (1.0 / 3.0)
        hc_bracket = (max(-0.5 * a * a - 1.0, -0.49 * L * L), 0.25 * L * L)
    lo, hi = (check_finite("hc bracket", v) for v in hc_bracket)
    if not lo < hi:
        raise SceneError(f"hc_bracket must be (lo, hi) with lo < hi, got {hc_bracket!r}.")
    hint, seen = {}, {}

    def solve(hc, estimate):
        s = _steady(
            model, profile, hc, V, beta, k, L, kinks, x, n, rtol, method, estimate, roughness, dict(hint)
        )
        hint.update(q=s._problem.q_full, rupture=s.rupture[0] if s.rupture else None)
        return s

    def miss(hc):
        if hc not in seen:
            seen[hc] = solve(hc, False)
        return seen[hc].load - F

    mlo, mhi = miss(lo), miss(hi)
    if not (mlo > 0.0 > mhi):
        raise SolverError(
            f"steady_under_load: F = {F:g} is not bracketed by hc in ({lo:g}, {hi:g}) (load - F = "
            f"{mlo:.3g}, {mhi:.3g}); pass hc_bracket."
        )
    hc = brentq(miss, lo, hi, xtol=max(1e-13, 10.0 * rtol), rtol=1e-13, maxiter=200)
    return solve(hc, True) if estimate_error or hc not in seen else seen[hc]
