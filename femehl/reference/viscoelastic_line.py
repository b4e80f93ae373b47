"""Steady rolling and sliding of a rigid cylinder on a standard-linear-solid Winkler foundation.

Independent of femehl's time stepping: the steady equations are solved directly as a
two-point boundary value problem by collocation (:func:`scipy.integrate.solve_bvp`).

At a steady state (V, SRR, hc constant) the line contact of :mod:`femehl.problem.line` on the
foundation ``Viscoelastic(G0, tau, G_inf, elastic=Winkler(k))`` has the film
``d = hc + x^2/2 + J0 p/k + q``; the Reynolds equation integrates once to a constant
flux (as in :mod:`femehl.reference.line_steady`) and the creep's memory equation
``tau_c Dq/Dt = dJ p/k - q`` with ``D/Dt = -2 U_s d/dx`` (the material moves at ``-2 U_s``,
``U_s = V (1 + SRR/2)/2`` the substrate surface's speed, :meth:`femehl.Motion.surface_speeds`)
is an ODE along x::

    beta d^3 p' = -V (d - d_*),        -2 U_s tau_c q' = dJ p/k - q,    dJ = J_inf - J0,
    p(-L) = p(L) = 0,   q(L) = 0  (the material enters at x = L unloaded, with no creep),

with ``d_*`` (the film where p' = 0) a free parameter: three conditions for two first
order equations and one parameter.  The solution is continued in ``dJ`` from the elastic
one of :mod:`femehl.reference.line_steady` (compliance J0).  Energetics (:mod:`femehl.solver.energetics`,
per unit length, ``W = -(J0 p/k + q)``, ``S = U_s - U_i = V SRR/2`` the sliding speed)::

    f = int [S/(6 beta d) - (W + d/2) p'] dx,   D_film = int [S^2/(6 beta d) + (beta/2) d^3 p'^2] dx,
    P_sliding = -U_s int W p' dx,   f U_s - T U_i = D_film + P_sliding,

with ``T = int [S/(6 beta d) + (d/2) p'] dx`` the shear force on the cylinder's surface.
In pure rolling (SRR = 0) ``f`` is the rolling resistance.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femehl.errors import SceneError, SolverError

__all__ = ["SteadyViscoelasticLine", "steady_viscoelastic_line"]


@dataclass(frozen=True)
class SteadyViscoelasticLine:
    """The steady solution: headline figures and its fields on ``x``."""

    load: float
    film_center: float
    film_min: float
    friction: float
    shear_indenter: float
    dissipation_film: float
    power_sliding: float
    d_star: float
    x: np.ndarray
    p: np.ndarray
    q: np.ndarray
    d: np.ndarray


def steady_viscoelastic_line(
    k: float,
    beta: float,
    hc: float,
    L: float,
    V: float,
    solid,
    *,
    slide_roll: float = 2.0,
    tol: float = 1e-8,
    steps: int = 4,
) -> SteadyViscoelasticLine:
    """Steady state at velocity ``V``, slide-to-roll ratio ``slide_roll`` and clearance ``hc``
    on ``solid`` (a :class:`femehl.Viscoelastic`, its elastic part taken as ``Winkler(k)``) on
    ``[-L, L]``; ``slide_roll = 2`` is the paper's pure sliding, 0 pure rolling.

    ``tol`` is solve_bvp's residual tolerance, ``steps`` the continuation steps in dJ.
    """
    from scipy.integrate import solve_bvp

    from femehl.reference.line_steady import steady_line

    if not V > 0.0:
        raise SceneError(f"the steady reference needs V > 0, got {V!r}.")
    if not (np.isfinite(slide_roll) and slide_roll > -2.0):
        raise SceneError(
            f"the steady reference needs the substrate's surface moving toward -x (slide_roll > -2, "
            f"its material entering at x = L), got slide_roll = {slide_roll!r}."
        )
    Ui, Us = 0.5 * V * (1.0 - 0.5 * slide_roll), 0.5 * V * (1.0 + 0.5 * slide_roll)
    S = Us - Ui
    J0, dJ_end, tc = solid.J0, solid.J_inf - solid.J0, solid.tau_creep
    el = steady_line(k / J0, beta, hc, L, V, full=True)
    x = np.linspace(-L, L, 2001)
    y, par = np.vstack([el.pressure(x), np.zeros_like(x)]), np.array([el.d_star])
    sol = None
    for dJ in np.linspace(0.0, dJ_end, steps + 1)[1:] if dJ_end > 0.0 else [0.0]:

        def rhs(x, y, par, dJ=dJ):
            d = hc + 0.5 * x * x + J0 * y[0] / k + y[1]
            return np.vstack([-V * (d - par[0]) / (beta * d**3), (y[1] - dJ * y[0] / k) / (2.0 * Us * tc)])

        def bc(ya, yb, par):
            return np.array([ya[0], yb[0], yb[1]])

        sol = solve_bvp(rhs, bc, x, y, p=par, tol=tol, max_nodes=500_000)
        if sol.status != 0:
            raise SolverError(f"steady viscoelastic line: solve_bvp failed at dJ = {dJ:g} ({sol.message})")
        x, y, par = sol.x, sol.y, sol.p
    xs = np.union1d(np.linspace(-L, L, 20001), sol.x)
    p, q = sol.sol(xs)
    d = hc + 0.5 * xs**2 + J0 * p / k + q
    dp = -V * (d - sol.p[0]) / (beta * d**3)
    W = -(J0 * p / k + q)

    def integral(f):
        return float(np.trapezoid(f, xs))

    return SteadyViscoelasticLine(
        load=integral(p),
        film_center=float(hc + J0 * sol.sol(0.0)[0] / k + sol.sol(0.0)[1]),
        film_min=float(d.min()),
        friction=integral(S / (6.0 * beta * d) - (W + 0.5 * d) * dp),
        shear_indenter=integral(S / (6.0 * beta * d) + 0.5 * d * dp),
        dissipation_film=integral(S * S / (6.0 * beta * d) + 0.5 * beta * d**3 * dp * dp),
        power_sliding=-Us * integral(W * dp),
        d_star=float(sol.p[0]),
        x=xs,
        p=p,
        q=q,
        d=d,
    )
