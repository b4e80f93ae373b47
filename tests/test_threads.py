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


# ---- the dense operator's row loops: the cores of a lone process, one in a parallel set ----
def test_row_loops_cover_every_row_once_and_match_one_thread(monkeypatch):
    """:func:`in_rows` hands out every row once, in any number of blocks; the products and the
    Boussinesq build split by rows are the one-thread ones to the bit (each row's sum is
    made in the same order)."""
    import functools

    import numpy as np

    from femehl.discretize.fe_disk import FEDisc
    from femehl.elastic import dense

    seen = np.zeros(1001, dtype=int)
    blocks = []

    def mark(i0, i1):
        seen[i0:i1] += 1
        blocks.append((i0, i1))

    runs = {}
    for k in (1, 3):
        monkeypatch.setattr(dense, "loop_threads", lambda k=k: k)
        seen[:], blocks[:] = 0, []
        dense.in_rows(mark, seen.size)
        assert np.all(seen == 1) and len(blocks) == k
        C = dense.SingleCompliance(np.random.default_rng(1).standard_normal((1001, 700)))
        x = np.random.default_rng(2).standard_normal(700)
        disc = FEDisc(femehl.presets.paper_sphere(), mesh="coarse", operator="dense")
        pools = []
        for make in (functools.partial(C.__matmul__, x), disc.boussinesq):  # each in a pool of k
            monkeypatch.setattr(dense, "_POOL", None)
            runs.setdefault(k, []).append(make())
            pools.append(None if dense._POOL is None else dense._POOL[0])
        assert pools == ([None, None] if k == 1 else [k, k])
    assert all(np.array_equal(a, b) for a, b in zip(runs[1], runs[3], strict=True))


def test_row_loops_run_on_one_thread_in_a_fork_or_off_the_main_thread():
    """A lone process spreads its row loops over its cores; a forked one (the automatic
    mode's companions) and a thread other than the main one keep to one: the parallelism
    there is the processes'."""
    import os
    import threading
    import warnings

    from femehl.elastic.dense import loop_threads

    assert loop_threads() == len(os.sched_getaffinity(0))
    got = []
    th = threading.Thread(target=lambda: got.append(loop_threads()))
    th.start()
    th.join()
    r, w = os.pipe()
    with warnings.catch_warnings():  # Python >= 3.12 warns of a fork beside threads
        warnings.simplefilter("ignore", DeprecationWarning)
        pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        os.write(w, bytes([loop_threads()]))
        os._exit(0)
    os.waitpid(pid, 0)
    assert got == [1] and os.read(r, 1) == bytes([1])
