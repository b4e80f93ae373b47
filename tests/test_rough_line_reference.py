"""The rough line contact (femehl.Roughness on a LineScene) run to its steady state, against the
exact steady reference with rough surfaces (femehl.reference.line_jfo_steady, ``roughness=``:
quadrature and shooting in the film's pressure, docs/design.md sections 17-18), full Sommerfeld
and Reynolds.

The scene: the cylinder on Winkler k = 1, beta = 10, L = 2.5, V = 0.05, roughness sigma = 0.05,
K = 2, the load ramped to F = 0.5 over t <= 1 and held: mixed lubrication, the asperities carry
74 % (full Sommerfeld) and 66 % (Reynolds, the film cavitated behind x = -0.628) of the load,
the thinnest film 0.72 sigma (0.76 sigma).  The reference's hc at the load F (``HC``:
:func:`steady_under_load` at rtol 1e-12, own uncertainty 2.3e-12 in the load, 5.3e-11 in p;
the slow test recomputes it); the default test checks that the reference at ``HC`` carries F
to 1e-9 (measured 2.3e-12), which pins ``HC`` to 6e-10 (dF/dhc = -1.7) at the cost of one
solve instead of a root find.

Measured, FE (bdf2, uniform mesh) minus reference at the steady state (T = 400):

    full Sommerfeld     hc          share       film(0)/ref   film_min/ref   max|P|/max P   film profile
    200                 +4.15e-5    -9.83e-6    +1.13e-3      -2.2e-6        9.30e-4        2.46e-2
    400                 +1.04e-5    -2.51e-6    +2.81e-4      +1.6e-5        2.59e-4        6.56e-3
    800                 +2.59e-6    -6.30e-7    +7.03e-5      +2.6e-6        6.55e-5        1.66e-3
    order               2.00 2.00   1.97 1.99   2.00 2.00     (sampling)     1.85 1.98      1.91 1.98
    Reynolds
    200                 +3.41e-5    +7.47e-5    +1.10e-3      -4.7e-5        5.21e-4        1.48e-2
    400                 +8.37e-6    +2.48e-5    +2.72e-4      -2.4e-5        1.31e-4        3.88e-3
    800                 +2.15e-6    +3.94e-6    +6.87e-5      +4.9e-7        3.38e-5        9.82e-4
    order               2.03 1.96   1.59 2.65   2.01 1.99     (sampling)     1.99 1.96      1.94 1.98

(the film profile: max |d_FE - d_ref| over the element centroids, over the reference's minimum
film).  The friction force against the reference's by quadrature (:meth:`SteadyJFO.friction`),
relative: full Sommerfeld -9.0e-4 / -2.3e-4 / -5.6e-5 (order 2.00, 2.00), Reynolds -5.5e-4 /
-1.4e-4 / -3.5e-5 (2.02, 1.96).  Second order in space, as the smooth line contact
(tests/test_line.py): the FE and the reference solve the same model.  The minimum film is the
smallest of the film points, the nodes and the origin, so its error is that of sampling the
minimum too, and is not monotone; the Reynolds share's order moves as the cavity's edge crosses
the nodes.  The tolerances below
are 3x the 400-element errors (the minimum film: 3x the largest error on the three meshes).

How the FE run is made steady: the load's transient takes a few hundred time units to die out
(2 L / V = 100 is the time the surfaces take to cross the domain): at t = 60 the share is still
2e-3 off (hc 5e-5, five times its 400-element error), at t = 117 1e-5, at t = 220 1e-7.  Runs
go to T = 400, and the states at t ~ 300 and 400 agree to 1e-11.  ``dt_max = 10``: with the
default T/10 the steps grow to it once the run is steady, and at steps of 40 and more the
lagged step, one iteration of the steady problem's fixed point, oscillates with a growing
amplitude (full Sommerfeld, 400 elements, before the adaptive steps caught it: the share
+-8e-6 about its limit at t = 550 with steps of 40, 1.4e-4 off at t = 800 with steps of 80).
The adaptive steps now catch that mode and keep the steps below it
(:func:`test_the_lag_mode_is_caught_on_long_steady_steps`); ``dt_max = 10`` keeps these runs
short of it.  ``tol = 1e-4``: a steady state of the scheme is its steady
weak form whatever the steps (docs/design.md section 4), so only the path depends on tol; the
final states at tol 1e-4 and 1e-5 agree to 2e-14 in hc and 5e-13 in the share (400 elements;
Reynolds 5 s against 29 s).
"""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest
from scipy.integrate import solve_bvp
from scipy.stats import norm

import femehl
from femehl import Motion, RampHold, Roughness
from femehl.errors import SceneError
from femehl.problem.line import LineScene
from femehl.reference.line_jfo_steady import (
    RoughSurfaces,
    steady_full_film,
    steady_reynolds,
    steady_under_load,
)
from femehl.reference.rough_contact import greenwood_tripp
from femehl.solver.adaptive import AdaptiveSteps

SIGMA, KA, K, BETA, L, V, F = 0.05, 2.0, 1.0, 10.0, 2.5, 0.05, 0.5
ROUGH = Roughness(sigma=SIGMA, stiffness=KA)
T_END, DT_MAX, STEP_TOL = 400.0, 10.0, 1e-4
MODELS = {None: ("full-film", steady_full_film), "reynolds": ("reynolds", steady_reynolds)}
#: the reference's hc at the load F (steady_under_load, rtol 1e-12; recomputed by the slow test)
HC = {None: -0.36363047076143756, "reynolds": -0.35760736549865046}

#: 3x the 400-element errors (module docstring); the minimum film 3x the largest on 200-800
TOL = {
    None: dict(
        hc=3.2e-5, share=7.5e-6, center=8.5e-4, film=2e-2, film_min=5e-5, pressure=8e-4, friction=7e-4
    ),
    "reynolds": dict(
        hc=2.6e-5, share=7.5e-5, center=8.2e-4, film=1.2e-2, film_min=1.5e-4, pressure=4e-4, friction=4e-4
    ),
}


def scene(cavitation):
    motion = Motion(gap=0.6, velocity=V, load=RampHold(0.0, F, 1.0))
    return LineScene(k=K, L=L, beta=BETA, motion=motion, roughness=ROUGH, cavitation=cavitation)


def fe_steady(cavitation, n):
    """(stepper, the state at t ~ T - 100, the state at T)."""
    stepper = femehl.make_stepper(scene(cavitation), n_elements=n, scheme="bdf2")
    earlier = last = None
    for state in femehl.march(stepper, T_END, AdaptiveSteps(tol=STEP_TOL, dt0=1e-3, dt_max=DT_MAX)):
        if state.t <= T_END - 100.0:
            earlier = state
        last = state
    return stepper, earlier, last


def reference(cavitation, rtol=1e-10):
    _, solve = MODELS[cavitation]
    return solve(None, HC[cavitation], V, BETA, K, L, roughness=ROUGH, rtol=rtol, estimate_error=False)


def errors(ref, stepper, state):
    """FE minus reference: hc, the asperities' share, the central, minimum and whole film
    (relative to the reference's minimum film), the total pressure at the nodes (over its peak),
    the friction force (relative; the reference's by quadrature, :meth:`SteadyJFO.friction`)."""
    disc = stepper.disc
    x = np.asarray(disc.nodes)[:, 0]
    P = ref.total_pressure(x)
    center = float(ref.film(np.array([0.0]))[0])
    xc = np.asarray(disc.xc)
    xc = xc[:, 0] if xc.ndim == 2 else xc
    return dict(
        hc=state.hc - ref.hc,
        share=state.info["asperity_share"] - ref.asperity_load / ref.load,
        center=(state.film_center - center) / center,
        film=float(np.abs(state.d - ref.film(xc)).max()) / ref.film_min,
        film_min=(state.film_min - ref.film_min) / ref.film_min,
        pressure=float(np.abs(state.p - P).max()) / P.max(),
        friction=state.info["friction"] / ref.friction()["friction"] - 1.0,
    )


@pytest.fixture(scope="module")
def refs():
    return {cav: reference(cav) for cav in MODELS}


@pytest.fixture(scope="module")
def runs():
    return {cav: fe_steady(cav, 400) for cav in MODELS}


# ---------------------------------------------------------------------------
# the reference itself


def test_rough_surfaces_model():
    """The mean gap is the normal distribution's formula (scipy.stats.norm), the separation solves
    d = c + p_a(d)/k, and a femehl.Roughness or a tuple is taken for the roughness."""
    r = RoughSurfaces.of(ROUGH)
    assert r == RoughSurfaces.of((SIGMA, KA)) == RoughSurfaces(SIGMA, KA, 0.02)
    d = np.linspace(-10.0, 20.0, 601) * SIGMA
    t = d / SIGMA
    h = SIGMA * (t * norm.cdf(t) + norm.pdf(t) + 0.02 * norm.sf(t))
    assert np.allclose(r.mean_gap(d), h, rtol=1e-14, atol=1e-17)
    assert np.allclose(r.asperity_pressure(d), KA * greenwood_tripp(t), rtol=1e-15, atol=0)
    for k in (1.0, 1e-2, 1e3):
        c = np.linspace(-1.0, 1.0, 401)
        dd = r.separation(c, k)
        assert np.abs(dd - c - r.asperity_pressure(dd) / k).max() < 1e-14 * max(1.0, KA / k)
    assert np.array_equal(r.separation(c, math.inf), c)
    for bad in ((0.05,), "rough", (0.0, 2.0), (0.05, 2.0, 1.5)):
        with pytest.raises(SceneError):
            RoughSurfaces.of(bad)
    with pytest.raises(SceneError, match="no roughness"):  # JFO's content of a mean gap: not written
        steady_under_load("jfo", None, F, V, BETA, K, L, roughness=ROUGH)


def test_reference_carries_the_load_and_keeps_its_equations(refs):
    """At HC the reference carries F (pins HC); d = hc + s + P/k; one flux in the full film,
    beta h_T^3 p' + V h_T = V q (fourth-order differences of the dense pressure); Reynolds:
    p >= 0, p = 0 on the cavity, p = p' = 0 and h_T = q at the rupture."""
    for cav, ref in refs.items():
        assert ref.load == pytest.approx(F, abs=1e-9)  # measured 2.3e-12 and 2.0e-12
        assert ref.roughness == RoughSurfaces(SIGMA, KA)
        assert np.abs(ref.d - (ref.hc + 0.5 * ref.x**2 + ref.P / K)).max() < 1e-14
        assert np.allclose(ref.P, ref.p + KA * greenwood_tripp(ref.d / SIGMA), rtol=1e-14, atol=0)
        assert np.allclose(ref.h_T, ref.mean_gap(ref.x), rtol=1e-14, atol=0)
        assert 0.6 < ref.asperity_load / ref.load < 0.8
        assert ref.load == pytest.approx(np.trapezoid(ref.P, ref.x), rel=1e-5)
        pa = ref.asperity_pressure(ref.x)
        assert ref.asperity_load == pytest.approx(np.trapezoid(pa, ref.x), rel=1e-5)
        assert ref.film_min < 0.8 * SIGMA  # the mean planes nearly touch
        q = -ref.J / V
        full = [r for r in ref.regions if r.kind == "full"]
        e = 2e-4
        x = np.concatenate([np.linspace(r.a + 5 * e, r.b - 5 * e, 400) for r in full])
        pr = ref.pressure
        dp = (pr(x - 2 * e) - 8 * pr(x - e) + 8 * pr(x + e) - pr(x + 2 * e)) / (12 * e)
        h = ref.mean_gap(x)
        # measured 4.1e-7 (full) and 1.7e-7 (Reynolds), whatever the difference step: the dense
        # output's derivative at rtol 1e-10, near the ends where V h = 46 V q cancels against
        # beta h^3 p'; against the ODE's own p' the differences are 1.2e-8 of the largest
        assert np.abs((BETA * h**3 * dp + V * h) / (V * q) - 1.0).max() < 1e-6
        if cav == "reynolds":
            assert ref.case == "outlet-cavity" and len(ref.rupture) == 1
            xr = ref.rupture[0]
            assert ref.p.min() >= -1e-12 * ref.p.max()
            assert np.all(ref.p[ref.x < xr] == 0.0) and np.all(ref.theta[ref.x < xr] < 1.0)
            assert ref.mean_gap(np.array([xr]))[0] == pytest.approx(q, rel=1e-12)
            v = pr(np.array([xr, xr + 2e-5, xr + 4e-5]))
            dpr = (-3 * v[0] + 4 * v[1] - v[2]) / 4e-5
            assert abs(dpr) < 1e-5 * np.abs(ref.pressure_gradient(ref.x)).max()
        else:
            assert ref.case == "full" and ref.p.min() < -0.01  # the film's exit tension


def test_full_film_reference_against_collocation(refs):
    """Another algorithm for the same rough full film: scipy's solve_bvp (collocation on a mesh,
    the flux film q a parameter), with the model written out here (h_T by scipy.stats.norm, the
    separation by Newton).  Measured: q 1e-13, the load 8e-11, p 2.2e-9 of its peak."""
    ref = refs[None]
    hc = ref.hc

    def separation(x, p):
        c = hc + 0.5 * x * x + p / K
        d = c.copy()
        for _ in range(60):  # from d = c <= the root, increasing
            t = d / SIGMA
            step = (d - c - KA * greenwood_tripp(t) / K) / (
                1.0 + (2.5 * KA / SIGMA) * greenwood_tripp(t, 1.5) / K
            )
            d = d - step
            if np.abs(step).max() < 1e-15:
                return d
        raise AssertionError("Newton did not converge")

    def rhs(x, y, par):
        d = separation(x, y[0])
        t = d / SIGMA
        h = SIGMA * (t * norm.cdf(t) + norm.pdf(t) + 0.02 * norm.sf(t))
        return np.vstack([V * (par[0] - h) / (BETA * h**3), y[0] + KA * greenwood_tripp(t)])

    x = np.linspace(-L, L, 201)
    y0 = np.vstack([np.maximum(0.0, 0.3 * (1.0 - x * x)), np.zeros_like(x)])
    sol = solve_bvp(rhs, lambda a, b, par: np.array([a[0], b[0], a[1]]), x, y0, p=[0.05], tol=1e-7)
    assert sol.status == 0
    assert sol.p[0] == pytest.approx(-ref.J / V, rel=1e-9)
    assert sol.y[1, -1] == pytest.approx(ref.load, rel=1e-8)
    xs = np.linspace(-L, L, 1001)
    assert np.abs(sol.sol(xs)[0] - ref.pressure(xs)).max() < 1e-7 * ref.P.max()


@pytest.mark.slow
def test_far_from_contact_the_rough_reference_is_the_smooth_one():
    """A film >= 10.9 sigma (the cylinder of tests/test_line.py, film 0.125, sigma = 0.0115): the
    asperities (F_{5/2}(10.9) = 5e-30) and the gap's correction are below double precision; the
    rough shooting (Newton for the separation where hc + s + p/k < 12 sigma, the mean gap, the
    asperities' load as a third component) gives the smooth solution.  Measured at rtol 1e-10:
    J 6.6e-13, the load 3.4e-13, p 9.5e-11 of its peak (2.4 s against 0.25 s)."""
    kw = dict(beta=10.0, k=1.0, estimate_error=False, rtol=1e-10)
    smooth = steady_full_film(None, -0.5, **kw)
    rough = steady_full_film(None, -0.5, roughness=(0.0115, 2.0), **kw)
    assert rough.film_min > 10.8 * 0.0115
    assert rough.asperity_load < 1e-25
    assert rough.J == pytest.approx(smooth.J, rel=1e-11)
    assert rough.load == pytest.approx(smooth.load, rel=1e-11)
    assert np.abs(rough.p - smooth.p).max() < 1e-9 * smooth.p.max()
    assert np.array_equal(smooth.P, smooth.p) and np.array_equal(smooth.h_T, smooth.d)
    assert smooth.asperity_load == 0.0 and smooth.roughness is None


# ---------------------------------------------------------------------------
# the FE run against it


@pytest.mark.parametrize("cavitation", [None, "reynolds"], ids=["full-sommerfeld", "reynolds"])
def test_fe_steady_state_is_the_reference(cavitation, runs, refs):
    stepper, earlier, state = runs[cavitation]
    # steady: the state 100 time units earlier is the same (measured 1e-11)
    assert state.t == T_END and earlier.t > T_END - 120.0
    assert abs(state.hc - earlier.hc) < 1e-8
    assert abs(state.info["asperity_share"] - earlier.info["asperity_share"]) < 1e-8
    assert np.abs(state.p - earlier.p).max() < 1e-8 * state.p.max()
    assert state.load == pytest.approx(F, abs=1e-12)
    if cavitation == "reynolds":  # the cavitated rows hold the film's pressure, not the total
        free = stepper.disc.free
        film = state.p[free] - state.own["p_asperity"]
        assert film.min() > -1e-9 * state.p.max()
    err = errors(refs[cavitation], stepper, state)
    for name, tol in TOL[cavitation].items():
        assert abs(err[name]) < tol, (name, err[name], tol)


@pytest.mark.slow
@pytest.mark.parametrize("cavitation", [None, "reynolds"], ids=["full-sommerfeld", "reynolds"])
def test_fe_converges_to_the_reference_at_second_order(cavitation):
    """200, 400, 800 elements: the errors of hc, the central film, the film profile and the
    pressure fall at order 2 (measured 1.85-2.03; the module docstring); and the reference's
    hc at the load, found again by steady_under_load, is HC."""
    model, _ = MODELS[cavitation]
    s = steady_under_load(
        model,
        None,
        F,
        V,
        BETA,
        K,
        L,
        roughness=ROUGH,
        hc_bracket=(HC[cavitation] - 1e-3, HC[cavitation] + 1e-3),
        rtol=1e-10,
        estimate_error=False,
    )
    assert s.hc == pytest.approx(HC[cavitation], abs=1e-9) and s.load == pytest.approx(F, abs=1e-9)
    ref = reference(cavitation)
    errs = [errors(ref, *fe_steady(cavitation, n)[::2]) for n in (200, 400, 800)]
    for name in ("hc", "center", "film", "pressure", "friction"):
        e = [abs(v[name]) for v in errs]
        orders = np.log2(np.array(e[:-1]) / np.array(e[1:]))
        assert np.all(orders > 1.7), (name, e, orders)
    for name in ("share", "film_min"):
        assert abs(errs[2][name]) < TOL[cavitation][name] / 2


def test_the_lag_mode_is_caught_on_long_steady_steps(caplog, runs):
    """With the default ceiling (T/10 = 80) the steady run's steps grow to where the lagged
    step diverges in sign-alternating increments (the steady problem's fixed point: share
    1.4e-4 off at t = 800 before, with Milne's estimate within tol).  The adaptive steps see
    the period-two mode (successive film increments opposite and not decaying), retry the step
    at a quarter of it and keep every later step there: measured, caught at steps of 80 then
    20, the last steps 5; the state at t = 800 is steady to 1e-15 and is the dt_max = 10
    run's at T = 400 (hc 1.4e-15 apart, share 7e-14)."""
    stepper = femehl.make_stepper(scene(None), n_elements=400, scheme="bdf2")
    with caplog.at_level(logging.INFO, logger="femehl"):
        states = list(femehl.march(stepper, 2 * T_END, AdaptiveSteps(tol=STEP_TOL, dt0=1e-3)))
    caught = [r.getMessage() for r in caplog.records if "oscillates from step to step" in r.getMessage()]
    assert caught and "steps of 80" in caught[0]
    last = states[-1]
    earlier = [s for s in states if s.t <= 2 * T_END - 100.0][-1]
    assert max(b.t - a.t for a, b in zip(states[-20:-1], states[-19:], strict=True)) <= 20.0
    assert abs(last.hc - earlier.hc) < 1e-12
    steady = runs[None][2]
    assert abs(last.hc - steady.hc) < 1e-11
    assert abs(last.info["asperity_share"] - steady.info["asperity_share"]) < 1e-11
