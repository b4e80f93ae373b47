"""``femehl.solve``: run a scene with a registered solver and collect a Result.

Methods are discretizations registered in :data:`femehl.discretize.METHODS`; every
one is advanced by the same :class:`~femehl.solver.stepper.LaggedStepper`, and every run
goes through :func:`run_loop`.  The stepping itself is the generator
:func:`femehl.solver.stepping.march`; :func:`steps` exposes it directly.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Iterator

from femehl.errors import SceneError
from femehl.output.result import Result
from femehl.problem.scene import Scene
from femehl.solver.loop import _registry, make_stepper, methods, run_loop
from femehl.solver.stepping import State, march
from femehl.solver.threads import one_blas_thread

__all__ = ["make_stepper", "steps", "solve", "solve_line", "run_loop", "run_to_folder", "methods"]


@one_blas_thread
def steps(scene: Scene, t_end: float, dt: float, method: str | None = None, **options) -> Iterator[State]:
    """Generator of States, the initial one first (see :func:`femehl.solver.stepping.march`)."""
    stepper = make_stepper(scene, method, **options)
    yield from march(stepper, t_end, dt)


#: the accuracy of a run that states neither its discretization nor its time step
DEFAULT_TOL = 1e-2


def discretization_options(method: str) -> set[str]:
    """The option names that choose ``method``'s discretization (its constructor's
    parameters, less those that only choose how its operators are computed, such as FE's
    ``operator``: those keep a run automatic)."""
    cls = _registry()[method]
    return set(inspect.signature(cls).parameters) - {"scene"} - set(getattr(cls, "operator_options", ()))


def is_automatic(scene, method: str | None, dt, options) -> bool:
    """True when femehl chooses the discretization: no ``dt`` and none of its options given."""
    from femehl.accuracy.auto import LADDERS

    method = scene.default_method if method is None else method
    if method not in _registry():
        raise SceneError(f"unknown method {method!r}: choose one of {sorted(_registry())}.")
    return dt is None and method in LADDERS and not (discretization_options(method) & set(options))


#: options of the automatic mode only (:func:`femehl.accuracy.auto.solve_to_tolerance`)
AUTO_ONLY = ("max_elements", "max_wall", "level", "on_run")


def refuse_auto_only(options) -> None:
    """SceneError when an expert run (``dt`` or a discretization option) got an option of
    the automatic mode (:data:`AUTO_ONLY`)."""
    given = sorted(k for k in AUTO_ONLY if k in options)
    if given:
        raise SceneError(
            f"{', '.join(given)} apply to the automatic mode only, where femehl chooses the mesh "
            "and the steps: leave out dt and the discretization options (mesh=, n_elements=, "
            f"...), or leave out {', '.join(given)}."
        )


@one_blas_thread
def solve(
    scene: Scene,
    method: str | None = None,
    *,
    t_end: float = 5.0,
    dt: float | None = None,
    tol: float | None = None,
    step_tol: float | None = None,
    store_every: int = 1,
    callback: Callable[[State], None] | None = None,
    estimate: bool = True,
    out=None,
    overwrite: bool = False,
    resume: bool = False,
    progress: bool = False,
    checkpoint_every: int | None = None,
    log: Callable[[str], None] | None = None,
    **options,
) -> Result:
    """Run ``scene`` from t = 0 to ``t_end`` and return a :class:`~femehl.output.result.Result`.

    Two modes, decided here once (docs/design.md sections 8 and 9):

    * **automatic** (neither ``dt`` nor a discretization option such as ``mesh`` is
      given): femehl chooses the mesh and the time steps so that the load, central and
      minimum film are within ``tol`` (default 1e-2) at every step
      (:func:`femehl.accuracy.auto.solve_to_tolerance`); the result carries the error estimate,
      ``result.uncertainty(name, t)``; ``max_wall=`` (seconds) and ``max_elements=``
      (cells) bound what it may spend, ``on_run=`` sees every finished run (the first too);
    * **expert** (``dt`` or ``mesh=`` / ``dr=`` / ``n_elements=`` ... given): that
      discretization, with fixed steps ``dt`` (default 0.01), or adaptive steps when
      ``step_tol`` is given.  The result carries the space part of the error estimate
      from a companion run twice as coarse with the same steps (FE ladder rungs and
      ``"fitted"``, line contact; about 10-25 % more work; ``estimate=False`` skips it)
      and, with ``step_tol``, the time part (:func:`femehl.accuracy.auto.expert_estimate`).

    With ``out`` a folder, the run is written there as it goes
    (:class:`femehl.output.run.RunFolder`: summary.csv with the estimate's columns,
    field series, checkpoint, PNGs, auto.json).

    Parameters
    ----------
    scene : femehl.Scene
        The problem (see :mod:`femehl.problem.scene`, :mod:`femehl.problem.presets`).
    method : str, default: "fe"
        A key of :data:`femehl.discretize.METHODS`: "fe" (finite elements, default
        for a 2-D scene), "fd" (the paper's polar finite differences, expert mode only)
        or "line" (line contact, the default for a :class:`femehl.problem.line.LineScene`).
    t_end : float, default: 5.0
        End time (normalized).
    dt : float, optional
        Fixed time step (expert mode; default 0.01, the paper's value); with ``step_tol``,
        the first step.
    tol : float, optional
        The accuracy target of the automatic mode: load, central and minimum film within
        this relative error (default 1e-2).
    step_tol : float, optional
        Expert mode: adaptive time steps (:mod:`femehl.solver.adaptive`) to this relative
        local error per unit time; the scheme is then BDF2 unless given.  ``dt_min``,
        ``dt_max`` and ``safety`` tune the controller.
    store_every : int, default: 1
        Keep (and with ``out``, write) the fields of every ``store_every``-th step (and
        the last); 0 keeps none.
    callback : callable, optional
        Called with each State as it is produced (progress bars, writers); in automatic
        mode with the States of every run (``state.info`` has no level: use
        ``result.info["auto"]`` afterwards).
    estimate : bool, default: True
        Expert mode: also run the coarser companion for the space estimate.
    out : path-like, optional
        A run folder to write the run into as it goes.  Refused (OutputError) when it
        holds a run, unless ``overwrite`` (its femehl files are replaced; other files
        stay) or ``resume`` (continued from its checkpoint: same scene, method and mesh;
        summary.csv is appended; the Result starts at the checkpoint).
    overwrite, resume : bool, default: False
        See ``out``.
    progress : bool, default: False
        A tqdm progress bar for each run.
    checkpoint_every : int, optional
        With ``out``: save the state to ``checkpoint.npz`` every this many steps (default:
        ``store_every``; 0: only at the end) and at the end (:mod:`femehl.output.checkpoint`).
    log : callable, optional
        With ``out``: also given each report line (they go to the logger ``"femehl"``).
    **options
        Options of the method (FD ``dr``, ``dtheta``; FE ``mesh``; line ``n_elements``)
        and of the stepper (``scheme``, ``linear_solver``, ``terms``, ...).

    Raises
    ------
    SceneError, OutputError
        A bad option or an unusable folder, before anything is written.
    SolverError, KeyboardInterrupt
        The run stopped: ``exc.result`` is the partial Result; a folder's files stay readable.
    """
    from femehl.output._validation import check_flag, check_tol

    tol, step_tol = check_tol(tol), check_tol(step_tol, "step_tol")
    if "max_wall" in options:  # checked before a folder is touched
        from femehl.accuracy.auto import check_max_wall

        options["max_wall"] = check_max_wall(options["max_wall"])
    bars = _bars(check_flag("progress", progress))
    folder = _folder(out, overwrite=overwrite, resume=resume, checkpoint_every=checkpoint_every, log=log)
    saved = None if folder is None else folder.saved_plan()
    automatic = saved is not None or is_automatic(scene, method, dt, options)
    check_tolerances(automatic, tol, step_tol)
    run = _automatic if automatic else _expert
    kw = dict(t_end=t_end, dt=dt, store_every=store_every, callback=callback, folder=folder, progress=bars)
    kw.update(tol=tol, step_tol=step_tol, estimate=estimate, saved=saved)
    try:
        result = run(scene, method, **kw, **options)
    except BaseException:
        if folder is not None:
            folder.stopped()
        raise
    return result if folder is None else folder.finish(result)


def _folder(out, **kw):
    """The :class:`~femehl.output.run.RunFolder` of ``out`` (None: in memory, and no folder
    option may be given)."""
    from femehl.output.run import RunFolder

    if out is not None:
        return RunFolder(out, **kw)
    given = sorted(k for k, v in kw.items() if v not in (None, False))
    if given:
        raise SceneError(
            f"{', '.join(given)} apply to a run folder: give out= (the folder), or leave them out."
        )
    return None


def _bars(progress: bool):
    """The progress-bar maker of every run (None: no bars)."""
    from femehl.output.progress import time_bar

    return time_bar if progress else None


def _automatic(scene, method, *, tol, step_tol, estimate, saved, dt, t_end, store_every, folder, **kw):
    """The automatic mode: the sequence (:mod:`femehl.accuracy.auto`), or its saved
    candidate going on (a resumed run folder)."""
    from femehl.accuracy import auto

    if dt is not None:
        raise SceneError("an automatic run chooses its time steps: leave dt out (or give the mesh too).")
    method = scene.default_method if method is None else method
    if folder is not None:
        folder.check(t_end, None, store_every)
    if saved is not None:
        return auto.resume_to_tolerance(
            scene, folder, saved, t_end=t_end, method=method, store_every=store_every, **kw
        )
    return auto.solve_to_tolerance(
        scene,
        t_end=t_end,
        tol=DEFAULT_TOL if tol is None else tol,
        method=method,
        store_every=store_every,
        folder=folder,
        **kw,
    )


def _expert(
    scene,
    method,
    *,
    tol,
    step_tol,
    estimate,
    saved,
    dt,
    t_end,
    store_every,
    callback,
    folder,
    progress,
    **options,
):
    """The expert mode: one run on the given discretization, and its coarser companion
    for the space estimate (:func:`femehl.accuracy.auto.companion_run`)."""
    from femehl.accuracy.auto import companion_run, expert_estimate
    from femehl.solver import loop
    from femehl.solver.adaptive import CONTROLS
    from femehl.solver.stepping import check_run

    refuse_auto_only(options)
    controls = {k: options.pop(k) for k in CONTROLS if k in options}
    if step_tol is None:
        dt = 0.01 if dt is None else dt
        check_run(t_end, dt)
    else:
        options.setdefault("scheme", "bdf2")
    if folder is not None:
        folder.check(t_end, dt, store_every)
    method = scene.default_method if method is None else method
    result = loop.run_scene(
        scene,
        method,
        options,
        t_end,
        dt,
        step_tol=step_tol,
        store_every=store_every,
        on_state=callback,
        sink=folder,
        progress=progress,
        **controls,
    )
    if not estimate or folder is not None and folder.resume or result.info.get("nothing_to_do"):
        return result  # a resumed run: no companion for its part only
    full, half, ratio, order = companion_run(scene, result.method, options, result, dt, step_tol)
    result.estimate = expert_estimate(result, full, half, ratio, order, adaptive=step_tol is not None)
    return result


def check_tolerances(automatic: bool, tol, step_tol) -> None:
    """``tol`` is the automatic mode's accuracy target, ``step_tol`` the expert mode's step
    controller: SceneError naming the fix when one is given to the other mode."""
    if automatic and step_tol is not None:
        raise SceneError(
            "step_tol tunes the adaptive steps of an expert run (a mesh or dt given); the "
            "automatic mode chooses its own steps to tol: leave step_tol out, or give the mesh."
        )
    if not automatic and tol is not None:
        raise SceneError(
            f"tol = {tol!r} is the automatic mode's accuracy target, and this run is an expert one "
            "(a mesh, grid or dt given): for adaptive time steps on that discretization give "
            "step_tol= (a local error per unit time, e.g. 1e-3); for the accuracy target leave "
            "out dt and the discretization options."
        )


def solve_line(
    scene,
    t_end: float,
    dt: float,
    *,
    store_every: int = 1,
    callback: Callable[[State], None] | None = None,
    **options,
) -> Result:
    """Run a line-contact scene: ``solve(scene, method="line", ...)`` with positional times.

    ``options`` are the discretization's (``n_elements``, ``grading``, ``fine``, see
    :class:`femehl.discretize.fe_line.LineDisc`) and the stepper's (``scheme``).
    The Result's ``disc.x`` / ``disc.xc`` are the nodes (where ``State.p`` lives) and the
    element centroids (``State.d``, ``State.w``).
    """
    return solve(
        scene, method="line", t_end=t_end, dt=dt, store_every=store_every, callback=callback, **options
    )


def run_to_folder(scene, folder, *, store_every=10, **options) -> Result:
    """``solve(scene, out=folder, store_every=10, ...)``: solve ``scene`` and write
    ``folder/summary.csv``, ``fields.pvd`` + ``.vtu``, PNGs (see :func:`solve` for the
    options, ``out=`` for the folder's: ``overwrite``, ``resume``, ``progress``,
    ``checkpoint_every``, ``log``)."""
    return solve(scene, out=folder, store_every=store_every, **options)
