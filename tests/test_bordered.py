"""An imposed load's or a free indenter's step solved bordered: hc one more unknown of one
Krylov solve, against the two right-hand sides it replaces."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp

import femehl
from femehl.errors import SingularSystemError
from femehl.problem.scene import Constant, Domain, Fluid, Motion, RampHold, Scene
from femehl.solver import linsolve
from femehl.solver.linsolve import BorderedOperator, DirectSolver, RecycledGCR, StepOperator


def _bordered(seed=0, corner=0.5):
    """A random dense step operator (as in test_linsolve) and a border on it."""
    rng = np.random.default_rng(seed)
    C = rng.random((300, 200)) / 200
    F = sp.csr_matrix(rng.random((200, 300)) / 300)
    base = StepOperator(
        D=sp.diags(2.0 + rng.random(200), format="csr"), films=[(1.0, F, F @ C)], C=C, key=1.0
    )
    row = rng.random(200) / 200
    return BorderedOperator(base, row, corner), base, rng


def _explicit(op: BorderedOperator, base: StepOperator) -> np.ndarray:
    """The bordered matrix written out: ``[[A, G 1], [-l, c]]``."""
    n = base.D.shape[0]
    M = np.zeros((n + 1, n + 1))
    M[:n, :n] = base.matrix()
    M[:n, n] = op.column
    M[n, :n] = -op.row
    M[n, n] = op.corner
    return M


@pytest.mark.parametrize("corner", [0.0, 0.5])
def test_the_krylov_solve_of_a_bordered_step_is_the_bordered_system(corner):
    """The recycled Krylov solver on a :class:`BorderedOperator` solves the bordered matrix
    written out (to its rtol), and so does the direct solve through its Schur complement."""
    op, base, rng = _bordered(corner=corner)
    b = rng.random(201)
    want = np.linalg.solve(_explicit(op, base), b)
    ((x, cx),) = RecycledGCR().solve(op, [b], 0.0)
    np.testing.assert_allclose(x, want, rtol=0, atol=1e-7 * np.max(np.abs(want)))
    # the tracked C x is the film's change: C p plus eta
    np.testing.assert_allclose(cx, base.C @ x[:200] + x[200], rtol=0, atol=1e-9 * np.max(np.abs(cx)))
    ((xd, _),) = DirectSolver().solve(op, [b], 0.0)
    np.testing.assert_allclose(xd, want, rtol=0, atol=1e-11 * np.max(np.abs(want)))


def test_a_bordered_step_keeps_its_preconditioner_and_follows_the_border():
    """The next step's border (another row and corner) is taken by the kept LU's Schur
    complement (one more solve with it), not by a refresh."""
    op, base, rng = _bordered()
    solver = RecycledGCR()
    solver.solve(op, [rng.random(201)], 0.0)
    lus = solver.info["factorizations"]
    op2 = BorderedOperator(base, rng.random(200) / 100, 2.0)
    b = rng.random(201)
    ((x, _),) = solver.solve(op2, [b], 0.0)
    assert solver.info["factorizations"] == lus
    np.testing.assert_allclose(_explicit(op2, base) @ x, b, rtol=0, atol=1e-7 * np.linalg.norm(b))


def test_a_row_the_film_does_not_answer_is_singular():
    """A load row orthogonal to the pressure's response to hc (no corner): femehl's error,
    not a division by zero."""
    op, base, _ = _bordered(corner=0.0)
    lu = base.factorize(np.float64, 0.0)
    w = lu.solve(op.column)
    row = np.zeros(200)
    row[0], row[1] = w[1], -w[0]  # row . w = 0
    with pytest.raises(SingularSystemError, match="load row is singular"):
        linsolve.BorderedLU(lu, BorderedOperator(base, row, 0.0), 0.0)


def _load_controlled():
    F = 4.0 / (3.0 * np.pi)
    return Scene(
        substrate=femehl.HalfSpace(),
        fluid=Fluid(200.0),
        motion=Motion(gap=0.1, load=RampHold(0.0, F, 0.5), velocity=0.0),
        domain=Domain(2.0),
    )


def _free_indenter():
    return Scene(
        substrate=femehl.HalfSpace(),
        fluid=Fluid(200.0),
        motion=Motion(gap=Constant(0.1), velocity=0.0, mass=0.1, force=4.0 / (3.0 * np.pi)),
        domain=Domain(2.0),
    )


def _viscoelastic_load():
    """An imposed load on a viscoelastic half space: the step's film has a scale (its memory)."""
    return dataclasses.replace(_load_controlled(), substrate=femehl.Viscoelastic(G0=2.0, tau=0.5))


@pytest.mark.parametrize("make", [_load_controlled, _free_indenter, _viscoelastic_load])
def test_a_bordered_run_is_as_accurate_as_two_right_hand_sides_in_a_third_of_the_iterations(
    make, monkeypatch
):
    """Against the same run solved to rtol 1e-12, the bordered run's load, hc and films are as
    close as the two right-hand sides' (coarse mesh, dt = 0.01, to t = 0.6; measured apart /
    bordered: films 7.6e-7 / 1.2e-7 and 2.5e-7 / 5.9e-8, hc 5e-9 / 1e-8 and 7e-11 / 1e-10,
    load 1e-15 / 2.4e-10 and 3.4e-9 / 1.2e-8; on the viscoelastic substrate films 1.6e-7 /
    9.1e-8, hc 3.6e-9 / 4.1e-9, load 2e-15 / 1.5e-10: the solves' rtol 1e-8 carried by the
    lagged steps; bound 2e-6), in fewer preconditioned iterations (measured 264 against 540,
    177 against 408, 263 against 508; 0.34-0.43 on fitted levels 1 and 0.5: bound 0.6)."""
    sc = make()

    def run(bordered, **kw):
        monkeypatch.setattr(RecycledGCR, "borders", bordered)
        return femehl.solve(
            sc, t_end=0.6, mesh="coarse", dt=0.01, scheme="bdf2", store_every=0, estimate=False, **kw
        )

    ref, apart, one = run(False, rtol=1e-12), run(False), run(True)
    for q in ("load", "hc", "film_center", "film_min"):
        scale = np.max(np.abs(getattr(ref, q)))
        for res in (apart, one):
            assert np.max(np.abs(getattr(res, q) - getattr(ref, q))) <= 2e-6 * scale, q
    assert one.info["krylov_iterations"] <= 0.6 * apart.info["krylov_iterations"]


def test_a_stalled_bordered_solve_is_solved_apart(monkeypatch):
    """A bordered solve that fails (a SingularSystemError from the solver) is solved again
    with two right-hand sides, and the run is the same as one solved apart throughout."""
    sc = _load_controlled()
    calls = []
    real = linsolve.RecycledGCR.solve

    def failing(self, op, rhs, t):
        if isinstance(op, BorderedOperator) and len(calls) < 3:
            calls.append(t)
            raise SingularSystemError("stalled", t=t)
        return real(self, op, rhs, t)

    monkeypatch.setattr(linsolve.RecycledGCR, "solve", failing)
    got = femehl.solve(sc, t_end=0.1, mesh="coarse", dt=0.01, store_every=0, estimate=False)
    monkeypatch.setattr(linsolve.RecycledGCR, "solve", real)
    monkeypatch.setattr(RecycledGCR, "borders", False)
    apart = femehl.solve(sc, t_end=0.1, mesh="coarse", dt=0.01, store_every=0, estimate=False)
    assert len(calls) == 3
    np.testing.assert_allclose(got.hc, apart.hc, rtol=1e-6)


def test_an_imposed_load_with_jfo_cavitation_is_bordered_too(monkeypatch):
    """JFO's switched system (the gas at cavitated nodes) bordered by the load row: every step
    in one solve, as accurate as two right-hand sides against a run solved to rtol 1e-12
    (coarse mesh, dt = 0.01, load ramped to the Hertz load by t = 1, then sliding, to t =
    1.6, 178 nodes cavitated at the end; measured apart / bordered: films 8.6e-7 / 2.4e-7,
    hc 9.6e-9 / 1e-8, load 1e-15 / 1e-9; the same bound 2e-6), in fewer preconditioned
    iterations (measured 605 against 1,364)."""
    F = 4.0 / (3.0 * np.pi)
    sc = Scene(
        substrate=femehl.HalfSpace(),
        fluid=Fluid(200.0, cavitation="jfo"),
        motion=Motion(
            gap=0.1, load=RampHold(0.0, F, 1.0), velocity=lambda t: float(np.tanh(max(t - 1.0, 0.0)))
        ),
        domain=Domain(2.0),
    )
    from femehl.solver import stepper

    bordered_steps = []
    real = stepper.LaggedStepper._border

    def counted(self, *args):
        out = real(self, *args)
        bordered_steps.append(out is not None)
        return out

    monkeypatch.setattr(stepper.LaggedStepper, "_border", counted)

    def run(bordered, **kw):
        monkeypatch.setattr(RecycledGCR, "borders", bordered)
        bordered_steps.clear()
        res = femehl.solve(
            sc, t_end=1.6, mesh="coarse", dt=0.01, scheme="bdf2", store_every=1, estimate=False, **kw
        )
        return res, list(bordered_steps)

    (ref, _), (apart, _), (one, steps) = run(False, rtol=1e-12), run(False), run(True)
    assert steps and all(steps)
    assert np.sum(np.asarray(one.states[-1].own["p_aux"]) < 0.0) > 50  # the cavity's switched nodes
    for q in ("load", "hc", "film_center", "film_min"):
        scale = np.max(np.abs(getattr(ref, q)))
        for res in (apart, one):
            assert np.max(np.abs(getattr(res, q) - getattr(ref, q))) <= 2e-6 * scale, q
    assert one.info["krylov_iterations"] <= 0.6 * apart.info["krylov_iterations"]
