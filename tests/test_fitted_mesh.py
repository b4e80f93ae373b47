"""Tests of femehl.discretize.fitted: contact extents, scene-fitted meshes and their cache."""

from __future__ import annotations

import math

import numpy as np
import pytest

import femehl
from femehl.discretize import fitted as F
from femehl.discretize.fitted import contact_extent, fitted_disk, fitted_sizes, hertz_ellipse
from femehl.discretize.mesh import areas, load_mesh
from femehl.errors import MeshError, SceneError
from femehl.problem.indenters import Ellipsoid, FlatPunch, Shape, Sphere
from femehl.problem.scene import Domain, Motion, RampHold, Scene, TanhStart, Winkler

#: Elements crossed along each contact axis (the contact width 2a) that a fitted
#: mesh at level 1 must have.  The medium ladder crosses the ellipsoid's short axis
#: (2 ax = 0.88) with about 9; the fitted size field gives about 2 a / (0.095 a_min) >= 21.
MIN_ACROSS = 18
#: Element size at the contact edge, at most this fraction of the contact width 2a
#: along that axis (edge size 0.0407 ell vs 2 ell: 1/49 for the x-end of the ellipse).
MAX_EDGE_FRACTION = 1 / 20


def ellipsoid(Rx, Ry, h_end=-0.5):
    return Scene(
        indenter=Ellipsoid(Rx, Ry),
        motion=Motion(gap=RampHold(0.1, h_end, 1.0), velocity=TanhStart(1.0, 1.0)),
        domain=Domain(2.0),
    )


def punch():
    return Scene(indenter=FlatPunch(0.5, 0.5), motion=Motion(gap=RampHold(0.1, -0.3, 1.0)))


SCENES = {
    "ellipsoid_y": ellipsoid(0.5, 2.0),
    "ellipsoid_x": ellipsoid(2.0, 0.5),
    "flat_punch": punch(),
}


@pytest.fixture(scope="module")
def meshes(tmp_path_factory):
    """Fitted level-1 meshes of the three scenes (cache in a temporary folder)."""
    cache = tmp_path_factory.mktemp("fitted_cache")
    return {k: fitted_disk(sc, 3.0, cache_dir=cache) for k, sc in SCENES.items()}


# ---------------------------------------------------------------------------
# contact_extent


def test_sphere_extent_is_hertz():
    """Imposed gap hc -> -1: Hertz radius a = sqrt(R delta) = 1 (design.md section 2); R = 2: sqrt(2)."""
    ax, ay = contact_extent(femehl.presets.paper_sphere(), 5.0)
    assert ax == pytest.approx(1.0, rel=1e-9) and ay == pytest.approx(1.0, rel=1e-9)
    sc = Scene(indenter=Sphere(2.0), motion=Motion(gap=RampHold(0.1, -0.5, 1.0)), domain=Domain(2.0))
    assert contact_extent(sc, 2.0) == pytest.approx((1.0, 1.0), rel=1e-9)


def test_extent_uses_the_run_only():
    """At t_end = 0.5 the ramp has reached hc = 0.1 - 1.1 * 0.5 = -0.45: a = sqrt(0.45)."""
    ax, _ = contact_extent(femehl.presets.paper_sphere(), 0.5)
    assert ax == pytest.approx(math.sqrt(0.45), rel=1e-6)
    assert contact_extent(femehl.presets.paper_sphere(), 0.05) == (0.0, 0.0)  # not yet touching


def test_sphere_extent_under_load():
    """Imposed F = 4/(3 pi) is the Hertz load at a = 1 (nu = 0.5); nu = 0: F scales by 1/cc = 1/2."""
    sc = Scene(indenter=Sphere(1.0), motion=Motion(gap=0.1, load=4.0 / (3.0 * math.pi)))
    assert contact_extent(sc, 3.0) == pytest.approx((1.0, 1.0), rel=1e-6)
    sc = Scene(
        indenter=Sphere(1.0),
        substrate=femehl.HalfSpace(0.0),
        motion=Motion(gap=0.1, load=2.0 / (3.0 * math.pi)),
    )
    assert contact_extent(sc, 3.0) == pytest.approx((1.0, 1.0), rel=1e-6)


def test_a_free_indenter_is_fitted_to_its_free_fall():
    """A free indenter (mass, force): its fitted extent is the deepest dry indentation the
    force can drive it to from its initial gap, the Hertz energy balance in closed form
    ``(4 / (3 pi)) (2/5) delta^(5/2) = F (delta + h0)`` (the film only slows it: the run's
    deepest point, hc = -1.72 with this film, is above it), deeper than the static load's."""
    from femehl.elastic.contact import dry_contact_extent

    F_ = 4.0 / (3.0 * math.pi)  # the Hertz load at delta = 1
    sc = Scene(indenter=Sphere(1.0), motion=Motion(gap=0.1, velocity=0.0, mass=0.1, force=F_))
    ax, ay, delta = dry_contact_extent(sc, 2.0)
    assert F_ * 0.4 * delta**2.5 == pytest.approx(F_ * (delta + 0.1), rel=1e-3)
    assert 1.72 < delta and ax == ay == pytest.approx(math.sqrt(delta), rel=1e-9)
    # nothing pushes it down: no contact to fit
    still = Scene(indenter=Sphere(1.0), motion=Motion(gap=0.1, velocity=0.0, mass=0.1))
    assert dry_contact_extent(still, 2.0) == (0.0, 0.0, 0.0)


def test_generic_shape_uses_sneddon():
    """A Shape that is a sphere goes through the ray-by-ray Sneddon route: a = 1 to 1e-4."""
    sc = Scene(
        indenter=Shape(lambda x, y: (x**2 + y**2) / 2, symmetric_y=True),
        motion=Motion(gap=RampHold(0.1, -1.0, 1.0)),
    )
    assert contact_extent(sc, 3.0) == pytest.approx((1.0, 1.0), rel=1e-4)
    sc = Scene(
        indenter=Shape(lambda x, y: (x**2 + y**2) / 2, symmetric_y=True),
        motion=Motion(gap=0.1, load=4.0 / (3.0 * math.pi)),
    )
    assert contact_extent(sc, 3.0) == pytest.approx((1.0, 1.0), rel=1e-3)


def test_flat_punch_extent_solves_sneddon():
    """Sneddon for the rounded punch: delta = (c/rho) (sqrt(c^2 - a^2) - a acos(a/c))."""
    c, c2 = contact_extent(punch(), 3.0)
    assert c == pytest.approx(c2, rel=1e-9)
    a, rho = 0.5, 0.5
    delta = (c / rho) * (math.sqrt(c * c - a * a) - a * math.acos(a / c))
    assert delta == pytest.approx(0.3, rel=2e-3)


def test_ellipsoid_extent_is_hertz_ellipse():
    """Axes swap with the orientation; the aspect ratio matches Hamrock-Brewe's
    k = 1.0339 (R_long/R_short)^0.636 to 3 %, and the axes are not the geometric
    overlap (sqrt(2 R delta)) scaled by one factor."""
    ax, ay = contact_extent(SCENES["ellipsoid_y"], 3.0)
    bx, by = contact_extent(SCENES["ellipsoid_x"], 3.0)
    assert (ax, ay) == pytest.approx((by, bx), rel=1e-12)
    assert ay / ax == pytest.approx(1.0339 * 4.0**0.636, rel=0.03)
    assert ax < math.sqrt(0.5 * 0.5) < math.sqrt(2.0 * 0.5) < ay  # less eccentric than sqrt(Rx/Ry)
    a, b, m = hertz_ellipse(1.0, 1.0, 0.7)
    assert a == b == pytest.approx(math.sqrt(0.7)) and m == 0.0


def test_winkler_extent_is_geometric_overlap():
    """Winkler: the overlap hc + r^2/2 < 0, a = sqrt(2 delta); under load F = k pi delta^2."""
    sc = Scene(indenter=Sphere(1.0), substrate=Winkler(1.0), motion=Motion(gap=RampHold(0.1, -0.5, 1.0)))
    assert contact_extent(sc, 3.0) == pytest.approx((1.0, 1.0), rel=2e-3)
    delta = 0.3
    sc = Scene(
        indenter=Sphere(1.0), substrate=Winkler(2.0), motion=Motion(gap=0.1, load=2.0 * math.pi * delta**2)
    )
    assert contact_extent(sc, 3.0) == pytest.approx((math.sqrt(2 * delta),) * 2, rel=5e-3)


def test_extent_bad_t_end():
    with pytest.raises(SceneError, match="t_end"):
        contact_extent(femehl.presets.paper_sphere(), 0.0)


# ---------------------------------------------------------------------------
# fitted meshes


def _across(dm, axis, a):
    """Distinct elements crossed along the contact width [-a, a] of the x (0) or y (1) axis."""
    s = np.linspace(-a, a, 4001) if not (dm.half and axis == 1) else np.linspace(1e-9, a, 2001)
    off = 1e-4 * a
    x, y = (s, np.full_like(s, off)) if axis == 0 else (np.full_like(s, off), s)
    e = dm.mesh.element_finder()(x, y)
    n = np.unique(e[e >= 0]).size
    return 2 * n if (dm.half and axis == 1) else n  # the half disk holds half the y axis


def _edge_size(dm, x, y):
    """Equilateral-equivalent size sqrt(4 A / sqrt(3)) of the element holding (x, y)."""
    e = dm.mesh.element_finder()(np.array([x]), np.array([y]))[0]
    return math.sqrt(4.0 * areas(dm)[e] / math.sqrt(3.0))


@pytest.mark.parametrize("name", list(SCENES))
def test_fitted_mesh_resolves_the_contact(meshes, name):
    dm = meshes[name]
    ax, ay = contact_extent(SCENES[name], 3.0)
    assert _across(dm, 0, ax) >= MIN_ACROSS
    assert _across(dm, 1, ay) >= MIN_ACROSS
    assert _edge_size(dm, -ax, 1e-4) <= MAX_EDGE_FRACTION * 2 * ax
    assert _edge_size(dm, 1e-4, ay * (1 - 1e-4)) <= MAX_EDGE_FRACTION * 2 * ay


def test_ladder_does_not_resolve_the_ellipse():
    """The motivation: the medium ladder crosses the short axis with fewer than half as many."""
    ax, _ = contact_extent(SCENES["ellipsoid_y"], 3.0)
    assert _across(load_mesh("medium"), 0, ax) < MIN_ACROSS / 1.5


@pytest.mark.parametrize("name", list(SCENES))
def test_fitted_mesh_is_a_valid_disk(meshes, name):
    dm = meshes[name]
    assert dm.half and dm.L == 2.0 and dm.name.startswith("fitted-")
    again = load_mesh(dm, L=2.0, half=True)  # every load_mesh check
    assert again is dm
    # inscribed polygon: relative deficit about h_far^2 / (6 L^2) = 4e-3 (load_mesh notes)
    assert areas(dm).sum() == pytest.approx(math.pi * 2.0, rel=1e-2)


def test_full_disk_for_asymmetric_shape(tmp_path):
    sc = Scene(
        indenter=Shape(lambda x, y: (x**2 + y**2) / 2 + 0.01 * x * y), motion=Motion(gap=RampHold(0.1, -0.5))
    )
    dm = fitted_disk(sc, 2.0, level=2.1, cache_dir=tmp_path)
    assert not dm.half and load_mesh(dm, L=2.0, half=False) is dm
    with pytest.raises(MeshError, match="symmetric"):
        fitted_disk(sc, 2.0, half=True, cache_dir=tmp_path)


def test_sphere_level_one_matches_medium_rung():
    """The size field reduces to the medium rung for the paper sphere at beta = 200."""
    s = fitted_sizes(femehl.presets.paper_sphere(), 3.0)
    assert s.h_contact == pytest.approx(0.095) and s.edge_coef == pytest.approx(0.0407, rel=1e-3)
    assert s.size(1.0, 0.0) == pytest.approx(0.0407, rel=1e-3)
    assert s.size(2.0, 0.0) == pytest.approx(0.304, rel=1e-2)


def test_level_scales_sizes_and_elements(tmp_path):
    sc = SCENES["ellipsoid_y"]
    s1, s2 = fitted_sizes(sc, 3.0, 1.0), fitted_sizes(sc, 3.0, 1.0 / 1.45)
    for x, y in [(0.0, 0.0), (-0.44, 0.0), (0.3, 1.1), (1.9, 0.1)]:
        assert s2.size(x, y) == pytest.approx(s1.size(x, y) / 1.45, rel=1e-12)
    n1 = fitted_disk(sc, 3.0, level=1.45, cache=False).mesh.t.shape[1]
    n2 = fitted_disk(sc, 3.0, level=1.0, cache=False).mesh.t.shape[1]
    assert 1.7 < n2 / n1 < 2.4


@pytest.mark.parametrize("name", sorted(SCENES))
def test_vectorized_sizes_and_other_levels_are_the_same_field(name):
    """``sizes`` (arrays) is ``size`` (scalar, what gmsh calls) point by point, including
    the origin, the contact edge and the rim; ``at_level`` is ``fitted_sizes`` at that
    level, and so are their cell estimates."""
    sc = SCENES[name]
    base = fitted_sizes(sc, 3.0, 1.0)
    rng = np.random.default_rng(1)
    x, y = rng.uniform(-2.0, 2.0, (2, 500))
    x[:3], y[:3] = (0.0, base.ax, 2.0), (0.0, 0.0, 0.0)
    scalar = np.array([base.size(a, b) for a, b in zip(x, y, strict=True)])
    np.testing.assert_allclose(base.sizes(x, y), scalar, rtol=1e-14)
    for level in (4.0, 0.5):
        direct = fitted_sizes(sc, 3.0, level)
        moved = base.at_level(level)
        np.testing.assert_allclose(moved.sizes(x, y), direct.sizes(x, y), rtol=1e-14)
        assert moved.estimate_elements(False) == pytest.approx(direct.estimate_elements(False), rel=1e-12)


def test_edge_band_narrows_with_beta():
    """W(beta) = max(0.05, 1.17 beta^(-1/3)): 0.2 at beta = 200."""
    w = [fitted_sizes(femehl.presets.paper_sphere(beta=b), 3.0).width for b in (200.0, 2000.0, 1e6)]
    assert w[0] == pytest.approx(0.2, rel=1e-2)
    assert w[1] == pytest.approx(0.2 / 10 ** (1 / 3), rel=1e-2)
    assert w[2] == F.W_MIN


def test_thin_films_get_a_contact_zone_at_the_edge_scale(tmp_path):
    """Above beta ~ 218 the contact zone is at most C_CONTACT_EDGE edge sizes (the trapped
    dimple's rim crosses it during the approach); up to beta = 200 it is unchanged.  The
    gmsh mesh honours it: element sizes (sqrt of 4 area / sqrt 3) inside the contact zone of
    a beta = 20000 sphere at level 2."""
    paper = [fitted_sizes(femehl.presets.paper_sphere(beta=b), 3.0) for b in (20.0, 200.0)]
    assert [s.h_contact for s in paper] == [pytest.approx(0.095, rel=1e-12)] * 2
    for beta in (2000.0, 20000.0):
        s = fitted_sizes(femehl.presets.paper_sphere(beta=beta), 3.0)
        assert s.h_contact == pytest.approx(F.C_CONTACT_EDGE * s.edge_coef * min(s.ax, s.ay), rel=1e-12)
        assert s.h_contact < 0.5 * 0.095
    sc = femehl.presets.paper_sphere(beta=20000.0)
    s = fitted_sizes(sc, 3.0, level=2.0)
    dm = fitted_disk(sc, 3.0, level=2.0, cache_dir=tmp_path)
    p, t = dm.mesh.p, dm.mesh.t
    c = p[:, t].mean(axis=1)
    a = p[:, t[1]] - p[:, t[0]]
    b = p[:, t[2]] - p[:, t[0]]
    h = np.sqrt(4.0 / math.sqrt(3.0) * 0.5 * np.abs(a[0] * b[1] - a[1] * b[0]))
    inner = np.hypot(*c) < 0.6 * s.ax
    assert inner.sum() > 100
    assert np.median(h[inner]) == pytest.approx(s.h_contact, rel=0.25)


@pytest.mark.parametrize("level", [0.0, -1.0, math.nan, "fine"])
def test_bad_level(level):
    with pytest.raises(MeshError, match="level"):
        fitted_disk(SCENES["flat_punch"], 3.0, level=level, cache=False)


# ---------------------------------------------------------------------------
# cache


def test_cache_returns_the_identical_mesh(tmp_path, monkeypatch):
    sc = SCENES["ellipsoid_x"]
    first = fitted_disk(sc, 3.0, level=1.45, cache_dir=tmp_path)
    files = list(tmp_path.glob("fitted_half-*.msh"))
    assert len(files) == 1

    def no_gmsh(*args, **kw):
        raise AssertionError("a cached mesh must not be regenerated")

    monkeypatch.setattr(F, "sized_disk", no_gmsh)
    second = fitted_disk(sc, 3.0, level=1.45, cache_dir=tmp_path)
    assert second.name == first.name and second.half == first.half
    np.testing.assert_array_equal(second.mesh.p, first.mesh.p)
    np.testing.assert_array_equal(second.mesh.t, first.mesh.t)
    # another level is another key
    with pytest.raises(AssertionError, match="regenerated"):
        fitted_disk(sc, 3.0, level=1.0, cache_dir=tmp_path)


def test_damaged_cache_is_regenerated(tmp_path):
    sc = SCENES["flat_punch"]
    dm = fitted_disk(sc, 3.0, level=2.1, cache_dir=tmp_path)
    (path,) = tmp_path.glob("*.msh")
    path.write_bytes(b"not a mesh")
    again = fitted_disk(sc, 3.0, level=2.1, cache_dir=tmp_path)
    np.testing.assert_array_equal(again.mesh.t, dm.mesh.t)
    assert load_mesh(path, half=True).mesh.t.shape == dm.mesh.t.shape  # rewritten


def test_solver_runs_on_a_fitted_mesh(tmp_path):
    sc = SCENES["ellipsoid_y"]
    dm = fitted_disk(sc, 0.6, level=2.1, cache_dir=tmp_path)
    res = femehl.solve(sc, t_end=0.6, dt=0.05, mesh=dm, store_every=0)
    assert np.isfinite(res.film_min[-1]) and res.load[-1] > 0


def test_load_mesh_names_the_fitted_fix():
    with pytest.raises(MeshError, match="fitted_disk"):
        load_mesh("fitted")


def test_heightmap_extent():
    """A sampled sphere (HeightMap) goes through the Sneddon route: a = 1 to 1 %."""
    from femehl.problem.indenters import HeightMap

    g = np.linspace(-3.0, 3.0, 241)
    X, Y = np.meshgrid(g, g, indexing="ij")
    sc = Scene(indenter=HeightMap(g, g, (X**2 + Y**2) / 2), motion=Motion(gap=RampHold(0.1, -1.0)))
    assert contact_extent(sc, 2.0) == pytest.approx((1.0, 1.0), rel=1e-2)


def test_too_many_elements_refused_before_gmsh(monkeypatch):
    def no_gmsh(*args, **kw):
        raise AssertionError("gmsh must not run")

    monkeypatch.setattr(F, "sized_disk", no_gmsh)
    with pytest.raises(MeshError, match="larger level"):
        fitted_disk(SCENES["ellipsoid_y"], 3.0, level=1e-3, cache=False)


def test_mesh_fitted_is_a_solver_option():
    """``mesh="fitted"`` builds the scene's fitted mesh; for the paper sphere at level 1 its size
    field is the medium rung's (2988 against 2982 elements measured), so the counts agree."""
    st = femehl.make_stepper(femehl.presets.paper_sphere(), mesh="fitted")
    assert st.info["mesh"].startswith("fitted-") and st.info["half"]
    assert abs(st.info["elements"] / 2982 - 1.0) < 0.05


def test_wide_exit_zone_of_an_ellipse_keeps_sizes_positive(tmp_path):
    """At small beta the exit zone is wide, and along the long axis of an ellipse the edge
    size can exceed the contact size: the band must then grow away from the edge (it used
    to shrink to zero there: 7.7e8 elements estimated for Rx = 1, Ry = 2, beta = 20)."""
    sc = Scene(
        indenter=Ellipsoid(1.0, 2.0),
        fluid=femehl.Fluid(beta=20.0),
        motion=Motion(gap=RampHold(0.1, -1.0, 1.0), velocity=TanhStart(1.0, 1.0)),
        domain=Domain(3.0),
    )
    sz = fitted_sizes(sc, 8.0)
    ax, ay = contact_extent(sc, 8.0)
    assert sz.edge_coef * max(ax, ay) > sz.h_contact  # the case this test is about
    r, th = np.meshgrid(np.linspace(0, 3.0, 301), np.linspace(0, math.pi, 91))
    h = np.array(
        [sz.size(x, y) for x, y in zip((r * np.cos(th)).ravel(), (r * np.sin(th)).ravel(), strict=True)]
    )
    assert h.min() >= min(sz.h_contact, sz.edge_coef * min(ax, ay)) * (1 - 1e-12)
    # about as many elements as the sphere of the same depth (the ellipse is 1.6 times larger)
    sphere = fitted_sizes(Scene(fluid=femehl.Fluid(beta=20.0), motion=sc.motion, domain=Domain(3.0)), 8.0)
    assert sz.estimate_elements(True) < 3 * sphere.estimate_elements(True)
    dm = fitted_disk(sc, 8.0, cache_dir=tmp_path)
    assert dm.mesh.t.shape[1] < 2 * sz.estimate_elements(True)
