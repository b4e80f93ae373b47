"""The recycled Krylov solver's preconditioner refresh when the held rows move."""

import numpy as np
import pytest
import scipy.sparse as sp

from femehl.solver import linsolve
from femehl.solver.linsolve import RecycledGCR, StepOperator, factor_cost


def _operator(n=200, ne=300, seed=0):
    rng = np.random.default_rng(seed)
    C = rng.random((ne, n)) / n
    F = sp.csr_matrix(rng.random((n, ne)) / ne)
    D = sp.diags(2.0 + rng.random(n), format="csr")
    return StepOperator(D=D, films=[(1.0, F, F @ C)], C=C, key=1.0), rng


def _solve(solver, op, b):
    its0, lu0 = solver.info["krylov_iterations"], solver.info["factorizations"]
    ((x, _),) = solver.solve(op, [b], 0.0)
    return x, solver.info["krylov_iterations"] - its0, solver.info["factorizations"] - lu0


@pytest.mark.parametrize("moved", [10, 60])
def test_a_preconditioner_is_refreshed_when_many_held_rows_moved(moved):
    """Rows held at zero (the Reynolds condition's cavitated nodes) that differ from the
    factorized ones in more than ``factor_cost`` rows (40 here) refresh the preconditioner
    before the solve; fewer are left to the Krylov iterations.  Both answers solve the
    system they were given."""
    base, rng = _operator()
    assert factor_cost(base) == 40.0
    held1 = np.arange(0, 100)
    held2 = np.arange(moved, 100 + moved)  # 2 * moved rows differ
    solver = RecycledGCR()
    op1 = base.with_fixed(held1)
    _solve(solver, op1, rng.random(200))
    op2 = base.with_fixed(held2)
    b = rng.random(200)
    x, its, lus = _solve(solver, op2, b)
    np.testing.assert_allclose(op2.matrix() @ x, b, rtol=0, atol=1e-7 * np.linalg.norm(b))
    assert lus == (1 if 2 * moved > 40 else 0)


def test_the_refresh_saves_the_iterations_of_the_stale_rows(monkeypatch):
    """What the rule is for: after 120 moved rows the stale factor needs 22 iterations
    here, the refreshed one 2 (its LU is single precision)."""
    base, rng = _operator(seed=1)
    ops = [base.with_fixed(np.arange(0, 100)), base.with_fixed(np.arange(60, 160))]
    bs = [rng.random(200), rng.random(200)]

    def second_solve():
        solver = RecycledGCR(recycle=0)
        _solve(solver, ops[0], bs[0])
        return _solve(solver, ops[1], bs[1])[1]

    with_rule = second_solve()
    monkeypatch.setattr(linsolve, "HELD_CHANGE", np.inf)
    without = second_solve()
    assert with_rule <= 3 and without >= 15, (with_rule, without)


def test_the_replaced_rows_are_the_held_or_the_switched_ones():
    """The rule reads a Reynolds step's held rows and a JFO step's switched unknowns alike,
    and counts the rows that changed either way."""
    base, _ = _operator(n=20, ne=30)
    assert linsolve._replaced_rows(base) is None
    held = base.with_fixed(np.array([7, 3, 5]))
    np.testing.assert_array_equal(linsolve._replaced_rows(held), [3, 5, 7])
    switched = np.zeros(20, dtype=bool)
    switched[[2, 4]] = True
    op = linsolve.SwitchedOperator(base, sp.identity(20, format="csr"), switched)
    np.testing.assert_array_equal(linsolve._replaced_rows(op), [2, 4])
    # 3, 5, 7 against 2, 4: five rows changed
    assert linsolve._rows_moved(np.array([3, 5, 7]), np.array([2, 4]), 4.9)
    assert not linsolve._rows_moved(np.array([3, 5, 7]), np.array([2, 4]), 5.0)
    assert not linsolve._rows_moved(None, None, 0.0)
    assert linsolve._rows_moved(None, np.array([1]), 0.5)
