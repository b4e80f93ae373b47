"""The one driver loop: build a method's stepper (:func:`make_stepper`) and march it,
feeding every State to a Result and to the handlers attached (:func:`run_loop`).

Every way of running femehl (``femehl.solve`` in both modes, the automatic sequence,
``run_to_folder``, the CLI, sweeps) goes through here; docs/design.md section 8.
"""

from __future__ import annotations

import inspect
import math
import time
from collections.abc import Callable
from contextlib import nullcontext

from femehl.errors import SceneError, SolverError
from femehl.output.result import Result
from femehl.problem.scene import Scene
from femehl.solver.stepping import FixedSteps, State, march
from femehl.solver.threads import one_blas_thread

__all__ = ["make_stepper", "methods", "run_loop", "run_scene"]


def _registry():
    from femehl.discretize import METHODS, method_class

    method_class("fe")  # imports the registered discretizations
    return METHODS


@one_blas_thread
def make_stepper(scene, method: str | None = None, **options):
    """Build the stepper of ``method`` for ``scene`` (operators are built here, once).

    ``options`` are split between the discretization (its constructor's parameters, e.g.
    FE ``mesh``, FD ``dr``, line ``n_elements``) and the one stepper
    (:class:`femehl.solver.stepper.LaggedStepper`: ``scheme``, ``linear_solver``, ``terms``
    and the linear solver's ``rtol``, ``refactor_after``, ``recycle``).
    """
    from femehl.solver.linsolve import LINEAR_SOLVERS
    from femehl.solver.stepper import LaggedStepper

    methods = _registry()
    if not isinstance(scene, Scene):
        raise SceneError(
            f"scene must be a femehl.Scene (femehl.line.LineScene(...) makes a line contact's), "
            f"got {type(scene).__name__}."
        )
    if method is None:
        method = scene.default_method
    if not isinstance(method, str) or method not in methods:
        raise SceneError(f"unknown method {method!r}: choose one of {sorted(methods)}.")
    cls = methods[method]
    disc_keys = set(inspect.signature(cls).parameters) - {"scene"}
    solver_keys = set()
    for sol in LINEAR_SOLVERS.values():
        solver_keys |= set(inspect.signature(sol).parameters)
    step_keys = {"scheme", "linear_solver", "terms"} | solver_keys
    unknown = set(options) - disc_keys - step_keys
    if unknown:
        raise SceneError(
            f"method {method!r} does not take {sorted(unknown)}; it takes {sorted(disc_keys | step_keys)}."
        )
    disc = cls(scene, **{k: v for k, v in options.items() if k in disc_keys})
    return LaggedStepper(disc, **{k: v for k, v in options.items() if k in step_keys})


def methods() -> list[str]:
    """Names of the registered methods."""
    return sorted(_registry())


def run_loop(
    stepper,
    t_end: float,
    dt: float | None = None,
    *,
    step_tol: float | None = None,
    steps=None,
    start: State | None = None,
    store_every: int = 1,
    on_state: Callable[[State], None] | None = None,
    **controls,
) -> Result:
    """The one driver loop: march ``stepper`` and feed every State to a Result and ``on_state``.

    Every way of running femehl (``solve``, ``run_to_folder``, the CLI) goes through
    here.  The step policy: fixed steps ``dt`` (:class:`femehl.solver.stepping.FixedSteps`),
    or adaptive steps to ``step_tol`` (:class:`femehl.solver.adaptive.AdaptiveSteps`, ``dt``
    the first step, ``controls`` its ``dt_min``, ``dt_max``, ``safety``), or ``steps``, a
    policy object (e.g. :class:`femehl.solver.stepping.GivenSteps`, another run's times), all
    walked by the one time loop :func:`femehl.solver.stepping.march`.  ``start`` resumes from a State (its own
    record is kept, ``on_state`` is not called for it).  If the run stops on a
    :class:`~femehl.errors.SolverError` or is interrupted, the partial Result is attached
    to the exception as ``.result`` and the exception propagates; everything fed to
    ``on_state`` before stays valid.
    """
    if isinstance(store_every, bool) or not isinstance(store_every, int) or store_every < 0:
        raise SceneError(f"store_every must be an integer >= 0, got {store_every!r}.")
    if steps is not None:
        if dt is not None or step_tol is not None or controls:
            raise SceneError(
                "steps= is the whole step policy: give no dt, step_tol or step controls with it."
            )
        policy = steps
    elif step_tol is None:
        if controls:
            raise SceneError(f"{sorted(controls)} tune adaptive steps: give step_tol= as well.")
        policy = FixedSteps(0.01 if dt is None else dt)
    else:
        from femehl.solver.adaptive import AdaptiveSteps

        if dt is not None:
            controls.setdefault("dt0", dt)
        policy = AdaptiveSteps(step_tol, **controls)
    states = march(stepper, t_end, policy, start=start)
    result = Result(scene=stepper.scene, method=stepper.method, disc=stepper.disc)
    last = None
    rejected, dts = 0, []
    try:
        for state in states:
            keep = store_every > 0 and state.step % store_every == 0
            result.record(state, store_fields=keep)
            rejected += state.info.get("rejected", 0)
            if state.info.get("dt", 0.0) > 0.0:
                dts.append(state.info["dt"])
            if on_state is not None and (start is None or last is not None):
                on_state(state)
            last = (state, keep)
    except (SolverError, KeyboardInterrupt) as exc:
        exc.result = result
        raise
    finally:
        if last is not None and store_every > 0 and not last[1]:
            result._stored.append(last[0])
        result.info.update(getattr(stepper, "info", {}))  # counters as at the end of the run
        result.info["steps"] = result.nsteps
        if step_tol is not None:
            result.info.update(
                step_tol=step_tol,
                rejected_steps=rejected,
                dt_smallest=min(dts, default=math.nan),
                dt_largest=max(dts, default=math.nan),
            )
    return result


def run_scene(
    scene,
    method,
    options: dict,
    t_end: float,
    dt: float | None = None,
    *,
    step_tol: float | None = None,
    store_every: int = 1,
    on_state: Callable[[State], None] | None = None,
    sink=None,
    plan: dict | None = None,
    progress: Callable | None = None,
    label: str = "",
    **controls,
) -> Result:
    """One run of one discretization: :func:`make_stepper` then :func:`run_loop`.

    The expert mode and every run of the automatic sequence come here.  ``sink`` (a
    :class:`femehl.output.run.RunFolder`, or None: in memory) is attached to the loop:
    ``sink.writer(stepper, t_end, dt, step_tol, plan, t0)`` is a context manager whose
    value is fed every State and gives ``start`` (a checkpoint to resume from, or None)
    and ``done`` (a Result when there is nothing left to run).  ``progress(desc, t_end,
    t_start)`` makes a progress handler with ``close()``.
    """
    t0 = time.perf_counter()
    stepper = make_stepper(scene, method, **options)
    writing = nullcontext() if sink is None else sink.writer(stepper, t_end, dt, step_tol, plan, t0)
    with writing as writer:
        if writer is not None and writer.done is not None:
            return writer.done
        start = None if writer is None else writer.start
        bar = _bar(progress, stepper, t_end, start, label)
        try:
            result = run_loop(
                stepper,
                t_end,
                dt,
                step_tol=step_tol,
                start=start,
                store_every=store_every,
                on_state=chain([writer, on_state, bar]),
                **controls,
            )
        finally:
            if bar is not None:
                bar.close()
        return result if writer is None else writer.finished(result)


def _bar(progress, stepper, t_end, start, label):
    """The progress handler ``progress`` makes for this run (None without one)."""
    if progress is None:
        return None
    cells = stepper.info.get("elements", "?") if hasattr(stepper, "info") else "?"
    what = f"{label}, " if label else ""
    t_start = 0.0 if start is None else float(start.t)
    return progress(f"{stepper.method} ({what}{cells} cells)", t_end, t_start)


def chain(handlers):
    """One State handler calling each of ``handlers`` (None entries skipped), or None."""
    handlers = [h for h in handlers if h is not None]
    if not handlers:
        return None
    if len(handlers) == 1:
        return handlers[0]

    def each(state):
        for h in handlers:
            h(state)

    return each
