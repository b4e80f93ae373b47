"""Run a scene into an output folder: summary CSV and field series written as it goes.

This is what ``femehl run`` does, usable from Python too.  The marching is
:func:`femehl.api.run_loop`; here each new State is written (summary row,
field series, checkpoint) as it comes.  Every option and the folder are checked
before anything in the folder is touched: a folder that already holds a run is
refused unless ``overwrite`` (its femehl files are replaced; other files stay)
or ``resume`` (it is continued from its checkpoint).

If the run stops on a :class:`~femehl.errors.SolverError` (film rupture,
singular system) or is interrupted (KeyboardInterrupt, Ctrl-C), everything
written so far stays readable, the checkpoint holds the last good state, the
PNGs are drawn from the states reached, and the exception is re-raised with
``exc.result`` set to the partial :class:`~femehl.output.result.Result`.

Reports go to the :mod:`logging` logger ``"femehl"`` (INFO); nothing is printed.
"""

from __future__ import annotations

import logging
import pathlib
import time

import numpy as np

from femehl.errors import OutputError, SceneError, SolverError
from femehl.output import RunWriter, checkpoint, draw_figures
from femehl.output._validation import check_flag, check_resume_overwrite, check_run_options, check_tol
from femehl.output.folder import check_folder, prepare_folder
from femehl.output.result import Result
from femehl.solver.loop import make_stepper, run_loop
from femehl.solver.threads import one_blas_thread

__all__ = ["run_to_folder"]

logger = logging.getLogger("femehl")


def _reporter(log):
    """``say(message)``: to the logger, and to ``log`` too if one was given."""
    if log is not None and not callable(log):
        raise SceneError(f"log must be a callable taking one string (or None), got {log!r}.")

    def say(message: str) -> None:
        logger.info(message)
        if log is not None:
            log(message)

    return say


def _check_resume_time(start, t_end: float, dt: float) -> None:
    """The checkpoint's time is on the run's time grid and not past ``t_end``."""
    k = round(start.t / dt) if dt is not None else 0
    if dt is not None and abs(k * dt - start.t) > 1e-9 * max(1.0, start.t):
        raise SceneError(
            f"cannot resume at t = {start.t:g} with dt = {dt:g}: resume with the dt of the original run."
        )
    if t_end < start.t - 1e-9 * max(1.0, start.t):
        raise SceneError(
            f"t_end = {t_end:g} is before the checkpoint at t = {start.t:g}: "
            f"give t_end >= {start.t:g} to resume."
        )


def _terms(scene, stepper, t_end: float) -> str:
    eff = scene.effects(t_end)
    info = getattr(stepper, "info", {}) or {}
    return (
        f"femehl: method {stepper.method}, terms: squeeze={eff['squeeze']}, "
        f"sliding={eff['sliding']}, elasticity={eff['elasticity']}, "
        f"imposed_load={eff['imposed_load']}; "
        + ", ".join(
            f"{k}={v}"
            for k, v in info.items()
            if k in ("mesh", "elements", "nodes", "unknowns", "half", "operator")
        )
    )


def _pictures(result: Result, folder: pathlib.Path) -> None:
    """The PNGs of the states reached (a failure to draw does not hide the run's outcome)."""
    if not result.states:
        return
    try:
        draw_figures(result, folder)
    except Exception as exc:  # noqa: BLE001 - pictures are a convenience
        logger.warning("femehl: could not draw the PNGs in %s (%s: %s)", folder, type(exc).__name__, exc)


def _redraw_history(folder: pathlib.Path) -> None:
    """history.png again, now with the error estimate's band (a failure only warns)."""
    from femehl.output.plots import plot_history

    if not (folder / "history.png").is_file():
        return
    try:
        plot_history(folder)
    except Exception as exc:  # noqa: BLE001 - pictures are a convenience
        logger.warning("femehl: could not redraw %s/history.png (%s: %s)", folder, type(exc).__name__, exc)


@one_blas_thread
def run_to_folder(
    scene,
    folder,
    *,
    method=None,
    t_end=5.0,
    dt=None,
    store_every=10,
    progress=False,
    log=None,
    checkpoint_every=None,
    resume=False,
    overwrite=False,
    tol=None,
    step_tol=None,
    **options,
) -> Result:
    """Solve ``scene`` and write ``folder/summary.csv``, ``fields.pvd`` + ``.vtu``, PNGs.

    Parameters
    ----------
    scene : femehl.Scene
    folder : path-like
    method : str, default: "fe"
    t_end : float, default: 5.0
    dt : float, optional
        Fixed time step (expert mode, default 0.01); with ``step_tol`` the first step.
    store_every : int, default: 10
        Fields are kept and written every ``store_every`` steps (and at the end).
    progress : bool, default: False
        Show a tqdm progress bar.
    log : callable, optional
        Also given each report line (they go to the logger ``"femehl"`` in any case).
    checkpoint_every : int, optional
        Save the state to ``folder/checkpoint.npz`` every this many steps (default:
        ``store_every``; 0: only at the end) and at the end (see
        :mod:`femehl.output.checkpoint`).
    resume : bool, default: False
        Continue from ``folder/checkpoint.npz`` (same scene, method and mesh, else
        SceneError): summary.csv is appended and the field series numbering goes on
        after the files present.  The returned Result starts at the checkpoint.
    overwrite : bool, default: False
        Replace a run already in ``folder`` (its femehl files are removed first; other
        files are left alone).  Without it such a folder is refused with OutputError.
    tol : float, optional
        Automatic mode (neither ``dt`` nor a discretization option given, as
        :func:`femehl.solve`): the relative accuracy, default 1e-2; the coarse pilot runs
        stay in memory, each run that may be the answer is written here as it goes (a
        finer one replaces it), and at the end ``summary.csv`` gets the error estimate
        columns (:data:`femehl.output.table.ERROR_COLUMNS`) and ``auto.json`` what was
        chosen.
    step_tol : float, optional
        Expert mode: adaptive time steps to this relative error per unit time
        (:mod:`femehl.solver.adaptive`); ``dt`` is then the first step and the scheme BDF2
        unless given.  ``store_every`` and ``checkpoint_every`` count accepted steps.
    **options
        Discretization options of the method (``mesh``, ``dr``, ``dtheta``, ...): expert mode.
        Automatic mode: ``max_wall`` (seconds) and ``max_elements`` (cells), the budgets of
        :func:`femehl.accuracy.auto.solve_to_tolerance` (a candidate written here always finishes;
        only the pilots in memory are abandoned at ``max_wall``).

    Raises
    ------
    SceneError, OutputError
        A bad option or an unusable folder, before anything is written.
    SolverError, KeyboardInterrupt
        The run stopped: ``exc.result`` is the partial Result, the files stay readable.
    """
    from femehl.api import DEFAULT_TOL, check_tolerances, is_automatic, refuse_auto_only

    tol, step_tol = check_tol(tol), check_tol(step_tol, "step_tol")
    if "max_wall" in options:  # checked before the folder is touched
        from femehl.accuracy.auto import check_max_wall

        options["max_wall"] = check_max_wall(options["max_wall"])
    resume, overwrite = check_resume_overwrite(resume, overwrite)
    say = _reporter(log)
    common = dict(
        method=method,
        t_end=t_end,
        store_every=store_every,
        progress=progress,
        say=say,
        checkpoint_every=checkpoint_every,
        options=options,
    )
    saved_auto = None
    if resume:
        saved_auto = checkpoint.read_params(check_folder(folder, resume=True)).get("auto")
    if saved_auto is None and not is_automatic(scene, method, dt, options):
        refuse_auto_only(options)
        check_tolerances(False, tol, step_tol)
        res = _stream(scene, folder, dt=dt, step_tol=step_tol, resume=resume, overwrite=overwrite, **common)
        # the space estimate from the coarser companion (a resumed run: its part only)
        if not resume and not res.info.get("nothing_to_do"):
            _expert_estimate(scene, pathlib.Path(folder), res, dt, step_tol, options, t_end, say)
        return res
    check_tolerances(True, tol, step_tol)
    if dt is not None:
        raise SceneError("an automatic run chooses its time steps: leave dt out (or give the mesh too).")
    return _automatic(
        scene,
        folder,
        tol=DEFAULT_TOL if tol is None else tol,
        resume=resume,
        overwrite=overwrite,
        saved=saved_auto,
        **common,
    )


def _automatic(
    scene, folder, *, tol, resume, overwrite, saved, method, t_end, store_every, say, options, **common
):
    """The automatic run: pilots in memory, candidates streamed into ``folder``."""
    from femehl.accuracy import auto

    t0 = time.perf_counter()
    check_run_options(t_end, 0.01, store_every, common.get("checkpoint_every"))
    folder = check_folder(folder, resume=resume, overwrite=overwrite)
    method = scene.default_method if method is None else method
    first = {"candidate": True}

    def stream(options, plan, *, resume=False):
        """One run of the automatic sequence streamed into ``folder`` (``plan``: its level)."""
        return _stream(
            scene,
            folder,
            method=method,
            t_end=t_end,
            dt=None,
            step_tol=plan["tol_t"],
            resume=resume,
            overwrite=overwrite if first["candidate"] or resume else True,
            store_every=store_every,
            say=say,
            options=options,
            auto_plan=plan,
            **common,
        )

    def runner(*, level, tol_t, options, previous):
        plan = {
            "tol": tol,
            "level": level,
            "tol_t": tol_t,
            "t_fit": t_end,
            "companion": auto.companion_record(previous),
        }
        if not first["candidate"]:
            plan["replaces"] = True  # a finer candidate replaces the coarser one's files
        try:
            return stream(options, plan)
        finally:
            first["candidate"] = False

    if resume:
        # the saved candidate goes on, on the mesh it was fitted with (to the run's first
        # t_end); the budgets of the sequence no longer apply
        t_fit = float(saved.get("t_fit", saved["companion"]["t"][-1]))
        kept = {k: v for k, v in options.items() if k not in ("max_wall", "max_elements")}
        ladder = auto.LADDERS[method]
        options = {**ladder.options(scene, t_fit, saved["level"]), **kept}
        res = stream(options, saved, resume=True)
        if res.info.get("nothing_to_do"):
            return res
        res.info.update(level=saved["level"], tol_t=saved["tol_t"])
        level_c = float(saved["companion"]["level"])
        companion = auto.CompanionSeries(saved["companion"])
        if t_end > companion.t[-1] * (1.0 + 1e-9):  # extended: its companion goes on too
            say(f"femehl: the coarser companion (level {level_c:.3g}) again to t = {t_end:g} (the estimate)")
            companion = auto.companion_to(scene, method, t_end, t_fit, level_c, store_every, kept)
        res.estimate = _continued(folder, auto.estimate(res, companion, level_c / saved["level"]))
        res.info["auto"] = {"tol": saved["tol"], "resumed": True}
    else:
        say(f"femehl: automatic run to tol = {tol:g} (pilot runs in memory, then the run itself)")
        try:
            res = auto.solve_to_tolerance(
                scene,
                t_end=t_end,
                tol=tol,
                method=method,
                store_every=store_every,
                runner=runner,
                progress=_pilot_bar if common.get("progress") else None,
                **options,
            )
        except SolverError as exc:
            say(f"femehl: run stopped at t = {exc.t}: {exc}")
            raise
        if first["candidate"]:  # the budget ended the sequence in its pilots: write the last one
            say(
                f"femehl: the budget ended the sequence before a run that could be the answer; "
                f"writing the last pilot (level {res.info['level']:.3g}) into {folder}"
            )
            try:
                res.save(folder, overwrite=overwrite)
            except OSError as exc:
                raise OutputError(
                    f"cannot write into {str(folder)!r} ({exc.strerror or exc}): free space or fix "
                    "permissions, then run again."
                ) from exc
    _write_estimate(folder, res)
    res.info["wall_s"] = time.perf_counter() - t0  # pilots and candidates
    a = res.info.get("auto", {})
    if "levels" in a:
        say(
            "femehl: chose "
            + ", ".join(
                f"level {lv:.3g}: {n} cells, {k} steps"
                for lv, n, k in zip(a["levels"], a["elements"], a["steps"], strict=True)
            )
            + f"; estimated error {a.get('total', float('nan')):.2g} "
            + ("(tol reached" if a["reached"] else "(tol NOT reached")
            + f": accepted at <= {a['accept']:g} tol)"
        )
    return res


def _continued(folder, est: dict) -> dict:
    """A resumed run's estimate going on from its earlier part's (saved when it was resumed):
    the total is a running maximum over the whole run and the time part accumulates."""
    from femehl.output.table import EARLIER_ESTIMATE, _earlier_estimate

    before = _earlier_estimate(folder / "summary.csv")
    if not before:
        return est
    last = before[max(before, key=float)]

    def cell(q, part):
        try:
            return float(last.get(f"err_{q}" if part == "total" else f"err_{q}_{part}", "nan"))
        except ValueError:
            return float("nan")

    for q, parts in est.items():
        if q == "t" or parts["total"] is None:
            continue
        total0, time0 = cell(q, "total"), cell(q, "time")
        if not np.isfinite(total0):
            continue
        total = np.maximum(parts["total"], total0)
        tpart = np.minimum(parts["time"] + (time0 if np.isfinite(time0) else 0.0), total)
        est[q] = {"total": total, "space": total - tpart, "time": tpart}
    logger.info("femehl: the estimate goes on from the one in %s", folder / EARLIER_ESTIMATE)
    return est


def _pilot_bar(desc, t_end):
    from femehl.output.progress import TimeBar

    return TimeBar(f"femehl {desc}", t_end)


def _expert_estimate(scene, folder, res, dt, step_tol, options, t_end, say) -> None:
    """An expert run's estimate (:func:`femehl.accuracy.auto.expert_estimate`) into summary.csv."""
    from femehl.accuracy.auto import companion_run, expert_estimate

    options = {"scheme": "bdf2", **options} if step_tol is not None else dict(options)
    step = (0.01 if dt is None else dt) if step_tol is None else dt
    companion, ratio = companion_run(scene, res.method, options, t_end, step, step_tol, {})
    res.estimate = expert_estimate(res, companion, ratio, adaptive=step_tol is not None)
    if res.estimate is not None:
        _write_estimate(folder, res)
        if companion is not None:
            say(f"femehl: space estimate from a companion run {ratio:.3g} times coarser")


def _write_estimate(folder, res) -> None:
    """The error columns of summary.csv and ``auto.json`` (what the automatic run chose)."""
    import json

    from femehl.output.table import add_error_columns

    try:
        if res.estimate is not None:
            add_error_columns(folder / "summary.csv", res.estimate)
            _redraw_history(folder)
        if "auto" in res.info:
            info = {k: v for k, v in res.info["auto"].items()}
            tmp = folder / "auto.json.tmp"
            tmp.write_text(json.dumps(info, indent=1, default=float))
            tmp.replace(folder / "auto.json")
    except OSError as exc:
        raise OutputError(
            f"cannot write the error estimate into {str(folder)!r} ({exc.strerror or exc}): the run's "
            "files are there without it; free space or fix permissions, then resume (--resume) to "
            "write it."
        ) from exc


def _stream(
    scene,
    folder,
    *,
    method,
    t_end,
    dt,
    step_tol,
    resume,
    overwrite,
    store_every,
    progress,
    say,
    checkpoint_every,
    options,
    auto_plan=None,
) -> Result:
    """One run of one discretization, written into ``folder`` as it goes."""
    if step_tol is not None:
        options = {"scheme": "bdf2", **options}
    step = 0.01 if dt is None else dt  # fixed steps; with step_tol only checked (None: the controller's)
    t_end, step, nsteps, store_every, every = check_run_options(t_end, step, store_every, checkpoint_every)
    dt = step if step_tol is None or dt is not None else None
    progress = check_flag("progress", progress)
    folder = check_folder(folder, resume=resume, overwrite=overwrite)
    t0 = time.perf_counter()
    stepper = make_stepper(scene, method, **options)
    params = checkpoint.run_params(scene, stepper, step)
    params["tol"] = step_tol  # the checkpoint's name for the step controller's tolerance
    if auto_plan is not None:
        params["auto"] = auto_plan
    start = None
    if resume:
        checkpoint.check_params(checkpoint.read_params(folder), params)
        start = checkpoint.load_checkpoint(folder, reference=stepper.initial_state())
        _check_resume_time(start, t_end, None if step_tol is not None else dt)
    say(_terms(scene, stepper, t_end) + f"; set-up {time.perf_counter() - t0:.1f} s")
    if "cavitation_note" in stepper.info:
        say(f"femehl: cavitation: {stepper.info['cavitation_note']}")

    # ---- everything is checked: from here on the folder is written ----
    try:
        removed = prepare_folder(folder, overwrite=overwrite)
        if resume and not t_end <= start.t + 1e-9 * max(1.0, start.t):
            writer = checkpoint.resume_writer(folder, stepper.disc, store_every, start.t)
        elif not resume:
            writer = RunWriter(folder, stepper.disc, every=store_every)
            checkpoint.write_params(folder, params)
    except OSError as exc:
        raise OutputError(
            f"cannot write into {str(folder)!r} ({exc.strerror or exc}): free space or fix "
            "permissions, then run again (or resume: --resume)."
        ) from exc
    if removed:
        if auto_plan is not None and auto_plan.get("replaces"):
            say(
                f"femehl: automatic: this finer run replaces the coarser one's {len(removed)} "
                f"file(s) in {folder}"
            )
        else:
            say(f"femehl: overwrite: removed {len(removed)} file(s) of the earlier run in {folder}")
    if resume:
        say(f"femehl: resuming from the checkpoint at t = {start.t:g} (step {start.step})")
        if t_end <= start.t + 1e-9 * max(1.0, start.t):
            say(
                f"femehl: the run in {folder} is already at t_end = {t_end:g}: nothing to do, "
                "nothing rewritten (give a larger t_end to go on)"
            )
            done = Result(scene=stepper.scene, method=stepper.method, disc=stepper.disc)
            done.record(start, store_fields=False)
            done.info.update(getattr(stepper, "info", {}), steps=0, wall_s=time.perf_counter() - t0)
            done.info["nothing_to_do"] = True
            return done
    bar = None
    if progress:
        from femehl.output.progress import TimeBar

        what = f"level {auto_plan['level']:.3g}, " if auto_plan is not None else ""
        bar = TimeBar(
            f"femehl {stepper.method} ({what}{stepper.info.get('elements', '?')} cells)",
            t_end,
            0.0 if start is None else float(start.t),
        )
    last = {"state": None, "saved": None}

    def on_state(state):
        try:
            writer(state)
            last["state"] = state
            if every and state.step % every == 0:
                checkpoint.save_checkpoint(folder, state)
                last["saved"] = state
        except OSError as exc:
            raise OutputError(
                f"cannot write into {str(folder)!r} at t = {state.t:g} "
                f"({exc.strerror or exc}): free space or fix permissions, then resume "
                "(resume=True, --resume)."
            ) from exc
        if bar is not None:
            bar(state)

    result = None
    finished = False
    try:
        result = run_loop(
            stepper, t_end, dt, step_tol=step_tol, start=start, store_every=store_every, on_state=on_state
        )
        finished = True
    except SolverError as exc:
        result = getattr(exc, "result", None)
        say(f"femehl: run stopped at t = {exc.t}: {exc}")
        raise
    except KeyboardInterrupt as exc:
        result = getattr(exc, "result", None)
        say("femehl: interrupted")
        raise
    finally:
        if bar is not None:
            bar.close()
        writer.close()  # the last state's fields, CSV closed
        state = last["state"]
        if state is not None and state is not last["saved"]:
            checkpoint.save_checkpoint(folder, state)  # the last good state
        if result is not None:
            result.info["wall_s"] = time.perf_counter() - t0
            _pictures(result, folder)
        if state is not None and not finished:
            say(f"femehl: output up to t = {state.t:g} is in {folder}; the checkpoint is at t = {state.t:g}")
    return result
