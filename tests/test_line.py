"""Tests of femehl.line (cylinder on a Winkler foundation) against
femehl.reference.line_steady and exact limits.

Measured figures these tolerances come from (k = 1, beta = 10, hc = -0.5, L = 2,
graded mesh ratio 3, dt = 0.05, t = 15; errors of the final state):

    elements   max|d - d_exact|/min d   |load - exact|/exact
    200        5.54e-3                  4.34e-6
    400        1.55e-3                  1.06e-6
    800        3.97e-4                  2.65e-7
    observed order 1.84 (200->400), 1.96 (400->800) for the film, 2.0 for the load

so the scheme is second order in space, and the steady state of the lagged
scheme does not depend on dt (checked below).  The tolerances are the
measured values times about 1.5, and an observed order of at least 1.6.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from femehl.api import make_stepper, solve_line
from femehl.errors import SceneError
from femehl.output.result import Result
from femehl.problem.line import LineScene, contact_halfwidth, line_nodes
from femehl.problem.scene import Constant, Motion, RampHold, Table, TanhStart
from femehl.reference.line_steady import steady_line, steady_line_load
from femehl.solver.stepping import State
from femehl.solver.terms import StepContext

K, BETA, HC, L = 1.0, 10.0, -0.5, 2.0


def sliding_scene(**kw):
    args = dict(k=K, beta=BETA, L=L, motion=Motion(gap=RampHold(0.1, HC, 1.0), velocity=TanhStart(1.0, 1.0)))
    args.update(kw)
    return LineScene(**args)


@pytest.fixture(scope="module")
def exact():
    return steady_line(K, BETA, HC, L, full=True)


@pytest.fixture(scope="module")
def runs():
    sc = sliding_scene()
    return {n: solve_line(sc, 15.0, 0.05, n_elements=n, store_every=10) for n in (200, 400)}


def errors(res, ex):
    f = res.final
    de = ex.film(res.disc.xc)
    return np.abs(f.d - de).max() / de.min(), abs(f.load - ex.load) / ex.load


# ---------------------------------------------------------------------------
# the exact steady solution itself


def test_steady_line_is_consistent(exact):
    x, d, p, ds = steady_line(K, BETA, HC, L, n=801)
    assert ds == pytest.approx(exact.d_star, rel=1e-12)
    assert abs(exact.end_error) < 1e-9
    # p(+-L) = 0 and p = k (d - hc - x^2/2)
    assert abs(p[0]) < 1e-12 and abs(p[-1]) < 1e-8
    assert np.allclose(p, K * (d - HC - 0.5 * x * x))
    # nontrivial: elastic deflection several times the film, film positive
    assert p.max() / K > 3 * d.min() > 0
    # the flux relation beta d^3 p' = -V (d - d_*), by central differences on a fine grid
    xf = np.linspace(-L, L, 8001)
    df, pf = exact.film(xf), exact.pressure(xf)
    flux = (BETA * df**3 * np.gradient(pf, xf) + (df - ds))[1:-1]  # one-sided ends left out
    assert np.abs(flux).max() < 5e-5
    # the load by trapezoid agrees with the integrated one
    assert np.trapezoid(p, x) == pytest.approx(exact.load, rel=1e-5)
    # an independent stiff integrator (implicit Radau instead of the explicit DOP853) gives the
    # same answer
    r = steady_line(K, BETA, HC, L, method="Radau", rtol=1e-7, full=True)
    assert r.d_star == pytest.approx(exact.d_star, rel=1e-8)  # measured 2.7e-10
    assert r.load == pytest.approx(exact.load, rel=1e-8)  # measured 6.5e-12


def test_steady_line_load_inverts_steady_line(exact):
    s = steady_line_load(K, BETA, exact.load, L, hc_bracket=(-0.6, -0.4), rtol=1e-10)
    assert s.hc == pytest.approx(HC, abs=1e-8)
    assert s.load == pytest.approx(exact.load, rel=1e-9)


# ---------------------------------------------------------------------------
# (a) long-time transient sliding against the steady solution


def test_transient_reaches_exact_steady_state(runs, exact):
    e = {n: errors(r, exact) for n, r in runs.items()}
    film_order = math.log2(e[200][0] / e[400][0])
    load_order = math.log2(e[200][1] / e[400][1])
    assert e[400][0] < 2.5e-3, e
    assert e[400][1] < 2e-6, e
    assert film_order > 1.6 and load_order > 1.6, (film_order, load_order)
    for r in runs.values():
        assert isinstance(r, Result)
        assert np.all(r.film_min > 0)  # the film never closed
        i = np.searchsorted(r.t, 14.0)
        assert abs(r.load[-1] - r.load[i]) < 1e-8  # steady: nothing changes
        assert abs(r.film_center[-1] - r.film_center[i]) < 1e-8
        # film at x = 0 and the exit constriction
        assert r.film_center[-1] == pytest.approx(float(exact.film(0.0)), rel=2e-2)
        assert r.final.film_min_at[0] < -0.5  # exit constriction at x < 0
        assert r.final.film_min_at[1] == 0.0


def test_friction_against_the_exact_steady_state(runs, exact):
    """The full film's friction force and its parts (femehl.solver.energetics) against the exact
    steady solution's, integrated by quadrature (:meth:`SteadyJFO.friction`).  Measured, relative
    error on 200 / 400 / 800 elements: friction 4.9e-5 / 1.2e-5 / 3.0e-6, Couette shear 8.3e-6 /
    2.1e-6 / 5.2e-7, Poiseuille shear and pressure drag 1.9e-4 / 4.9e-5 / 1.2e-5: second order.
    Tolerances 3x the 400-element errors, and the order above 1.8."""
    ref = exact.solution.friction()
    assert ref["shear_poiseuille"] < 0 < ref["shear_couette"] and ref["pressure_drag"] > 0
    tol = dict(friction=4e-5, shear_couette=6e-6, shear_poiseuille=1.5e-4, pressure_drag=1.5e-4)
    for name, t in tol.items():
        e = [abs(runs[n].final.info[name] / ref[name] - 1.0) for n in (200, 400)]
        assert e[1] < t and math.log2(e[0] / e[1]) > 1.8, (name, e)


def test_steady_state_does_not_depend_on_dt(runs):
    r = solve_line(sliding_scene(), 15.0, 0.2, n_elements=200, store_every=1000)
    a, b = r.final, runs[200].final
    assert np.abs(a.d - b.d).max() < 1e-8
    assert abs(a.load - b.load) < 1e-8


def test_result_arrays_and_states(runs):
    r = runs[200]
    n = r.t.size
    assert n == 301 and r.t[0] == 0.0 and r.t[-1] == pytest.approx(15.0)
    for a in (r.hc, r.V, r.load, r.film_center, r.film_min, r.summary()["film_min_x"], r.p_max):
        assert a.shape == (n,)
    assert r.disc.x.size == 201 and r.disc.xc.size == 200
    assert r.states[0].step == 0 and r.states[-1].step == 300
    s = r.state_at(7.0)
    assert isinstance(s, State) and s.t == pytest.approx(7.0)
    assert s.p.shape == r.disc.x.shape and s.d.shape == r.disc.xc.shape and s.w.shape == r.disc.xc.shape
    assert s.p[0] == 0.0 and s.p[-1] == 0.0
    assert np.allclose(s.d, s.hc + r.disc.xc**2 / 2 - s.w)
    assert s.load == pytest.approx(np.trapezoid(s.p, r.disc.x), rel=1e-12)  # P1: trapezoid is exact


# ---------------------------------------------------------------------------
# (b) squeeze between a parabola and a plane (rigid limit, V = 0)


def squeeze_load(hc, hdot, beta, L):
    """Exact load of beta (d^3 p')' = dhc/dt, d = hc + x^2/2, p(+-L) = 0.

    beta d^3 p' = hdot x, so p(x) = -(hdot / (2 beta)) (1/d(x)^2 - 1/d(L)^2) and, with
    a^2 = 2 hc, int_{-L}^{L} dx/d^2 = 4 (L/(a^2 (a^2 + L^2)) + atan(L/a)/a^3).
    """
    a2 = 2.0 * hc
    a = math.sqrt(a2)
    uL = hc + 0.5 * L * L
    I = 4.0 * (L / (a2 * (a2 + L * L)) + math.atan(L / a) / a**3)
    return -(hdot / (2.0 * beta)) * (I - 2.0 * L / uL**2)


def test_squeeze_film_rigid_limit():
    beta, rate = 1.0, -0.7
    sc = LineScene(k=1e8, beta=beta, L=2.0, motion=Motion(gap=RampHold(1.0, 0.3, 1.0), velocity=0.0))
    err = {}
    for dt in (0.01, 0.005):
        r = solve_line(sc, 1.0, dt, n_elements=400, grading="uniform", store_every=10**6)
        for tq in (0.5, 1.0):
            i = int(np.argmin(np.abs(r.t - tq)))
            # each step solves the squeeze problem of its lagged film d^k = d(hc^k):
            # this isolates the spatial error (measured 1.3e-6 at n = 400)
            lag = r.load[i] / squeeze_load(r.hc[i - 1], rate, beta, 2.0) - 1.0
            assert abs(lag) < 5e-6, (dt, tq, lag)
            err[dt, tq] = r.load[i] / squeeze_load(r.hc[i], rate, beta, 2.0) - 1.0
            assert abs(r.V[i]) == 0.0
    # against hc(t) itself the lag is first order in dt (measured -1.86e-2 / -9.36e-3 at t = 0.5)
    for tq in (0.5, 1.0):
        ratio = err[0.01, tq] / err[0.005, tq]
        assert 1.9 < ratio < 2.1, (tq, ratio)
        assert abs(err[0.005, tq]) < 2e-2


def test_bdf2_squeeze_has_no_lag_error():
    """BDF2 with the extrapolated film is exact in time for a linear hc(t): spatial error only."""
    beta, rate = 1.0, -0.7
    sc = LineScene(k=1e8, beta=beta, L=2.0, motion=Motion(gap=RampHold(1.0, 0.3, 1.0), velocity=0.0))
    r = solve_line(sc, 1.0, 0.02, n_elements=400, grading="uniform", scheme="bdf2")
    for tq in (0.5, 1.0):
        i = int(np.argmin(np.abs(r.t - tq)))
        assert abs(r.load[i] / squeeze_load(r.hc[i], rate, beta, 2.0) - 1.0) < 5e-6  # measured 1.3e-6


def test_bdf2_reaches_the_same_steady_state(runs):
    # BDF2 with extrapolated d^3 needs the smaller step: at dt = 0.2 it keeps oscillating
    # (measured), the Euler scheme settles up to dt = 0.5
    r = solve_line(sliding_scene(), 15.0, 0.05, n_elements=200, scheme="bdf2", store_every=1000)
    assert np.abs(r.final.d - runs[200].final.d).max() < 1e-8
    assert r.final.info["residual"] < 1e-12


# ---------------------------------------------------------------------------
# (c) imposed load


def test_imposed_load_squeeze_is_exact_and_monotone():
    F = 1.0
    sc = LineScene(k=K, beta=BETA, L=L, motion=Motion(gap=0.1, velocity=0.0), load=F)
    r = solve_line(sc, 5.0, 0.05, n_elements=200)
    assert np.all(np.abs(r.load[1:] - F) / F < 1e-10)
    assert np.all(np.diff(r.hc) < 0.0)  # the film is squeezed out
    assert np.all(r.film_min > 0.0)
    for s in r.states[1:]:
        assert s.info["residual"] < 1e-12


def test_imposed_load_sliding_reaches_steady_gap(exact):
    sc = sliding_scene(motion=Motion(gap=0.1, velocity=TanhStart(1.0, 1.0)), load=exact.load)
    r = solve_line(sc, 15.0, 0.05, n_elements=400, store_every=1000)
    assert np.all(np.abs(r.load[1:] - exact.load) / exact.load < 1e-10)
    # steady hc under that load is -0.5 up to the discretization (load error ~1e-6)
    assert r.hc[-1] == pytest.approx(HC, abs=1e-5)


def test_load_given_through_motion():
    """Motion(load=...) (the 2-D convention) works the same; gap(0) is the initial clearance."""
    sc = LineScene(k=K, beta=BETA, L=L, motion=Motion(gap=RampHold(0.1, -0.5, 1.0), load=1.0))
    assert sc.motion.load_controlled and isinstance(sc.motion.load, Constant)
    r = solve_line(sc, 1.0, 0.05, n_elements=100)
    assert r.hc[0] == 0.1
    assert np.all(np.abs(r.load[1:] - 1.0) < 1e-10)


def test_load_function_of_time():
    F = lambda t: 0.5 + 0.5 * min(t, 1.0)  # noqa: E731
    sc = LineScene(k=K, beta=BETA, L=3.0, motion=Motion(gap=0.2, velocity=TanhStart(1.0, 1.0)), load=F)
    r = solve_line(sc, 3.0, 0.05, n_elements=200)
    target = np.array([F(t) for t in r.t[1:]])
    assert np.all(np.abs(r.load[1:] - target) / target < 1e-10)


# ---------------------------------------------------------------------------
# (d) no dense matrix anywhere


@pytest.mark.parametrize("load", [None, 1.0])
def test_step_matrix_is_sparse(load):
    motion = Motion(gap=0.1, velocity=TanhStart(1.0, 1.0)) if load else sliding_scene().motion
    st = make_stepper(sliding_scene(motion=motion, load=load), "line", n_elements=300)
    s0 = st.initial_state()
    s1 = st.step(s0, 0.05, 0.05)
    ctx = StepContext(
        t_new=1.5,
        dt=0.05,
        a0=1.0,
        d=s1.d,
        d_lag=s1.d,
        history=s1.d,
        p=s1.p[st.disc.free],
        V=0.5,
        beta=st.beta,
    )
    op, b = st.operator(ctx)
    A = op.matrix()
    n = st.disc.n
    assert sp.issparse(A) and A.format == "csc" and not op.dense
    assert A.shape == (n, n) and b.shape == (n,)
    assert A.nnz <= 3 * n  # tridiagonal
    for obj in (st, st.disc):
        for name, v in vars(obj).items():
            if isinstance(v, np.ndarray):  # O(n) data, no dense operator
                assert v.ndim == 1 or v.size <= 4 * st.disc.nelements, name
            elif sp.issparse(v):
                assert v.nnz <= 4 * max(v.shape), name
    assert isinstance(s1, State) and s1.step == 1


def test_line_nodes():
    x = line_nodes(2.0, 100, "uniform")
    assert np.allclose(np.diff(x), 0.04)
    g = line_nodes(2.0, 100, 3.0, fine=1.0)
    h = np.diff(g)
    assert g[0] == -2.0 and g[-1] == 2.0 and np.all(h > 0)
    assert h.max() / h.min() == pytest.approx(3.0, rel=0.05)
    g2 = line_nodes(2.0, 200, 3.0, fine=1.0)
    assert np.allclose(g2[::2], g, atol=1e-6)  # doubling halves each element
    c = line_nodes(2.0, 50, lambda x: 1 + np.exp(-x * x))
    assert c.size == 51 and np.all(np.diff(c) > 0)


# ---------------------------------------------------------------------------
# (e) invalid inputs


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(k=0.0), "Winkler stiffness k"),
        (dict(k=-1.0), "Winkler stiffness k"),
        (dict(k=float("nan")), "Winkler stiffness k"),
        (dict(beta=0.0), "beta"),
        (dict(beta="x"), "beta"),
        (dict(L=-2.0), "domain half length"),
        (dict(L=1.0), "too small to hold the contact"),
        (dict(motion=(0.1, 1.0)), "Motion"),
        (dict(motion=Motion(gap=-0.1, velocity=1.0)), "must be > 0"),
        (dict(motion=Motion(gap=0.0, velocity=1.0)), "must be > 0"),
        (dict(load="heavy"), "load"),
        (dict(load=1.0, motion=Motion(gap=0.1, load=1.0)), "imposed twice"),
        (dict(load=float("inf"), motion=Motion(gap=0.1)), "finite"),
        (dict(load=100.0, motion=Motion(gap=0.1)), "too small to hold the contact"),
    ],
)
def test_invalid_scene(kw, match):
    with pytest.raises(SceneError, match=match):
        sliding_scene(**kw)


def test_invalid_run_options():
    sc = sliding_scene()
    with pytest.raises(SceneError, match="n_elements"):
        make_stepper(sc, "line", n_elements=2)
    with pytest.raises(SceneError, match="n_elements"):
        make_stepper(sc, "line", n_elements=100.5)
    with pytest.raises(SceneError, match="grading"):
        make_stepper(sc, "line", grading=0.5)
    with pytest.raises(SceneError, match="grading"):
        make_stepper(sc, "line", grading="graded")
    with pytest.raises(SceneError, match="rho"):
        make_stepper(sc, "line", grading=lambda x: -1.0 + 0 * x)
    with pytest.raises(SceneError, match="LineScene"):
        make_stepper(object(), "line")
    with pytest.raises(SceneError, match="scheme"):
        make_stepper(sc, "line", scheme="rk4")
    with pytest.raises(SceneError, match="dt"):
        solve_line(sc, 1.0, -0.1)
    with pytest.raises(SceneError, match="store_every"):
        solve_line(sc, 1.0, 0.1, store_every=-1)
    with pytest.raises(SceneError, match="beta"):
        steady_line(1.0, -1.0, -0.5, 2.0)
    with pytest.raises(SceneError, match="V"):
        steady_line(1.0, 1.0, -0.5, 2.0, V=0.0)


def test_scene_is_frozen():
    sc = sliding_scene()
    with pytest.raises(dataclasses.FrozenInstanceError):
        sc.domain = None
    # the dry Winkler contact of the default ramp to hc = -0.5: a = sqrt(2 * 0.5)
    assert contact_halfwidth(LineScene()) == pytest.approx(1.0)
    assert isinstance(LineScene(load=1.0, motion=Motion(gap=0.1)).motion.load, Constant)


# ---------------------------------------------------------------------------
# the example runs (short)


def test_example_runs(tmp_path):
    path = Path(__file__).resolve().parents[1] / "examples" / "cylinder_winkler.py"
    spec = importlib.util.spec_from_file_location("cylinder_winkler", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    out = mod.main(t_end=15.0, dt=0.2, n_elements=200, outdir=tmp_path, verbose=False)
    assert out["film_error"] < 1e-2 and out["load_error"] < 1e-4
    assert Path(out["png"]).is_file()


def test_negative_line_load_is_refused_up_front():
    """The film cannot pull: a load history going negative is refused when the scene is built."""
    with pytest.raises(SceneError, match=r"F\(t=1\.7\) = -0\.01 is negative"):
        LineScene(load=Table([0.0, 1.0, 2.0], [0.5, 0.2, -0.1]))
    with pytest.raises(SceneError, match="negative"):
        LineScene(load=-1.0)
