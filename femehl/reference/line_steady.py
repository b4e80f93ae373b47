"""Exact steady sliding of a rigid cylinder on a Winkler foundation, full film (paper section 4).

The cylinder case (``profile=None``, no cavitation condition) of the one steady line reference,
:func:`femehl.reference.line_jfo_steady.steady_full_film`, in the names of the paper's section 4:
``d_*`` is the film thickness where p' = 0.  Derivation, method and independent checks:
docs/design.md section 17.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from femehl.errors import SolverError
from femehl.reference.line_jfo_steady import SteadyJFO, steady_full_film
from femehl.validation import check_positive

__all__ = ["steady_line", "steady_line_load", "SteadyLine"]


@dataclass(frozen=True)
class SteadyLine:
    """The steady solution, with its dense interpolant.

    Attributes
    ----------
    k, beta, hc, L, V : float
        The problem (``k = math.inf``: a rigid substrate).
    d_star : float
        Film thickness where p' = 0 (flux ``-V d_*``).
    load : float
        ``int_{-L}^{L} p dx``.
    end_error : float
        ``d(L) - (hc + L^2/2) = p(L)/k`` of the final shot (the missed boundary condition).
    solution : SteadyJFO
        The general solver's solution (``model="full-film"``, ``case="full"``).
    """

    k: float
    beta: float
    hc: float
    L: float
    V: float
    d_star: float
    load: float
    end_error: float
    solution: SteadyJFO = field(repr=False, compare=False)

    def film(self, x):
        """Film thickness d(x) = hc + x^2/2 + p/k."""
        return self.solution.film(x)

    def pressure(self, x):
        """Pressure p(x) (dense output of the integrator)."""
        return self.solution.pressure(x)


def _solve(k, beta, hc, L, V, method, rtol, x=None, n=2001) -> SteadyLine:
    s = steady_full_film(
        None, hc, V=V, beta=beta, k=k, L=L, x=x, n=n, rtol=rtol, method=method, estimate_error=False
    )
    return SteadyLine(
        k=s.k,
        beta=s.beta,
        hc=s.hc,
        L=s.L,
        V=s.V,
        d_star=-s.J / s.V,
        load=s.load,
        end_error=s.end_error / s.k,
        solution=s,
    )


def steady_line(
    k: float,
    beta: float,
    hc: float,
    L: float,
    V: float = 1.0,
    *,
    x=None,
    n: int = 2001,
    method: str | None = None,
    rtol: float = 1e-12,
    full: bool = False,
):
    """Steady sliding of a cylinder at fixed clearance ``hc``, full film (p may be < 0).

    Parameters
    ----------
    k, beta : float
        Winkler stiffness (``math.inf``: rigid) and film parameter (as in
        :class:`femehl.problem.line.LineScene`).
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
    method : {"DOP853", "Radau", "BDF", "RK45"}, optional
        Integrator of :func:`scipy.integrate.solve_ivp`; default as
        :func:`~femehl.reference.line_jfo_steady.steady_full_film` (DOP853, Radau for a film
        soft everywhere).
    rtol : float, default: 1e-12
        Relative tolerance of the integration (1e-14 to 1e-6).
    full : bool, default: False
        Return the :class:`SteadyLine` object (dense interpolant, load) instead.

    Returns
    -------
    x, d, p, d_star : ndarray, ndarray, ndarray, float
        The points, the film thickness and the pressure there, and the film thickness
        where the pressure gradient vanishes; when ``full``, the :class:`SteadyLine`
        instead.
    """
    if full:
        return _solve(k, beta, hc, L, V, method, rtol)
    xs = np.linspace(-L, L, int(n)) if x is None else np.asarray(x, dtype=float)
    sl = _solve(k, beta, hc, L, V, method, rtol, x=xs)
    return sl.solution.x, sl.solution.d, sl.solution.p, sl.d_star


def steady_line_load(
    k: float,
    beta: float,
    F: float,
    L: float,
    V: float = 1.0,
    *,
    hc_bracket=None,
    method: str | None = None,
    rtol: float = 1e-12,
) -> SteadyLine:
    """Steady sliding under an imposed load per unit length ``F``: find hc by brentq.

    The load of :func:`steady_line` decreases monotonically as hc grows; the
    default bracket is ``[-(1.5 F/k)^(2/3) - 1, L^2/4]`` (from the dry contact
    ``F = (2/3) k a^3``, ``hc = -a^2/2``, widened).  ``k`` must be finite: the full-film
    load of a rigid cylinder is 0 whatever hc.
    """
    F = check_positive("load F", F)
    k = check_positive("Winkler stiffness k", k, "A rigid cylinder's full-film load is 0 whatever hc.")
    L = check_positive("domain half length L", L)
    if hc_bracket is None:
        a = (1.5 * F / k) ** (1.0 / 3.0)
        hc_bracket = (max(-0.5 * a * a - 1.0, -0.49 * L * L), 0.25 * L * L)
    lo, hi = (float(v) for v in hc_bracket)
    last = {}

    def g(hc):
        s = _solve(k, beta, hc, L, V, method, rtol)
        last[hc] = s
        return s.load - F

    glo, ghi = g(lo), g(hi)
    if not (glo > 0.0 > ghi):
        raise SolverError(
            f"steady_line_load: F = {F:g} is not bracketed by hc in ({lo:g}, {hi:g}) "
            f"(load - F = {glo:.3g}, {ghi:.3g}); pass hc_bracket."
        )
    # the load is computed to about rtol, so hc is not worth more digits than that
    hc = brentq(g, lo, hi, xtol=max(1e-13, 10 * rtol), rtol=1e-13)
    return last[hc] if hc in last else _solve(k, beta, hc, L, V, method, rtol)
