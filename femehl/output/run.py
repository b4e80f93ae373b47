"""A run folder: summary CSV, field series, checkpoint and PNGs written as the run goes.

:class:`RunFolder` is attached to the one loop (:func:`femehl.solver.loop.run_scene`) by
:func:`femehl.solve` ``(..., out=folder)``; ``run_to_folder`` is that call with
``store_every=10`` (:func:`femehl.api.run_to_folder`), which ``femehl run`` and sweeps use
(docs/design.md section 8).
Every option and the folder are checked before anything in the folder is touched: a
folder that already holds a run is refused unless ``overwrite`` (its femehl files are
replaced; other files stay) or ``resume`` (it is continued from its checkpoint).

If the run stops on a :class:`~femehl.errors.SolverError` (film rupture,
singular system) or is interrupted (KeyboardInterrupt, Ctrl-C), everything
written so far stays readable, the checkpoint holds the last good state, the
PNGs are drawn from the states reached, and the exception is re-raised with
``exc.result`` set to the partial :class:`~femehl.output.result.Result`.

Reports go to the :mod:`logging` logger ``"femehl"`` (INFO); nothing is printed.
"""

from __future__ import annotations

import json
import logging
import pathlib
import time

from femehl.errors import OutputError, SceneError, SolverError
from femehl.output import RunWriter, checkpoint, draw_figures
from femehl.output._validation import check_resume_overwrite, check_run_options
from femehl.output.folder import check_folder, prepare_folder
from femehl.output.result import Result

__all__ = ["RunFolder"]

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


def _pictures(result: Result, folder: pathlib.Path, skip=()) -> None:
    """The PNGs of the states reached (a failure to draw does not hide the run's outcome)."""
    if not result.states:
        return
    try:
        draw_figures(result, folder, skip)
    except Exception as exc:  # noqa: BLE001 - pictures are a convenience
        logger.warning("femehl: could not draw the PNGs in %s (%s: %s)", folder, type(exc).__name__, exc)


def _draw_history(folder: pathlib.Path) -> None:
    """history.png from the folder's summary.csv, with the error estimate's band when its
    columns are there (a failure only warns)."""
    from femehl.output.plots import plot_history

    if not (folder / "summary.csv").is_file():
        return
    try:
        plot_history(folder)
    except Exception as exc:  # noqa: BLE001 - pictures are a convenience
        logger.warning("femehl: could not redraw %s/history.png (%s: %s)", folder, type(exc).__name__, exc)


class RunFolder:
    """The folder a run is written into, attached to the loop by :func:`femehl.solve`.

    ``check`` the run's options and the folder before anything runs; ``writer`` is
    opened for each run that may be the answer (the expert run; each candidate of the
    automatic sequence, a finer one replacing the coarser one's files) and fed its
    States; ``finish`` writes the answer's estimate columns and ``auto.json``.
    """

    def __init__(self, folder, *, overwrite=False, resume=False, checkpoint_every=None, log=None):
        self.resume, self.overwrite = check_resume_overwrite(resume, overwrite)
        self.say = _reporter(log)
        self.checkpoint_every = checkpoint_every
        self.path = folder
        self.written = False  # a writer was opened: a later run replaces its files
        self.history_due = False  # a run ended and left its history.png to finish()
        self.t0 = time.perf_counter()

    def check(self, t_end: float, dt: float | None, store_every: int) -> None:
        """The run's options and the folder (OutputError, SceneError), before anything runs."""
        _t, _dt, _n, self.store_every, self.every = check_run_options(
            t_end, 0.01 if dt is None else dt, store_every, self.checkpoint_every
        )
        self.path = check_folder(self.path, resume=self.resume, overwrite=self.overwrite)

    def saved_plan(self) -> dict | None:
        """The automatic plan of the run to resume (None: an expert one, or no resume)."""
        if not self.resume:
            return None
        return checkpoint.read_params(check_folder(self.path, resume=True)).get("auto")

    def writer(self, stepper, t_end, dt, step_tol, plan=None, t0=None) -> _Writer:
        """The context manager feeding one run's States into the folder."""
        overwrite = self.overwrite if not self.written or self.resume else True
        if self.written and plan is not None:
            plan = {**plan, "replaces": True}  # a finer candidate replaces the coarser one's files
        self.written = True
        return _Writer(self, stepper, t_end, dt, step_tol, plan, overwrite, t0)

    def earlier_estimate(self) -> dict:
        """``{(quantity, part): value}`` at the end of a resumed run's earlier part ({} if none)."""
        from femehl.output.table import EARLIER_ESTIMATE, ERROR_QUANTITIES, _earlier_estimate

        before = _earlier_estimate(self.path / "summary.csv")
        if not before:
            return {}
        last = before[max(before, key=float)]
        logger.info("femehl: the estimate goes on from the one in %s", self.path / EARLIER_ESTIMATE)
        names = {"total": "err_{}", "space": "err_{}_space", "time": "err_{}_time"}
        return {
            (q, part): _number(last.get(c.format(q), ""))
            for q in ERROR_QUANTITIES
            for part, c in names.items()
        }

    def finish(self, res: Result) -> Result:
        """The answer in the folder (the first run, held in memory, when the budget ended the
        sequence after it), its error columns, ``auto.json`` and the report."""
        if res.info.get("nothing_to_do"):
            return res
        if not self.written:
            self._write_first(res)
        _write_estimate(self.path, res)
        if self.history_due or (res.estimate is not None and (self.path / "history.png").is_file()):
            self._history()  # with the estimate's band, once
        res.info["wall_s"] = time.perf_counter() - self.t0  # companions, first run and candidates too
        if res.estimate is not None and res.estimate.how == "companion":
            self.say(
                f"femehl: error estimate from companion runs {res.estimate.ratio:.3g} times coarser on the "
                "run's steps (space) and on steps twice as long (time)"
            )
        elif res.estimate is not None and res.estimate.how == "companion+controller":
            self.say(
                f"femehl: error estimate from a companion run {res.estimate.ratio:.3g} times coarser on the "
                "run's steps (space) and the step controller's local errors (time)"
            )
        self.say_choice(res.info.get("auto", {}))
        return res

    def stopped(self) -> None:
        """After a fault between a run's end and :meth:`finish` (its companions): the history
        the run left to finish."""
        if self.history_due:
            self._history()

    def _history(self) -> None:
        _draw_history(self.path)
        self.history_due = False

    def _write_first(self, res: Result) -> None:
        self.say(
            f"femehl: the budget ended the sequence before a run that could be the answer; "
            f"writing the first run (level {res.info['level']:.3g}) into {self.path}"
        )
        try:
            res.save(self.path, overwrite=self.overwrite)
        except OSError as exc:
            raise OutputError(
                f"cannot write into {str(self.path)!r} ({exc.strerror or exc}): free space or fix "
                "permissions, then run again."
            ) from exc

    def say_choice(self, a: dict) -> None:
        """What the automatic sequence chose (nothing for an expert or resumed run)."""
        if "levels" not in a:
            return
        at = a.get("adapted_at")
        runs = [
            f"level {lv:.3g}: {n} cells, {k} steps"
            for lv, n, k in zip(a["levels"], a["elements"], a["steps"], strict=True)
        ]
        if at is not None:  # the runs after the one at that level are on meshes adapted to it
            i = next(i for i, lv in enumerate(a["levels"]) if lv == at) + 1
            runs[i] = f"then on meshes adapted to it, {runs[i]}"
        self.say(
            "femehl: chose "
            + ", ".join(runs)
            + f"; estimated error {a.get('total', float('nan')):.2g} "
            + ("(tol reached" if a["reached"] else "(tol NOT reached")
            + f": accepted at <= {a['accept']:g} tol)"
        )


def _number(cell: str) -> float:
    try:
        return float(cell)
    except ValueError:
        return float("nan")


def _write_estimate(folder, res) -> None:
    """The error columns of summary.csv and ``auto.json`` (what the automatic run chose)."""
    from femehl.output.table import add_error_columns

    try:
        if res.estimate is not None:
            add_error_columns(folder / "summary.csv", res.estimate)
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


class _Writer:
    """One run written into a :class:`RunFolder` as it goes: entered before the loop,
    called with each State, left after it (also when it stops: the files stay readable)."""

    def __init__(self, folder: RunFolder, stepper, t_end, dt, step_tol, plan, overwrite, t0):
        self.folder, self.stepper, self.t_end, self.plan = folder, stepper, float(t_end), plan
        self.dt, self.step_tol, self.overwrite = dt, step_tol, overwrite
        self.t0 = time.perf_counter() if t0 is None else t0
        self.start = self.done = self.result = None
        self.last = self.saved = self.files = None
        self.ended = False

    def __enter__(self) -> _Writer:
        folder, stepper, say = self.folder, self.stepper, self.folder.say
        path, scene = folder.path, stepper.scene
        step = 0.01 if self.dt is None else self.dt
        params = checkpoint.run_params(scene, stepper, step)
        params["tol"] = self.step_tol  # the checkpoint's name for the step controller's tolerance
        if self.plan is not None:
            params["auto"] = self.plan
        if folder.resume:
            checkpoint.check_params(checkpoint.read_params(path), params)
            self.start = checkpoint.load_checkpoint(path, reference=stepper.initial_state())
            _check_resume_time(self.start, self.t_end, None if self.step_tol is not None else self.dt)
        say(_terms(scene, stepper, self.t_end) + f"; set-up {time.perf_counter() - self.t0:.1f} s")
        if "cavitation_note" in stepper.info:
            say(f"femehl: cavitation: {stepper.info['cavitation_note']}")
        at_end = self.start is not None and self.t_end <= self.start.t + 1e-9 * max(1.0, self.start.t)
        # ---- everything is checked: from here on the folder is written ----
        try:
            removed = prepare_folder(path, overwrite=self.overwrite)
            if folder.resume and not at_end:
                self.files = checkpoint.resume_writer(path, stepper.disc, folder.store_every, self.start.t)
            elif not folder.resume:
                self.files = RunWriter(path, stepper.disc, every=folder.store_every)
                checkpoint.write_params(path, params)
        except OSError as exc:
            raise OutputError(
                f"cannot write into {str(path)!r} ({exc.strerror or exc}): free space or fix "
                "permissions, then run again (or resume: --resume)."
            ) from exc
        self._removed(removed)
        if self.start is not None:
            say(f"femehl: resuming from the checkpoint at t = {self.start.t:g} (step {self.start.step})")
        if at_end:
            self.done = self._nothing_to_do()
        return self

    def _removed(self, removed) -> None:
        if not removed:
            return
        where = self.folder.path
        if self.plan is not None and self.plan.get("replaces"):
            self.folder.say(
                f"femehl: automatic: this finer run replaces the coarser one's {len(removed)} "
                f"file(s) in {where}"
            )
        else:
            self.folder.say(
                f"femehl: overwrite: removed {len(removed)} file(s) of the earlier run in {where}"
            )

    def _nothing_to_do(self) -> Result:
        self.folder.say(
            f"femehl: the run in {self.folder.path} is already at t_end = {self.t_end:g}: nothing to do, "
            "nothing rewritten (give a larger t_end to go on)"
        )
        stepper = self.stepper
        done = Result(scene=stepper.scene, method=stepper.method, disc=stepper.disc)
        done.record(self.start, store_fields=False)
        done.info.update(getattr(stepper, "info", {}), steps=0, wall_s=time.perf_counter() - self.t0)
        done.info["nothing_to_do"] = True
        return done

    def __call__(self, state) -> None:
        try:
            self.files(state)
            self.last = state
            every = self.folder.every
            if every and state.step % every == 0:
                checkpoint.save_checkpoint(self.folder.path, state)
                self.saved = state
        except OSError as exc:
            raise OutputError(
                f"cannot write into {str(self.folder.path)!r} at t = {state.t:g} "
                f"({exc.strerror or exc}): free space or fix permissions, then resume "
                "(resume=True, --resume)."
            ) from exc

    def finished(self, result: Result) -> Result:
        self.result, self.ended = result, True
        return result

    def __exit__(self, kind, exc, tb) -> bool:
        if self.done is not None:
            return False
        say, path = self.folder.say, self.folder.path
        result = self.result if exc is None else getattr(exc, "result", None)
        if isinstance(exc, SolverError):
            say(f"femehl: run stopped at t = {exc.t}: {exc}")
        elif isinstance(exc, KeyboardInterrupt):
            say("femehl: interrupted")
        self.files.close()  # the last state's fields, CSV closed
        state = self.last
        if state is not None and state is not self.saved:
            checkpoint.save_checkpoint(path, state)  # the last good state
        if result is not None:
            result.info["wall_s"] = time.perf_counter() - self.t0
            # a run that ended is finished by RunFolder.finish (or RunFolder.stopped after a
            # fault between the two), which draws its history with the estimate: drawn once
            _pictures(result, path, skip=() if exc is not None else ("history.png",))
            self.folder.history_due = exc is None and bool(result.states)
        if state is not None and not self.ended:
            say(f"femehl: output up to t = {state.t:g} is in {path}; the checkpoint is at t = {state.t:g}")
        return False
