"""Meshes adapted to a run (femehl.discretize.adapted): the size field puts the cells where
the film curves, its level scales the cells like level^-2, and on a smooth field with one
sharp feature the adapted meshes interpolate it at second order with far fewer cells
than uniform ones."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import matplotlib.tri as mtri
import numpy as np
import pytest

from femehl.discretize.adapted import AdaptedSizes, adapted_sizes, curvature_indicator
from femehl.discretize.mesh import areas, centroids, sized_disk
from femehl.errors import SceneError


def ring(x, y):
    """A film 0.2 thick at the ring r = 1 (width 0.08) and 1.2 elsewhere: one sharp feature."""
    r = np.hypot(x, y)
    return 1.2 - np.exp(-(((r - 1.0) / 0.08) ** 2))


def fake_run(dm):
    """A 'run' whose one stored state has the ring as its film and no pressure."""
    c = centroids(dm)
    n = dm.mesh.p.shape[1]
    disc = SimpleNamespace(mesh=dm.mesh, areas=areas(dm), free=np.arange(n), L=dm.L, half=dm.half)
    state = SimpleNamespace(t=1.0, d=ring(c[:, 0], c[:, 1]), p=np.zeros(n))
    return SimpleNamespace(disc=disc, states=[state])


def interpolation_error(dm) -> float:
    """Max relative error of the ring's linear interpolant on ``dm`` (sampled finely)."""
    p = dm.mesh.p
    f = mtri.LinearTriInterpolator(mtri.Triangulation(p[0], p[1], dm.mesh.t.T), ring(p[0], p[1]))
    r = np.linspace(0.6, 1.4, 401)
    th = np.linspace(0.05, math.pi - 0.05, 61)
    R, T = np.meshgrid(r, th)
    x, y = R * np.cos(T), R * np.sin(T)
    exact = ring(x, y)
    return float(np.max(np.abs(f(x, y) - exact) / exact))


@pytest.fixture(scope="module")
def source():
    return sized_disk(2.0, True, lambda x, y: 0.06)


def test_sizes_follow_the_curvature_and_the_level(source):
    run = fake_run(source)
    sizes = adapted_sizes(run, 2000)
    assert sizes.cells(1.0) == pytest.approx(2000, rel=0.02)  # calibrated
    assert sizes.cells(0.5) == pytest.approx(4 * sizes.cells(1.0), rel=0.15)  # graded sizes scale ~level
    ind = curvature_indicator(run.disc, run.states[0])
    s_elem = np.mean(sizes.s[source.mesh.t], axis=0)
    sharp = ind >= np.quantile(ind, 0.95)
    assert np.mean(s_elem[sharp]) < 0.3 * np.mean(s_elem)  # small where the film curves
    mesh = sizes.mesh(1.0)
    assert mesh.mesh.t.shape[1] == pytest.approx(sizes.cells(1.0), rel=0.25)  # gmsh follows the field
    again = AdaptedSizes.from_record(sizes.record())  # what a run folder keeps
    assert again.cells(0.7) == sizes.cells(0.7)


def test_adapted_meshes_converge_at_second_order_with_fewer_cells(source):
    """Measured: 1,702 and 6,550 cells at levels 1 and 0.5, max relative interpolation
    error 0.32 and 0.078 (ratio 4.1); a uniform mesh of 6,624 cells 0.38 (4.9 times)."""
    sizes = adapted_sizes(fake_run(source), 1500)
    coarse, fine = sizes.mesh(1.0), sizes.mesh(0.5)
    e1, e2 = interpolation_error(coarse), interpolation_error(fine)
    # level 1 -> 0.5 halves every size: the interpolation error of a smooth field / 4
    assert 2.8 < e1 / e2 < 5.6, (e1, e2)
    # a uniform mesh with as many cells as the finer adapted one is far less accurate
    n = fine.mesh.t.shape[1]
    h = math.sqrt(0.5 * math.pi * 4.0 / (n * math.sqrt(3.0) / 4.0))
    uniform = sized_disk(2.0, True, lambda x, y: h)
    assert uniform.mesh.t.shape[1] == pytest.approx(n, rel=0.15)
    assert interpolation_error(uniform) > 3.0 * e2


def test_bad_input_is_refused(source):
    with pytest.raises(SceneError, match="FE disk run"):
        adapted_sizes(SimpleNamespace(disc=None, states=[]), 1000)
    with pytest.raises(SceneError, match="stored states"):
        adapted_sizes(SimpleNamespace(disc=fake_run(source).disc, states=[]), 1000)
    with pytest.raises(SceneError, match="cells"):
        adapted_sizes(fake_run(source), 3)
    with pytest.raises(SceneError, match="level"):
        adapted_sizes(fake_run(source), 1000).cells(0.0)


def test_a_full_disk_run_and_the_plan_round_trip():
    """Sizes from a real FE run on the full disk (an indenter not symmetric in y), and the
    adapted ladder a resumed run rebuilds from a run folder's plan meshes the same disk."""
    import femehl
    from femehl.accuracy.auto import _ladder_of, adapted_ladder
    from femehl.problem.indenters import Shape

    tilted = Shape(lambda x, y: (x**2 + y**2) / 2 + 0.05 * y)
    scene = dataclasses.replace(femehl.presets.paper_sphere(), indenter=tilted)
    res = femehl.solve(scene, t_end=0.3, dt=0.05, mesh="coarse", store_every=1, estimate=False)
    assert res.disc.half is False
    sizes = adapted_sizes(res, 800)
    ladder = adapted_ladder(sizes)
    mesh = ladder.options(scene, 0.3, 1.0)["mesh"]
    assert mesh.half is False and mesh.mesh.t.shape[1] == pytest.approx(800, rel=0.3)
    again = _ladder_of("fe", {"level": 1.0, **ladder.record})
    assert np.array_equal(again.options(scene, 0.3, 1.0)["mesh"].mesh.p, mesh.mesh.p)


def test_a_linear_size_field_is_read_by_gmsh_as_it_is_by_python(source):
    """LinearSizes: exact on a linear field, its largest value outside the triangles; gmsh's
    mesh under it (a background view) is the mesh of the same sizes given as a callback,
    and its element sizes follow the field (h = 0.06 at x = -2 to 0.18 at x = 2)."""
    from femehl.discretize.mesh import LinearSizes

    p, t = source.mesh.p, source.mesh.t
    field = LinearSizes(p, t, 0.12 + 0.03 * p[0], far=0.3)
    for x, y in [(0.3, 0.7), (-1.2, 0.1), (1.0, 1.2)]:
        assert field(x, y) == pytest.approx(0.12 + 0.03 * x, rel=1e-12)
    assert field(0.0, -0.5) == 0.3  # below the half disk: outside every triangle
    # a constant field: the cells of the constant callback (gmsh also reads the view on the
    # sliver between the source's polygon and the arc, where a call gives far)
    const = sized_disk(2.0, True, LinearSizes(p, t, np.full(p.shape[1], 0.12), far=0.3))
    assert const.mesh.t.shape[1] == sized_disk(2.0, True, lambda x, y: 0.12).mesh.t.shape[1]
    view = sized_disk(2.0, True, field)
    c, a = centroids(view), areas(view)
    left, right = a[np.abs(c[:, 0] + 1.0) < 0.2], a[np.abs(c[:, 0] - 1.0) < 0.2]
    # sizes 0.09 and 0.15 at x = -1 and 1: area ratio (0.15 / 0.09)^2 = 2.78
    assert np.median(right) / np.median(left) == pytest.approx(2.78, rel=0.15)
