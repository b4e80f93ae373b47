"""Steady sliding on a standard-linear-solid Winkler foundation: femehl's runs (automatic
and expert mode) against the collocation reference femehl.reference.viscoelastic_line,
and that reference against its elastic limits (femehl.reference.line_steady, shooting)."""

from __future__ import annotations

import numpy as np
import pytest

import femehl
from femehl.problem.line import LineScene
from femehl.reference.line_steady import steady_line
from femehl.reference.viscoelastic_line import steady_viscoelastic_line

K, BETA, HC, L, V = 1.0, 10.0, -0.5, 2.0, 1.0  # the default LineScene's steady sliding


def sls(tau):
    return femehl.Viscoelastic(G0=1.0, G_inf=0.5, tau=tau)  # J0 = 1, J_inf = 2, tau_c = 2 tau


def test_reference_limits():
    """G0 = G_inf: the elastic solution (k); tau -> inf: the unrelaxed one (k G0), tau -> 0:
    the relaxed one (k G_inf), errors O(L/(V tau_c)) and O(V tau_c / a); the energy
    balance f V = D_film + P_sliding (an identity of the steady equations) closes."""
    same = steady_viscoelastic_line(K, BETA, HC, L, V, femehl.Viscoelastic(G0=2.0, G_inf=2.0, tau=1.0))
    assert same.load == pytest.approx(steady_line(2.0, BETA, HC, L, V, full=True).load, rel=1e-6)
    assert abs(same.power_sliding) < 1e-8  # the quadrature of J0 p p'/k (exactly 0): 2e-10
    slow = steady_viscoelastic_line(K, BETA, HC, L, V, sls(1e6))
    fast = steady_viscoelastic_line(K, BETA, HC, L, V, sls(1e-4))
    assert slow.load == pytest.approx(
        steady_line(K, BETA, HC, L, V, full=True).load, rel=1e-5
    )  # measured 2e-7
    assert fast.load == pytest.approx(
        steady_line(K / 2.0, BETA, HC, L, V, full=True).load, rel=2e-3
    )  # 2 V tau_c = 4e-4
    for r in (same, slow, fast, steady_viscoelastic_line(K, BETA, HC, L, V, sls(1.0))):
        assert r.friction * V == pytest.approx(r.dissipation_film + r.power_sliding, rel=1e-7)
    # P ~ 1/tau_c in the slow limit (1.3e-5 at tau = 1e4, 1.3e-7 at 1e6), ~ tau_c in the fast one
    assert 0.0 < slow.power_sliding < 1e-6 and 0.0 < fast.power_sliding < 1e-3


@pytest.mark.parametrize("tau", [0.01, 1.0, 1e4])
def test_automatic_mode_reaches_the_steady_reference(tau):
    """``femehl.solve(scene, t_end, tol)`` with no dt: the steps grow to the substrate's
    step limit (a quarter of the domain's transit, 0.5 here) and the steady load and the
    dissipated power P_sliding match the reference.  Measured (400 elements): load
    2.5e-6, 2.6e-6, 1.0e-6 off; P_sliding 3.2e-4, 3.8e-5, 1.4e-5 off at tau = 0.01, 1, 1e4
    (the old memory: P 50-101 % low at tau = 1e4, dt up to t_end/10 = 1.2).  Tolerances:
    the load 2e-5, P 1e-3 (about 3x the largest measured, spatial errors of the 400
    element mesh: the thinner memory boundary layer at tau = 0.01 is the worst)."""
    ref = steady_viscoelastic_line(K, BETA, HC, L, V, sls(tau))
    r = femehl.solve(LineScene(k=K, beta=BETA, viscoelastic=sls(tau)), t_end=12.0, tol=1e-2)
    assert r.load[-1] == pytest.approx(ref.load, rel=2e-5)
    assert r.power_sliding[-1] == pytest.approx(ref.power_sliding, rel=1e-3)
    assert r.friction[-1] == pytest.approx(ref.friction, rel=1e-4)
    assert np.nanmax(r.dt) <= sls(tau).step_limit(r.scene, r.disc, 12.0) * (1 + 1e-9)


def test_fixed_steps_give_the_same_steady_state():
    """Expert mode at tau = 0.1 (tau_c = 0.2, a memory length 2 V tau_c = 0.4 ~ the contact):
    dt = 0.02 and 0.32 (a shift of 0.64 per step) give the same steady load to 9e-7
    (measured: 9.8e-6 and 9.0e-6 off the reference; the old memory: +1.6e-3 and +19 %);
    tolerances 6e-6 apart and 2e-5 from the reference (2x the measured spatial error)."""
    ref = steady_viscoelastic_line(K, BETA, HC, L, V, sls(0.1))
    scene = LineScene(k=K, beta=BETA, viscoelastic=sls(0.1))
    load = {
        dt: femehl.solve_line(scene, t_end=15.0, dt=dt, scheme="bdf2", estimate=False).load[-1]
        for dt in (0.02, 0.32)
    }
    assert load[0.02] == pytest.approx(load[0.32], rel=6e-6)
    for v in load.values():
        assert v == pytest.approx(ref.load, rel=2e-5)


def test_step_limit():
    """The substrate states its limit; substrates without memory have none."""
    from femehl.api import make_stepper
    from femehl.elastic.base import step_limit

    scene = LineScene(k=K, beta=BETA, viscoelastic=sls(1.0))
    disc = make_stepper(scene, "line").disc
    span = np.ptp(disc.film_points[:, 0])
    assert step_limit(scene.substrate, scene, disc, 12.0) == pytest.approx(span / 8.0)  # V_max = 1
    assert step_limit(femehl.Winkler(1.0), scene, disc, 12.0) == np.inf
