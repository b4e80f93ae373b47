"""The closed-form rigid cylinder with the Reynolds outlet (femehl.reference.rigid_cylinder).

Checked against the literature constants of Martin's solution, against a direct quadrature of
the once-integrated Reynolds equation, against femehl's steady shooting reference
(femehl.reference.line_jfo_steady, rigid and nearly rigid), for its scalings and its approach to
the infinite inlet, and for its errors.  No expected value is copied from the code under test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from femehl.errors import SceneError
from femehl.reference.line_jfo_steady import steady_jfo, steady_reynolds
from femehl.reference.rigid_cylinder import martin_cylinder


def quad_ode_pressure(hc, beta, V, L, R, x_c, x):
    """p(x) = (V/beta) int_x^L (d - d(x_c))/d^3 dx' by adaptive quadrature: no substitution used.

    Split where the integrand changes sign (x = +-x_c), so each piece is one-signed.
    """

    def d(s):
        return hc + 0.5 * s * s / R

    d_star = d(x_c)
    cuts = [x, *sorted(c for c in (x_c, -x_c) if x < c < L), L]
    val = sum(
        quad(lambda s: (d(s) - d_star) / d(s) ** 3, lo, hi, epsabs=0.0, epsrel=1e-13, limit=400)[0]
        for lo, hi in zip(cuts[:-1], cuts[1:], strict=True)
    )
    return V / beta * val


# ---------------------------------------------------------------------------
# 1. the literature constants (infinite inlet)


def test_infinite_inlet_reproduces_martins_constants():
    """Martin (1916), rigid isoviscous cylinder, Reynolds (Swift-Stieber) outlet, infinite inlet.

    Literature constants (flow toward +x there; mirrored here, the outlet is on the -x side):
    outlet at ``x_c = 0.4751 sqrt(2 R h_c)`` and load per unit length ``W = 4.896 eta u R / h_c``,
    ``u = (u_a + u_b)/2`` the mean (entrainment) speed, as quoted for the rigid cylinder near a
    plane with Reynolds boundary conditions in Hamrock, Schmid & Jacobson, Fundamentals of Fluid
    Film Lubrication (2nd ed., Marcel Dekker, 2004; also their Fundamentals of Machine
    Elements); the solution is H. M. Martin's, "Lubrication of gear teeth", Engineering 102
    (1916) 119-121.

    Unit conversion.  femehl's dimensional equation (docs/design.md section 1) in the indenter's
    frame, steady and 1-D, is ``(d^3 p'/(12 eta))' = -(U/2) d'`` with U the substrate's speed:
    only one surface moves, so the mean speed is ``u = U/2``.  Integrated once,
    ``d^3 p' = -6 eta U (d - d_*) = -12 eta u (d - d_*)``: the common form
    ``dp/dx = 6 eta U (h - h_*)/h^3`` holds with U the SUM of the surface speeds (here the
    sliding speed); with the mean speed the factor is 12.  Normalizing (section 2: x by
    l = sqrt(R h_inf), d by h_inf, p by p0 = 4 pi G sqrt(h_inf/R), V = U/V_ss,
    beta = (2/3)(h_inf^2/R)(pi G)/(eta V_ss)) gives
    ``d^3 p' = -(6 eta U l/(p0 h_inf^2)) (d - d_*) = -(3 eta U R/(2 pi G h_inf^2)) (d - d_*)
    = -(V/beta) (d - d_*)``.  So the one coefficient of the equation is ``12 eta u`` in
    dimensional and ``V/beta`` in normalized units; the load is linear in it, hence
    ``W = C eta u R/h_c`` (dimensional) is ``W = (C/12) (V/beta) R/h_c`` (normalized, in units
    of ``p0 l``, with R and h_c normalized), and the literature's C is ``12 beta h_c W/(V R)``.
    """
    hc, beta, V, R = 0.02, 3.0, 0.7, 1.0  # arbitrary: the constants do not depend on them
    m = martin_cylinder(hc, beta, V, L=np.inf, R=R)
    a = math.sqrt(2.0 * R * hc)
    # the outlet: the literature quotes 4 decimals, so half a unit of the last one
    assert abs(m.x_outlet / a - (-0.4751)) <= 0.5e-4
    # the load: 12 beta hc W/(V R) = 6 cos^2 g_c = 4.89497 here (4.89508 with the rounded
    # tan g_c = 0.4751), while the source prints 4.896: one unit of its last digit above the
    # correctly rounded 4.895, a rounding in the source; so the tolerance is 1.5 units of the last
    # printed digit (3e-4 relative)
    C = 12.0 * beta * hc * m.load / (V * R)
    assert abs(C - 4.896) <= 1.5e-3
    # and the outlet is where p = p' = 0: the defining equation by direct quadrature of the
    # unsubstituted integral over [x_c, inf) (quad at epsrel 1e-13 on one-signed pieces of size
    # ~p_max; measured 7e-16 p_max), tolerance 1e-12 p_max
    assert abs(quad_ode_pressure(hc, beta, V, np.inf, R, m.x_outlet, m.x_outlet)) <= 1e-12 * m.p_max


# ---------------------------------------------------------------------------
# the closed forms against a direct quadrature of the ODE (no substitution)


@pytest.mark.parametrize(
    "hc, beta, V, L, R",
    [(0.1, 1.0, 1.0, 2.0, 1.0), (0.01, 3.0, 2.0, 1.5, 2.0), (0.05, 0.5, 1.0, np.inf, 0.7)],
)
def test_closed_forms_against_quadrature(hc, beta, V, L, R):
    m = martin_cylinder(hc, beta, V, L=L, R=R)
    assert -L < m.x_outlet < 0.0 < m.x_pmax < L
    # the quadratures run at epsrel 1e-13 on one-signed pieces (measured agreement <= 7e-16);
    # the tolerances are 1e-12 of the scale, 10 times the quadrature's own
    xs = np.concatenate([np.linspace(m.x_outlet, 3 * m.x_pmax, 9), [m.x_pmax]])
    p_quad = np.array([quad_ode_pressure(hc, beta, V, L, R, m.x_outlet, x) for x in xs])
    assert np.abs(m.pressure(xs) - p_quad).max() <= 1e-12 * m.p_max
    assert p_quad.max() == pytest.approx(m.p_max, rel=1e-12)  # the peak is at x_pmax
    # d_* = d(x_c), p = 0 downstream of the outlet
    assert m.d_star == pytest.approx(hc + 0.5 * m.x_outlet**2 / R, rel=1e-14)
    x_cav = np.linspace(-min(L, 5.0), m.x_outlet, 7)
    assert np.all(m.pressure(x_cav) == 0.0)

    def d(x):
        return hc + 0.5 * x * x / R

    def dp(x):
        return -V / beta * (d(x) - m.d_star) / d(x) ** 3

    def integral(f, lo, hi):
        return quad(f, lo, hi, epsabs=0.0, epsrel=1e-13, limit=400)[0]

    # the load, the pressure drag and the Poiseuille shear by quadrature of p and p' (split at the
    # peak and, for an infinite inlet, at 10 a and 1000 a, a = sqrt(2 R hc))
    a = math.sqrt(2.0 * R * hc)
    cuts = [m.x_outlet, m.x_pmax, *([10.0 * a, 1e3 * a] if math.isinf(L) else [L])]
    pieces = list(zip(cuts[:-1], cuts[1:], strict=True))
    load = sum(integral(m.pressure, lo, hi) for lo, hi in pieces) + (
        integral(m.pressure, cuts[-1], L) if math.isinf(L) else 0.0
    )
    assert load == pytest.approx(m.load, rel=1e-12)
    drag = sum(integral(lambda x: m.pressure(x) * x / R, lo, hi) for lo, hi in pieces)
    poiseuille = sum(integral(lambda x: 0.5 * d(x) * dp(x), lo, hi) for lo, hi in pieces)
    tol = 1e-12
    if math.isinf(L):
        # past x_e = 1000 a, p = 4 V R^2/(3 beta x^3) (1 + O(a^2/x^2)) and (d/2) p' = -V R/(beta x^2)
        # (1 + O(a^2/x^2)): the tails 4 V R/(3 beta x_e) and -V R/(beta x_e), ~1e-3 of the totals,
        # are added; their own error, 1e-6 of them, sets the tolerance 1e-8
        drag += 4.0 * V * R / (3.0 * beta * cuts[-1])
        poiseuille -= V * R / (beta * cuts[-1])
        tol = 1e-8
    assert drag == pytest.approx(m.pressure_drag, rel=tol)
    assert poiseuille == pytest.approx(m.poiseuille, rel=tol)
    assert m.poiseuille == pytest.approx(-0.5 * m.pressure_drag, rel=1e-14)
    # Couette: int_{-L}^{L} dx/d
    assert 2.0 * integral(lambda x: 1.0 / d(x), 0.0, L) == pytest.approx(m.couette_integral, rel=1e-12)


# ---------------------------------------------------------------------------
# 2. femehl's steady shooting reference


@pytest.mark.parametrize("model", ["reynolds", "jfo"])
@pytest.mark.parametrize("hc, beta, V, L, R", [(0.1, 1.0, 1.0, 2.0, 1.0), (0.05, 3.0, 2.0, 1.5, 1.3)])
def test_against_rigid_shooting_reference(model, hc, beta, V, L, R):
    """The rigid film (k = inf) of line_jfo_steady, which solves the same equation by shooting.

    Its Reynolds solution is the comparison; its JFO one too: with a flooded inlet and the only
    cavity open to the outlet, the rupture condition p = p' = 0 is the same and no reformation
    occurs, so JFO and Reynolds coincide (design.md 17.5, "outlet-cavity").  The reference
    bounds its own error by ``uncertainty`` (the change at a 100 times looser rtol); the closed
    form is exact to a few ulps, so the difference must be within that bound (plus 1e-13 of the
    scale, for round-off when the bound is tiny).
    """
    solve = steady_reynolds if model == "reynolds" else steady_jfo
    profile = None if R == 1.0 else (lambda x: 0.5 * x * x / R)
    s = solve(profile, hc, V=V, beta=beta, L=L)
    m = martin_cylinder(hc, beta, V, L=L, R=R)
    u = s.uncertainty
    assert s.case == "outlet-cavity" and len(s.rupture) == 1 and s.reformation == ()
    assert abs(s.load - m.load) <= u["load"] + 1e-13 * m.load
    assert abs(s.rupture[0] - m.x_outlet) <= u["rupture"] + 1e-13 * L
    assert abs(-s.J / V - m.d_star) <= u["J"] / V + 1e-13 * m.d_star
    x = np.linspace(-L, L, 801)
    assert np.abs(s.pressure(x) - m.pressure(x)).max() <= u["p"] + 1e-13 * m.p_max


def test_against_nearly_rigid_winkler_reference():
    """A Winkler foundation of large k: the closed form within the deflection's first-order effect.

    The deflection p/k changes the film by at most ``eps = p_max/(k hc)`` relative; p, d_* and
    the outlet respond linearly through the ``d^-2, d^-3`` of the equation, so each differs by
    at most ~3 eps (relative; p of p_max).  Measured (hc = 0.1, beta = 1, L = 2: eps = 5.5e-5 at
    k = 1e6): load 0.044 eps, d_* 0.53 eps, outlet 1.5 eps, p 1.1 eps.  The difference is first
    order in 1/k: from k = 1e5 to 1e6 it falls 10-fold (measured 9.91 to 10.00; the O(1/k^2)
    term is ~16 eps of it, <= 1%), checked within [9, 11].
    """
    hc, beta, V, L = 0.1, 1.0, 1.0, 2.0
    m = martin_cylinder(hc, beta, V, L=L)
    x = np.linspace(-L, L, 801)
    errs = {}
    for k in (1e5, 1e6):
        s = steady_reynolds(None, hc, V=V, beta=beta, k=k, L=L, estimate_error=False)
        eps = m.p_max / (k * hc)
        e = {
            "load": abs(s.load - m.load) / m.load,
            "d_star": abs(-s.J / V - m.d_star) / m.d_star,
            "outlet": abs(s.rupture[0] - m.x_outlet) / abs(m.x_outlet),
            "p": np.abs(s.pressure(x) - m.pressure(x)).max() / m.p_max,
        }
        for name, v in e.items():
            assert v <= 3.0 * eps, (k, name, v / eps)
        errs[k] = e
    for name in errs[1e5]:
        assert 9.0 <= errs[1e5][name] / errs[1e6][name] <= 11.0, name


# ---------------------------------------------------------------------------
# 3. scalings and the approach to the infinite inlet


def test_scalings_of_the_infinite_inlet():
    """W ~ (V/beta) R/hc, x_c ~ sqrt(R hc), p_max ~ (V/beta) sqrt(R) hc^(-3/2) (infinite inlet).

    With x = a tan g the infinite-inlet outlet angle is a pure number, so these hold exactly;
    the tolerance 1e-13 is a few hundred ulps (brentq to 4 eps in g_c, then closed forms).
    """
    base = martin_cylinder(0.1, 1.0, 1.0)
    for hc, beta, V, R in [
        (1e-3, 1.0, 1.0, 1.0),
        (10.0, 1.0, 1.0, 1.0),
        (0.1, 7.0, 0.3, 1.0),
        (0.2, 2.0, 3.0, 4.0),
    ]:
        m = martin_cylinder(hc, beta, V, R=R)
        c = (V / beta) * R / (hc / 0.1)
        assert m.load == pytest.approx(base.load * c, rel=1e-13)
        assert m.x_outlet == pytest.approx(base.x_outlet * math.sqrt(R * hc / 0.1), rel=1e-13)
        assert m.p_max == pytest.approx(
            base.p_max * (V / beta) * math.sqrt(R) * (hc / 0.1) ** -1.5, rel=1e-13
        )
        # the dimensionless load does not depend on the parameters at all
        assert beta * hc * m.load / (V * R) == pytest.approx(0.1 * base.load, rel=1e-13)


def test_finite_inlet_approaches_the_infinite_one():
    """The finite-L defects, derived from the closed form with eps = pi/2 - g_L ~ a/L.

    cos^2 g_L = a^2/(L^2 + a^2) enters the load directly, while the outlet angle moves only by
    O(eps^3) (the inlet's missing part of the outlet equation is cos^2 g_c eps^3/3 + O(eps^5)).
    So, with a = sqrt(2 R hc) and G(g) = int_g^{pi/2} cos^2 t (sin^2 t - sin^2 g) dt:

    * load: W_inf - W_L = 2 V R^2/(beta (L^2 + a^2)) + O(L^-3), an L^-2 law independent of hc:
      the inlet pressure defect p_inf(L) ~ 4 V R^2/(3 beta L^3) lost over the domain's length L,
      plus the tail int_L^inf p_inf = 2 V R^2/(3 beta L^2);
    * outlet: x_c(L) - x_c(inf) = a^4/(3 G'(g_c) L^3) + O(L^-5), G'(g) = -sin 2g int_g^{pi/2} cos^2;
    * peak pressure: p_max(inf) - p_max(L) ~ L^-3.
    """
    hc, beta, V, R = 0.1, 2.0, 1.5, 1.3
    a = math.sqrt(2.0 * R * hc)
    m_inf = martin_cylinder(hc, beta, V, R=R)
    gc = math.atan(m_inf.x_outlet / a)
    G1 = -math.sin(2.0 * gc) * (math.pi / 4.0 - (2.0 * gc + math.sin(2.0 * gc)) / 4.0)
    rest, p_def = {}, {}
    for L in (16.0, 32.0, 64.0):
        m = martin_cylinder(hc, beta, V, L=L, R=R)
        lead = 2.0 * V * R**2 / (beta * (L * L + a * a))
        dW = m_inf.load - m.load
        # the leading term: relative remainder O(a/L) (measured 0.12 to 0.13 a/L)
        assert dW / lead == pytest.approx(1.0, abs=0.2 * a / L)
        rest[L] = dW - lead
        # the outlet: relative remainder O((a/L)^2) (measured 1.6 to 1.9 (a/L)^2)
        assert (m.x_outlet - m_inf.x_outlet) * L**3 / a**4 == pytest.approx(
            1.0 / (3.0 * G1), rel=3.0 * (a / L) ** 2
        )
        p_def[L] = m_inf.p_max - m.p_max
    # the load's remainder and the peak's defect fall as L^-3: 8-fold per doubling of L, to
    # within their own O(a/L) relative corrections (measured 8.6 and 8.3; 7.97 and 7.99)
    for L in (16.0, 32.0):
        assert 7.0 <= rest[L] / rest[2 * L] <= 9.5
        assert 7.5 <= p_def[L] / p_def[2 * L] <= 8.5


# ---------------------------------------------------------------------------
# 4. bad input


@pytest.mark.parametrize(
    "kwargs, fix",
    [
        ({"hc": 0.0}, "needs a gap"),
        ({"hc": -0.1}, "needs a gap"),
        ({"hc": math.nan}, "needs a gap"),
        ({"beta": 0.0}, "film parameter"),
        ({"beta": -1.0}, "film parameter"),
        ({"V": 0.0}, "carries the liquid toward -x"),
        ({"V": -1.0}, "mirror x"),
        ({"V": math.inf}, "carries the liquid toward -x"),
        ({"V": math.nan}, "carries the liquid toward -x"),
        ({"L": 0.0}, "must be > 0"),
        ({"L": -2.0}, "must be > 0"),
        ({"L": -math.inf}, "must be > 0"),
        ({"L": math.nan}, "must be > 0"),
        ({"L": "2"}, "numpy.inf"),
        ({"R": 0.0}, "normalized cylinder"),
        ({"hc": True}, "needs a gap"),
    ],
)
def test_bad_input_names_the_fix(kwargs, fix):
    args = {"hc": 0.1, "beta": 1.0, "V": 1.0, "L": 2.0, "R": 1.0} | kwargs
    with pytest.raises(SceneError, match=fix):
        martin_cylinder(**args)


def test_pressure_outside_the_domain_is_refused():
    m = martin_cylinder(0.1, 1.0, 1.0, L=2.0)
    assert m.pressure(2.0) == pytest.approx(0.0, abs=1e-15 * m.p_max)  # the inlet, p(L) = 0
    for x in (2.5, [-3.0, 0.0], math.nan):
        with pytest.raises(SceneError, match=r"\[-L, L\]"):
            m.pressure(x)
