"""Run a scene into an output folder: summary CSV and field series written as it goes.

This is what ``femehl run`` does, usable from Python too.  If the run stops
on a :class:`~femehl.errors.SolverError` (film rupture, singular system),
everything written so far stays readable, the PNGs are drawn from the
states reached, and the error is re-raised with ``error.result`` set to the
partial :class:`~femehl.result.Result`.
"""

from __future__ import annotations

import pathlib
import time

from .api import make_stepper
from .errors import SceneError, SolverError
from .output import RunWriter, centreline_png, checkpoint, quicklook_png
from .result import Result
from .stepping import check_run, march

__all__ = ["run_to_folder"]


def run_to_folder(scene, folder, *, method=None, t_end=5.0, dt=0.01, store_every=10,
                  progress=False, log=print, checkpoint_every=None, resume=False, **options) -> Result:
    """Solve ``scene`` and write ``folder/summary.csv``, ``fields.pvd`` + ``.vtu``, PNGs.

    Parameters
    ----------
    scene : femehl.Scene
    folder : path-like
    method : str, default: "fe"
    t_end, dt : float, default: 5.0, 0.01
    store_every : int, default: 10
        Fields are kept and written every ``store_every`` steps (and at the end).
    progress : bool, default: False
        Show a tqdm progress bar.
    log : callable, default: print
        Where the one-line reports go.
    checkpoint_every : int, optional
        Save the state to ``folder/checkpoint.npz`` every this many steps (default:
        ``store_every``) and at the end (see :mod:`femehl.output.checkpoint`).
    resume : bool, default: False
        Continue from ``folder/checkpoint.npz`` (same scene, method and mesh, else
        SceneError): summary.csv is appended and the field series numbering goes on.
        The returned Result starts at the checkpoint.
    """
    t_end, dt, nsteps = check_run(t_end, dt)
    folder = pathlib.Path(folder)
    t0 = time.perf_counter()
    stepper = make_stepper(scene, method, **options)
    info = getattr(stepper, "info", {})
    eff = scene.effects(t_end)
    log(f"femehl: method {stepper.method}, terms: squeeze={eff['squeeze']}, "
        f"sliding={eff['sliding']}, elasticity={eff['elasticity']}, "
        f"imposed_load={eff['imposed_load']}; "
        + ", ".join(f"{k}={v}" for k, v in info.items() if k in ("mesh", "elements", "nodes", "unknowns", "half"))
        + f"; set-up {time.perf_counter() - t0:.1f} s")
    result = Result(scene=scene, method=stepper.method, disc=stepper.disc)
    params = checkpoint.run_params(scene, stepper, dt)
    start = None
    if resume:
        checkpoint.check_params(checkpoint.read_params(folder), params)
        start = checkpoint.load_checkpoint(folder)
        log(f"femehl: resuming from the checkpoint at t = {start.t:g} (step {start.step})")
        writer = checkpoint.resume_writer(folder, stepper.disc, store_every, start.t)
    else:
        writer = RunWriter(folder, stepper.disc, every=store_every)
    checkpoint.write_params(folder, params)
    every = store_every if checkpoint_every is None else checkpoint_every
    if isinstance(every, bool) or not isinstance(every, int) or every < 0:
        raise SceneError(f"checkpoint_every must be an integer >= 0, got {checkpoint_every!r}.")
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=nsteps, unit="step", desc=f"femehl {stepper.method}", leave=True)
    last = None
    try:
        for state in march(stepper, t_end, dt, start=start):
            keep = bool(store_every) and state.step % store_every == 0
            result.record(state, store_fields=keep)
            if state is not start:              # a resumed run's first state is already written
                writer(state)
                if every and state.step % every == 0:
                    checkpoint.save_checkpoint(folder, state)
            last = (state, keep)
            if bar is not None and state.step:
                bar.update(1)
                bar.set_postfix(t=f"{state.t:.3g}", load=f"{state.load:.4g}", dmin=f"{state.film_min:.3g}", refresh=False)
    except SolverError as exc:
        exc.result = result
        log(f"femehl: run stopped at t = {exc.t}: {exc}\n"
            f"femehl: output up to t = {result.t[-1]:g} is in {folder}")
        raise
    finally:
        if bar is not None:
            bar.close()
        writer.close()
        if last is not None and last[0] is not start:
            checkpoint.save_checkpoint(folder, last[0])      # the last good state
        if last is not None and store_every and not last[1]:
            result._stored.append(last[0])
        result.info.update(info)
        result.info["wall_s"] = time.perf_counter() - t0
        if result.states:
            centreline_png(result, folder / "centreline.png")
            quicklook_png(result, folder / "fields.png")
    return result
