"""FE vs the paper-faithful FD reference on the paper case (beta = 200, h0 = 0.1).

Both solvers run the same scene with the same dt = 0.02 (so the lagged scheme's
time error is common to both and the comparison isolates the spatial
discretizations) to t = 2 (indentation, then sliding).  FD at dr = 0.025,
dtheta = pi/36 — the coarsest FD grid that stays stable through the sliding
start-up (its forward differences are downwind at the exit); FE on the
"medium" mesh.

Tolerances come from the refinement studies of each solver (figures measured
on this machine):

* FE along the ladder coarse -> medium -> fine changes load by < 0.03 %,
  central film by < 0.2 %, minimum film by < 1 % (t = 2), so the FE values are
  converged to better than 1 %; the comparison error is the FD's.
* FD is first order in dr: at t = 1, dr = 0.05 -> 0.025 changes the central
  film by 2.4 % and the load by 0.15 %, so its error at dr = 0.025 is about
  that size again: tolerance 1.5 % on load, 5 % on the films at t <= 1.
* At t = 2 the minimum film sits in the side lobes of the horseshoe at
  r ~ 1.  Refining the FD in dtheta (pi/36 -> pi/48) changes it by < 1 %,
  in dr (0.025 -> 0.0125) by +6.8 % (0.02457 -> 0.02623): first order in dr,
  so the FD error at dr = 0.025 is about twice that step, 13 %, and its
  Richardson extrapolation (0.0279) agrees with the FE value (0.0277, medium;
  0.0278, fine) to 1 %.  Tolerance 15 % for this entry; the same
  extrapolation brings the central film (0.0425 vs FE 0.0425) and the load
  (0.4726 vs 0.4727 at t = 1) into agreement.
* Centreline pressure profile, relative L2 over x in [-1.5, 1.5]: measured
  1.0 %, 0.5 %, 2.0 % at t = 0.5, 1, 2; tolerance 3 % (t <= 1) and 4 % (t = 2).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import femehl

TIMES = (0.5, 1.0, 2.0)


@pytest.fixture(scope="module")
def runs():
    scene = femehl.presets.paper_sphere(beta=200.0, h0=0.1)
    kw = dict(t_end=2.0, dt=0.02, store_every=25)
    fe = femehl.solve(scene, "fe", mesh="medium", **kw)
    fd = femehl.solve(scene, "fd", dr=0.025, dtheta=math.pi / 36, **kw)
    return fe, fd


@pytest.mark.parametrize("t", TIMES)
def test_load_agrees(runs, t):
    fe, fd = runs
    a, b = fe.value_at("load", t), fd.value_at("load", t)
    assert abs(a - b) < 0.015 * b, (a, b)


@pytest.mark.parametrize("t", TIMES)
def test_central_film_agrees(runs, t):
    fe, fd = runs
    a, b = fe.value_at("film_center", t), fd.value_at("film_center", t)
    assert abs(a - b) < 0.05 * b, (a, b)


@pytest.mark.parametrize("t,tol", [(0.5, 0.05), (1.0, 0.05), (2.0, 0.15)])
def test_minimum_film_agrees(runs, t, tol):
    fe, fd = runs
    a, b = fe.value_at("film_min", t), fd.value_at("film_min", t)
    assert abs(a - b) < tol * b, (a, b)


@pytest.mark.parametrize("t,tol", [(0.5, 0.03), (1.0, 0.03), (2.0, 0.04)])
def test_centreline_pressure_profiles_agree(runs, t, tol):
    fe, fd = runs
    x = np.linspace(-1.5, 1.5, 301)
    pts = np.column_stack([x, np.zeros_like(x)])
    pa, pb = fe.pressure_at(pts, t), fd.pressure_at(pts, t)
    err = np.linalg.norm(pa - pb) / np.linalg.norm(pb)
    assert err < tol, err


def test_sliding_shows_exit_constriction(runs):
    """During sliding both solvers put the minimum film on the exit side (x < 0), and on
    the exit half of the centreline the film has its constriction near x = -1 (paper
    Fig. 6).  (At t = 2 the start-up still carries the fluid trapped during indentation
    toward the exit, so the centreline film has a second, transient dip on the inlet
    side near x = +0.55; the exit constriction is the minimum over x < 0.)"""
    fe, fd = runs
    x = np.linspace(-1.5, 0.0, 301)
    pts = np.column_stack([x, np.zeros_like(x)])
    for res in (fe, fd):
        i = int(np.argmin(res.film_at(pts, 2.0)))
        assert -1.25 < x[i] < -0.85, (res.method, x[i])
        s = res.summary()
        k = int(np.argmin(np.abs(res.t - 2.0)))
        assert s["film_min_x"][k] < 0.0
