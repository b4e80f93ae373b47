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
from .errors import SolverError
from .output import RunWriter, centreline_png, quicklook_png
from .result import Result
from .stepping import check_run, march

__all__ = ["run_to_folder"]


def run_to_folder(scene, folder, *, method=None, t_end=5.0, dt=0.01, store_every=10,
                  progress=False, log=print, **options) -> Result:
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
    """
    t_end, dt, nsteps = check_run(t_end, dt)
    folder = pathlib.Path(folder)
    t0 = time.perf_counter()
    stepper = make_stepper(scene, method, **options)
    info = getattr(stepper, "info", {})
    eff = scene.effects(t_end)
    log(f"femehl: method {stepper.method}, terms: squeeze={eff['squeeze']}, "
        f"sliding={eff['sliding']}, elasticity={eff['elasticity']}; "
        + ", ".join(f"{k}={v}" for k, v in info.items() if k in ("mesh", "elements", "nodes", "unknowns", "half"))
        + f"; set-up {time.perf_counter() - t0:.1f} s")
    result = Result(scene=scene, method=stepper.method, disc=stepper.disc)
    writer = RunWriter(folder, stepper.disc, every=store_every)
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=nsteps, unit="step", desc=f"femehl {stepper.method}", leave=True)
    last = None
    try:
        for state in march(stepper, t_end, dt):
            keep = bool(store_every) and state.step % store_every == 0
            result.record(state, store_fields=keep)
            writer(state)
            last = (state, keep)
            if bar is not None and state.step:
                bar.update(1)
                bar.set_postfix(t=f"{state.t:.3g}", load=f"{state.load:.4g}", dmin=f"{state.film_min:.3g}")
    except SolverError as exc:
        exc.result = result
        log(f"femehl: run stopped at t = {exc.t}: {exc}\n"
            f"femehl: output up to t = {result.t[-1]:g} is in {folder}")
        raise
    finally:
        if bar is not None:
            bar.close()
        writer.close()
        if last is not None and store_every and not last[1]:
            result._stored.append(last[0])
        result.info.update(info)
        result.info["wall_s"] = time.perf_counter() - t0
        if result.states:
            centreline_png(result, folder / "centreline.png")
            quicklook_png(result, folder / "fields.png")
    return result
