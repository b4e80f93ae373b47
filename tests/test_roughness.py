"""Rough surfaces (femehl.Roughness): asperity contact through the lagged step.

Checked against independent solutions: the Greenwood-Tripp function by quadrature
(femehl.reference.rough_contact), the dry rough contact of a line on a Winkler foundation
(a scalar equation per point, solved here by brentq) and of a sphere on the half space
(the reference's axisymmetric Newton solve); the smooth limit; the energy budget.
"""

from __future__ import annotations

import functools
import math
import pathlib

import numpy as np
import pytest
from scipy.optimize import brentq

import femehl
from femehl import Fluid, Motion, RampHold, Roughness, Scene
from femehl.errors import SceneError, SceneFileError
from femehl.problem.line import LineScene
from femehl.problem.roughness import RESIDUAL, greenwood_tripp, mean_gap
from femehl.reference import rough_contact as ref
from femehl.solver.adaptive import AdaptiveSteps
from femehl.solver.energetics import sliding_energetics


def test_greenwood_tripp_by_parabolic_cylinder_functions_against_quadrature():
    """The solver's F_n is a spline of log F_n on knots 0.01 apart, its values from scipy's pbdv;
    its slope -n F_{n-1} one of log F_{n-1}; checked between the knots against the reference's
    quadrature (5e-14 against mpmath).  Interpolation: about h^4 max|(log F)^(4)| / 384 = 3e-11
    (measured 2.2e-10: pbdv's own error at the knots); pbdv is 3.4e-9 off near t = 5.8, where
    F_{5/2} is 1e-10 of its scale."""
    t = np.linspace(-30.0, 30.0, 6001) + 0.0037  # between the knots
    near = np.abs(t - 5.8) < 0.5
    for n in (2.5, 1.5):
        F, dF = greenwood_tripp(t, n)
        eF = np.abs(F / ref.greenwood_tripp(t, n) - 1.0)
        edF = np.abs(dF / ref.greenwood_tripp_derivative(t, n) - 1.0)
        assert eF[~near].max() < 5e-10 and edF[~near].max() < 5e-10, (eF[~near].max(), edF[~near].max())
        assert eF[near].max() < 5e-9 and edF[near].max() < 5e-9
    F, dF = greenwood_tripp(np.array([-50.0, -40.0]), 2.5)  # continued by the tangent, finite
    assert np.all(np.isfinite(F)) and np.all(dF < 0) and F[0] > F[1]


def test_mean_gap_limits_and_slope():
    """The expected local gap over Gaussian heights, plus the residual film in full contact."""
    sigma, eps = 0.05, RESIDUAL
    h, slope, wet = mean_gap(np.array([0.0, 10 * sigma, -10 * sigma]), sigma)
    assert h[0] == pytest.approx(sigma * (1 / math.sqrt(2 * math.pi) + eps / 2), rel=1e-14)
    assert h[1] == pytest.approx(10 * sigma, rel=1e-15) and slope[1] == pytest.approx(1.0, abs=1e-15)
    assert h[2] == pytest.approx(eps * sigma, rel=1e-12) and wet[2] < 1e-20
    d = np.linspace(-3 * sigma, 3 * sigma, 13)
    step = 1e-6 * sigma
    fd = (mean_gap(d + step, sigma)[0] - mean_gap(d - step, sigma)[0]) / (2 * step)
    assert np.allclose(fd, mean_gap(d, sigma)[1], rtol=1e-8, atol=1e-12)
    assert np.all(mean_gap(np.linspace(-30, 30, 601) * sigma, sigma)[1] > 0)  # h rises with d


def _line_dry(rough, k, hc, x):
    """The dry rough contact of the cylinder on Winkler(k) at hc: P = p_a(hc + x^2/2 + P/k)."""

    def P(xi):
        top = rough.pressure(hc + xi * xi / 2)[0]
        return (
            0.0 if top < 1e-300 else brentq(lambda q: q - rough.pressure(hc + xi * xi / 2 + q / k)[0], 0, top)
        )

    return np.array([P(xi) for xi in x])


@pytest.mark.parametrize("k, hc", [(1.0, -0.1), (10.0, -0.3)])
def test_zero_speed_line_is_the_dry_rough_contact(k, hc):
    """No sliding, the gap held: the film drains and the asperities carry the whole load, as the
    independent pointwise solution says; at k = 10 the mean separation goes below zero (through
    contact, where a smooth film would have to close)."""
    rough = Roughness(sigma=0.05, stiffness=2.0)
    scene = LineScene(
        k=k, L=2.0, beta=1e4, motion=Motion(gap=RampHold(0.2, hc, 1.0), velocity=0.0), roughness=rough
    )
    res = femehl.solve(scene, t_end=30.0, n_elements=400, step_tol=1e-4, estimate=False)
    x = np.linspace(-2, 2, 4001)
    load = np.trapezoid(_line_dry(rough, k, hc, x), x)
    assert res.value_at("load", 30.0) / load - 1 == pytest.approx(0.0, abs=2e-4)  # measured 4.4e-5 (k = 1)
    assert res.value_at("asperity_share", 30.0) == pytest.approx(1.0, abs=1e-6)
    if k == 10.0:
        assert res.value_at("film_min", 30.0) < 0.0  # the mean planes overlap: the asperities carry it


@pytest.mark.parametrize("cavitation", [None, "reynolds"])
@pytest.mark.parametrize("k, hc", [(1.0, 0.02), (10.0, 0.01), (10.0, -0.3)])
def test_a_line_started_in_contact_starts_on_its_asperities(k, hc, cavitation):
    """The gap held from t = 0 with the asperities pressing: the run starts at rest (the
    film at ambient pressure, the substrate on the asperities: the pointwise dry contact)
    and nothing moves after, with or without the Reynolds condition (a start undeformed
    under that condition was no equilibrium); at hc = -0.3 (-6 sigma) the mean planes
    overlap from the start.  Measured: 7.0e-5 and 7.1e-5 of the peak pressure on 400
    elements; the load after 25 steps within 4e-14 of the start's."""
    rough = Roughness(sigma=0.05, stiffness=2.0)
    motion = Motion(gap=hc, velocity=0.0)
    scene = LineScene(k=k, L=2.0, beta=1e4, motion=motion, roughness=rough, cavitation=cavitation)
    res = femehl.solve(scene, t_end=1.0, n_elements=400, step_tol=1e-4, estimate=False)
    start, exact = res.states[0], _line_dry(rough, k, hc, res.disc.x)
    assert np.max(np.abs(start.p - exact)) / exact.max() < 2e-4
    assert start.info["asperity_share"] == pytest.approx(1.0, abs=1e-12)
    assert res.load[-1] / res.load[0] - 1 == pytest.approx(0.0, abs=1e-10)


@pytest.mark.parametrize("cavitation", [None, "reynolds"])
def test_a_line_started_in_contact_under_load_carries_it(cavitation):
    """Under an imposed load the start at rest carries ``F(0)``: hc is one more unknown of
    the static contact (measured: the pointwise dry contact at that hc carries the load to
    4.5e-5, the pressure 1.3e-4 of its peak; hc moves by 2e-16 over 25 steps).  At
    ``F(0) = 0`` the indenter starts where the asperities do not touch, and the run under
    the Reynolds condition goes on (it stopped at the step floor at t = 5e-7)."""
    rough, x = Roughness(0.05, 2.0), np.linspace(-2.5, 2.5, 5001)
    for F0 in (0.3, 0.0):
        motion = Motion(gap=0.02, velocity=0.05, load=RampHold(F0, 0.3, 1.0))
        scene = LineScene(k=1.0, L=2.5, beta=10.0, motion=motion, roughness=rough, cavitation=cavitation)
        res = femehl.solve(scene, t_end=0.5, n_elements=400, step_tol=1e-4, estimate=False)
        start = res.states[0]
        assert start.load == pytest.approx(F0, abs=1e-12)
        if F0 > 0.0:
            dry = np.trapezoid(_line_dry(rough, 1.0, start.hc, x), x)
            assert dry / F0 - 1 == pytest.approx(0.0, abs=2e-4)
            assert res.t[1] > 0.0 and abs(res.hc[1] - start.hc) < 1e-3  # no jump
        else:
            lowest = start.info["film_points_min"]  # where the lift is measured
            assert lowest == pytest.approx(8.5 * rough.sigma, rel=1e-12) and start.p.max() == 0.0
        assert res.t[-1] == pytest.approx(0.5)


def test_a_free_indenter_started_in_contact_starts_where_it_is():
    """A free indenter's position is its initial condition: it starts at hc(0), on the
    asperities' static contact there (its load then accelerates it)."""
    rough = Roughness(0.05, 2.0)
    motion = Motion(gap=0.02, velocity=0.0, mass=1.0, force=0.05)
    res = femehl.solve(
        LineScene(k=1.0, L=2.0, beta=1e4, motion=motion, roughness=rough),
        t_end=0.05,
        n_elements=400,
        dt=0.01,
        estimate=False,
    )
    start, exact = res.states[0], _line_dry(rough, 1.0, 0.02, res.disc.x)
    assert start.hc == 0.02 and np.max(np.abs(start.p - exact)) / exact.max() < 2e-4


@pytest.mark.parametrize("cavitation", [None, "reynolds"])
def test_a_viscoelastic_line_started_in_contact_creeps_from_glassy_to_relaxed(cavitation):
    """A viscoelastic Winkler line (J0 = 0.5, J_inf = 1, creep time 1) started on its
    asperities: the load is put on at t = 0, so the start is the dry contact of the glassy
    solid (k / J0), and under the held gap the solid creeps to the relaxed one's (k / J_inf)
    by t = 20.  Measured: 7.1e-5 and 7.0e-5 of the peak pressure against the pointwise
    solutions, with and without the Reynolds condition (which stopped at the step floor in
    the first steps when the start was undeformed)."""
    rough = Roughness(0.05, 2.0)
    solid = femehl.Viscoelastic(G0=2.0, G_inf=1.0, tau=0.5)
    motion = Motion(gap=0.02, velocity=0.0)
    scene = LineScene(
        k=1.0, L=2.0, beta=1e4, motion=motion, roughness=rough, cavitation=cavitation, viscoelastic=solid
    )
    res = femehl.solve(scene, t_end=20.0, n_elements=400, step_tol=1e-4, estimate=False)
    for state, k in ((res.states[0], 2.0), (res.states[-1], 1.0)):
        exact = _line_dry(rough, k, 0.02, res.disc.x)
        assert np.max(np.abs(state.p - exact)) / exact.max() < 2e-4


def test_a_sphere_started_in_contact_starts_on_its_asperities():
    """The sphere's start on its asperities (Reynolds condition) against the axisymmetric
    Newton solution (femehl.reference): second order in the mesh size (measured 1.26 % on
    the coarse ladder mesh, 0.57 % on the medium, 0.31 % on the fine), and at rest after
    (the load within 5e-10 over 0.5 time units)."""
    sigma, K, hc = 0.1, 1.0, 0.05
    motion = Motion(gap=hc, velocity=0.0)
    scene = Scene(fluid=Fluid(1e5, cavitation="reynolds"), motion=motion, roughness=Roughness(sigma, K))
    reference = ref.rough_sphere_contact(hc, sigma, K, L=2.0).load
    coarse = femehl.solve(scene, t_end=0.5, mesh="coarse", step_tol=1e-4, estimate=False)
    medium = femehl.solve(scene, t_end=0.01, mesh="medium", dt=0.01, estimate=False)
    errors = [abs(r.load[0] / reference - 1) for r in (coarse, medium)]
    assert errors[0] < 2e-2 and errors[0] / errors[1] > 1.8
    assert coarse.load[-1] / coarse.load[0] - 1 == pytest.approx(0.0, abs=1e-8)


def test_automatic_mode_on_a_stress_case_started_in_contact():
    """The stress matrix's beta = 2, h0 = 0.01 sphere (its film closes when smooth) with a
    roughness of 2 films and the Reynolds condition, started with its asperities pressing,
    on the default path: it reaches the tolerance and agrees with an expert run on the fine
    ladder mesh (BDF2, dt = 0.005) within the tolerance plus that run's own estimate.  Before
    the start at rest every run finer than the first stopped at the step floor at t ~ 1e-7.
    Measured: load 0.31 %, films 0.11 %, in 1.5 s (two runs)."""
    tol, t_end = 5e-2, 0.4
    scene = Scene(  # benchmarks/stress.py's paper_scene(2, 0.01, 0.1), rough
        indenter=femehl.Sphere(1.0),
        substrate=femehl.HalfSpace(0.5),
        fluid=Fluid(2.0, cavitation="reynolds"),
        motion=Motion(gap=RampHold(0.01, -1.0, 1.0), velocity=femehl.TanhStart(t1=1.0, T=0.1)),
        domain=femehl.Domain(2.0),
        roughness=Roughness(0.02, 2.0),
    )
    auto = femehl.solve(scene, t_end=t_end, tol=tol)
    assert auto.info["auto"]["reached"] and len(auto.info["auto"]["levels"]) >= 2
    # the start's Newton steps stop at a change of 1e-8 of the pressure, and each of their
    # linear solves leaves a residual of 1e-8 (the Krylov rtol): measured 2.6e-9 and 1.1e-8 on
    # the meshes of two versions' automatic runs
    assert auto.states[0].info["asperity_share"] == pytest.approx(1.0, abs=3e-8)
    expert = femehl.solve(scene, t_end=t_end, dt=0.005, mesh="fine", scheme="bdf2")
    for name in ("load", "film_center", "film_min"):
        got, want = auto.value_at(name, t_end), expert.value_at(name, t_end)
        own = expert.uncertainty(name, t_end)["total"]
        assert abs(got / want - 1) <= tol + own, (name, got, want, own)


@pytest.mark.parametrize(
    "indenter, operator",
    [
        (femehl.Sphere(), "dense"),
        pytest.param(femehl.Shape(lambda x, y: (x * x + y * y) / 2), "dense", marks=pytest.mark.slow),
        pytest.param(femehl.Sphere(), "fast", marks=pytest.mark.slow),
    ],
    ids=["half disk", "full disk", "fast operator"],
)
def test_zero_speed_sphere_is_the_rough_contact_reference(indenter, operator):
    """The FE disk (coarse ladder mesh, half space) at rest under a held gap, against the
    axisymmetric Newton solution of the same Greenwood-Tripp law (femehl.reference); the
    sphere as a Shape with no symmetry declared runs on the full disk; the fast (H^2)
    operator forms the rough correction's products with its sparse near field. Measured:
    4.9e-4 (half; the fast operator's within 1e-10 of it), 4.8e-4 (full, 2,876 cells), 2.2e-4
    on the medium half disk."""
    sigma, K, hc = 0.1, 1.0, -0.5
    scene = Scene(
        indenter=indenter,
        fluid=Fluid(beta=1e5),
        motion=Motion(gap=RampHold(0.2, hc, 1.0), velocity=0.0),
        roughness=Roughness(sigma, K),
    )
    res = femehl.solve(scene, t_end=5.0, mesh="coarse", step_tol=1e-4, estimate=False, operator=operator)
    assert res.info["half"] == isinstance(indenter, femehl.Sphere) and res.info["operator"] == operator
    reference = ref.rough_sphere_contact(hc, sigma, K, L=2.0)
    assert res.value_at("load", 5.0) / reference.load - 1 == pytest.approx(0.0, abs=1.5e-3)
    assert res.value_at("asperity_share", 5.0) == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("cavitation", [None, "reynolds"])
def test_thick_film_is_the_smooth_run(cavitation):
    """Far from contact (film >= 15 sigma) the roughness changes nothing: F_{5/2}(15) ~ 1e-52;
    with the Reynolds condition too (its held rows hold the film's pressure, here all of it)."""
    motion = Motion(gap=0.1, velocity=1.0, load=RampHold(0.0, 0.5, 1.0))
    runs = [
        femehl.solve(
            LineScene(k=1.0, beta=10.0, motion=motion, roughness=r, cavitation=cavitation),
            t_end=3.0,
            n_elements=200,
            dt=0.01,
            estimate=False,
        )
        for r in (None, Roughness(sigma=0.005, stiffness=1.0))
    ]
    assert runs[1].film_min.min() > 15 * 0.005
    for q in ("load", "film_min", "film_center", "friction", "hc"):
        assert np.allclose(getattr(runs[1], q), getattr(runs[0], q), rtol=1e-10, atol=1e-14)
    assert np.all(runs[1].asperity_load < 1e-80)  # F_{5/2}(20) at the start
    if cavitation:
        area = [r.value_at("cavitated_area", 3.0) for r in runs]
        assert area[0] > 0.1 and area[1] == pytest.approx(area[0], rel=1e-12)


@functools.cache  # the same steady state serves the budget and the cavitation test
def _mixed_steady(srr, n=400, T=60.0, cavitation=None, tol=1e-5):
    rough = Roughness(sigma=0.05, stiffness=2.0, friction=0.1, aspect=0.5)
    motion = Motion(gap=0.6, velocity=0.05, slide_roll=srr, load=RampHold(0.0, 0.5, 1.0))
    scene = LineScene(k=1.0, L=2.5, beta=10.0, motion=motion, roughness=rough, cavitation=cavitation)
    stepper = femehl.make_stepper(scene, n_elements=n, scheme="bdf2")
    state = list(femehl.march(stepper, T, AdaptiveSteps(tol=tol, dt0=1e-3)))[-1]
    speeds = scene.motion.surface_speeds(T)
    e = sliding_energetics(stepper.disc, state, scene.fluid.beta, speeds, **stepper.roughness.budget(state))
    return state, speeds, e, stepper


@pytest.mark.parametrize("srr, tol", [(2.0, 5e-4), (0.0, 2e-3)])
def test_energy_budget_of_a_mixed_steady_state(srr, tol):
    """f U_s - T U_i = D_film + P_sliding + D_solid + power_roughness (design.md section 16),
    at a steady state where the asperities carry about 3/4 of the load; the remainder is the
    discretization's (200 / 400 / 800 elements at SRR 0: 1.8e-3 / 8.4e-4 / 5.9e-4)."""
    state, (Ui, Us), e, _ = _mixed_steady(srr)
    assert 0.6 < state.info["asperity_share"] < 0.85
    shear = e["shear_couette"] + e["shear_poiseuille"] + state.info["asperity_friction"]
    power = e["friction"] * Us - shear * Ui
    assert e["dissipation_solid"] == pytest.approx(0.2 * (Us - Ui) * state.info["asperity_load"], rel=1e-12)
    spent = e["dissipation_film"] + e["power_sliding"] + e["dissipation_solid"] + e["power_roughness"]
    assert abs(power - spent) < tol * power


def test_cavitated_rows_hold_the_film_pressure():
    """Reynolds cavitation on a rough film: ``p_film = P - p_a >= 0``, held at 0 on the
    cavitated set, where the asperities carry the whole pressure; without the film's
    tension behind the contact the asperities carry less of the load than in full
    Sommerfeld (0.66 against 0.74 here)."""
    # tol 1e-4: the same end state as 1e-5 (tests/test_rough_line_reference.py), at a fifth of the cost
    state, _, _, stepper = _mixed_steady(2.0, cavitation="reynolds", tol=1e-4)
    full = _mixed_steady(2.0)[0]
    free = np.flatnonzero(np.asarray(state.own["p_aux"]) >= 0.0)
    held = np.flatnonzero(np.asarray(state.own["p_aux"]) < 0.0)
    P = np.asarray(state.p)[stepper.disc.free_index]
    film = P - np.asarray(state.own["p_asperity"])
    assert held.size > 20 and np.max(np.abs(film[held])) < 1e-12 * np.max(P)
    assert film[free].min() > -1e-6 * np.max(P) and state.info["p_negative_min"] > -1e-6
    assert np.max(np.asarray(state.own["p_asperity"])[held]) > 0.01  # the asperities touch there
    assert 0.6 < state.info["asperity_share"] < full.info["asperity_share"] - 0.05


def test_a_rough_start_may_overlap_down_to_the_film_limit():
    """A rough scene may start with its mean planes overlapping (the run starts on the
    asperities), down to the lowest film a run may reach, -10 sigma; a smooth one may not."""
    rough = Roughness(sigma=0.05, stiffness=2.0)
    assert Scene(motion=Motion(gap=-0.45), roughness=rough).motion.hc(0.0) == -0.45
    with pytest.raises(SceneError, match=r"must be > -0.5 \(with this roughness: above -0.5, -10 sigma\)"):
        Scene(motion=Motion(gap=-0.55), roughness=rough)
    with pytest.raises(SceneError, match=r"must be > 0: with p = 0"):
        Scene(motion=Motion(gap=-0.45))
    with pytest.raises(SceneError, match=r"hc\(0\) = -0.6 must be > -0.5 \(with this roughness"):
        LineScene(k=1.0, motion=Motion(gap=-0.6), roughness=rough)


def test_bad_roughness_input():
    for kw in (
        {"sigma": 0.0, "stiffness": 1.0},
        {"sigma": float("nan"), "stiffness": 1.0},
        {"sigma": 0.1, "stiffness": -1.0},
        {"sigma": 0.1, "stiffness": 1.0, "friction": -0.1},
        {"sigma": 0.1, "stiffness": 1.0, "friction": True},
        {"sigma": 0.1, "stiffness": 1.0, "friction": 0.1},  # no aspect: the friction's unit is unknown
        {"sigma": 0.1, "stiffness": 1.0, "friction": 0.1, "aspect": 0.0},
    ):
        with pytest.raises(SceneError):
            Roughness(**kw)
    with pytest.raises(SceneError, match="femehl.Roughness"):
        Scene(roughness=0.1)
    for cavitation in ("jfo", "half-sommerfeld"):  # written for a smooth film's content and clipping
        with pytest.raises(SceneError, match="cavitation = 'reynolds'"):
            Scene(fluid=Fluid(cavitation=cavitation), roughness=Roughness(0.1, 1.0))
    assert Scene(fluid=Fluid(cavitation="reynolds"), roughness=Roughness(0.1, 1.0)).roughness.sigma == 0.1


def test_scene_file_roughness(tmp_path):
    from femehl.problem.scenefile import load_scene_file

    f = tmp_path / "a.toml"
    f.write_text("[roughness]\nsigma = 0.05\nstiffness = 2.0\nfriction = 0.2\naspect = 0.03\n")
    assert load_scene_file(f)[0].roughness == Roughness(0.05, 2.0, 0.2, 0.03)
    f.write_text("[roughness]\nsigma = 0.05\n")
    with pytest.raises(SceneFileError, match="takes sigma and stiffness"):
        load_scene_file(f)
    f.write_text("[si]\nR = 0.01\n[roughness]\nsigma = 0.05\nstiffness = 2.0\n")
    with pytest.raises(SceneFileError, match="normalized units"):
        load_scene_file(f)


def test_run_folder_has_the_asperities(tmp_path):
    import meshio

    scene = Scene(
        fluid=Fluid(beta=1e5),
        motion=Motion(gap=RampHold(0.2, -0.5, 1.0), velocity=0.0),
        roughness=Roughness(0.1, 1.0),
    )
    femehl.solve(scene, t_end=1.0, mesh="coarse", dt=0.1, estimate=False, out=tmp_path / "run")
    header = (tmp_path / "run" / "summary.csv").read_text().splitlines()[0].split(",")
    assert {"asperity_load", "asperity_share", "asperity_friction"} <= set(header)
    last = sorted((tmp_path / "run").glob("**/*.vtu"))[-1]
    p_a = meshio.read(last).point_data["asperity_pressure"]
    assert p_a.max() > 0 and np.all(p_a >= -1e-12)


def test_si_roughness_is_greenwood_tripp_of_the_surface_statistics(tmp_path):
    """[si] roughness keys (examples/pdms_ball.toml): the stiffness against the reference's own
    formula, sigma over h_inf, the aspect sqrt(h_inf/R) the friction needs; the example runs
    from its file (its [run] settings, the first steps)."""
    from femehl.cli import main as cli_main
    from femehl.problem.scenefile import load_scene_file

    example = pathlib.Path(__file__).resolve().parents[1] / "examples" / "pdms_ball.toml"
    scene, run = load_scene_file(example)
    assert scene.cavitation == "reynolds" and run["mesh"] == "coarse"
    K = ref.gt_stiffness(0.0095, 0.4e6, 1.8e-4, 2e10, 10e-6, 0.5e-6)
    assert scene.roughness.stiffness == pytest.approx(K, rel=1e-12)
    assert scene.roughness.sigma == pytest.approx(0.5e-6 / 1.8e-4, rel=1e-12)
    assert scene.roughness.aspect == pytest.approx(math.sqrt(1.8e-4 / 0.0095), rel=1e-12)
    assert scene.roughness.friction == 0.3
    assert scene.motion.F(0.0) == 0.0 and scene.motion.F(2.0) == pytest.approx(
        0.5 / run["_dimensional"].force
    )
    rc = cli_main(["run", str(example), "--t-end", "0.05", "--out", str(tmp_path / "run"), "--quiet"])
    assert rc == 0 and (tmp_path / "run" / "summary_si.csv").is_file()
    si = "R = 0.0095\nG = 0.4e6\neta = 0.1\nV_ss = 0.01\nh_inf = 1.8e-4\nh0 = 2e-5\nload = 0.5\n"
    f = tmp_path / "s.toml"
    f.write_text("[si]\n" + si + "roughness_rms = 0.5e-6\n")
    with pytest.raises(SceneFileError, match="asperity_density"):
        load_scene_file(f)


@pytest.mark.slow
def test_free_indenter_comes_to_rest_on_the_asperities():
    """A light free cylinder (m = 1e-3) pushed by F = 0.5 onto a rough Winkler foundation, no
    sliding: it bounces, the film drains (beta = 1e4) and it settles where the dry rough
    contact carries F (the pointwise reference, solved here for hc). Measured: hc -0.370379
    against -0.370442 (200 elements, step_tol 1e-4; 98 s, 20,534 steps)."""
    rough = Roughness(sigma=0.05, stiffness=2.0)
    motion = Motion(gap=0.2, velocity=0.0, mass=1e-3, force=0.5)
    scene = LineScene(k=1.0, L=2.5, beta=1e4, motion=motion, roughness=rough)
    res = femehl.solve(scene, t_end=30.0, n_elements=200, step_tol=1e-4, estimate=False)
    x = np.linspace(-2.5, 2.5, 5001)
    hc = brentq(lambda h: np.trapezoid(_line_dry(rough, 1.0, h, x), x) - 0.5, -1.0, 0.0, xtol=1e-12)
    assert res.hc[-1] == pytest.approx(hc, abs=5e-4)
    assert res.asperity_share[-1] == pytest.approx(1.0, abs=1e-6)


def test_a_runaway_step_is_stopped_below_the_limit():
    """Through contact the film may fall below zero, but not past -10 sigma (the asperities
    would press at 320 K): a fixed step of 2 time units on a rough line overshoots (measured:
    the film reached -1.1e5 at t = 4) and raises femehl's error naming the fix, never a
    run of nonsense to a singular system (what a coarse companion did before the limit)."""
    from femehl.errors import FilmRuptureError

    motion = Motion(gap=0.2, velocity=1.0, load=femehl.Table([0.0, 1.0], [0.0, 0.5]))
    scene = LineScene(k=1.0, L=2.5, beta=8.0, motion=motion, roughness=Roughness(0.05, 2.0))
    with pytest.raises(FilmRuptureError, match="below the rough surfaces' limit -0.5.*smaller dt"):
        femehl.solve(scene, t_end=40.0, n_elements=100, dt=2.0, scheme="bdf2", estimate=False)


def test_a_slow_scene_starts_with_steps_below_its_squeeze_time():
    """The rough PDMS ball at 1.8e-6 m/s (beta = 1.6e7): the usual first step 0.05 tol = 5e-4
    takes the film, its coefficient lagged at d0 = 40 sigma, through the asperities in one
    step (to -9 sigma, measured); the default first step is the squeeze time 1/(beta d0^2)
    (5e-6), over which the film falls by a small part of itself."""
    from femehl.problem.scenefile import scene_from_mapping, tomllib
    from femehl.solver.adaptive import _limits, _squeeze_time

    example = pathlib.Path(__file__).resolve().parents[1] / "examples" / "pdms_ball.toml"
    raw = tomllib.loads(example.read_text())
    raw["si"]["V_ss"] = 1.78e-6
    scene = scene_from_mapping(raw, "pdms_ball.toml")[0]
    stepper = femehl.make_stepper(scene, mesh="coarse", scheme="euler")
    s0 = stepper.initial_state()
    tau = _squeeze_time(scene, s0)
    assert tau == pytest.approx(1.0 / (scene.fluid.beta * s0.film_min**2), rel=1e-12)
    dt0, dt_min, _ = _limits(8.0, 1e-2, None, None, None, squeeze=tau)
    assert dt0 == tau and dt_min == pytest.approx(0.01 * tau)
    sigma = scene.roughness.sigma
    assert stepper.step(s0, 5e-4, 5e-4).film_min < -5 * sigma  # the old first step overshoots
    assert stepper.step(s0, dt0, dt0).film_min > 0.9 * s0.film_min
