"""Scenes beyond the paper: indenter shapes, substrates, imposed load, SI, files.

Physics checks here:

- imposed load: the bordered step keeps ``int p dA = F(t)`` at every step;
- a rigid sphere sinking under a constant load follows the exact finite-domain
  Reynolds squeeze law (derived in :func:`squeeze_G`), integrated with solve_ivp;
- an elastic sphere under a constant load approaches the Hertz indentation;
- a compressible half space (nu = 0.3) deflects 2(1 - nu) = 1.4 times more.
"""

from __future__ import annotations

import csv
import itertools
import math
import re

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.integrate import solve_ivp

import femehl
from femehl.api import make_stepper, run_to_folder
from femehl.cli import main as cli_main
from femehl.errors import SceneError, SceneFileError
from femehl.problem.indenters import INDENTERS, Ellipsoid, FlatPunch, HeightMap, Shape, Sphere, si_indenter
from femehl.problem.scene import (
    Constant,
    Dimensional,
    Domain,
    Fluid,
    HalfSpace,
    Layer,
    Motion,
    RampHold,
    Rigid,
    Scene,
    Table,
    Winkler,
)
from femehl.problem.scenefile import SUBSTRATES, load_scene_file
from femehl.solver.stepping import march

HERTZ_LOAD = 4.0 / (3.0 * math.pi)  # normalized Hertz load at hc = -1 (docs/design.md, section 2)


def ripple(x, y):
    """A sphere with an oblique ripple: s >= 0, s(0, 0) = 0, not symmetric in y."""
    return 0.5 * (x * x + y * y) + 0.02 * (1.0 - np.cos(4.0 * x + 2.0 * y))


def sphere_map(half_width=2.5, n=51):
    g = np.linspace(-half_width, half_width, n)
    return HeightMap(g, g, 0.5 * (g[:, None] ** 2 + g[None, :] ** 2))


#: one instance of every registered indenter kind (the registry must not outgrow this)
EXAMPLE_INDENTERS = {
    "sphere": lambda: Sphere(1.0),
    "ellipsoid": lambda: Ellipsoid(0.5, 2.0),
    "flat_punch": lambda: FlatPunch(0.5, 0.5),
    "heightmap": sphere_map,
    "shape": lambda: Shape(ripple),
}
EXAMPLE_SUBSTRATES = {
    "halfspace": HalfSpace(0.5),
    "layer": Layer(5.0, nu=0.4),  # thick: the cheap low-rank form of its operator
    "winkler": Winkler(1.0),
    "rigid": Rigid(),
    "viscoelastic": femehl.Viscoelastic(G0=2.0, tau=0.1),
}


def test_examples_cover_the_registries():
    assert set(EXAMPLE_INDENTERS) == set(INDENTERS)
    assert set(EXAMPLE_SUBSTRATES) == set(SUBSTRATES)
    for name, make in EXAMPLE_INDENTERS.items():
        assert isinstance(make(), INDENTERS[name])


# ---------------------------------------------------------------------------
# indenter shapes
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(EXAMPLE_INDENTERS))
def test_indenter_contract(name):
    """gap(x, y) broadcasts, is >= 0 with s(0, 0) = 0, and symmetric_y tells the truth."""
    ind = EXAMPLE_INDENTERS[name]()
    rng = np.random.default_rng(1)
    x, y = rng.uniform(-1.9, 1.9, (2, 7, 5))
    s = ind.gap(x, y)
    assert s.shape == (7, 5) and np.all(np.isfinite(s)) and np.all(s >= 0.0)
    assert float(ind.gap(0.0, 0.0)) == pytest.approx(0.0, abs=1e-14)
    assert isinstance(ind.symmetric_y, bool) and isinstance(ind.axisymmetric, bool)
    mirrored = np.allclose(ind.gap(x, -y), s, rtol=0, atol=1e-12)
    assert mirrored == ind.symmetric_y  # (the example Shape is not symmetric)
    if ind.axisymmetric:
        th = rng.uniform(0, 2 * math.pi, 5)
        r = np.hypot(x[0], y[0])
        assert np.allclose(ind.gap(r * np.cos(th), r * np.sin(th)), s[0], rtol=0, atol=1e-12)


def test_ellipsoid_shape_and_flags():
    e = Ellipsoid(0.5, 2.0)
    assert e.gap(1.0, 0.0) == pytest.approx(1.0) and e.gap(0.0, 1.0) == pytest.approx(0.25)
    assert e.symmetric_y and not e.axisymmetric
    assert Ellipsoid(1.5, 1.5).axisymmetric
    assert np.allclose(
        Ellipsoid(1.0, 1.0).gap([0.3, 1.1], [0.7, -0.2]), Sphere().gap([0.3, 1.1], [0.7, -0.2])
    )


def test_flat_punch_is_flat_then_c1_rounded():
    fp = FlatPunch(a=0.6, edge_radius=0.3)
    r = np.linspace(0.0, 1.8, 3601)
    s = fp.gap(r, 0 * r)
    assert np.all(s[r <= 0.6] == 0.0)
    assert np.allclose(s[r > 0.6], (r[r > 0.6] - 0.6) ** 2 / 0.6)
    slope = np.diff(s) / np.diff(r)
    assert np.max(np.abs(np.diff(slope))) < 2.0 * (r[1] - r[0]) / 0.3  # no kink: C1


def test_heightmap_is_bilinear_and_detects_symmetry():
    x = np.linspace(-2.0, 2.0, 9)
    y = np.linspace(-2.5, 2.5, 11)
    f = lambda x, y: 0.3 + 0.2 * x - 0.1 * y + 0.05 * x * y  # noqa: E731
    hm = HeightMap(x, y, f(x[:, None], y[None, :]))
    pts = np.random.default_rng(2).uniform(-2.0, 2.0, (2, 50))
    assert np.allclose(hm.gap(*pts), f(*pts), rtol=0, atol=1e-13)  # bilinear is exact
    assert not hm.symmetric_y
    assert sphere_map().symmetric_y
    assert not HeightMap(x, y + 0.1, np.zeros((9, 11))).symmetric_y  # y grid not symmetric
    assert HeightMap(x, y, np.zeros((9, 11)), symmetric_y=False).symmetric_y is False
    assert hm.extent == 2.0
    # the grid's own boundary is inside (mesh nodes are snapped onto r = L)
    assert np.isfinite(hm.gap(2.0, 0.0)) and np.isfinite(hm.gap(-2.0 - 1e-14, 0.0))


def test_heightmap_from_file(tmp_path):
    g = np.linspace(-2.5, 2.5, 21)
    np.savez(tmp_path / "m.npz", x=g, y=g, z=0.5 * (g[:, None] ** 2 + g[None, :] ** 2))
    hm = HeightMap.from_file(tmp_path / "m.npz")
    assert hm.symmetric_y and hm.gap(0.25, 0.0) == pytest.approx(0.5 * 0.25**2, abs=0.01)
    np.savez(tmp_path / "bad.npz", x=g, z=g)
    with pytest.raises(SceneError, match=r"lacks arrays \['y'\].*np.savez"):
        HeightMap.from_file(tmp_path / "bad.npz")
    with pytest.raises(SceneError, match="does not exist"):
        HeightMap.from_file(tmp_path / "none.npz")


def test_shape_wraps_a_function():
    sh = Shape(ripple, name="ripple")
    assert not sh.symmetric_y and not sh.axisymmetric
    x = np.array([[0.1, -0.4], [1.0, 0.3]])
    assert np.array_equal(sh.gap(x, x.T), ripple(x, x.T))
    assert Shape(lambda x, y: 0.0).gap(np.ones(3), np.ones(3)).shape == (3,)  # scalar broadcast


@pytest.mark.parametrize(
    "make,match",
    [
        (lambda: Ellipsoid(-1.0, 1.0), r"Rx must be > 0.*positive radii"),
        (lambda: Ellipsoid(1.0, 0.0), r"Ry must be > 0"),
        (lambda: FlatPunch(0.5, 0.0), r"edge_radius must be > 0.*rounded edge"),
        (lambda: FlatPunch(0.5, -0.1), r"edge_radius must be > 0"),
        (lambda: FlatPunch(0.0, 0.5), r"radius a must be > 0.*Sphere"),
        (lambda: Shape(lambda x, y: np.full_like(x, np.nan)), r"not finite.*fix the function"),
        (lambda: Shape(lambda x, y: x[:1]), r"returned shape.*one value per point"),
        (lambda: Shape(lambda x, y: math.sin(x)), r"raised TypeError.*numpy arrays"),
        (lambda: Shape("x**2"), r"must be a callable"),
        (lambda: HeightMap([0, 2, 1], [0, 1], np.zeros((3, 2))), r"strictly increasing.*sort"),
        (lambda: HeightMap([0, 1], [0, 1], [[0, np.nan], [0, 0]]), r"NaN.*fill the gaps"),
        (lambda: HeightMap([0, 1, 2], [0, 1], np.zeros((2, 3))), r"shape \(2, 3\).*transpose"),
        (lambda: HeightMap([0.0], [0, 1], np.zeros((1, 2))), r"at least 2"),
    ],
)
def test_bad_indenters_raise_clear_errors(make, match):
    with pytest.raises(SceneError, match=match):
        make()


def test_heightmap_outside_points_raise():
    hm = sphere_map(2.0, 21)
    with pytest.raises(SceneError, match=r"outside its grid.*extend the map"):
        hm.gap(np.array([0.0, 2.5]), np.array([0.0, 0.0]))


# ---------------------------------------------------------------------------
# the generic domain check
# ---------------------------------------------------------------------------
def test_domain_check_is_the_old_rule_for_a_sphere():
    """L >= 1.5 a_Hertz = 1.5 sqrt(R |hc|): exactly 1.5 accepted, just below refused."""
    for R, hc in [(1.0, -1.0), (2.0, -0.5)]:
        a = math.sqrt(R * -hc)
        Scene(indenter=Sphere(R), motion=Motion(gap=RampHold(0.1, hc, 1.0)), domain=Domain(1.5 * a))
        with pytest.raises(SceneError, match=r"too small to hold the contact.*Use L >= "):
            Scene(indenter=Sphere(R), motion=Motion(gap=RampHold(0.1, hc, 1.0)), domain=Domain(1.49 * a))


def test_domain_check_under_imposed_load():
    """Hertz: F = (4/(3 pi)) a^3, so F = 8 x Hertz load has a = 2 and needs L >= 3."""
    Scene(motion=Motion(gap=0.1, load=HERTZ_LOAD), domain=Domain(1.5))
    with pytest.raises(SceneError, match=r"imposed load.*too small|too small.*imposed load"):
        Scene(motion=Motion(gap=0.1, load=HERTZ_LOAD), domain=Domain(1.49))
    table = Table((0.0, 5.0, 20.0), (0.0, 8 * HERTZ_LOAD, 8 * HERTZ_LOAD))  # max reached at t=5
    Scene(motion=Motion(gap=0.1, load=table), domain=Domain(3.01))
    with pytest.raises(SceneError, match=r"Use L >= 3\b"):
        Scene(motion=Motion(gap=0.1, load=table), domain=Domain(2.9))
    # the compressible half space is softer: 1.4 x deeper for the same load (a^3 ~ c F)
    with pytest.raises(SceneError, match="too small"):
        Scene(substrate=HalfSpace(0.3), motion=Motion(gap=0.1, load=HERTZ_LOAD), domain=Domain(1.5))
    # a rigid substrate is never indented under load
    Scene(substrate=Rigid(), motion=Motion(gap=0.1, load=100.0), domain=Domain(1.0))


def test_domain_check_for_other_shapes():
    # ellipsoid: the long axis (Ry) sets the contact: a_geo = sqrt(2 Ry |hc|) = 2
    with pytest.raises(SceneError, match=r"out to r = 2\b.*Use L >= 2\.12"):
        Scene(indenter=Ellipsoid(0.5, 2.0), motion=Motion(gap=RampHold(0.1, -1.0, 1.0)))
    Scene(indenter=Ellipsoid(0.5, 2.0), motion=Motion(gap=RampHold(0.1, -1.0, 1.0)), domain=Domain(2.15))
    # flat punch: a_geo = a + sqrt(2 e |hc|)
    a_geo = 1.0 + math.sqrt(2 * 0.5 * 1.0)
    with pytest.raises(SceneError, match="too small"):
        Scene(
            indenter=FlatPunch(1.0, 0.5),
            motion=Motion(gap=RampHold(0.1, -1.0, 1.0)),
            domain=Domain(1.05 * a_geo),
        )
    Scene(
        indenter=FlatPunch(1.0, 0.5), motion=Motion(gap=RampHold(0.1, -1.0, 1.0)), domain=Domain(1.07 * a_geo)
    )
    # a user function that is not finite on the domain
    with pytest.raises(SceneError, match=r"not finite.*fix the function"):
        Scene(indenter=Shape(lambda x, y: np.where(np.hypot(x, y) > 1.5, np.nan, x * x)))


def test_heightmap_must_cover_the_domain():
    hm = sphere_map(1.5, 31)
    with pytest.raises(SceneError, match=r"does not cover the domain.*extend the map"):
        Scene(indenter=hm, motion=Motion(gap=RampHold(0.1, -0.2, 1.0)), domain=Domain(2.0))
    Scene(indenter=hm, motion=Motion(gap=RampHold(0.1, -0.2, 1.0)), domain=Domain(1.5))


def test_initial_film_must_be_positive_for_any_shape():
    with pytest.raises(SceneError, match=r"initial film.*s >= 0 with s\(0, 0\) = 0"):
        Scene(indenter=Shape(lambda x, y: x * x - 0.3), motion=Motion(gap=RampHold(0.2, 0.1, 1.0)))


# ---------------------------------------------------------------------------
# every registered shape x substrate x motion runs, with only the terms it needs
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("sliding", [False, True], ids=["still", "sliding"])
@pytest.mark.parametrize("control", ["gap", "load"])
@pytest.mark.parametrize("substrate", sorted(EXAMPLE_SUBSTRATES))
@pytest.mark.parametrize("indenter", sorted(EXAMPLE_INDENTERS))
def test_combination_runs(indenter, substrate, control, sliding):
    """Coarse mesh, t_end = 0.2, dt = 0.05: finite fields, positive squeeze load, and only
    the terms the scene calls for (no Couette term without sliding, no dense operator for a
    rigid or Winkler substrate, the full disk for a shape not symmetric in y)."""
    ind = EXAMPLE_INDENTERS[indenter]()
    sub = EXAMPLE_SUBSTRATES[substrate]
    V = Constant(0.5) if sliding else Constant(0.0)
    F = 0.05
    if control == "gap":
        motion = Motion(gap=RampHold(0.3, 0.1, 1.0), velocity=V)
    else:
        motion = Motion(gap=0.3, velocity=V, load=Table((0.0, 0.1), (0.0, F)))
    scene = Scene(indenter=ind, substrate=sub, fluid=Fluid(10.0), motion=motion)
    st = make_stepper(scene, "fe", mesh="coarse")
    states = list(march(st, 0.2, 0.05))
    assert len(states) == 5
    for s in states:
        assert np.all(np.isfinite(s.p)) and np.all(np.isfinite(s.d)) and np.isfinite(s.hc)
        assert s.film_min > 0.0
    eff = scene.effects(0.2)
    assert st.info["couette_assembled"] is sliding is eff["sliding"]
    assert eff["imposed_load"] is (control == "load") and eff["squeeze"]
    assert bool(st.info["half"]) == ind.symmetric_y
    if substrate in ("halfspace", "layer", "viscoelastic"):  # dense (a thick layer; a relaxing half space)
        assert isinstance(st.C, np.ndarray)
    else:
        assert sp.issparse(st.C) and not st.dense
        assert all(sp.issparse(v) for v in st.film_products.values())
    loads = np.array([s.load for s in states[1:]])
    if control == "load":
        target = np.array([min(s.t / 0.1, 1.0) * F for s in states[1:]])
        assert np.max(np.abs(loads - target)) <= 1e-9 * F
        assert all(b.hc < a.hc for a, b in itertools.pairwise(states))  # it sinks
    elif not sliding:
        assert np.all(loads > 0.0)  # squeeze film
    if not sliding:
        assert np.all(np.array([s.p.min() for s in states]) > -1e-12 * max(s.p_max for s in states))


# ---------------------------------------------------------------------------
# imposed load
# ---------------------------------------------------------------------------
def squeeze_G(hc, L):
    """Exact finite-domain squeeze law of a rigid sphere, F = -(dhc/dt) (pi/(2 beta)) G(hc).

    With w = 0, d = hc + r^2/2 and V = 0 the Reynolds equation is axisymmetric:
    beta (1/r)(r d^3 p')' = dhc/dt.  Integrating once (regular at r = 0):
    p' = (dhc/dt) r / (2 beta d^3).  With u = d (du = r dr) and p(L) = 0:
    p = -(dhc/dt)/(4 beta) (1/d^2 - 1/u_L^2), u_L = hc + L^2/2.  The load
    F = int 2 pi r p dr = 2 pi int_hc^u_L p du
      = -(dhc/dt) (pi/(2 beta)) [1/hc - 1/u_L - (u_L - hc)/u_L^2].
    """
    uL = hc + 0.5 * L * L
    return 1.0 / hc - 1.0 / uL - (uL - hc) / uL**2


def squeeze_reference(F, beta, h0, L, ts):
    sol = solve_ivp(
        lambda t, h: [-F * (2.0 * beta / math.pi) / squeeze_G(h[0], L)],
        (0.0, ts[-1]),
        [h0],
        t_eval=ts,
        rtol=1e-12,
        atol=1e-14,
        method="LSODA",
    )
    return sol.y[0]


def test_squeeze_G_matches_quadrature():
    """G(hc) against a direct quadrature of the pressure of the derivation above."""
    from scipy.integrate import quad

    hc, L, beta, hdot = 0.3, 2.0, 1.7, -0.9
    uL = hc + L * L / 2
    p = lambda r: -(hdot / (4 * beta)) * (1 / (hc + r * r / 2) ** 2 - 1 / uL**2)  # noqa: E731
    F = quad(lambda r: 2 * math.pi * r * p(r), 0, L, epsabs=1e-13, epsrel=1e-13)[0]
    assert F == pytest.approx(-hdot * math.pi / (2 * beta) * squeeze_G(hc, L), rel=1e-10)


def test_rigid_sphere_follows_the_squeeze_law():
    """A rigid sphere under constant load F: hc(t) from femehl vs the squeeze-law ODE.

    beta = 1, F = 1.5, hc(0) = 0.5, t in [0, 1] (hc falls to ~0.145), BDF2, dt = 0.02
    (the time error is then below the mesh error: dt = 0.01 changes hc by < 1e-4).
    Measured max relative error of hc: coarse 8.1e-3, medium 4.3e-3 (fine 2.1e-3, not
    run here): second order in the mesh size (ratio 1.45 per rung).  The load equals F
    to round-off at every step.
    """
    beta, F, h0, L = 1.0, 1.5, 0.5, 2.0
    sc = Scene(substrate=Rigid(), fluid=Fluid(beta), motion=Motion(gap=h0, load=F), domain=Domain(L))
    errs = []
    for mesh in ("coarse", "medium"):
        r = femehl.solve(sc, "fe", mesh=mesh, t_end=1.0, dt=0.02, store_every=0, scheme="bdf2")
        ref = squeeze_reference(F, beta, h0, L, r.t)
        errs.append(float(np.max(np.abs(r.hc - ref) / ref)))
        assert np.max(np.abs(r.load[1:] - F)) <= 1e-9 * F
    assert errs[0] < 1.2e-2 and errs[1] < 6e-3, errs
    assert errs[1] < 0.65 * errs[0], errs  # the error decreases with the mesh


def test_fd_imposed_load_follows_the_squeeze_law():
    """The FD solver's bordered step: load = F to round-off, squeeze law to first order."""
    beta, F, h0, L = 1.0, 1.5, 0.5, 2.0
    sc = Scene(substrate=Rigid(), fluid=Fluid(beta), motion=Motion(gap=h0, load=F), domain=Domain(L))
    errs = []
    for dr, n in [(0.1, 12), (0.05, 24)]:
        r = femehl.solve(sc, "fd", dr=dr, dtheta=math.pi / n, t_end=1.0, dt=0.02, store_every=0)
        assert np.max(np.abs(r.load[1:] - F)) <= 1e-9 * F
        errs.append(float(np.max(np.abs(r.hc - squeeze_reference(F, beta, h0, L, r.t)) / r.hc)))
    assert errs[1] < 0.7 * errs[0] and errs[1] < 0.04, errs  # measured 4.9e-2, 2.7e-2


def hertz_run(F, nu=0.5, t_end=3.0):
    """Elastic sphere, beta = 200, load ramped from 0 to F over t in [0, 0.5], then held."""
    sc = Scene(
        substrate=HalfSpace(nu),
        fluid=Fluid(200.0),
        motion=Motion(gap=0.1, load=Table((0.0, 0.5), (0.0, F))),
        domain=Domain(2.0),
    )
    return femehl.solve(sc, "fe", mesh="coarse", t_end=t_end, dt=0.05, store_every=0)


@pytest.mark.parametrize("scale", [0.5, 1.0])
def test_elastic_sphere_approaches_hertz(scale):
    """Under a constant load the sphere sinks toward the Hertz depth hc_H from above.

    Normalized Hertz: load 4/(3 pi) at hc = -1 and F ~ |hc|^(3/2), so
    hc_H = -(F / (4/(3 pi)))^(2/3).  The film never drains completely: it thins
    slowly (the central film is ~ 0.04 at t = 3 and falls like a power of t), and
    hc = -delta_elastic + d_centre, so hc stays above hc_H by about the central film.
    Measured at t = 3 (coarse mesh): hc = -0.9685 for hc_H = -1 (3.2 % of |hc_H|),
    -0.6007 for -0.630 (4.6 %); with the central film subtracted, hc - d_c = -1.008
    and -0.637 (0.8 %, 1.1 %: the trapped film makes the pressure slightly non-Hertzian).
    """
    F = scale * HERTZ_LOAD
    hc_H = -(scale ** (2.0 / 3.0))
    r = hertz_run(F)
    hold = r.t >= 0.5
    # the load row is a row of the step's one (bordered) solve, held to its relative residual:
    # rtol 1e-8, the row scaled to the right-hand side's size, so at most sqrt(2) rtol of F
    # (measured 1.5e-9; 1e-15 when hc came from two solves in closed form)
    assert np.max(np.abs(r.load[hold] - F)) <= 2e-8 * F
    hc = r.hc[hold]
    assert np.all(np.diff(hc) < 0.0)  # keeps sinking
    assert np.all(hc > hc_H)  # from above
    assert 0.0 < hc[-1] - hc_H < 0.06 * abs(hc_H)
    assert np.all(np.diff(r.film_center[hold]) < 0.0)  # the film keeps draining
    dry = r.hc[-1] - r.film_center[-1]  # elastic depth under the tip
    assert abs(dry - hc_H) < 0.02 * abs(hc_H)


def test_compressible_halfspace_deflection_scaling():
    """nu = 0.3: w = -c X p with c = 2(1 - nu) = 1.4, exactly, for FE and FD operators;
    in a run under the same small squeeze pressure the central deflection ratio is 1.4
    up to the film's response to the deflection (O(w/d)); under a held load at long times
    the indentation ratio tends to the Hertz value 1.4^(2/3) (a^3 ~ c F)."""
    fe = [femehl.make_stepper(Scene(substrate=HalfSpace(nu)), "fe", mesh="coarse") for nu in (0.5, 0.3)]
    p = np.random.default_rng(3).random(fe[0].disc.n)
    assert np.allclose(fe[1].C @ p, 1.4 * (fe[0].C @ p), rtol=1e-14, atol=0)
    fd = [
        femehl.make_stepper(Scene(substrate=HalfSpace(nu)), "fd", dr=0.2, dtheta=math.pi / 8)
        for nu in (0.5, 0.3)
    ]
    q = np.random.default_rng(4).random(fd[0].disc.n)
    assert np.allclose(fd[1].C @ q, 1.4 * (fd[0].C @ q), rtol=1e-14, atol=0)
    # small deflection: the squeeze pressure hardly depends on the substrate
    w0 = []
    for nu in (0.5, 0.3):
        sc = Scene(
            substrate=HalfSpace(nu),
            fluid=Fluid(2000.0),
            motion=Motion(gap=RampHold(0.3, 0.1, 1.0)),
            domain=Domain(2.0),
        )
        s = femehl.solve(sc, "fe", mesh="coarse", t_end=0.2, dt=0.05).states[-1]
        w0.append(s.hc - s.film_center)  # w(0, 0) (s(0, 0) = 0)
    ratio = w0[1] / w0[0]
    rel_w = abs(w0[0]) / 0.26  # deflection / film at the tip
    assert 1.4 * (1 - 3 * rel_w) < ratio <= 1.4, (ratio, rel_w)


# ---------------------------------------------------------------------------
# the terms a run assembles, as logged at its start
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "sub,V,load", [(Rigid(), 0.0, None), (Winkler(2.0), 0.5, None), (HalfSpace(), 0.0, 0.05)]
)
def test_logged_terms_agree_with_the_stepper(tmp_path, sub, V, load):
    lines = []
    sc = Scene(
        substrate=sub, fluid=Fluid(10.0), motion=Motion(gap=RampHold(0.3, 0.1, 1.0), velocity=V, load=load)
    )
    res = run_to_folder(
        sc, tmp_path, method="fe", mesh="coarse", t_end=0.1, dt=0.05, store_every=0, log=lines.append
    )
    m = re.search(r"terms: squeeze=(\w+), sliding=(\w+), elasticity=(\w+), imposed_load=(\w+)", lines[0])
    assert m, lines[0]
    squeeze, sliding, elasticity, imposed = m.groups()
    assert squeeze == "True"
    assert sliding == str(res.info["couette_assembled"]) == str(V != 0.0)
    assert elasticity == sub.kind
    assert (res.info["operator_bytes"] > 1e6) is (elasticity == "halfspace")  # dense only then
    assert imposed == str(load is not None)


# ---------------------------------------------------------------------------
# scene files
# ---------------------------------------------------------------------------
def _write(tmp_path, text, name="s.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_scene_file_new_indenters_and_load(tmp_path):
    g = np.linspace(-2.5, 2.5, 11)
    np.savez(tmp_path / "map.npz", x=g, y=g, z=0.5 * (g[:, None] ** 2 + g[None, :] ** 2))
    cases = {
        '[indenter]\nkind = "ellipsoid"\nRx = 0.5\nRy = 2.0\n': Ellipsoid(0.5, 2.0),
        '[indenter]\nkind = "flat_punch"\na = 0.5\nedge_radius = 0.3\n': FlatPunch(0.5, 0.3),
    }
    motion = (
        '[motion.gap]\nkind = "constant"\nvalue = 0.2\n[motion.load]\nkind = "table"\n'
        "times = [0.0, 1.0]\nvalues = [0.0, 0.3]\n"
    )
    for text, want in cases.items():
        sc, run = load_scene_file(_write(tmp_path, text + motion))
        assert sc.indenter == want and sc.motion.load_controlled and sc.motion.F(0.5) == 0.15
        assert sc.motion.hc(0.0) == 0.2 and run == {}
    sc, _ = load_scene_file(
        _write(
            tmp_path,
            '[indenter]\nkind = "heightmap"\nfile = "map.npz"\n'
            '[motion]\nload = 0.1\n[motion.gap]\nkind = "constant"\nvalue = 0.2\n',
        )
    )
    assert isinstance(sc.indenter, HeightMap) and sc.indenter.symmetric_y and sc.motion.F(3.0) == 0.1
    sc, _ = load_scene_file(
        _write(
            tmp_path,
            '[indenter]\nkind = "heightmap"\nx = [-2.0, 2.0]\n'
            "y = [-2.0, 2.0]\nz = [[4.0, 4.0], [4.0, 4.0]]\n"
            '[motion.gap]\nkind = "constant"\nvalue = 0.2\n',
        )
    )
    assert sc.indenter.gap(0.0, 0.0) == 4.0


@pytest.mark.parametrize(
    "text,match",
    [
        ('[indenter]\nkind = "cone"\n', r"\[indenter\] kind = 'cone' is not known; use one of"),
        ('[indenter]\nkind = "ellipsoid"\nRx = -1.0\nRy = 1.0\n', r"\[indenter\].*Rx must be > 0"),
        ('[indenter]\nkind = "flat_punch"\na = 0.5\nedge_radius = 0.0\n', r"edge_radius must be > 0"),
        ('[indenter]\nkind = "shape"\nfunc = "x**2"\n', r"must be a callable.*heightmap"),
        ('[indenter]\nkind = "heightmap"\nfile = "nope.npz"\n', r"\[indenter\].*does not exist"),
        (
            '[indenter]\nkind = "heightmap"\nfile = "small.npz"\n',
            r"does not cover the domain.*extend the map",
        ),
        (
            '[motion.load]\nkind = "table"\ntimes = [0.0, 1.0]\nvalues = [0.0, nan]\n',
            r"\[motion.load\].*finite \(no NaN",
        ),
        ("[motion]\nload = nan\n", r"\[motion.load\].*finite"),
        ("[motion]\nspeed = 1.0\n", r"\[motion\] takes gap, velocity, slide_roll, load"),
        ("[motion]\nforce = 1.0\n", r"force and hc_dot0 belong to a free indenter: give mass"),
        (
            "[si]\nR = 0.01\nG = 1e5\neta = 1.0\nV_ss = 0.01\nh_inf = 1e-4\nh0 = 1e-5\n"
            '[indenter]\nkind = "heightmap"\n',
            r"cannot be given in SI units",
        ),
        (
            "[si]\nR = 0.01\nG = 1e5\neta = 1.0\nV_ss = 0.01\nh_inf = 1e-4\nh0 = 1e-5\n"
            '[indenter]\nkind = "ellipsoid"\nRx = 0.01\nRy = -0.02\n',
            r"\[si\].*Ry \[m\] must be > 0",
        ),
    ],
)
def test_bad_scene_files(tmp_path, text, match):
    g = np.linspace(-1.0, 1.0, 5)
    np.savez(tmp_path / "small.npz", x=g, y=g, z=0.5 * (g[:, None] ** 2 + g[None, :] ** 2))
    with pytest.raises(SceneFileError, match=match):
        load_scene_file(_write(tmp_path, text))


# ---------------------------------------------------------------------------
# SI units
# ---------------------------------------------------------------------------
DIM = Dimensional(R=0.01, G=1e5, eta=1.0, V_ss=0.01, h_inf=1e-4, nu=0.5)


def test_si_indenter_conversion():
    e = si_indenter("ellipsoid", {"Rx": 0.005, "Ry": 0.02}, DIM)
    assert e == Ellipsoid(0.5, 2.0)
    fp = si_indenter("flat_punch", {"a": 0.5 * DIM.length, "edge_radius": 0.003}, DIM)
    assert fp.a == pytest.approx(0.5) and fp.edge_radius == pytest.approx(0.3)
    # the normalized gap of a sphere of radius R is r^2/2 in units of h_inf
    sphere = si_indenter("sphere", {"R": 0.01}, DIM)
    x = 1e-3  # m
    assert sphere.gap(x / DIM.length, 0.0) * DIM.h_inf == pytest.approx(x * x / (2 * 0.01))


def test_result_table_in_si():
    sc = DIM.scene(h0=1e-5)
    res = femehl.solve(sc, "fe", mesh="coarse", t_end=0.2, dt=0.1, store_every=0)
    tab = DIM.result_table(res)
    assert set(tab) == {
        "t",
        "hc",
        "load",
        "film_center",
        "film_min",
        "film_min_x",
        "film_min_y",
        "p_max",
        "p_max_x",
        "p_max_y",
        "friction",
        "shear_couette",
        "shear_poiseuille",
        "pressure_drag",
        "side_force",
        "friction_coefficient",
    }
    assert np.allclose(tab["t"], res.t * DIM.time)
    assert np.allclose(tab["hc"], res.hc * 1e-4) and tab["hc"][0] == pytest.approx(1e-5)
    assert np.allclose(tab["load"], res.load * DIM.pressure * DIM.length**2)
    assert np.allclose(tab["p_max"], res.p_max * 4 * math.pi * 1e5 * math.sqrt(1e-4 / 0.01))
    assert DIM.RESULT_COLUMNS["load"][2] == "N"


def test_cli_writes_si_summary(tmp_path, capsys):
    scene = _write(
        tmp_path,
        "[si]\nR = 0.01\nG = 1e5\neta = 1.0\nV_ss = 0.01\nh_inf = 1e-4\n"
        'h0 = 1e-5\nload = 0.01\n[indenter]\nkind = "ellipsoid"\nRx = 0.005\nRy = 0.02\n',
    )
    sc, run = load_scene_file(scene)
    assert isinstance(run["_dimensional"], Dimensional)
    assert sc.indenter == Ellipsoid(0.5, 2.0)
    F = 0.01 / DIM.force
    assert sc.motion.load_controlled and sc.motion.F(1.0) == pytest.approx(F)
    out = tmp_path / "out"
    rc = cli_main(
        [
            "run",
            str(scene),
            "--mesh",
            "coarse",
            "--t-end",
            "0.1",
            "--dt",
            "0.05",
            "--out",
            str(out),
            "--quiet",
        ]
    )
    assert rc == 0
    cap = capsys.readouterr()
    assert "imposed_load=True" in cap.err  # the run report goes to stderr (logging)
    with open(out / "summary_si.csv") as fh:
        rows = list(csv.reader(fh))
    assert rows[0][:4] == ["t_s", "hc_m", "load_N", "film_center_m"]
    data = np.array(rows[1:], dtype=float)
    # the imposed load, in N: ramped from 0 over t1 (one time scale by default), then held
    assert data[-1, 2] == pytest.approx(0.01 * data[-1, 0] / DIM.time, rel=1e-9)
    assert data[0, 1] == pytest.approx(1e-5)
