"""The Krylov residual follows a thinning film (femehl.solver.linsolve.film_rtol_scale).

The solve's error moves the film by about ``rtol`` times the deflection whatever the film,
so a film much thinner than the deflection carries a relative error that grows as it
thins.  The scene is the stress case beta = 2, h0 = 0.01, T = 0.1 (the paper's sphere with
a fast sliding start) on the coarse ladder mesh, whose film thins to 0.0056 against a
deflection of 1.4 by t = 2.21 (d / w = 4e-3); the reference is the same run solved by a
direct LU every step.
"""

from __future__ import annotations

import numpy as np
import pytest

import femehl
import femehl.solver.stepper as stepper_module
from femehl import Domain, Fluid, HalfSpace, Motion, RampHold, Scene, Sphere, TanhStart
from femehl.solver import linsolve
from femehl.solver.linsolve import FILM_RTOL_FLOOR, FILM_RTOL_REF, film_rtol_scale


@pytest.mark.parametrize(
    "dmin, wmax, expected",
    [
        (0.5, 1.0, 1.0),  # a thick film: unchanged
        (FILM_RTOL_REF * 2.0, 2.0, 1.0),  # at the reference ratio: unchanged
        (1e-4, 1.0, 1e-4 / FILM_RTOL_REF),  # in proportion below it
        (1e-9, 1.0, FILM_RTOL_FLOOR),  # never below the floor
        (-1e-3, 1.0, FILM_RTOL_FLOOR),  # a (rejected) non-positive film: the floor
        (0.01, 0.0, 1.0),  # no deflection yet (the first step)
    ],
)
def test_scale_is_the_film_ratio(dmin, wmax, expected):
    d = np.array([3.0, dmin, 1.0])
    w = np.array([0.0, -wmax, 0.5 * wmax])
    assert film_rtol_scale(d, w) == pytest.approx(expected, rel=1e-12)


def _scene():
    return Scene(
        indenter=Sphere(1.0),
        substrate=HalfSpace(0.5),
        fluid=Fluid(2.0),
        motion=Motion(gap=RampHold(h0=0.01, h_end=-1.0, t1=1.0), velocity=TanhStart(t1=1.0, T=0.1)),
        domain=Domain(2.0),
    )


KW = dict(mesh="coarse", t_end=2.25, dt=0.01, scheme="bdf2", store_every=1, estimate=False)


@pytest.fixture(scope="module")
def direct():
    return femehl.solve(_scene(), linear_solver="lu", **KW)


def test_residual_follows_the_film(monkeypatch, direct):
    """With the reference ratio at 1 (every film counts as thin), each step's true residual
    is within the base rtol (1e-8, dense) times the film ratio of the state it started from,
    and the film follows the direct solve to 1e-6 (without the scaling: 5e-5 to 8e-5)."""
    monkeypatch.setattr(linsolve, "FILM_RTOL_REF", 1.0)
    res = femehl.solve(_scene(), **KW)
    scales = [film_rtol_scale(s.d, s.w) for s in res.states[:-1]]
    residuals = [s.info["residual"] for s in res.states[1:]]
    assert min(scales) < 1e-2  # the film really is thin against the deflection
    assert all(r <= 1e-8 * c for r, c in zip(residuals, scales, strict=True))
    assert np.abs(res.film_min / direct.film_min - 1.0).max() < 2e-6


def test_unscaled_residual_leaves_a_larger_film_error(monkeypatch, direct):
    """The same run with the scaling switched off: the film error the test above bounds is
    then 30 times larger (so the bound above tests the scaling, not the solver)."""
    monkeypatch.setattr(stepper_module, "film_rtol_scale", lambda d, w: 1.0)
    res = femehl.solve(_scene(), **KW)
    assert np.abs(res.film_min / direct.film_min - 1.0).max() > 2e-5
