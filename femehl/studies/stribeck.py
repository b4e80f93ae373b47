"""The Stribeck curve: the steady state of one scene at many speeds, on the sweep's Dask path.

:func:`stribeck` (``femehl stribeck SCENE.toml --speeds LO HI``) runs the scene at ``num``
speeds spaced evenly in log between ``LO`` and ``HI`` as a sweep (:mod:`femehl.studies.sweeps`:
one folder per case, finished cases reused, a failed case recorded), reads each case's last
state and writes the curve, ``OUT/stribeck.csv``, and its picture, ``OUT/stribeck.png``.

The speed is ``si.V_ss`` for a scene in SI units (m/s: the sum of the surfaces' speeds,
twice the entrainment speed) and ``fluid.beta = beta / s`` for a scene in normalized units,
``s`` the factor on its speed (the Reynolds equation depends on the speed only through
``V / beta`` once time is counted in sliding distance, so the same run to the same
``t_end`` reaches the same sliding distance at every speed).  The regimes, the columns and
the speed group: docs/tribology.md, "The Stribeck curve".
"""

from __future__ import annotations

import math
import pathlib

import numpy as np

from femehl.errors import FemehlError

__all__ = [
    "BOUNDARY_SHARE",
    "FULL_FILM_SHARE",
    "STEADY_CHANGE",
    "plan_stribeck",
    "stribeck",
    "stribeck_curve",
]

#: the asperities carry at least this share of the load: boundary lubrication
BOUNDARY_SHARE = 0.9
#: ... at most this share: a full film (between the two: mixed)
FULL_FILM_SHARE = 0.02
#: a case is steady when its friction changed by less than this (relative) since its last
#: stored state at or before 4/5 of its run
STEADY_CHANGE = 0.02


class StribeckError(FemehlError):
    """A Stribeck study that cannot be set up (its speeds, its scene)."""


def _raw(scene_file) -> dict:
    """The scene's tables: ``scene_file`` itself if a dict, else the TOML file read."""
    from femehl.problem.scenefile import tomllib

    if isinstance(scene_file, dict):
        return scene_file
    path = pathlib.Path(scene_file)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise StribeckError(f"scene file {str(path)!r} does not exist: check the path.") from None
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise StribeckError(f"cannot read the scene file {str(path)!r}: {exc}.") from None


def plan_stribeck(scene_file, speeds, num: int = 26, out=None, run=None):
    """The sweep of ``scene_file`` over ``num`` speeds from ``speeds[0]`` to ``speeds[1]``.

    Returns ``(plan, speed_name)``: the :class:`femehl.studies.sweeps.SweepPlan` and the
    swept parameter (``"si.V_ss"`` or ``"fluid.beta"``).  The cases keep no field series
    (``store_every = 0``: a slow case's would be 60-70 MB) unless ``run`` or the scene's
    ``[run]`` says ``store_every``.
    """
    from femehl.studies.sweeps import plan_sweep

    try:
        lo, hi = (float(s) for s in speeds)
    except (TypeError, ValueError):
        raise StribeckError(f"speeds must be two numbers LO HI, got {speeds!r}.") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 < lo < hi):
        raise StribeckError(f"speeds must be 0 < LO < HI (finite), got {lo!r} and {hi!r}.")
    if isinstance(num, bool) or not isinstance(num, int) or num < 2:
        raise StribeckError(f"num must be an integer >= 2 (the number of speeds), got {num!r}.")
    raw = _raw(scene_file)
    factors = np.logspace(math.log10(lo), math.log10(hi), num)
    if "si" in raw:
        name, values = "si.V_ss", [float(v) for v in factors]
    else:
        name, values = "fluid.beta", [_base_beta(raw) / float(s) for s in factors]
    if out is None:
        name_of = "scene" if isinstance(scene_file, dict) else pathlib.Path(scene_file).with_suffix("").name
        out = name_of + "-stribeck"
    stated = {**(raw.get("run") or {}), **(run or {})}
    if "store_every" not in stated:  # a curve needs each case's summary, not its field series
        run = {**(run or {}), "store_every": 0}
    plan = plan_sweep(scene_file, {name: values}, run=run, out=out)
    return plan, name


def _base_beta(raw) -> float:
    """The normalized scene's own beta (its [fluid] beta, else the default of its kind)."""
    ind = raw.get("indenter")
    line = isinstance(ind, dict) and ind.get("kind") == "cylinder"
    return float(raw.get("fluid", {}).get("beta", 10.0 if line else 200.0))


def stribeck_curve(plan, table, name: str, raw: dict):
    """One row per speed from a finished sweep's ``table`` (:func:`femehl.studies.sweeps.read_results`).

    Columns: ``speed`` (m/s, or the factor on the scene's speed), ``beta``, ``status``,
    ``t`` (the last state's time), ``load``, ``friction`` (femehl's units),
    ``friction_coefficient`` (``friction / load * sqrt(h_inf/R)``; NaN when the scene does
    not know ``h_inf/R``: a normalized scene without ``[roughness] aspect``),
    ``film_center``, ``film_min``, ``film_over_sigma`` (the central film over the roughness,
    the "lambda ratio"), ``asperity_share``, ``regime`` and ``steady``; for a scene in SI
    units also ``film_center_m``, ``film_min_m`` and ``hersey`` ``= eta U_e R / W`` with
    ``U_e = V_ss/2`` the entrainment speed.
    """
    import pandas as pd

    from femehl.problem.scene import Dimensional

    si = raw.get("si")
    rows = []
    for case in plan.cases:
        value = float(case.params[name])
        part = table[table["case"] == case.key].sort_values("t")
        rough = getattr(case.scene, "roughness", None)
        row = {"speed": value if si is not None else _base_beta(raw) / value}
        row["beta"] = float(case.scene.fluid.beta)
        row["status"] = str(part["status"].iloc[-1]) if len(part) else "missing"
        last = part.iloc[-1] if len(part) else None
        ok = last is not None and row["status"] == "done" and np.isfinite(last["t"])
        for c in ("t", "load", "friction", "film_center", "film_min", "asperity_share"):
            row[c] = float(last[c]) if ok and c in last.index else float("nan")
        if si is not None:
            dim = Dimensional(
                **{k: si[k] for k in ("R", "G", "eta", "h_inf")}, V_ss=value, nu=si.get("nu", 0.5)
            )
            aspect = dim.aspect
        else:
            dim, aspect = None, getattr(rough, "aspect", None)
        load = row["load"]
        row["friction_coefficient"] = (
            row["friction"] / load * aspect if aspect is not None and load > 0 else float("nan")
        )
        sigma = getattr(rough, "sigma", None)
        row["film_over_sigma"] = row["film_center"] / sigma if sigma else float("nan")
        share = row["asperity_share"] if rough is not None else 0.0
        row["asperity_share"] = share
        if not ok or not np.isfinite(share):
            row["regime"] = ""
        elif share >= BOUNDARY_SHARE:
            row["regime"] = "boundary"
        elif share <= FULL_FILM_SHARE:
            row["regime"] = "full film"
        else:
            row["regime"] = "mixed"
        row["steady"] = bool(ok and _steady(_history(plan.out / "cases" / case.key, part)))
        if dim is not None:
            row["film_center_m"] = row["film_center"] * dim.height
            row["film_min_m"] = row["film_min"] * dim.height
            W = load * dim.force
            row["hersey"] = dim.eta * (value / 2.0) * dim.R / W if W > 0 else float("nan")
        rows.append(row)
    return pd.DataFrame(rows).sort_values("speed", ignore_index=True)


def _history(folder, part):
    """``(t, friction)`` of every step from the case's ``summary.csv`` (the sweep's table
    has its stored times only, which may be a few), else of ``part``."""
    from femehl.output.table import read_summary

    try:
        table = read_summary(pathlib.Path(folder) / "summary.csv")
        return table["t"], table["friction"]
    except (FemehlError, KeyError):
        return part["t"].to_numpy(float), part["friction"].to_numpy(float)


def _steady(history) -> bool:
    """The friction changed by less than :data:`STEADY_CHANGE` over the last fifth of the run."""
    t, f = (np.asarray(a, dtype=float) for a in history)
    if t.size < 2 or not np.all(np.isfinite(f[-1:])):
        return False
    i = np.flatnonzero(t <= 0.8 * t[-1])
    if i.size == 0:
        return False
    before = f[i[-1]]  # the last state at least a fifth of the run before the end
    return bool(abs(f[-1] - before) <= STEADY_CHANGE * max(abs(f[-1]), 1e-300))


def stribeck(
    scene_file,
    speeds,
    num: int = 26,
    *,
    out=None,
    run=None,
    scheduler=None,
    workers=None,
    memory_limit=None,
    overwrite: bool = False,
    retry_failed: bool = False,
    progress: bool = True,
):
    """Run the Stribeck study of ``scene_file`` and write ``OUT/stribeck.csv`` and ``.png``.

    Parameters
    ----------
    scene_file : path or dict
        A TOML scene (SI or normalized units), or its tables as a dict, whose run reaches
        a steady sliding state: an imposed load and a constant speed after its start
        (``[run] t_end``).
    speeds : (float, float)
        The lowest and highest speed: ``V_ss`` in m/s for an SI scene, else factors on
        the scene's speed.
    num : int, default 26
        The number of speeds, evenly spaced in log.
    out : path, optional
        The output folder (default ``<scene name>-stribeck``).
    run, scheduler, workers, memory_limit, overwrite, retry_failed, progress
        As :func:`femehl.studies.sweeps.sweep`: ``run`` the cases' run options (over the
        scene file's ``[run]``).

    Returns
    -------
    pandas.DataFrame
        :func:`stribeck_curve`'s table; ``attrs["png"]`` and ``attrs["csv"]`` its files.
    """
    from femehl.studies import sweeps as sw

    plan, name = plan_stribeck(scene_file, speeds, num, out, run)
    table = sw.sweep(
        plan=plan,
        scheduler=scheduler,
        workers=workers,
        memory_limit=memory_limit,
        overwrite=overwrite,
        retry_failed=retry_failed,
        progress=progress,
    )
    curve = stribeck_curve(plan, table, name, _raw(scene_file))
    from femehl.output._files import write_atomic

    curve.attrs["csv"] = write_atomic(
        plan.out / "stribeck.csv", lambda tmp: curve.to_csv(tmp, index=False), "write the Stribeck table"
    )
    curve.attrs["png"] = plot_stribeck(curve, plan.out / "stribeck.png", si="V_ss" in name)
    curve.attrs["sweep"] = table.attrs.get("sweep")
    return curve


def plot_stribeck(curve, path, si: bool = True) -> pathlib.Path:
    """The friction coefficient, the film over the roughness and the asperities' share of the
    load against the speed, the regimes shaded; written to ``path`` (atomically)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from femehl.output._files import write_atomic

    c = curve
    x = c["speed"].to_numpy(float)
    fig, axes = plt.subplots(3, 1, figsize=(6.4, 7.6), sharex=True, layout="constrained")
    mu = c["friction_coefficient"].to_numpy(float)
    y0, label0 = (
        (mu, "friction coefficient")
        if np.any(np.isfinite(mu))
        else (c["friction"], "friction (femehl units)")
    )
    panels = (
        (y0, label0, "log"),
        (
            c["film_over_sigma"] if np.any(np.isfinite(c["film_over_sigma"])) else c["film_center"],
            "central film / sigma" if np.any(np.isfinite(c["film_over_sigma"])) else "central film",
            "log",
        ),
        (c["asperity_share"], "asperities' share of the load", "linear"),
    )
    colours = {"boundary": "#f4cccc", "mixed": "#fff2cc", "full film": "#d9ead3"}
    edges = np.sqrt(x[1:] * x[:-1]) if x.size > 1 else np.array([])
    lo = np.r_[x[0] / 1.2 if x.size else 0, edges]
    hi = np.r_[edges, x[-1] * 1.2 if x.size else 1]
    for ax, (y, label, scale) in zip(axes, panels, strict=True):
        for a, b, regime in zip(lo, hi, c["regime"], strict=True):
            if regime in colours:
                ax.axvspan(a, b, color=colours[regime], lw=0)
        y = np.asarray(y, dtype=float)
        steady = c["steady"].to_numpy(bool)
        ax.plot(x, y, "-", color="0.3", lw=1)
        ax.plot(x[steady], y[steady], "o", color="C0", ms=4, label="steady")
        if (~steady).any():
            ax.plot(x[~steady], y[~steady], "x", color="C3", ms=5, label="not steady at t_end")
        ax.set_xscale("log")
        if scale == "log" and np.all(y[np.isfinite(y)] > 0):
            ax.set_yscale("log")
        ax.set_ylabel(label)
    axes[0].legend(loc="best", fontsize=8)
    for regime, colour in colours.items():
        axes[2].axvspan(0, 0, color=colour, label=regime)
    axes[2].legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("V_ss = U_i + U_s [m/s]" if si else "speed / the scene's speed")
    try:
        return write_atomic(path, lambda tmp: fig.savefig(tmp, dpi=120), "write the Stribeck picture")
    finally:
        plt.close(fig)
