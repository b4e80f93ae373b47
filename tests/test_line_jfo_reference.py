"""The exact steady line reference (femehl.reference.line_jfo_steady; its cylinder case
femehl.reference.line_steady).

Each test can fail: the conditions (3)-(7) of docs/design.md section 17 are checked on the
returned solution by finite differences, and the full film against closed forms: the rigid
slider (linear and cylinder), and the two-term expansions of the Winkler cylinder in its stiff
and soft limits (design.md section 17.6).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from femehl.errors import SceneError
from femehl.reference.line_jfo_steady import pocket_slider, steady_full_film, steady_jfo, steady_reynolds
from femehl.reference.line_steady import steady_line

K, BETA, HC = 1.0, 10.0, -0.5  # the Winkler cylinder of tests/test_line.py
POCKET, POCKET_KINKS = pocket_slider()  # depth 0.3, width 1, center -1; ramp from x = 1


@pytest.fixture(scope="module")
def sols():
    """The reference configurations (docs/design.md section 17.5)."""
    out = {
        "b-winkler": steady_jfo(None, HC, beta=BETA, k=K),
        "b-rigid": steady_jfo(None, 0.1, beta=1.0),
        "c-rigid": steady_jfo(POCKET, 0.1, beta=1.0, kinks=POCKET_KINKS),
        "c-winkler": steady_jfo(POCKET, 0.1, beta=10.0, k=100.0, kinks=POCKET_KINKS),
    }
    out["c-rigid-reynolds"] = steady_reynolds(POCKET, 0.1, beta=1.0, kinks=POCKET_KINKS)
    return out


def dp(sol, x, h):
    """p'(x) by fourth-order central differences of the dense pressure."""
    p = sol.pressure
    return (p(x - 2 * h) - 8 * p(x - h) + 8 * p(x + h) - p(x + 2 * h)) / (12 * h)


def dp_side(sol, x0, h):
    """p'(x0) by a second-order one-sided difference (h < 0: from the left)."""
    p = sol.pressure
    x = np.array([x0, x0 + h, x0 + 2 * h])
    v = p(x)
    return (-3 * v[0] + 4 * v[1] - v[2]) / (2 * h)


def full_points(sol, h, n=400):
    """Points inside the full regions, at least 5 h from their ends and from the kinks."""
    kinks = np.asarray(POCKET_KINKS)
    pts = []
    for r in sol.regions:
        if r.kind == "full":
            x = np.linspace(r.a + 5 * h, r.b - 5 * h, n)
            pts.append(x[np.min(np.abs(x[:, None] - kinks[None, :]), axis=1) > 5 * h])
    return np.concatenate(pts)


# ---------------------------------------------------------------------------
# the conditions, on every reference configuration


@pytest.mark.parametrize("name", ["b-winkler", "b-rigid", "c-rigid", "c-winkler"])
def test_jfo_conditions_hold(sols, name):
    s = sols[name]
    assert s.model == "jfo"
    assert s.case == ("outlet-cavity" if name.startswith("b") else "reformation")
    pmax = s.p.max()
    # complementarity (3)
    assert s.p.min() >= -1e-12 * pmax
    assert np.all((s.theta >= 0.0) & (s.theta <= 1.0))
    assert np.all(s.theta[s.p > 1e-9 * pmax] == 1.0)
    assert np.all(s.p[s.theta < 1.0] == 0.0)
    assert s.theta.min() < 0.9  # a real cavity
    # one flux (4) everywhere: in the full regions by finite differences of the returned p
    h = 2e-4
    x = full_points(s, h)
    d = s.film(x)
    flux = -s.beta * d**3 * dp(s, x, h) - s.V * d
    assert np.abs(flux / s.J - 1.0).max() < 1e-8
    assert np.allclose(s.pressure_gradient(x), dp(s, x, h), rtol=0, atol=1e-7 * np.abs(dp(s, x, h)).max())
    # ... and in the cavities the carried content
    cav = s.theta < 1.0
    assert np.allclose(-s.V * s.theta[cav] * s.d[cav], s.J, rtol=1e-13, atol=0)
    assert all(f == s.J for f in s.fluxes) and s.mass_source == 0.0
    # rupture (6): p = 0, p' = 0 from the full side
    dpmax = np.abs(s.pressure_gradient(s.x)).max()
    for xr in s.rupture:
        assert abs(s.pressure(np.array([xr]))[0]) < 1e-10 * pmax
        assert abs(dp_side(s, xr, 2e-5)) < 1e-6 * dpmax
        assert s.film(np.array([xr]))[0] == pytest.approx(-s.J / s.V, rel=1e-12)
    # reformation (7): p = 0, flux continuous, p' != 0 and theta jumps to 1
    for xf in s.reformation:
        assert abs(s.pressure(np.array([xf]))[0]) < 1e-10 * pmax
        df = s.film(np.array([xf]))[0]
        g = dp_side(s, xf, -1e-4)  # from the full side, x < x_f
        c_cav = s.fraction(np.array([xf + 1e-9]))[0] * df
        assert abs((-s.beta * df**3 * g - s.V * df) - (-s.V * c_cav)) < 1e-6 * abs(s.J)
        assert abs(g) > 0.05 * dpmax
        assert c_cav / df < 0.9
    # the ends, the load, the numerical uncertainty
    assert s.p[0] == 0.0 and abs(s.p[-1]) < 1e-10 * pmax
    assert s.load == pytest.approx(np.trapezoid(s.p, s.x), rel=1e-5)
    assert s.film_min == pytest.approx(s.d.min(), abs=1e-6) and s.film_min <= s.d.min()
    assert s.uncertainty["J"] < 1e-10 * abs(s.J) and s.uncertainty["load"] < 1e-8 * s.load
    assert s.uncertainty["p"] < 1e-8 * pmax


# ---------------------------------------------------------------------------
# (a) no cavitation: closed forms, the two limits of the Winkler cylinder, one flux


def test_rigid_linear_slider_is_the_closed_form():
    V, beta, m, ho = 2.0, 3.0, 0.1, 0.1
    hi = ho + 4 * m
    for fn in (steady_jfo, steady_reynolds):
        s = fn(lambda x: m * (x + 2.0), ho, V=V, beta=beta)
        assert s.case == "full" and s.rupture == () and s.reformation == ()
        q = 2 * ho * hi / (ho + hi)
        assert s.J == pytest.approx(-V * q, rel=1e-12)
        d = ho + m * (s.x + 2.0)
        p = V / (beta * m) * (0.5 * q * (1 / ho**2 - 1 / d**2) - (1 / ho - 1 / d))
        assert np.abs(s.p - p).max() < 1e-10 * p.max()
        W = V / (beta * m * m) * (math.log(hi / ho) - 2 * (hi - ho) / (hi + ho))
        assert s.load == pytest.approx(W, rel=1e-10)
        assert np.all(s.theta == 1.0) and s.film_min == pytest.approx(ho, rel=1e-12)


def rigid_cylinder(hc, beta, L, V=1.0):
    """Full Sommerfeld under the rigid cylinder h = hc + x^2/2 (hc > 0) on [-L, L], closed form.

    ``p' = V (q - h)/(beta h^3)``, so ``p = (V/beta) (q I3 - I2)`` with ``I_n = int_{-L}^x h^-n``
    (elementary with x = sqrt(2 hc) u) and ``q = I2(L)/I3(L)`` from p(L) = 0.  Returns q, p, p'.
    """
    c = math.sqrt(2.0 * hc)

    def F2(u):
        return 0.5 * (u / (1 + u * u) + np.arctan(u))

    def F3(u):
        return u / (4 * (1 + u * u) ** 2) + 3 * u / (8 * (1 + u * u)) + 0.375 * np.arctan(u)

    def I2(x):
        return c / hc**2 * (F2(np.asarray(x) / c) - F2(-L / c))

    def I3(x):
        return c / hc**3 * (F3(np.asarray(x) / c) - F3(-L / c))

    q = float(I2(L) / I3(L))

    def p(x):
        return V / beta * (q * I3(x) - I2(x))

    def dp(x):
        h = hc + 0.5 * np.asarray(x) ** 2
        return V * (q - h) / (beta * h**3)

    return q, p, dp


def test_rigid_cylinder_is_the_closed_form():
    # measured (DOP853, rtol 1e-12): q to 2.6e-14, p to 7.7e-12, 8.3e-12 and 1.1e-11 of its peak
    # (within the solution's own uncertainty estimate, 1.7e-10 to 5.7e-10), the load (0: p is
    # odd) to 3.5e-14 p_max L; tolerances 1e-12, 3e-11 (about 3x) and 1e-12
    for hc, beta, L in ((0.1, 1.0, 2.0), (0.01, 1.0, 2.0), (0.001, 0.1, 3.0)):
        q, p, _ = rigid_cylinder(hc, beta, L)
        s = steady_full_film(None, hc, beta=beta, L=L)
        assert s.case == "full" and s.k == math.inf
        assert -s.J == pytest.approx(q, rel=1e-12)
        pe = p(s.x)
        err = np.abs(s.p - pe).max()
        assert err < 3e-11 * pe.max() and err < s.uncertainty["p"]
        assert abs(s.load) < 1e-12 * pe.max() * L
        assert s.p.min() < -0.5 * pe.max()  # full Sommerfeld: the antisymmetric exit lobe


def test_friction_of_the_rigid_cylinder_is_martins():
    """:meth:`SteadyJFO.friction` (quadrature over the shot solution) against Martin's closed
    form (:mod:`femehl.reference.rigid_cylinder`) of the rigid cylinder under the Reynolds
    condition: measured Couette to 2e-16, Poiseuille 2.6e-14, pressure drag 7.7e-12 (the
    shot pressure's own error); tolerance 1e-10."""
    from femehl.reference.rigid_cylinder import martin_cylinder

    for hc, beta, V in ((0.05, 10.0, 1.0), (0.01, 1.0, 0.5)):
        f = steady_reynolds(None, hc, V, beta, math.inf, 2.0).friction()
        m = martin_cylinder(hc, beta, V, 2.0)
        assert f["shear_couette"] == pytest.approx(V * m.couette_integral / (6.0 * beta), rel=1e-10)
        assert f["shear_poiseuille"] == pytest.approx(m.poiseuille, rel=1e-10)
        assert f["pressure_drag"] == pytest.approx(m.pressure_drag, rel=1e-10)
        assert f["friction"] == pytest.approx(f["shear_couette"] + m.poiseuille + m.pressure_drag, rel=1e-10)


def test_stiff_winkler_cylinder_is_the_rigid_one_plus_its_first_correction():
    """k -> inf with hc > 0: p = p0 + p1/k + ..., q = q0 + q1/k + ... with the closed-form rigid p0
    and q0.  The O(1/k) equation ``beta (h^3 p1' + 3 h^2 p0 p0') = V (q1 - p0)`` and p1(+-L) = 0
    give q1 = 0 and the load ``int p1 = int x [V p0/(beta h^3) + 3 p0 p0'/h] dx = W1`` (parts;
    p0 is odd, h even), a quadrature of closed forms.  The next terms vanish by the same parity,
    so d_* - q0 and k load - W1 are O(1/k^2): measured 4.03e-5 and 1.63e-4 (relative) at k = 1e4,
    4.03e-7 and 1.63e-6 at k = 1e5.  Tolerances: 1.5x the measured values at k = 1e4, and the
    ratio of the two within 100 x [0.7, 1.4] (the order; the shooting's own error is < 1e-11)."""
    hc, beta, L = 0.1, 1.0, 2.0
    q0, p0, dp0 = rigid_cylinder(hc, beta, L)

    def integrand(x):
        h = hc + 0.5 * x * x
        return x * (p0(x) / (beta * h**3) + 3 * p0(x) * dp0(x) / h)

    W1 = 2.0 * quad(integrand, 0.0, L, epsabs=0.0, epsrel=1e-13, limit=200)[0]  # even integrand
    err = {}
    for k in (1e4, 1e5):
        s = steady_line(k, beta, hc, L, full=True)
        err[k] = (abs(s.d_star / q0 - 1.0), abs(k * s.load / W1 - 1.0))
    assert err[1e4][0] < 6e-5 and err[1e4][1] < 2.5e-4, err
    for i in (0, 1):
        assert 70.0 < err[1e4][i] / err[1e5][i] < 140.0, err


def test_soft_winkler_cylinder_is_the_flat_film_expansion():
    """eps = beta k / V -> 0: d' = x - (d - d_*)/(eps d^3) makes the film flat, d -> d0 = hc + L^2/2
    (p -> k (L^2 - x^2)/2).  The outer expansion ``d = d_* + eps d^3 (x - d')``, d(L) = d0 and the
    boundary layer at -L (width eps d0^3, where d drops from d0 to the outer film) give
        d_* = d0 - eps L d0^3 + eps^2 d0^6 + O(eps^3),
        load = k [2 L^3/3 - 2 eps L^2 d0^3 + 2 eps^2 (L d0^6 + L^3 d0^5)] + O(eps^3)
    (design.md section 17.6).  Measured (k = 1, hc = -0.5, L = 2): d_* off by 1.55e-7, the load
    by 5.0e-7 (relative) at eps = 1e-3, 1.54e-10 and 5.1e-10 at 1e-4.  Tolerances: 2x the
    values at 1e-3, and the ratio within 1000 x [0.7, 1.4] (third order: the eps^2 terms are
    right)."""
    k, hc, L = 1.0, -0.5, 2.0
    d0 = hc + 0.5 * L * L
    err = {}
    for eps in (1e-3, 1e-4):
        s = steady_line(k, eps / k, hc, L, full=True)
        ds = d0 - eps * L * d0**3 + eps**2 * d0**6
        W = k * (2 * L**3 / 3 - 2 * eps * L * L * d0**3 + 2 * eps**2 * (L * d0**6 + L**3 * d0**5))
        err[eps] = (abs(s.d_star - ds), abs(s.load / W - 1.0))
    assert err[1e-3][0] < 3e-7 and err[1e-3][1] < 1e-6, err
    for i in (0, 1):
        assert 700.0 < err[1e-3][i] / err[1e-4][i] < 1400.0, err


def test_full_film_cylinder_keeps_one_flux():
    # beta d^3 p' + V d = V d_* along the whole film, by fourth-order differences of the dense
    # pressure: measured 1.6e-9 at h = 1e-4 and 2e-4 alike (the dense output's own error, not
    # the differences'); tolerance 1e-8, as for the JFO solutions above
    ex = steady_line(K, BETA, HC, 2.0, full=True)
    h = 2e-4
    x = np.linspace(-2.0 + 5 * h, 2.0 - 5 * h, 2001)
    d = ex.film(x)
    flux = BETA * d**3 * dp(ex.solution, x, h) + d
    assert np.abs(flux / ex.d_star - 1.0).max() < 1e-8
    assert ex.pressure(np.array([-2.0, 2.0])) == pytest.approx([0.0, 0.0], abs=1e-12)
    assert ex.solution.p.min() < -0.1  # full Sommerfeld: the exit lobe is sub-ambient


def test_outlet_cavity_matches_the_full_film_upstream(sols):
    # JFO with the cavity at the outlet = the full film where the latter's p >= 0, once the
    # sub-ambient exit lobe's influence has decayed (it decays toward +x through the contact):
    # the two shootings of design.md 17.3 (step 1 on q, step 2 on the rupture point) agree
    s, ex = sols["b-winkler"], steady_full_film(None, HC, beta=BETA, k=K, estimate_error=False)
    x = np.linspace(-0.8, 2.0, 1401)
    pe = ex.pressure(x)
    assert pe.min() >= -1e-10
    assert np.abs(s.pressure(x) - pe).max() < 1e-9 * pe.max()
    assert s.J == pytest.approx(ex.J, rel=1e-9)
    assert s.load > ex.load * 1.03  # the sub-ambient lobe is gone


# ---------------------------------------------------------------------------
# JFO and Reynolds


def test_jfo_and_reynolds_coincide_with_an_outlet_cavity(sols):
    for name, kw in (("b-rigid", dict(hc=0.1, beta=1.0)), ("b-winkler", dict(hc=HC, beta=BETA, k=K))):
        j = sols[name]
        r = steady_reynolds(None, estimate_error=False, **kw)
        assert r.case == j.case == "outlet-cavity"
        assert r.rupture == pytest.approx(j.rupture, abs=1e-12)
        assert r.J == pytest.approx(j.J, rel=1e-12) and r.load == pytest.approx(j.load, rel=1e-12)
        assert r.mass_source == 0.0
        assert np.abs(r.p - j.p).max() < 1e-12 * j.p.max()


def test_reformation_jfo_against_reynolds(sols):
    j, r = sols["c-rigid"], sols["c-rigid-reynolds"]
    assert j.case == r.case == "reformation" and r.model == "reynolds"
    lo, hi = POCKET_KINKS[0], POCKET_KINKS[1]  # the pocket's edges, centre -1
    (xr,), (xf_j,), (xf_r,) = j.rupture, j.reformation, r.reformation
    # the same inlet region: rupture entering the pocket (its diverging half)
    assert r.rupture == j.rupture and r.J == j.J
    assert -1.0 < xr < hi
    # JFO reforms in the pocket's converging half; Reynolds still in the diverging one
    assert lo < xf_j < -1.0 < xf_r < xr
    # Reynolds: p' = 0 at reformation, a second flux, liquid created there
    dpmax = np.abs(r.pressure_gradient(r.x)).max()
    assert abs(dp_side(r, xf_r, -1e-4)) < 1e-6 * dpmax
    assert r.fluxes[0] == r.J and r.fluxes[1] < r.J  # more liquid leaves than entered
    assert r.mass_source == pytest.approx(r.fluxes[0] - r.fluxes[1]) and r.mass_source > 1e-3
    h = 2e-4
    x = full_points(r, h)
    x = x[x < xf_r]
    d = r.film(x)
    assert np.abs((-r.beta * d**3 * dp(r, x, h) - r.V * d) / r.fluxes[1] - 1.0).max() < 1e-8
    # the loads differ by a quarter
    assert r.load > 1.2 * j.load
    # the reference numbers quoted to the transient solver (rigid, beta = 1, V = 1, hc = 0.1)
    assert xr == pytest.approx(-0.5423917158984121, abs=1e-10)
    assert xf_j == pytest.approx(-1.164381394239151, abs=1e-10)
    assert xf_r == pytest.approx(-0.5637527788424606, abs=1e-10)
    assert j.J == pytest.approx(-0.10528949106109743, rel=1e-10)
    assert j.load == pytest.approx(12.665254540308194, rel=1e-10)
    assert r.load == pytest.approx(16.158861291242204, rel=1e-10)


# ---------------------------------------------------------------------------
# the solution's own numerical error


def test_halving_the_tolerance_changes_nothing(sols):
    a = sols["c-rigid"]  # rtol = 1e-12
    b = steady_jfo(POCKET, 0.1, beta=1.0, kinks=POCKET_KINKS, estimate_error=False, rtol=5e-13, x=a.x)
    for name in ("J", "load", "film_min"):
        assert abs(getattr(a, name) - getattr(b, name)) < 1e-8 * abs(getattr(a, name)), name
    assert np.abs(np.subtract(a.rupture, b.rupture)).max() < 1e-8
    assert np.abs(np.subtract(a.reformation, b.reformation)).max() < 1e-8
    assert np.abs(a.p - b.p).max() < 1e-8 * a.p.max()
    assert b.uncertainty == {}


# ---------------------------------------------------------------------------
# inputs


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(profile=0.5), "callable"),
        (dict(profile=lambda x: 1.0), "one finite value per point"),
        (dict(profile=lambda x: np.where(x > 1, np.nan, 0.5 * x * x)), "one finite value"),
        (dict(profile=lambda x: x.bad), "raised AttributeError"),
        (dict(hc=-0.1), "rigid slider"),
        (dict(hc=-3.0, k=1.0), r"hc \+ s\(\+-L\)"),
        (dict(V=0.0), "V"),
        (dict(beta=-1.0), "beta"),
        (dict(k=0.0), "Winkler stiffness"),
        (dict(rtol=1e-3), "rtol"),
        (dict(method="Euler"), "method"),
        (dict(x=[0.0, 3.0]), "x must be"),
        (dict(n=1), "n must be"),
    ],
)
def test_invalid_input(kw, match):
    with np.errstate(all="ignore"), pytest.raises(SceneError, match=match):
        steady_jfo(**{"profile": None, "hc": 0.1, **kw})


def test_inputs_are_not_mutated():
    x = np.linspace(-2.0, 2.0, 11)
    x0 = x.copy()
    kinks = [0.5]
    s = steady_jfo(lambda x: 0.1 * (x + 2.0), 0.1, beta=1.0, kinks=kinks, x=x, estimate_error=False)
    assert np.array_equal(x, x0) and kinks == [0.5]
    assert np.array_equal(s.x, x0) and s.p.shape == x.shape
