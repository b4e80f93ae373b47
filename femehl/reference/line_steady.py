"""Exact steady sliding of a rigid cylinder on a Winkler foundation (paper section 4).

Independent of the FE solver of :mod:`femehl.problem.line`: quadrature and shooting.

Derivation
----------
At steady sliding (dd/dt = 0, V constant, hc fixed) the line-contact equation

    beta (d^3 p')' = -V d'                 d = hc + x^2/2 + p/k

integrates once to a constant flux,

    beta d^3 p' = -V (d - d_*),

with ``d_*`` the (unknown) film thickness where p' = 0.  Since
``p = k (d - hc - x^2/2)``, ``p' = k (d' - x)`` and

    d' = x - V (d - d_*) / (beta k d^3),                                  (*)

a first-order ODE for d(x) given (hc, d_*).  The two conditions
p(-L) = p(L) = 0 read ``d(+-L) = hc + L^2/2``: one fixes the start of (*),
the other fixes ``d_*`` (shooting, :func:`scipy.optimize.brentq`).  The
pressure follows as ``p = k (d - hc - x^2/2)`` and the load ``int p dx`` is
integrated as a second component of the same ODE.  Cavitation is not
modeled (p may go negative), as in the transient solver.

Direction of integration.  Linearizing (*) about a solution,
``d(delta)/dx = -V (3 d_* - 2 d) / (beta k d^4) delta``: perturbations decay
toward +x where ``d < 1.5 d_*`` (the whole contact, at rate about
``V/(beta k d_*^3)``, huge for thin films) and grow toward +x only where
``d > 1.5 d_*`` (outside the contact, at a rate at most
``V/(16 beta k d_*^3)`` over a width ``~ d_*/a``, plus ``~ 2 V/(beta k d^3)``
with d large: a modest total).  So (*) is integrated from the exit
``x = -L`` toward the inlet ``x = +L`` and ``d_*`` is tuned until
``d(L) = hc + L^2/2``; integrating the other way (from x = L inward) would
cross the contact in its exponentially unstable direction and fails for any
nontrivial case.  ``d(L)`` increases monotonically with ``d_*``.  The
integrator is stiff (LSODA by default, Radau on request) with tight
tolerances.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from femehl.errors import SceneError, SolverError
from femehl.problem.scene import check_finite, check_positive

__all__ = ["steady_line", "steady_line_load", "SteadyLine"]


@dataclass(frozen=True)
class SteadyLine:
    """The steady solution, with its dense interpolant.

    Attributes
    ----------
    k, beta, hc, L, V : float
        The problem.
    d_star : float
        Film thickness where p' = 0 (flux ``-V d_*`` per unit beta).
    load : float
        ``int_{-L}^{L} p dx``.
    end_error : float
        ``d(L) - (hc + L^2/2)`` of the final shot (the missed boundary condition).
    """

    k: float
    beta: float
    hc: float
    L: float
    V: float
    d_star: float
    load: float
    end_error: float
    _sol: object

    def film(self, x):
        """Film thickness d(x) (dense output of the integrator)."""
        return self._sol.sol(np.asarray(x, dtype=float))[0]

    def pressure(self, x):
        """Pressure p(x) = k (d - hc - x^2/2)."""
        x = np.asarray(x, dtype=float)
        return self.k * (self.film(x) - self.hc - 0.5 * x * x)


def _shoot(k, beta, hc, L, V, d_star, method, rtol, dense=False):
    c = V / (beta * k)

    def f(x, y):
        d = y[0]
        return [x - c * (d - d_star) / d**3, k * (d - hc - 0.5 * x * x)]

    def jac(x, y):
        d = y[0]
        return [[-c * (3.0 * d_star - 2.0 * d) / d**4, 0.0], [k, 0.0]]

    d0 = hc + 0.5 * L * L
    return solve_ivp(
        f,
        (-L, L),
        [d0, 0.0],
        method=method,
        jac=jac,
        rtol=rtol,
        atol=rtol * 1e-2 * min(1.0, d0),
        dense_output=dense,
    )


def _solve(k, beta, hc, L, V, method, rtol, guess=None) -> SteadyLine:
    d0 = hc + 0.5 * L * L

    def miss(ds):
        s = _shoot(k, beta, hc, L, V, ds, method, rtol)
        if s.status != 0:
            raise SolverError(f"steady_line: the integration failed for d_* = {ds:g} ({s.message}).")
        return s.y[0, -1] - d0

    # d(L) grows with d_*: d_* = d0 overshoots; halve from there until it undershoots
    if guess is not None and 0.0 < guess < d0:
        lo, hi = 0.99 * guess, min(1.01 * guess, d0)
        mlo, mhi = miss(lo), miss(hi)
        if not (mlo < 0.0 < mhi):
            guess = None
    if guess is None or not 0.0 < guess < d0:
        hi, mhi = d0, miss(d0)
        lo, mlo = 0.5 * d0, miss(0.5 * d0)
    while mlo >= 0.0 and lo > 1e-6 * d0:
        hi, mhi = lo, mlo
        lo *= 0.5
        mlo = miss(lo)
    if not (mlo < 0.0 < mhi):
        raise SolverError(
            f"steady_line: cannot bracket d_* in ({lo:.3g}, {hi:.3g}) (misses {mlo:.3g}, {mhi:.3g}); "
            "check hc and L (the film hc + x^2/2 must open toward the ends)."
        )
    ds = brentq(miss, lo, hi, xtol=1e-15 * d0, rtol=4e-15, maxiter=200)
    sol = _shoot(k, beta, hc, L, V, ds, method, rtol, dense=True)
    return SteadyLine(
        k=k,
        beta=beta,
        hc=hc,
        L=L,
        V=V,
        d_star=float(ds),
        load=float(sol.y[1, -1]),
        end_error=float(sol.y[0, -1] - d0),
        _sol=sol,
    )


def _check(k, beta, hc, L, V, method):
    k = check_positive("Winkler stiffness k", k)
    beta = check_positive("beta", beta)
    hc = check_finite("hc", hc)
    L = check_positive("domain half length L", L)
    V = check_positive(
        "sliding velocity V", V, "For V = 0 the steady film is flat: there is no sliding solution."
    )
    if hc + 0.5 * L * L <= 0.0:
        raise SceneError(
            f"hc + L^2/2 = {hc + 0.5 * L * L:g} <= 0: the film is closed at the ends; use a larger L."
        )
    if method not in ("LSODA", "Radau", "BDF"):
        raise SceneError(f"method must be 'LSODA', 'Radau' or 'BDF', got {method!r}.")
    return k, beta, hc, L, V


def steady_line(
    k: float,
    beta: float,
    hc: float,
    L: float,
    V: float = 1.0,
    *,
    x=None,
    n: int = 2001,
    method: str = "LSODA",
    rtol: float = 1e-12,
    full: bool = False,
):
    """Steady sliding of a cylinder at fixed clearance ``hc``: shoot on ``d_*``.

    Parameters
    ----------
    k, beta : float
        Winkler stiffness and film parameter (as in :class:`femehl.problem.line.LineScene`).
    hc : float
        Fixed clearance (< 0: indentation).
    L : float
        Domain half length, p(+-L) = 0.
    V : float, default: 1.0
        Sliding velocity (> 0; the cylinder moves toward +x).
    x : array_like, optional
        Where to return d and p; default ``n`` equally spaced points on [-L, L].
    n : int, default: 2001
        Number of points of the default ``x``.
    method : {"LSODA", "Radau", "BDF"}, default: "LSODA"
        Stiff integrator of :func:`scipy.integrate.solve_ivp`.
    rtol : float, default: 1e-12
        Relative tolerance of the integration.
    full : bool, default: False
        Return the :class:`SteadyLine` object (dense interpolant, load) instead.

    Returns
    -------
    x, d, p, d_star : ndarray, ndarray, ndarray, float
        The points, the film thickness and the pressure there, and the film thickness
        where the pressure gradient vanishes; when ``full``, the :class:`SteadyLine`
        instead.
    """
    k, beta, hc, L, V = _check(k, beta, hc, L, V, method)
    sl = _solve(k, beta, hc, L, V, method, rtol)
    if full:
        return sl
    xs = np.linspace(-L, L, int(n)) if x is None else np.asarray(x, dtype=float)
    return xs, sl.film(xs), sl.pressure(xs), sl.d_star


def steady_line_load(
    k: float,
    beta: float,
    F: float,
    L: float,
    V: float = 1.0,
    *,
    hc_bracket=None,
    method: str = "LSODA",
    rtol: float = 1e-12,
) -> SteadyLine:
    """Steady sliding under an imposed load per unit length ``F``: find hc by brentq.

    The load of :func:`steady_line` decreases monotonically as hc grows; the
    default bracket is ``[-(1.5 F/k)^(2/3) - 1, L^2/4]`` (from the dry contact
    ``F = (2/3) k a^3``, ``hc = -a^2/2``, widened).
    """
    F = check_positive("load F", F)
    k, beta, _, L, V = _check(k, beta, 0.0, L, V, method)
    if hc_bracket is None:
        a = (1.5 * F / k) ** (1.0 / 3.0)
        hc_bracket = (max(-0.5 * a * a - 1.0, -0.49 * L * L), 0.25 * L * L)
    lo, hi = (float(v) for v in hc_bracket)
    last = {}

    def g(hc):
        s = _solve(k, beta, hc, L, V, method, rtol, guess=last.get("d_star"))
        last["d_star"], last[hc] = s.d_star, s
        return s.load - F

    glo, ghi = g(lo), g(hi)
    if not (glo > 0.0 > ghi):
        raise SolverError(
            f"steady_line_load: F = {F:g} is not bracketed by hc in ({lo:g}, {hi:g}) "
            f"(load - F = {glo:.3g}, {ghi:.3g}); pass hc_bracket."
        )
    # the load is computed to about rtol, so hc is not worth more digits than that
    hc = brentq(g, lo, hi, xtol=max(1e-13, 10 * rtol), rtol=1e-13)
    return last[hc] if hc in last else _solve(k, beta, hc, L, V, method, rtol, guess=last["d_star"])
