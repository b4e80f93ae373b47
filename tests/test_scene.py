"""Tests of femehl.problem.scene, femehl.presets and femehl.solver.stepping.march.

Invalid values must raise :class:`femehl.errors.SceneError` (a ValueError)
whose message names the fix; the SI conversion is checked against the
paper's definitions (Eq. 8, 10e) written out by hand; the time loop is
checked with a stub stepper (exact bookkeeping) and with the FD solver on a
rigid substrate, where the film is known in closed form (w = 0, d = hc + r^2/2).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from femehl import api
from femehl.errors import FilmRuptureError, SceneError, SolverError
from femehl.problem.presets import paper_sphere
from femehl.problem.scene import (
    Constant,
    Dimensional,
    Domain,
    Fluid,
    HalfSpace,
    Motion,
    RampHold,
    Rigid,
    Scene,
    Sphere,
    Table,
    TanhStart,
    Winkler,
)
from femehl.solver.stepping import State, check_run, march


def test_scene_error_is_value_error():
    assert issubclass(SceneError, ValueError)


# ---------------------------------------------------------------------------
# invalid values


@pytest.mark.parametrize("h0", [-0.1, 0.0])
def test_paper_sphere_rejects_nonpositive_h0(h0):
    with pytest.raises(SceneError, match=r"h0 must be > 0.*(gap|h0 = 0\.1)"):
        paper_sphere(h0=h0)


@pytest.mark.parametrize("h0", [-0.1, 0.0])
def test_scene_rejects_nonpositive_initial_gap(h0):
    """The Scene itself (not only the preset) checks hc(0) > 0 and says to start with a gap."""
    with pytest.raises(SceneError, match=r"must be > 0.*[Ss]tart with a positive gap"):
        Scene(motion=Motion(gap=RampHold(h0=h0, h_end=-1.0, t1=1.0)))
    with pytest.raises(SceneError, match=r"positive gap"):
        Scene(motion=Motion(gap=Table([0.0, 1.0], [h0, -1.0])))


@pytest.mark.parametrize("beta", [0.0, -200.0])
def test_beta_nonpositive(beta):
    with pytest.raises(SceneError, match=r"beta must be > 0.*Dimensional"):
        Fluid(beta)
    with pytest.raises(SceneError, match=r"beta must be > 0"):
        paper_sphere(beta=beta)


@pytest.mark.parametrize("beta", [math.nan, math.inf, -math.inf])
def test_beta_not_finite(beta):
    with pytest.raises(SceneError, match=r"beta must be finite"):
        Fluid(beta)


@pytest.mark.parametrize("beta", ["fast", None, [1.0]])
def test_beta_not_a_number(beta):
    with pytest.raises(SceneError, match=r"beta must be a real number"):
        Fluid(beta)


@pytest.mark.parametrize("R", [-1.0, 0.0, math.nan])
def test_sphere_radius(R):
    with pytest.raises(SceneError, match=r"Sphere radius R must be.*Use R = 1"):
        Sphere(R)


@pytest.mark.parametrize("nu", [0.5000001, 0.6, -1.0, -2.0, math.nan])
def test_poisson_ratio_out_of_range(nu):
    with pytest.raises(SceneError, match=r"Poisson ratio nu must"):
        HalfSpace(nu)


@pytest.mark.parametrize("nu", [0.5, 0.3, 0.0, -0.99])
def test_poisson_ratio_in_range(nu):
    """compliance 2(1 - nu): the factor 1/G -> 2(1 - nu)/G of docs/design.md, section 1."""
    assert HalfSpace(nu).compliance == pytest.approx(2 * (1 - nu))


def test_domain_too_small_for_contact():
    """hc = -1 makes a Hertz contact of radius sqrt(R |hc|) = 1; L = 1.2 < 1.5 a is refused."""
    with pytest.raises(SceneError, match=r"too small to hold the contact.*Use L >= 1\.5"):
        paper_sphere(L=1.2)
    paper_sphere(L=1.55)  # just above the limit 1.5 is accepted


def test_domain_check_only_for_indentation():
    """A run that never indents (hc >= 0) accepts a small domain."""
    sc = Scene(
        substrate=Rigid(), motion=Motion(gap=RampHold(1.0, 0.2, 1.0), velocity=0.0), domain=Domain(0.5)
    )
    assert sc.domain.L == 0.5


@pytest.mark.parametrize("L", [0.0, -2.0, math.inf])
def test_domain_radius(L):
    with pytest.raises(SceneError, match=r"Domain radius L must"):
        Domain(L)


@pytest.mark.parametrize(
    "times, values, msg",
    [
        ([], [], r"Table is empty: give at least one"),
        ([0.0, 1.0, 1.0], [0.1, 0.0, -1.0], r"strictly increasing: sort the rows"),
        ([0.0, 2.0, 1.0], [0.1, 0.0, -1.0], r"strictly increasing"),
        ([0.0, math.nan], [0.1, -1.0], r"finite \(no NaN or inf\)"),
        ([0.0, 1.0], [0.1, math.nan], r"finite \(no NaN or inf\)"),
        ([0.0, 1.0], [0.1, math.inf], r"finite"),
        ([0.0, 1.0, 2.0], [0.1, -1.0], r"3 times but 2 values: give one value per time"),
        (["a", "b"], [0.1, 0.2], r"must hold real numbers"),
    ],
)
def test_table_invalid(times, values, msg):
    with pytest.raises(SceneError, match=msg):
        Table(times, values)


def test_table_interpolates_and_holds():
    f = Table([0.0, 1.0, 3.0], [0.1, -1.0, -1.0])
    assert f(0.5) == pytest.approx(0.1 + 0.5 * (-1.1))
    assert f(-1.0) == pytest.approx(0.1) and f(10.0) == pytest.approx(-1.0)


@pytest.mark.parametrize("bad", ["fast", None, [0.0, 1.0], True])
def test_velocity_not_callable(bad):
    with pytest.raises(SceneError, match=r"velocity V\(t\) must be a number or a callable"):
        Motion(velocity=bad)


def test_gap_not_callable():
    with pytest.raises(SceneError, match=r"gap hc\(t\) must be a number or a callable"):
        Motion(gap="down")


def test_time_function_returning_nan():
    """A callable that returns NaN is caught when it is evaluated (here at t = 0 by the Scene)."""
    with pytest.raises(SceneError, match=r"finite values"):
        Scene(motion=Motion(gap=lambda t: math.nan))


@pytest.mark.parametrize(
    "kw, msg",
    [
        (dict(t1=0.0), r"t1 \(end of the ramp\) must be > 0"),
        (dict(h0=math.nan), r"h0 must be finite"),
    ],
)
def test_rampHold_invalid(kw, msg):
    with pytest.raises(SceneError, match=msg):
        RampHold(**kw)


def test_tanh_start_invalid():
    with pytest.raises(SceneError, match=r"T \(sliding ramp time\) must be > 0"):
        TanhStart(T=0.0)


def test_scene_component_types():
    with pytest.raises(SceneError, match=r"Scene.fluid must be a Fluid"):
        Scene(fluid=200.0)
    with pytest.raises(SceneError, match=r"gap\(x, y\) method"):
        Scene(indenter=object())


def test_winkler_stiffness():
    with pytest.raises(SceneError, match=r"Winkler stiffness k must be > 0"):
        Winkler(0.0)


# ---------------------------------------------------------------------------
# the paper case and its time functions


def test_paper_sphere_histories():
    """Eq. 12: hc = h0 - (1 + h0) t for t <= 1, -1 after; V = tanh(t - 1) for t >= 1."""
    sc = paper_sphere()
    for t in (0.0, 0.3, 1.0, 2.5):
        assert sc.motion.hc(t) == pytest.approx(0.1 - 1.1 * t if t <= 1 else -1.0, abs=1e-15)
        assert sc.motion.V(t) == pytest.approx(0.0 if t < 1 else math.tanh(t - 1), abs=1e-15)
    assert sc.fluid.beta == 200.0 and sc.domain.L == 2.0
    assert isinstance(sc.substrate, HalfSpace) and sc.substrate.compliance == 1.0


# ---------------------------------------------------------------------------
# SI <-> normalized

SI = dict(R=5e-3, G=1e5, eta=0.1, V_ss=1e-3, h_inf=2e-5, nu=0.5)


def test_dimensional_beta_by_hand():
    """beta = (2/3)(h_inf^2/R)(pi G)/(eta V_ss) = (2/3)(4e-10/5e-3)(pi 1e5)/(1e-4)
    = (2/3) * 8e-8 * pi * 1e9 = 160 pi / 3 = 167.55..."""
    dim = Dimensional(**SI)
    assert dim.beta == pytest.approx(160 * math.pi / 3, rel=1e-14)
    # the other scales of Eq. 8
    assert dim.length == pytest.approx(math.sqrt(1e-7), rel=1e-14)  # sqrt(R h_inf)
    assert dim.height == 2e-5
    assert dim.time == pytest.approx(2 * math.sqrt(1e-7) / 1e-3, rel=1e-14)  # 2 sqrt(R h_inf)/V
    assert dim.pressure == pytest.approx(4 * math.pi * 1e5 * math.sqrt(2e-5 / 5e-3), rel=1e-14)
    assert dim.force == pytest.approx(dim.pressure * 1e-7, rel=1e-14)


def test_dimensional_hertz_consistency():
    """docs/design.md, section 7: F = (16/3) G sqrt(R) delta^(3/2) at delta = h_inf must be the
    normalized Hertz load 4/(3 pi) times the force scale, and p0 = (8 G/pi) sqrt(delta/R)
    must be 2/pi^2 times the pressure scale.  Checks the scales against an independent law."""
    dim = Dimensional(**SI)
    F_si = 16 / 3 * SI["G"] * math.sqrt(SI["R"]) * SI["h_inf"] ** 1.5
    p0_si = 8 * SI["G"] / math.pi * math.sqrt(SI["h_inf"] / SI["R"])
    assert float(dim.from_si("force", F_si)) == pytest.approx(4 / (3 * math.pi), rel=1e-13)
    assert float(dim.from_si("pressure", p0_si)) == pytest.approx(2 / math.pi**2, rel=1e-13)


@pytest.mark.parametrize("q", ["length", "height", "time", "pressure", "force", "velocity"])
def test_to_si_from_si_round_trip(q):
    dim = Dimensional(**SI)
    v = np.array([0.0, 0.37, -2.5, 1e3])
    np.testing.assert_allclose(dim.from_si(q, dim.to_si(q, v)), v, rtol=1e-14, atol=0)
    assert float(dim.to_si(q, 1.0)) == pytest.approx(getattr(dim, q), rel=1e-15)


def test_to_si_unknown_quantity():
    with pytest.raises(SceneError, match=r"unknown quantity 'speed'; choose one of"):
        Dimensional(**SI).to_si("speed", 1.0)


def test_dimensional_scene():
    """Dimensional.scene gives the paper experiment with this beta and h0/h_inf, t1 in time units."""
    dim = Dimensional(**SI)
    sc = dim.scene(h0=2e-6, t1=2 * dim.time)
    assert isinstance(sc, Scene)
    assert sc.fluid.beta == pytest.approx(160 * math.pi / 3, rel=1e-14)
    assert sc.motion.hc(0.0) == pytest.approx(0.1, rel=1e-14)
    assert sc.motion.hc(2.0) == pytest.approx(-1.0) and sc.motion.hc(1.0) == pytest.approx(-0.45)
    assert sc.motion.V(1.9) == 0.0 and sc.motion.V(4.0) == pytest.approx(math.tanh(1.0))
    assert sc.substrate.compliance == pytest.approx(1.0)
    sc2 = dim.scene(h0=2e-6)
    assert sc2.motion.hc(1.0) == pytest.approx(-1.0) and sc2.domain.L == 2.0


@pytest.mark.parametrize(
    "key, value, msg",
    [
        ("R", -1.0, r"R \[SI\] must be > 0"),
        ("G", 0.0, r"G \[SI\] must be > 0"),
        ("eta", math.nan, r"eta \[SI\] must be finite"),
        ("V_ss", -1e-3, r"V_ss \[SI\] must be > 0"),
        ("h_inf", math.inf, r"h_inf \[SI\] must be finite"),
        ("nu", 0.7, r"Poisson ratio nu must lie in"),
    ],
)
def test_dimensional_invalid(key, value, msg):
    kw = dict(SI)
    kw[key] = value
    with pytest.raises(SceneError, match=msg):
        Dimensional(**kw)


def test_dimensional_scene_invalid_h0():
    with pytest.raises(SceneError, match=r"h0 \[m\] \(initial clearance\) must be > 0"):
        Dimensional(**SI).scene(h0=-1e-6)
    with pytest.raises(SceneError, match=r"t1 \[s\] must be > 0"):
        Dimensional(**SI).scene(h0=1e-6, t1=0.0)


# ---------------------------------------------------------------------------
# immutability and effects


def test_scene_is_frozen():
    sc = paper_sphere()
    with pytest.raises(dataclasses.FrozenInstanceError):
        sc.fluid = Fluid(1.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        sc.fluid.beta = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        sc.domain.L = 3.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        sc.motion.gap = Constant(0.5)
    with pytest.raises(dataclasses.FrozenInstanceError):
        Dimensional(**SI).R = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        Table([0.0], [1.0]).values = (2.0,)


def test_effects_paper_case():
    eff = paper_sphere().effects(5.0)
    assert eff["squeeze"] is True and eff["sliding"] is True
    assert eff["elasticity"] == "halfspace"
    # the paper's sliding starts at t = 1: a run to t = 0.9 has none
    eff = paper_sphere().effects(0.9)
    assert eff["squeeze"] is True and eff["sliding"] is False


def test_effects_static_scene():
    sc = Scene(substrate=Rigid(), motion=Motion(gap=0.5, velocity=0.0))
    eff = sc.effects(5.0)
    assert (eff["squeeze"], eff["sliding"], eff["elasticity"]) == (False, False, "rigid")
    # pure sliding at constant gap on a Winkler foundation
    eff = Scene(substrate=Winkler(2.0), motion=Motion(gap=Constant(0.5), velocity=1.0)).effects(1.0)
    assert (eff["squeeze"], eff["sliding"], eff["elasticity"]) == (False, True, "winkler")


# ---------------------------------------------------------------------------
# stepping.march


class StubStepper:
    """Records the (t_new, dt) it is asked for; film always positive."""

    method = "stub"

    def __init__(self, film=lambda t: 1.0):
        self.calls = []
        self.film = film

    def _state(self, step, t):
        z = np.zeros(1)
        return State(
            step=step,
            t=t,
            hc=0.0,
            V=0.0,
            p=z,
            w=z,
            d=z + self.film(t),
            load=0.0,
            film_center=self.film(t),
            film_min=self.film(t),
            film_min_at=(0.0, 0.0),
            p_max=0.0,
            p_max_at=(0.0, 0.0),
        )

    def initial_state(self):
        return self._state(0, 0.0)

    def step(self, state, t_new, dt):
        self.calls.append((t_new, dt))
        assert t_new == pytest.approx(state.t + dt, abs=1e-15)
        return self._state(state.step + 1, t_new)


def test_march_initial_then_one_per_step():
    stub = StubStepper()
    states = list(march(stub, 1.0, 0.25))
    assert [s.step for s in states] == [0, 1, 2, 3, 4]
    assert [s.t for s in states] == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert len(stub.calls) == 4


@pytest.mark.parametrize(
    "t_end, dt, n", [(1.0, 0.3, 4), (0.7, 0.2, 4), (1.0, 0.4, 3), (0.3, 0.1, 3), (2.0, 0.7, 3)]
)
def test_march_ends_exactly_at_t_end(t_end, dt, n):
    """t_end/dt not an integer: the last step is shortened and the run ends exactly at t_end.
    (0.3/0.1 = 2.9999999999999996 in floating point: still 3 steps.)"""
    stub = StubStepper()
    states = list(march(stub, t_end, dt))
    assert len(states) == n + 1
    assert states[-1].t == t_end
    assert all(h == pytest.approx(dt, rel=1e-12) for _, h in stub.calls[:-1])
    assert 0 < stub.calls[-1][1] <= dt * (1 + 1e-12)
    assert stub.calls[-1][1] == pytest.approx(t_end - (n - 1) * dt, rel=1e-9)


@settings(max_examples=200, deadline=None)
@given(st.floats(1e-3, 10.0), st.floats(1e-3, 1.0))
def test_march_property(t_end, frac):
    """Times strictly increase by at most dt, the count is ceil(t_end/dt) (to 1e-9 of a
    step), and the last time is t_end to within 1e-9 dt."""
    dt = t_end * frac
    stub = StubStepper()
    ts = [s.t for s in march(stub, t_end, dt)]
    assert ts[0] == 0.0
    steps = np.diff(ts)
    assert np.all(steps > 0) and np.all(steps <= dt * (1 + 1e-12))
    assert abs(ts[-1] - t_end) <= 1e-9 * dt
    assert len(ts) - 1 in (math.floor(t_end / dt + 1e-9), math.ceil(t_end / dt - 1e-9))


@pytest.mark.parametrize(
    "t_end, dt, msg",
    [
        (1.0, 0.0, r"dt must be > 0.*positive time step"),
        (1.0, -0.1, r"dt must be > 0"),
        (0.0, 0.1, r"t_end must be > 0"),
        (-1.0, 0.1, r"t_end must be > 0"),
        (math.nan, 0.1, r"t_end must be finite"),
        (1.0, math.inf, r"dt must be finite"),
        (0.1, 0.2, r"larger than t_end.*use dt <= t_end"),
        (1e3, 1e-5, r"too many: increase dt"),
    ],
)
def test_check_run_invalid(t_end, dt, msg):
    with pytest.raises(SceneError, match=msg):
        check_run(t_end, dt)
    with pytest.raises(SceneError, match=msg):
        next(march(StubStepper(), t_end, dt))


def test_march_raises_on_zero_film_stub():
    """The stub's film 0.35 - t reaches <= 0 between t = 0.3 and 0.4."""
    stub = StubStepper(film=lambda t: 0.35 - t)
    got = []
    with pytest.raises(FilmRuptureError) as exc:
        for s in march(stub, 1.0, 0.1):
            got.append(s)
    assert [round(s.t, 12) for s in got] == [0.0, 0.1, 0.2, 0.3]
    assert exc.value.t == pytest.approx(0.4)
    assert exc.value.d_min == pytest.approx(-0.05)


def test_film_rupture_rigid_substrate():
    """Rigid substrate, gap ramp 0.5 -> -0.5 over t in [0, 1]: w = 0, so the film at the tip
    is exactly d = hc(t) = 0.5 - t.  With dt = 0.15 the first non-positive film is at
    t = 0.6 (d = -0.1) at the tip (0, 0); the states before are valid (finite, positive,
    film_center = hc because w = 0)."""
    sc = Scene(
        substrate=Rigid(),
        fluid=Fluid(1.0),
        motion=Motion(gap=RampHold(h0=0.5, h_end=-0.5, t1=1.0), velocity=0.0),
        domain=Domain(2.0),
    )
    got = []
    with pytest.raises(FilmRuptureError, match=r"film thickness reached.*smaller dt") as exc:
        for s in api.steps(sc, 1.0, 0.15, "fd", dr=0.1, dtheta=math.pi / 4):
            got.append(s)
    err = exc.value
    assert isinstance(err, SolverError) and isinstance(err, RuntimeError)
    assert err.t == pytest.approx(0.6, abs=1e-12)
    assert err.where == pytest.approx((0.0, 0.0), abs=1e-12)
    assert err.d_min == pytest.approx(-0.1, abs=1e-12)
    assert [round(s.t, 12) for s in got] == [0.0, 0.15, 0.3, 0.45]
    for s in got:
        assert np.all(np.isfinite(s.p)) and np.all(np.isfinite(s.d))
        assert np.all(s.w == 0.0)
        assert s.film_min > 0 and s.film_center == pytest.approx(0.5 - s.t, abs=1e-12)
        assert s.film_min == pytest.approx(s.film_center, abs=1e-12)
        if s.step > 0:
            assert s.load > 0  # squeeze pressure under a closing gap
