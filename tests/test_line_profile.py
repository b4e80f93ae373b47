"""LineScene(profile=...): a user rigid gap s(x) for line contact."""

from __future__ import annotations

import numpy as np
import pytest

from femehl.api import make_stepper, solve_line
from femehl.errors import SceneError
from femehl.output.checkpoint import describe
from femehl.problem.line import LineScene, contact_halfwidth
from femehl.problem.scene import Constant, Motion, RampHold, TanhStart


def motion():
    return Motion(gap=RampHold(0.1, -0.5, 1.0), velocity=TanhStart(1.0, 1.0))


def test_no_profile_is_the_cylinder_as_before():
    # final loads of this short run before profile= existed (commit e2e6e30); the final d
    # and p were bit-identical then (sha1 of the arrays), the loads are pinned here
    before = {None: 0.9610926829534772, "reynolds": 1.0113743402793496}
    for cav, load in before.items():
        r = solve_line(LineScene(motion=motion(), cavitation=cav), 3.0, 0.1, n_elements=100)
        assert r.final.load == pytest.approx(load, rel=1e-13, abs=0.0)
    sc = LineScene(motion=motion())
    x = np.linspace(-2.0, 2.0, 7)
    assert np.array_equal(sc.indenter.line_gap(x), 0.5 * x * x)
    assert describe(sc)["indenter"]["type"] == "Cylinder"


def test_profile_equal_to_the_cylinder_gives_the_same_run():
    a = solve_line(LineScene(motion=motion()), 3.0, 0.1, n_elements=100)
    # a user profile has no dry-contact estimate, so its default fine zone is L/2: give
    # the cylinder's (a + 0.5 = 1.5) to compare on the same mesh
    b = solve_line(LineScene(motion=motion(), profile=lambda x: x**2 / 2), 3.0, 0.1, n_elements=100, fine=1.5)
    assert np.array_equal(a.disc.x, b.disc.x)
    assert np.array_equal(a.final.d, b.final.d) and np.array_equal(a.final.p, b.final.p)
    assert a.final.load == b.final.load


def test_profile_scene_and_its_default_mesh():
    sc = LineScene(motion=Motion(gap=Constant(0.2), velocity=1.0), k=1e4, profile=lambda x: 0.1 * (x + 2.0))
    assert contact_halfwidth(sc) is None
    x = np.linspace(-2.0, 2.0, 5)
    assert np.allclose(sc.indenter.line_gap(x), 0.1 * (x + 2.0))
    st = make_stepper(sc, "line", n_elements=40)  # default grading 3: fine zone L/2
    assert np.allclose(st.disc.shape, 0.1 * (st.disc.xc + 2.0))
    assert describe(sc)["indenter"]["type"] == "Profile"
    # an offset profile lets hc(0) be negative as long as the film is open
    LineScene(motion=Motion(gap=-0.5, velocity=1.0), profile=lambda x: 1.0 + 0.5 * x * x)
    # a short nearly rigid run: the slider converges toward the outlet -L, p > 0 builds up
    r = solve_line(sc, 1.0, 0.1, n_elements=40)
    assert r.final.load > 0 and np.all(r.film_min > 0)


@pytest.mark.parametrize(
    "profile, match",
    [
        (0.5, "must be a callable"),
        (lambda x: 1.0, "returned shape"),
        (lambda x: np.ones(3), "returned shape"),
        (lambda x: np.where(x > 1.0, np.nan, 0.0), "not finite at x"),
        (lambda x: 1.0 / (x - x), "not finite at x"),
        (lambda x: [float(v) ** 0.5 for v in x], "returned shape|real"),
        (lambda x: x.nonexistent, "raised AttributeError"),
        (lambda x: 0.5 * x - 1.0, "must be open everywhere"),
    ],
)
def test_bad_profile_is_refused(profile, match):
    with np.errstate(all="ignore"), pytest.raises(SceneError, match=match):
        LineScene(motion=motion(), profile=profile)
