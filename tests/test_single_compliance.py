"""A large dense compliance stored in single precision (femehl.elastic.dense): its products
are those of the float32-rounded matrix computed in double, and a run on it matches the
double-precision operator to the rounding times the film's amplification."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import femehl
import femehl.elastic.dense as dense
from femehl.elastic.dense import SingleCompliance, is_dense, stored


def test_products_are_those_of_the_rounded_matrix_in_double():
    rng = np.random.default_rng(3)
    C = rng.random((203, 101))  # a row count that is not a multiple of the kernel's 4
    S = SingleCompliance(C)
    R = C.astype(np.float32).astype(np.float64)  # the operator S stands for, exactly
    x, X, W = rng.random(101), rng.random((101, 3)), rng.standard_normal((2, 203))
    F = sp.random(40, 203, density=0.05, random_state=4, format="csr")
    scale = np.abs(R).sum()
    for got, want in ((S @ x, R @ x), (S @ X, R @ X), (W @ S, W @ R), (F @ S, F @ R)):
        assert got.dtype == np.float64
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-15 * scale)
    assert (W[0] @ S).shape == (101,)  # a vector on the left, as numpy's
    np.testing.assert_array_equal(S[:, [1, 7]], R[:, [1, 7]])
    np.testing.assert_array_equal(S[[0, 5]], R[[0, 5]])
    assert S.nbytes == C.size * 4 and S.shape == C.shape and is_dense(S)
    # the rounding is the only change: 2^-24 relative per entry at most
    assert np.max(np.abs(R - C) / np.abs(C)) <= 2.0**-24
    x[5] = np.nan  # a NaN is not optimized away
    assert np.isnan(S @ x).all()
    with pytest.raises(ValueError, match="entries"):
        S @ np.ones(100)


def test_only_large_dense_operators_are_stored_in_single_precision():
    small = np.ones((10, 5))
    assert stored(small) is small
    assert isinstance(stored(np.ones((dense.SINGLE_MIN_ENTRIES // 64, 64))), SingleCompliance)
    A = sp.eye(5000, format="csr")
    assert stored(A) is A  # a local substrate's sparse C


def _run(**kw):
    scene = femehl.presets.paper_sphere()
    return femehl.solve(scene, t_end=2.0, dt=0.02, scheme="bdf2", mesh="coarse", store_every=0, **kw)


def test_a_run_on_the_single_precision_operator_matches_double(monkeypatch):
    """The paper sphere on the coarse mesh through the sliding start, its C in single
    precision (the threshold lowered) against double.  The films are h + C p with a
    deflection about 40 times the film (1 against 0.025), so C's rounding (6e-8 relative)
    and the Krylov solve's rtol (1e-8) reach them multiplied by about 40: 4e-6 is the
    bound; the load, an integral of p, by 1e-7."""
    ref = _run()
    assert ref.info["operator_storage"] == "float64"
    monkeypatch.setattr(dense, "SINGLE_MIN_ENTRIES", 0)
    single = _run()
    assert single.info["operator_storage"] == "float32"
    assert single.nsteps == ref.nsteps
    np.testing.assert_allclose(single.load, ref.load, rtol=0, atol=1e-7 * np.abs(ref.load).max())
    for q in ("film_center", "film_min"):
        a, b = getattr(single, q), getattr(ref, q)
        assert np.max(np.abs(a - b) / np.abs(b)) <= 4e-6, q
