"""femehl's runs use one BLAS thread (docs/design.md section 16), the caller's limits restored."""

from __future__ import annotations

import pytest
from threadpoolctl import threadpool_info, threadpool_limits

import femehl
from femehl.errors import SceneError
from femehl.solver.threads import ENV, blas_threads, limited, one_blas_thread


def _blas():
    return {d["filepath"]: d["num_threads"] for d in threadpool_info() if d["user_api"] == "blas"}


def test_one_thread_inside_and_the_callers_limit_restored(monkeypatch):
    monkeypatch.delenv(ENV, raising=False)
    with threadpool_limits(2, user_api="blas"):
        outside = _blas()
        with limited():
            assert set(_blas().values()) == {1}
        assert _blas() == outside


def test_the_environment_sets_it(monkeypatch):
    monkeypatch.setenv(ENV, "2")
    assert blas_threads() == 2
    monkeypatch.setenv(ENV, "all")
    assert blas_threads() is None
    for bad in ("0", "-1", "many"):
        monkeypatch.setenv(ENV, bad)
        with pytest.raises(SceneError, match=ENV):
            blas_threads()


def test_entry_points_and_generators_run_limited(monkeypatch):
    monkeypatch.delenv(ENV, raising=False)
    seen = []

    @one_blas_thread
    def gen():
        seen.append(set(_blas().values()))
        yield 1

    assert list(gen()) == [1] and seen == [{1}]
    scene = femehl.presets.paper_sphere()
    states = []
    res = femehl.solve(
        scene, t_end=0.02, dt=0.01, mesh="coarse", estimate=False, callback=lambda s: states.append(_blas())
    )
    assert res.nsteps == 2 and all(set(b.values()) == {1} for b in states)
