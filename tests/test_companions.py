"""The companions beside a run (femehl.accuracy.companions): they replay exactly what
replaying after the run does, end with the run, and hand over to the replay after the run
when they cannot work."""

from __future__ import annotations

import logging
import os

import numpy as np
import pytest

import femehl
from femehl.accuracy import companions as comp
from femehl.accuracy.auto import REPLAY_HALVINGS, every_other_step
from femehl.errors import MeshError, SceneError
from femehl.problem.line import LineScene
from femehl.solver.loop import make_stepper, run_loop
from femehl.solver.stepping import GivenSteps, breakpoints_of

pytestmark = pytest.mark.skipif(not comp.concurrent(), reason="no processes beside the run here")

SCENE = LineScene()  # the paper's motion: indentation to t = 1, then sliding (a breakpoint)
T_END = 1.5


def _run():
    return run_loop(
        make_stepper(SCENE, "line", n_elements=200, scheme="bdf2"), T_END, step_tol=1e-3, store_every=0
    )


def _make():
    return make_stepper(SCENE, "line", n_elements=100, scheme="bdf2")


def _beside(run, make=_make):
    """Feed ``run``'s states (its times) to companions as the run would, and collect them."""
    with comp.Companions(make, T_END, breakpoints_of(SCENE), REPLAY_HALVINGS) as beside:
        for t in run.t:
            beside(type("S", (), {"t": t}))
        return beside.results()


def test_they_replay_what_fresh_replays_after_the_run_give():
    """Every step and every other step (each stretch between breakpoints whole), bit for bit
    the replays of fresh steppers on the same times."""
    run = _run()
    assert any(abs(t - 1.0) < 1e-12 for t in run.t)  # the run lands on the breakpoint
    got = _beside(run)
    assert got.stopped is None and got.order == 2 and got.cut == 0
    plans = (run.t[1:], every_other_step(run.t, breakpoints_of(SCENE)))
    for times, replay in zip(plans, (got.full, got.half), strict=True):
        after = run_loop(_make(), T_END, store_every=0, steps=GivenSteps(times, halvings=REPLAY_HALVINGS))
        assert np.array_equal(replay.t, after.t)
        for q in ("load", "film_center", "film_min"):
            assert np.array_equal(getattr(replay, q), getattr(after, q))
    assert got.full.scene is None  # the parent's scene goes back on (a user's shape may not pickle)


def test_a_companion_that_stops_says_why():
    def coarse():
        raise MeshError("no mesh this coarse")

    got = _beside(_run(), coarse)
    assert got.full is None and got.stopped == ("MeshError", "no mesh this coarse")


def test_a_companion_that_fails_hands_over(caplog):
    def broken():
        raise RuntimeError("out of memory, say")

    with caplog.at_level(logging.INFO, logger="femehl"):
        assert _beside(_run(), broken) is None
    assert "RuntimeError: out of memory, say" in caplog.text


def test_a_companion_that_hangs_hands_over(caplog):
    """A companion with no answer within ``wait`` of the run's end (a lock held across the
    fork, say) is ended, and the estimate is replayed after the run."""
    import time

    def hung():
        time.sleep(60)

    run = _run()
    with comp.Companions(hung, T_END, breakpoints_of(SCENE), REPLAY_HALVINGS) as beside:
        for t in run.t:
            beside(type("S", (), {"t": t}))
        pids = [p["pid"] for p in beside._procs]
        t0 = time.perf_counter()
        with caplog.at_level(logging.INFO, logger="femehl"):
            assert beside.results(wait=1.0) is None
    assert time.perf_counter() - t0 < 10.0 and "no answer within 1 s" in caplog.text
    for pid in pids:  # ended and reaped
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)


def test_they_end_with_a_run_that_stops():
    """A run that stops (a film that closes, Ctrl-C, max_wall) ends its companions and
    closes their pipes: no process and no descriptor is left behind."""
    fds = len(os.listdir("/proc/self/fd"))
    with pytest.raises(KeyboardInterrupt), comp.Companions(_make, T_END) as beside:
        beside(type("S", (), {"t": 0.0}))
        pids = [p["pid"] for p in beside._procs]
        raise KeyboardInterrupt
    for pid in pids:  # ended and reaped
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)
    assert not comp._OPEN
    assert len(os.listdir("/proc/self/fd")) == fds


def test_the_automatic_mode_gives_the_same_answer_either_way(monkeypatch):
    """The automatic sequence with its companions beside the runs, and replayed after them
    (FEMEHL_COMPANIONS=serial): the same runs, and the estimates within 1e-5 of each other
    (measured 7.5e-7: after the run the half-step replay starts on the full replay's warmed
    preconditioner, beside it on a fresh one, and each solve stops at its own tolerance)."""
    scene = femehl.presets.paper_sphere()
    beside = femehl.solve(scene, t_end=0.05, tol=3e-2, store_every=0)
    monkeypatch.setenv(comp.ENV, "serial")
    after = femehl.solve(scene, t_end=0.05, tol=3e-2, store_every=0)
    for key in ("elements", "steps", "levels"):
        assert beside.info["auto"][key] == after.info["auto"][key]
    for q in ("load", "film_center", "film_min"):
        assert np.array_equal(getattr(beside, q), getattr(after, q))
        a, b = beside.estimate.errors[q]["total"], after.estimate.errors[q]["total"]
        assert a.shape == b.shape and np.max(np.abs(a - b)) <= 1e-5 * np.max(b)


def test_the_switch_is_checked(monkeypatch):
    monkeypatch.setenv(comp.ENV, "serial")
    assert not comp.concurrent()
    monkeypatch.setenv(comp.ENV, "threads")
    with pytest.raises(SceneError, match="'auto'"):
        comp.concurrent()


def test_expert_adaptive_run_whose_companion_stops_keeps_the_controller_estimate(monkeypatch, caplog):
    """A companion that stops (the rough PDMS ball at 1e-3 m/s on the medium mesh: its coarser
    replay on steps twice as long overshot the rough limit at t = 5.78) leaves an adaptive
    expert run the step controller's time error, and the log says so (it said "no error
    estimate" while one was given)."""
    import femehl.accuracy.auto as auto

    monkeypatch.setattr(auto, "replays", lambda *a, **k: comp.Replayed(stopped=("FilmRuptureError", "test")))
    with caplog.at_level(logging.WARNING, logger="femehl"):
        res = femehl.solve(femehl.presets.paper_sphere(), t_end=0.2, mesh="medium", step_tol=1e-2)
    assert res.estimate is not None and res.estimate.how == "controller"
    assert res.estimate.worst("time") > 0.0
    msg = " ".join(r.getMessage() for r in caplog.records)
    assert "no space error estimate (the estimate is the step controller's time error alone)" in msg
    assert "coarser companion run stopped (test)" in msg


def _half_replay_stops(monkeypatch):
    """The companion's replay on every other step raises, as the rough PDMS ball's did."""
    import femehl.solver.loop as loop
    from femehl.errors import SolverError
    from femehl.solver.stepping import GivenSteps

    real, replays = loop.run_loop, []

    def run_loop(stepper, t_end, *args, **kw):
        if isinstance(kw.get("steps"), GivenSteps) and kw.get("store_every") == 0:
            replays.append(kw["steps"])
            if len(replays) == 2:
                raise SolverError("the step overshot (test)", t=0.1)
        return real(stepper, t_end, *args, **kw)

    monkeypatch.setattr(loop, "run_loop", run_loop)
    return replays


def test_expert_run_whose_doubled_step_companion_stops_keeps_its_space_estimate(monkeypatch, caplog):
    """Only the companion on steps twice as long stops (the rough PDMS ball at 1e-3 m/s on
    the medium mesh: its doubled steps, 1.4 time units after the run's 0.8 was cut, overshot
    the rough limit at t = 5.78): the estimate keeps the companion's space part, exactly
    the one of the whole companion pair, and takes the step controller's time part."""
    scene, kw = femehl.presets.paper_sphere(), dict(t_end=0.2, mesh="medium", step_tol=1e-2)
    both = femehl.solve(scene, **kw)
    replays = _half_replay_stops(monkeypatch)
    with caplog.at_level(logging.WARNING, logger="femehl"):
        res = femehl.solve(scene, **kw)
    assert len(replays) == 2 and res.estimate.how == "companion+controller"
    assert "the coarser companion on steps twice as long stopped (the step overshot (test))" in caplog.text
    for name in ("load", "film_center", "film_min"):
        np.testing.assert_array_equal(res.estimate[name]["space"], both.estimate[name]["space"])
    controller = femehl.accuracy.auto.time_error(res)
    np.testing.assert_array_equal(res.estimate["load"]["time"], controller)
    assert controller[-1] > 0.0
