"""Closed-form film of a rigid, isoviscous cylinder with the Reynolds outlet condition (Martin 1916).

In femehl's normalized line-contact units (docs/design.md, "Line contact" and section 17.1) the
rigid gap is ``d = hc + x^2/(2 R)``, the liquid is carried toward -x (inlet x = +L), and the
steady Reynolds equation integrated once is::

    beta d^3 p' = -V (d - d_*),   p(L) = 0,   p(x_c) = p'(x_c) = 0 (so d_* = d(x_c)),   p = 0 on x < x_c.

With ``x = a tan(g)``, ``a = sqrt(2 R hc)``, ``d = hc sec^2(g)`` every integral is elementary::

    p(g) = (V a / (beta hc^2 cos^2 g_c)) int_g^{g_L} cos^2 t (sin^2 t - sin^2 g_c) dt,   g_L = atan(L/a),

the outlet angle ``g_c`` in ``(-g_L, 0)`` makes that integral vanish at ``g = g_c`` (one root: the
integral increases with ``g_c``), and the load per unit length is
``W = V R (sin^2 g_L - sin^2 g_c)^2 / (2 beta hc cos^2 g_c)`` (``L = inf``: ``g_L = pi/2``,
``tan g_c = -0.47513``, ``W = 0.40791 V R/(beta hc)``).  An independent check of
:mod:`femehl.reference.line_jfo_steady`; ``tests/test_rigid_cylinder_reference.py``.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from femehl.errors import SceneError
from femehl.validation import check_positive

__all__ = ["MartinCylinder", "martin_cylinder"]

# Taylor coefficients of u - sin(u) = sum_k (-1)^(k+1) u^(2k+1)/(2k+1)!, k = 1..14: for |u| <= 2
# the first one left out, 2^31/31!, is < 1e-24, below double precision of the sums (>= u^5/150)
_SERIES = [(-1.0) ** (k + 1) / math.factorial(2 * k + 1) for k in range(1, 15)]


def _sin_defect(u, cubic=False):
    """``u - sin(u)`` (``cubic``: ``u - sin(u) - u^3/6``) without the cancellation at small ``u``."""
    u = np.asarray(u, dtype=float)
    small = np.abs(u) <= 2.0
    us = np.where(small, u, 0.0)
    u2 = us * us
    coef = _SERIES[1:] if cubic else _SERIES
    acc = np.zeros_like(us)
    for c in reversed(coef):
        acc = acc * u2 + c
    series = acc * (u2 * u2 * us if cubic else u2 * us)
    direct = u - np.sin(u) - (u**3 / 6.0 if cubic else 0.0)
    return np.where(small, series, direct)


def _s4(t):
    """``int_0^t cos^2 sin^2 = (4 t - sin 4t)/32``."""
    return _sin_defect(4.0 * np.asarray(t, dtype=float)) / 32.0


def _c2(t):
    """``int_0^t cos^2 = (2 t + sin 2t)/4``."""
    t = np.asarray(t, dtype=float)
    return 0.25 * (2.0 * t + np.sin(2.0 * t))


def _sin2(t):
    """``int_0^t sin^2 = (2 t - sin 2t)/4``."""
    return _sin_defect(2.0 * np.asarray(t, dtype=float)) / 4.0


def _sin4(t):
    """``int_0^t sin^4 = (12 t - 8 sin 2t + sin 4t)/32``, its t^3 terms cancelled exactly."""
    t = np.asarray(t, dtype=float)
    return (8.0 * _sin_defect(2.0 * t, cubic=True) - _sin_defect(4.0 * t, cubic=True)) / 32.0


def _bracket(g, gc, gL):
    """``int_g^{g_L} cos^2 t (sin^2 t - sin^2 g_c) dt``: the pressure in units of ``P0 sec^2 g_c``."""
    return (_s4(gL) - _s4(g)) - np.sin(gc) ** 2 * (_c2(gL) - _c2(g))


def _pressure_bracket(x, a, gc, L):
    """:func:`_bracket` at the points ``x``; for ``x > a`` in the angles ``u = pi/2 - g``.

    There ``cos^2 t sin^2 t`` and ``cos^2 t`` become ``sin^2 u cos^2 u`` and ``sin^2 u``, with
    ``u = atan(a/x)``, so the far upstream pressure (~ (a/x)^3) keeps its relative precision
    instead of being a difference of O(1) numbers; for ``x <= a`` the angles g are the small ones.
    """
    x = np.asarray(x, dtype=float)
    gL = 0.5 * math.pi if math.isinf(L) else math.atan(L / a)
    eL = 0.0 if math.isinf(L) else math.atan(a / L)
    e = np.arctan2(a, np.maximum(x, a))  # pi/2 - g for x > a
    far = (_s4(e) - _s4(eL)) - math.sin(gc) ** 2 * (_sin2(e) - _sin2(eL))
    near = _bracket(np.clip(np.arctan(x / a), gc, 0.25 * math.pi), gc, gL)
    return np.where(x > a, far, near)


@dataclass(frozen=True)
class MartinCylinder:
    """The rigid cylinder's Reynolds film (:func:`martin_cylinder`), in femehl's normalized units.

    Attributes
    ----------
    hc, beta, V, L, R : float
        The problem (``L = inf``: the classical infinite inlet).
    g_inlet, g_outlet : float
        The angles ``g_L = atan(L/a)`` and ``g_c`` of ``x = a tan g``, ``a = sqrt(2 R hc)``.
    load : float
        ``W = int p dx`` per unit length, closed form (see the module docstring).
    x_outlet : float
        The outlet (cavitation) point ``x_c = a tan g_c < 0``, where ``p = p' = 0``.
    d_star : float
        The film where ``p' = 0``: ``d(x_c)``; the flux is ``-V d_star``.
    p_max, x_pmax : float
        The peak pressure and where: ``x_pmax = -x_c`` (the other point where ``d = d_*``).
    poiseuille : float
        ``int (d/2) p' dx`` over the pressurized zone ``[x_c, L]`` (the Poiseuille shear); equal to
        ``-pressure_drag/2``, by parts, since ``d' = s'`` for a rigid gap.
    pressure_drag : float
        ``int p ds/dx dx = int p x/R dx`` over ``[x_c, L]`` (the pressure on the inclined cylinder).
    couette_integral : float
        ``int_{-L}^{L} dx/d = 2 g_L sqrt(2 R/hc)``; the Couette shear is ``S/(6 beta)`` times it
        (``S`` the sliding speed), and the friction force of
        :func:`femehl.solver.energetics.sliding_energetics` is
        ``S couette_integral/(6 beta) + poiseuille + pressure_drag``.
    """

    hc: float
    beta: float
    V: float
    L: float
    R: float
    g_inlet: float
    g_outlet: float
    load: float
    x_outlet: float
    d_star: float
    p_max: float
    x_pmax: float
    poiseuille: float
    pressure_drag: float
    couette_integral: float

    def film(self, x):
        """The rigid film ``d = hc + x^2/(2 R)``."""
        x = np.asarray(x, dtype=float)
        return self.hc + 0.5 * x * x / self.R

    def pressure(self, x):
        """Pressure p(x), closed form, vectorized over ``x`` in ``[-L, L]`` (0 for ``x < x_outlet``).

        Parameters
        ----------
        x : array_like
            Finite points of ``[-L, L]``.

        Returns
        -------
        ndarray or float
            ``p`` at ``x`` (a float for a scalar ``x``).
        """
        xa = np.asarray(x, dtype=float)
        if not np.all(np.isfinite(xa)) or np.any(np.abs(xa) > self.L):
            raise SceneError(
                f"x must be finite points of the domain [-L, L] = [-{self.L:g}, {self.L:g}]; "
                "evaluate the pressure inside it (it is 0 on the outlet side of x_outlet)."
            )
        a = math.sqrt(2.0 * self.R * self.hc)
        gc = self.g_outlet
        p0 = self.V * a / (self.beta * self.hc**2 * math.cos(gc) ** 2)
        p = np.where(xa > self.x_outlet, p0 * _pressure_bracket(xa, a, gc, self.L), 0.0)
        p = np.maximum(p, 0.0)  # round-off at the ends, where p ~ 1e-16 p_max
        return float(p) if p.ndim == 0 else p


def _check_number(name, value, hint):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise SceneError(f"{name} must be a real number, got {value!r} ({type(value).__name__}). {hint}")
    return float(value)


def martin_cylinder(hc: float, beta: float, V: float, L: float = np.inf, R: float = 1.0) -> MartinCylinder:
    """Steady film of a rigid cylinder on a rigid plane, Reynolds outlet condition, in closed form.

    Parameters
    ----------
    hc : float
        Clearance at the cylinder's apex (> 0: a rigid film needs a gap).
    beta : float
        Film parameter (> 0), as in :class:`femehl.problem.line.LineScene`.
    V : float
        The transport term's velocity of femehl's Reynolds equation, ``Motion.velocity``
        (twice the entrainment speed in units of V_ss; > 0: the liquid is carried toward -x,
        the inlet is ``x = +L``).
    L : float, default: inf
        Domain half length, ``p(L) = 0`` at the inlet (``inf``: the classical infinite inlet).
        Any ``L > 0`` holds the outlet, which lies in ``(-L, 0)``.
    R : float, default: 1.0
        Cylinder radius (1: femehl's normalized cylinder ``x^2/2``).

    Returns
    -------
    MartinCylinder
        Load, outlet, peak pressure, the shear-free friction figures and ``pressure(x)``.

    Raises
    ------
    SceneError
        For ``hc <= 0``, ``beta <= 0``, ``V <= 0``, ``L <= 0``, ``R <= 0`` or a non-finite value
        (``L`` may be ``inf``), with the fix in the message; :meth:`MartinCylinder.pressure` for
        points outside ``[-L, L]``.

    Notes
    -----
    The outlet angle is the one root in ``(-g_L, 0)`` of
    ``G(g) = int_g^{g_L} cos^2 t (sin^2 t - sin^2 g) dt`` (``G(-g_L) < 0 < G(0)`` and
    ``G' = -sin(2 g) int_g^{g_L} cos^2 > 0`` there), found by :func:`scipy.optimize.brentq` to
    machine precision.  Everything else is closed form: the load by parts, ``W = -int x p' dx``;
    ``pressure_drag = (1/R) int x p dx = (V a/(beta hc cos^2 g_c)) int_{g_c}^{g_L} sin^2 t (sin^2 t -
    sin^2 g_c) dt`` (by parts again) and ``poiseuille = -pressure_drag/2``.  The closed forms are
    written without cancellation of their leading terms as ``L/a -> 0`` (a nearly parallel gap),
    and hold to a few ulps of ``L/a = 1e-4`` to ``L = inf``.
    """
    hc = check_positive(
        "hc",
        hc,
        "A rigid cylinder on a rigid plane needs a gap (hc > 0); for an indentation use a deformable "
        "substrate (femehl.reference.line_jfo_steady.steady_reynolds with a finite k).",
    )
    beta = check_positive("beta", beta, "beta is the film parameter of the Reynolds equation, e.g. 1.")
    V = check_positive(
        "entrainment speed V",
        V,
        "V > 0 carries the liquid toward -x (inlet at x = +L); for the reverse direction mirror x "
        "(p(x) -> p(-x)). At V = 0 a rigid steady film carries no load.",
    )
    R = check_positive("cylinder radius R", R, "R = 1 is femehl's normalized cylinder x^2/2.")
    L = _check_number("domain half length L", L, "Pass L > 0, or L = numpy.inf for an infinite inlet.")
    if not L > 0.0:  # also NaN and -inf
        raise SceneError(
            f"domain half length L must be > 0 (or inf: an infinite inlet), got {L}: the inlet x = L "
            "must lie upstream of the outlet, which is on the -x side of the apex."
        )
    a = math.sqrt(2.0 * R * hc)
    gL = 0.5 * math.pi if math.isinf(L) else math.atan(L / a)

    def G(g):
        return float(_bracket(g, g, gL))

    gc = brentq(G, -gL, 0.0, xtol=1e-16 * gL, rtol=4.0 * np.finfo(float).eps, maxiter=200)
    sc2, cc2 = math.sin(gc) ** 2, math.cos(gc) ** 2
    p0 = V * a / (beta * hc * hc * cc2)
    load = V * R * (math.sin(gL - gc) * math.sin(gL + gc)) ** 2 / (2.0 * beta * hc * cc2)
    # int x p dx = (V/(2 beta)) int x^2 (d - d_*)/d^3 dx (by parts), in g: a^3/(hc^2 cos^2 g_c) times
    # int_{g_c}^{g_L} sin^2 t (sin^2 t - sin^2 g_c) dt, whose leading terms do not cancel as L -> 0
    drag_int = float(_sin4(gL) - _sin4(gc)) - sc2 * float(_sin2(gL) - _sin2(gc))
    pressure_drag = V * a * drag_int / (beta * hc * cc2)  # (1/R) int x p dx, a^3/R = 2 hc a
    x_c = a * math.tan(gc)
    return MartinCylinder(
        hc=hc,
        beta=beta,
        V=V,
        L=L,
        R=R,
        g_inlet=gL,
        g_outlet=gc,
        load=load,
        x_outlet=x_c,
        d_star=hc / cc2,
        p_max=p0 * float(_pressure_bracket(-x_c, a, gc, L)),
        x_pmax=-x_c,
        poiseuille=-0.5 * pressure_drag,
        pressure_drag=pressure_drag,
        couette_integral=2.0 * gL * a / hc,
    )
