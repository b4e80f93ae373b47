"""The recycled Krylov solver's preconditioner refresh when the held rows move."""

import dataclasses

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


@pytest.mark.parametrize("moved", [4, 60])
def test_a_preconditioner_is_refreshed_when_many_held_rows_moved(moved):
    """Rows held at zero (the Reynolds condition's cavitated nodes) that differ from the
    factorized ones in more than ``factor_cost`` rows (40 here), or than the iteration cap
    allows (30 / ROW_ITERATIONS = 10 here), refresh the preconditioner before the solve;
    fewer are left to the Krylov iterations.  Both answers solve the system they were
    given."""
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
    assert solver._row_budget(op2) == 10.0
    assert lus == (1 if 2 * moved > 10 else 0)


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


def test_moved_rows_are_refreshed_before_the_iteration_cap_is_spent():
    """The rows a stale preconditioner absorbs are also bounded by the solve's iteration cap
    (``ROW_ITERATIONS`` per row): with a cap of 9 iterations, 10 moved rows refresh it
    before the solve, where the cost rule alone (40 rows) let the solve run into the cap,
    fail and refresh after it (the rough PDMS ball's dense path: 30 iterations lost in
    every step whose Reynolds set moved in 13-37 rows)."""
    base, rng = _operator(seed=2)
    ops = [base.with_fixed(np.arange(0, 100)), base.with_fixed(np.arange(5, 105))]
    bs = [rng.random(200), rng.random(200)]
    solver = RecycledGCR(recycle=0, max_krylov=9)
    assert solver._row_budget(ops[1]) == 3.0  # min(factor_cost 40, 9 / 3)
    _solve(solver, ops[0], bs[0])
    x, its, lus = _solve(solver, ops[1], bs[1])
    np.testing.assert_allclose(ops[1].matrix() @ x, bs[1], rtol=0, atol=1e-7 * np.linalg.norm(bs[1]))
    assert lus == 1 and its <= 3, (lus, its)


class _NearOp:
    """The parts of a fast-path step operator the preconditioner reads."""

    fast, dense, key, held = True, False, 1.0, None

    def __init__(self, A):
        self.A = A
        self.D = A

    def near_matrix(self):
        return sp.csc_matrix(self.A)

    def coarse_system(self):
        return None


def _laplacian(m, held=()):
    """The 5-point Laplacian on an m x m grid plus a diagonal shift, rows ``held`` identity."""
    T = sp.diags([-1.0, 2.5, -1.0], [-1, 0, 1], shape=(m, m))
    A = (sp.kron(sp.identity(m), T) + sp.kron(T, sp.identity(m))).tolil()
    for i in held:
        A.rows[i], A.data[i] = [i], [1.0]
    return sp.csr_matrix(A)


@pytest.mark.parametrize("order_fill, orderings", [(1.2, 1), (0.5, 2)])
def test_the_fast_path_keeps_its_ordering_while_the_pattern_moves(monkeypatch, order_fill, orderings):
    """A near field whose held rows move keeps its nested-dissection ordering (METIS is not
    run again for each refresh) as long as an LU on it holds at most ``ORDER_FILL`` times
    the entries of the first; each LU solves its own matrix."""
    calls, order = [], linsolve.nested_dissection

    def counted(A):
        calls.append(A.shape)
        return order(A)

    monkeypatch.setattr(linsolve, "nested_dissection", counted)
    monkeypatch.setattr(linsolve, "ORDER_FILL", order_fill)
    solver = RecycledGCR()
    rng = np.random.default_rng(4)
    for held in (range(0, 40), range(30, 80), range(60, 110)):
        op = _NearOp(_laplacian(20, held))
        f = solver._refactor(op, 0.0)
        b = rng.random(400)
        x = f.lu.solve(b)
        assert np.linalg.norm(op.A @ x - b) <= 1e-5 * np.linalg.norm(b)  # single-precision factors
    assert len(calls) == orderings


@pytest.mark.parametrize("single", [False, True], ids=["ndarray C", "single-precision C"])
def test_a_step_product_adds_what_the_whole_product_would(single):
    """A rough film's ``F C`` (``StepProduct``), added row by row into the dense matrix, its
    held rows masked, and its columns read, against the product formed whole.  Both sum in
    double and round to the matrix's precision once: 1e-13 in double, and in single at most
    a unit in the last place of entries below 4 (2.4e-7, a sum taken in another order may
    round to the neighbour)."""
    from femehl.elastic.dense import SingleCompliance
    from femehl.solver.linsolve import StepProduct

    base, rng = _operator(n=120, ne=180, seed=5)
    C = SingleCompliance(base.C) if single else base.C
    Cw = C.a.astype(np.float64) if single else C  # the map C stands for
    F = sp.random(120, 180, density=0.01, random_state=6, format="csr")  # near contact: a few rows
    whole = dataclasses.replace(base, C=C, films=[*base.films, (0.7, F, np.asarray(F @ Cw))])
    lazy = dataclasses.replace(base, C=C, films=[*base.films, (0.7, F, StepProduct(F, C))])
    for a, b in ((whole, lazy), (whole.with_fixed(np.arange(30)), lazy.with_fixed(np.arange(30)))):
        for dtype, atol in ((np.float64, 1e-13), (np.float32, 2.4e-7)):
            np.testing.assert_allclose(b.matrix(dtype=dtype), a.matrix(dtype=dtype), rtol=0, atol=atol)
        idx = np.array([3, 50, 119])
        np.testing.assert_allclose(b.columns(idx), a.columns(idx), rtol=0, atol=1e-13)


@pytest.mark.parametrize("q, lus", [(4.0, 0), (5.0, 1)])
def test_a_step_four_times_longer_keeps_the_preconditioner(q, lus):
    """``dt`` grown by up to 4 (``c_0 = a0/dt`` fallen to a quarter, ``KEY_CHANGE`` = 3)
    keeps the LU: its preconditioned matrix ``I/q + (1 - 1/q) P^-1 D`` has a condition
    number of at most q, a few iterations against ``factor_cost`` (40 here); more
    refreshes it before the solve.  Both answers solve the system they were given."""
    base, rng = _operator(seed=3)
    c = 100.0  # the squeeze term dominates, as at the small steps after a breakpoint
    at = lambda c: dataclasses.replace(base, films=[(c, *base.films[0][1:])], key=c)  # noqa: E731
    solver = RecycledGCR(recycle=0)
    _solve(solver, at(c), rng.random(200))
    op = at(c / q)
    b = rng.random(200)
    x, its, got = _solve(solver, op, b)
    np.testing.assert_allclose(op.matrix() @ x, b, rtol=0, atol=1e-7 * np.linalg.norm(b))
    assert got == lus
    if not lus:
        assert its <= 8 < factor_cost(op), its
