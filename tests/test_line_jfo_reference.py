"""The exact steady JFO / Reynolds reference of line contact (femehl.reference.line_jfo_steady).

Each test can fail: the conditions (3)-(7) of the module docstring are checked on the
returned solution by finite differences, against closed forms and against the
independent full-Sommerfeld code :mod:`femehl.reference.line_steady`.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from femehl.errors import SceneError
from femehl.reference.line_jfo_steady import pocket_slider, steady_full_film, steady_jfo, steady_reynolds
from femehl.reference.line_steady import steady_line

K, BETA, HC = 1.0, 10.0, -0.5  # the Winkler cylinder of tests/test_line.py
POCKET, POCKET_KINKS = pocket_slider()  # depth 0.3, width 1, center -1; ramp from x = 1


@pytest.fixture(scope="module")
def sols():
    """The reference configurations (see the module docstring of line_jfo_steady)."""
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
# (a) no cavitation: closed form and the full-Sommerfeld code


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


def test_full_film_cylinder_is_line_steady():
    ex = steady_line(K, BETA, HC, 2.0, full=True)
    s = steady_full_film(None, HC, beta=BETA, k=K, estimate_error=False)
    assert s.J == pytest.approx(-ex.d_star, rel=1e-9)
    assert s.load == pytest.approx(ex.load, rel=1e-9)
    assert np.abs(s.p - ex.pressure(s.x)).max() < 1e-8 * s.p.max()
    assert s.p.min() < -0.1  # full Sommerfeld: the exit lobe is sub-ambient


def test_outlet_cavity_matches_line_steady_upstream(sols):
    # JFO with the cavity at the outlet = line_steady where the latter's p >= 0, once the
    # sub-ambient exit lobe's influence has decayed (it decays toward +x through the contact)
    s, ex = sols["b-winkler"], steady_line(K, BETA, HC, 2.0, full=True)
    x = np.linspace(-0.8, 2.0, 1401)
    pe = ex.pressure(x)
    assert pe.min() >= -1e-10
    assert np.abs(s.pressure(x) - pe).max() < 1e-9 * pe.max()
    assert s.J == pytest.approx(-ex.d_star, rel=1e-9)
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
