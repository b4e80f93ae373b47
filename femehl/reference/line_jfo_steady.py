"""Exact steady sliding of line contact: the one steady line reference (any rigid gap, rigid or Winkler).

Full film (:func:`steady_full_film`), mass-conserving JFO (:func:`steady_jfo`) or Reynolds
(:func:`steady_reynolds`) cavitation, by quadrature and shooting in the pressure, independent of
the FE solver of :mod:`femehl.problem.line`; :mod:`femehl.reference.line_steady` presents its
cylinder case.  The equations (numbered (1)-(7) in the docstrings), the method, the reference
configurations and the independent checks: docs/design.md section 17.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

from femehl.errors import SceneError, SolverError
from femehl.problem.scene import check_finite, check_positive
from femehl.validation import check_int

__all__ = [
    "Region",
    "SteadyJFO",
    "pocket_slider",
    "steady_full_film",
    "steady_jfo",
    "steady_reynolds",
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
        The solution on the points ``x`` (the free boundaries included).
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
        ``int_{-L}^{L} p dx``.
    film_min, film_min_at : float
        Minimum film thickness and where.
    regions : tuple of Region
        The full and cavitated intervals, from the outlet to the inlet.
    end_error : float
        ``p(L)`` of the final shot (the missed inlet boundary condition).
    uncertainty : dict
        Absolute change of ``J``, ``load``, ``film_min``, ``rupture``, ``reformation``
        (largest over the points) and ``p`` (largest over x) when the solution is redone
        at 100 times the ``rtol``: an upper estimate of its own numerical error.
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
        """Film thickness ``d = hc + s(x) + p/k``."""
        x = np.asarray(x, dtype=float)
        return self._problem.film(x, self.pressure(x))

    def fraction(self, x):
        """Liquid fraction theta(x): 1 in a full region, ``q / d`` in a cavity."""
        x = np.asarray(x, dtype=float)
        out = np.ones(x.shape)
        idx = self._region_of(x)
        for i, r in enumerate(self.regions):
            m = idx == i
            if r.kind == "cavity" and np.any(m):
                out[m] = r.q / self._problem.film(x[m], 0.0)
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
                d = pb.film(x[m], r._sol(x[m])[0])
                out[m] = pb.V * (r.q - d) / (pb.beta * d**3)
        return out


# --------------------------------------------------------------------------
# the problem and its full-region integrator
# --------------------------------------------------------------------------
class _Piecewise:
    """Dense output of an integration split at kinks: ``self(x) -> [p, load]``."""

    def __init__(self, pieces):
        self.pieces = pieces  # list of (a, b, OdeSolution)
        self.edges = np.array([pc[0] for pc in pieces] + [pieces[-1][1]])

    def __call__(self, x):
        x = np.atleast_1d(np.asarray(x, dtype=float))
        out = np.empty((2, x.size))
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

    def __init__(self, profile, hc, V, beta, k, L, kinks, rtol, method):
        self.profile, self.hc, self.V, self.beta, self.k, self.L = profile, hc, V, beta, k, L
        self.rigid = math.isinf(k)
        self.kinks = np.array(sorted(float(c) for c in kinks if -L < c < L))
        self.rtol = rtol
        xs = np.linspace(-L, L, 4001)
        self.grid, self.h_grid = xs, hc + self._s(xs)
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
        h = self.h(x)
        return h if self.rigid else h + np.asarray(p) / self.k

    def _h1(self, x):
        return self.hc + float(self.profile(np.array([x]))[0])

    def integrate(self, q, x0, x1, rtol=None, stop=None, dense=False):
        """(5) from x0 (p = 0) toward x1 > x0 with flux film q.

        ``stop``: None, "zero" (stop where p comes down to 0) or "tangent" (stop at the
        local minimum of p after its maximum, ``d`` coming down through q).
        Returns (x_end, p_end, load_end, reason, dense) with reason "end", "zero",
        "tangent" or "closed" (the film thickness reached ~0).
        """
        rtol = self.rtol if rtol is None else rtol
        V, beta, k, rigid = self.V, self.beta, self.k, self.rigid
        pscale = V * max(x1 - x0, 1e-3) / (beta * q * q)
        atol = [rtol * 1e-3 * pscale, rtol * 1e-3 * pscale * max(x1 - x0, 1e-3)]

        def film1(x, p):
            h = self._h1(x)
            return h if rigid else h + p / k

        def f(x, y):
            d = film1(x, y[0])
            return [V * (q - d) / (beta * d**3), y[0]]

        jac = None
        if not rigid and self.method in ("Radau", "BDF"):

            def jac(x, y):
                d = film1(x, y[0])
                return [[V * (2.0 * d - 3.0 * q) / (beta * k * d**4), 0.0], [1.0, 0.0]]

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
        y = np.array([0.0, 0.0])
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
        return xe, float(y[0]), float(y[1]), reason, (_Piecewise(pieces) if dense else None)


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

    hi = float(pb.h_grid.max())
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
    xe, pe, load, reason, sol = pb.integrate(q, -L, L, rtol, dense=True)
    if reason != "end":
        raise SolverError(f"steady_full_film: the film closes at x = {xe:.4g} (the solution needs contact).")
    return [Region("full", -L, L, q, sol)], pe


def _inlet_F(pb, xr, rtol):
    """Step 2's miss: p(L) from a rupture at xr, or -(distance left) if p came back to 0 first."""
    L = pb.L
    q = pb._h1(xr)
    if q <= 0.0:
        return -1.0 - (L - xr)
    xe, pe, _, reason, _ = pb.integrate(q, xr, L, rtol, stop="zero")
    return pe if reason == "end" else -(L - xe) - (1.0 if reason == "closed" else 0.0)


def _inlet_brackets(pb):
    """Step 2's scan of x_r (cached on the problem): brackets of sign changes, inlet first."""
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
    g = pb.h(xs) - q
    span = 1e-7 * pb.L
    ok = (xs > a + span) & (xs < b - span)
    below = np.flatnonzero(ok & (g < 0.0))
    if below.size == 0:
        return None
    i = int(below[0])
    lo = xs[i - 1] if g[i - 1] >= 0.0 else a + span

    return brentq(lambda x: pb._h1(x) - q, lo, xs[i], xtol=1e-15 * pb.L, rtol=1e-15, maxiter=200)


def _march_jfo(pb, q, xr, rtol):
    """Step 3: the regions downstream of the inlet's rupture xr, with the one flux q."""
    L = pb.L
    regions, x0 = [], -L
    state = "full" if pb._h1(-L) < q else "cavity"
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
    h0 = pb._h1(-L)
    inside = pb.grid <= xr
    hmax = float(pb.h_grid[inside].max())

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
    hs = pb.h(xs)
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
        q = pb._h1(xr)
        _, _, _, _, sol = pb.integrate(q, xr, L, rtol, dense=True)
        inlet = Region("full", xr, L, q, sol)
        down = _march_jfo(pb, q, xr, rtol) if model == "jfo" else _march_reynolds(pb, q, xr, rtol)
        if down is None:
            continue
        case = "outlet-cavity" if len(down) == 1 else "reformation"
        return [*down, inlet], case, miss
    raise SolverError(
        f"steady_{model}: no rupture point found that makes a consistent solution; the profile "
        "may need a cavity at the inlet or contact, which this reference does not handle."
    )


# --------------------------------------------------------------------------
# the public functions
# --------------------------------------------------------------------------
_METHODS = ("DOP853", "Radau", "BDF", "RK45")  # LSODA: its dense output misplaces events


def _check(profile, hc, V, beta, k, L, kinks, rtol, method):
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
    if math.isinf(k) and h.min() <= 0.0:
        i = int(np.argmin(h))
        raise SceneError(
            f"rigid slider: hc + s(x) = {h[i]:g} <= 0 at x = {xs[i]:.4g}, the film is closed; use hc > "
            f"{hc - h[i]:g} or a finite Winkler stiffness k."
        )
    return profile, hc, V, beta, k, L, kinks, rtol, method


def _build(pb, model, regions, case, miss, n, x) -> dict:
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
        _problem=pb,
    )
    xs = sol["x"]
    return dataclasses.replace(shell, p=shell.pressure(xs), theta=shell.fraction(xs), d=shell.film(xs))


def _difference(a: dict, b: dict) -> dict:
    def pts(u, v):
        if len(u) != len(v):
            return math.inf
        return max((abs(s - t) for s, t in zip(u, v, strict=True)), default=0.0)

    out = {name: abs(a[name] - b[name]) for name in ("J", "load", "film_min")}
    out["rupture"] = pts(a["rupture"], b["rupture"])
    out["reformation"] = pts(a["reformation"], b["reformation"])
    return out


def _steady(model, profile, hc, V, beta, k, L, kinks, x, n, rtol, method, estimate_error):
    profile, hc, V, beta, k, L, kinks, rtol, method = _check(profile, hc, V, beta, k, L, kinks, rtol, method)
    n = check_int("n", n, 2)
    if x is not None:
        xa = np.asarray(x, dtype=float)
        if xa.ndim != 1 or not np.all(np.isfinite(xa)) or np.abs(xa).max(initial=0.0) > L:
            raise SceneError(f"x must be a 1-D array of finite points of [-L, L] = [-{L:g}, {L:g}].")
    pb = _Problem(profile, hc, V, beta, k, L, kinks, rtol, method)
    regions, case, miss = _solve(pb, model, rtol)
    sol = _build(pb, model, regions, case, miss, n, x)
    unc = {}
    if estimate_error:
        loose = min(100.0 * rtol, 1e-6)
        r2, c2, m2 = _solve(pb, model, loose)
        s2 = _build(pb, model, r2, c2, m2, n, sol["x"])
        if c2 != case:
            raise SolverError(
                f"steady_{model}: the configuration changes with the tolerance ({case} at rtol = {rtol:g}, "
                f"{c2} at {loose:g}): the problem is too close to a change of configuration."
            )
        unc = _difference(sol, s2)
        tmp = _result(pb, s2, {})
        unc["p"] = float(np.abs(tmp.pressure(sol["x"]) - _result(pb, sol, {}).pressure(sol["x"])).max())
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
) -> SteadyJFO:
    return _steady("reynolds", profile, hc, V, beta, k, L, kinks, x, n, rtol, method, estimate_error)


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
) -> SteadyJFO:
    return _steady("full-film", profile, hc, V, beta, k, L, kinks, x, n, rtol, method, estimate_error)


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
    + _COMMON
)
steady_full_film.__doc__ = (
    """Steady sliding without a cavitation condition (full Sommerfeld: p may be < 0).

    On the cylinder (``profile=None``) :func:`femehl.reference.line_steady.steady_line` presents it
    in the names of the paper's section 4.
"""
    + _COMMON
)
