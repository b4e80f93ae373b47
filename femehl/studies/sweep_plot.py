"""Master curves of a sweep: headline quantities against a swept parameter, fitted
exponents, and the classical predictions beside them (``femehl sweep plot OUT``).

For each case the last stored time is taken (a sweep of steady sliding: the steady
state).  The cases are grouped by the other swept parameters (one curve each); on log
axes the central and minimum film and the load are drawn against ``x``, a power law
``q ~ x^n`` is fitted by least squares in log space over all finished cases of a
curve and over its upper half of ``x`` (the asymptotic end), and where ``x`` is the
film parameter beta the predictions of :mod:`femehl.reference.theory` are overlaid: the
Hamrock-Dowson isoviscous-elastic formulas for point contacts evaluated at each case's
own load and ellipticity (their stated accuracy as a band), and the Hertz load.  The
steady state of the normalized problem depends on beta and the sliding speed only
through beta / V, so the predictions use the case's ``beta / V`` at its last time.

The figure is ``OUT/master_curves.png``; the fitted exponents and the predicted ones
are also written to ``OUT/master_curves.md``.
"""

from __future__ import annotations

import json
import pathlib

import numpy as np

from femehl.errors import OutputError

__all__ = ["fit_power", "plot_master_curves", "steady_table"]

QUANTITIES = (("film_min", "minimum film"), ("film_center", "central film"), ("load", "load F"))


def fit_power(x, y) -> tuple[float, float]:
    """``(n, c)`` of the least-squares fit ``log y = n log x + log c`` (positive values only)."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    ok = (x > 0) & (y > 0) & np.isfinite(x) & np.isfinite(y)
    if np.count_nonzero(ok) < 2:
        return float("nan"), float("nan")
    n, logc = np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)
    return float(n), float(np.exp(logc))


def steady_table(out):
    """One row per finished case: its last stored time, parameters and scene description."""
    from femehl.studies.sweeps import read_results

    out = pathlib.Path(out)
    df = read_results(out)
    missing = sorted({"case", "status", "t", *(q for q, _ in QUANTITIES)} - set(df.columns))
    if missing:
        raise OutputError(
            f"{out}/results.parquet has no column(s) {', '.join(missing)}: it is damaged or not a "
            "femehl sweep's table; rerun the sweep (femehl sweep SWEEP.toml) to rewrite it from the cases."
        )
    done = df[(df["status"] == "done") & np.isfinite(df["t"])]
    last = done.sort_values("t").groupby("case", sort=False).tail(1).copy()
    scenes = {}
    for key in last["case"]:
        try:
            scenes[key] = json.loads((out / "cases" / key / "case.json").read_text()).get("scene", {})
        except (OSError, ValueError):
            scenes[key] = {}
    last["scene"] = last["case"].map(scenes)
    return last, df


def _swept(out) -> list[str]:
    try:
        spec = json.loads((pathlib.Path(out) / "sweep.json").read_text())
    except (OSError, ValueError):
        raise OutputError(f"{out} has no readable sweep.json: is it a sweep's output folder?") from None
    return list(spec.get("names", []))


def _numeric(col) -> bool:
    import pandas as pd

    return pd.api.types.is_numeric_dtype(col)


def plot_master_curves(out, x: str | None = None):
    """Draw ``OUT/master_curves.png`` (and ``.md``); returns ``(png path, printed lines)``."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from femehl.output.plots import _save

    out = pathlib.Path(out)
    if not out.is_dir():
        raise OutputError(
            f"{out} is not a folder: give the output folder of a sweep (its [sweep] out, or --out)."
        )
    last, df = steady_table(out)
    names = _swept(out)
    numeric = [n for n in names if n in last and _numeric(last[n])]
    if x is None:
        if not numeric:
            raise OutputError(f"{out}: no swept numeric parameter to put on the x axis; give --x NAME.")
        x = numeric[0]
    if x not in names:
        raise OutputError(f"--x {x!r} is not a swept parameter of {out}: choose one of {names}.")
    if x not in numeric:
        raise OutputError(
            f"--x {x!r} is not a number in every case (the x axis is logarithmic): choose one of "
            f"{numeric or 'the numeric swept parameters (there are none)'}."
        )
    if last.empty:
        raise OutputError(f"{out}: no finished case to plot (see the status column of results.parquet).")
    others = [n for n in names if n != x]
    groups = list(last.groupby(others, sort=True, dropna=False)) if others else [((), last)]
    varying = [n for n in others if last[n].nunique(dropna=False) > 1]  # name only these
    fig, axs = plt.subplots(1, 3, figsize=(15, 4.8))
    lines, rows = [], []
    for gi, (gkey, g) in enumerate(groups):
        g = g.sort_values(x)
        label = _label(others, gkey, varying)
        color = f"C{gi % 10}"
        xs = g[x].to_numpy(dtype=float)
        for ax, (q, qname) in zip(axs, QUANTITIES, strict=True):
            ys = g[q].to_numpy(dtype=float)
            e = _error(g, q)
            ax.plot(xs, ys, "o-", color=color, ms=4, label=label or "femehl")
            if np.any(np.isfinite(e)):
                ax.errorbar(xs, ys, yerr=np.where(np.isfinite(e), e * ys, 0), fmt="none", color=color, lw=0.8)
            n_all, _ = fit_power(xs, ys)
            upper = xs >= np.median(xs)
            n_up, _ = fit_power(xs[upper], ys[upper])
            lines.append(
                f"{qname}{' (' + label + ')' if label else ''}: ~ {x}^{n_all:.3f} over {x} in "
                f"[{xs.min():.4g}, {xs.max():.4g}] ({len(xs)} cases); upper half ^{n_up:.3f}"
            )
            rows.append((label, q, n_all, n_up, len(xs)))
        _overlay(axs, g, x, color, lines, rows, label, first=gi == 0)
    for ax, (_, qname) in zip(axs, QUANTITIES, strict=True):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(x)
        ax.set_ylabel(qname)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    failed = df.drop_duplicates("case")
    failed = int((failed["status"] != "done").sum())
    fig.suptitle(
        f"master curves of {out.name}: steady values (last stored time); {len(last)} cases"
        + (f", {failed} failed (not shown)" if failed else ""),
        fontsize=10,
    )
    png = _save(plt, fig, out / "master_curves.png", dpi=100)
    _write_md(out / "master_curves.md", x, rows, lines)
    return png, lines


def _error(g, q) -> np.ndarray:
    """The estimated relative error of ``q`` per case: the total, else space + time parts."""
    nan = np.full(len(g), np.nan)

    def col(name):
        return np.abs(g[name].to_numpy(dtype=float)) if name in g else nan

    total = col(f"err_{q}")
    parts = np.nansum(np.vstack([col(f"err_{q}_space"), col(f"err_{q}_time")]), axis=0)
    some = np.isfinite(col(f"err_{q}_space")) | np.isfinite(col(f"err_{q}_time"))
    return np.where(np.isfinite(total), total, np.where(some, parts, np.nan))


def _label(others, gkey, varying) -> str:
    if not others:
        return ""
    gkey = gkey if isinstance(gkey, tuple) else (gkey,)
    pairs = [(n, v) for n, v in zip(others, gkey, strict=True) if n in varying]
    return ", ".join(
        _short(v) if isinstance(v, str) and v.startswith("{") else f"{n} = {_short(v)}" for n, v in pairs
    )


def _short(v) -> str:
    if isinstance(v, str) and v.startswith("{"):
        try:
            d = json.loads(v)
        except ValueError:
            return v
        head = [str(d.pop("kind"))] if "kind" in d else []
        return " ".join(head + [f"{k}={d[k]:g}" if isinstance(d[k], float) else f"{k}={d[k]}" for k in d])
    return f"{v:g}" if isinstance(v, float) else str(v)


def _overlay(axs, g, x, color, lines, rows, label, first=True):
    """The classical predictions where ``x`` is beta (:mod:`femehl.reference.theory`).

    Hamrock-Dowson at each case's own steady load, ``beta / V`` and ellipticity, dashed
    at ``eps = h_inf / R =`` :data:`femehl.reference.theory.DEFAULT_EPS` with the band over
    :data:`femehl.reference.theory.EPS_RANGE` (the formulas are not exactly scale-free in femehl's
    variables); the similarity-theory slope ``beta^-3/5`` through the largest-beta
    central film; the Hertz load at the case's indentation ``-hc``.
    """
    if x != "fluid.beta":
        return
    from femehl.reference import theory

    radii = [_radii(s) for s in g["scene"]]
    if any(r is None for r in radii):
        return
    Rx = np.array([r[0] for r in radii])
    Ry = np.array([r[1] for r in radii])
    xs = g[x].to_numpy(dtype=float)
    V = np.abs(g["V"].to_numpy(dtype=float))
    if not np.all(V > 0):
        lines.append("  no classical predictions: not every case slides at its last stored time")
        return
    beta_eff = xs / V
    load = g["load"].to_numpy(dtype=float)
    tag = f" ({label})" if label else ""
    for ax, which in ((axs[0], "minimum"), (axs[1], "central")):
        pred = theory.hd_film(beta_eff, load, which, Rx=Rx, Ry=Ry)
        lo, hi = theory.hd_film_band(beta_eff, load, which, Rx=Rx, Ry=Ry)
        ax.plot(
            xs, pred, "--", color=color, lw=1, label=f"Hamrock-Dowson {which} (dashed)" if first else None
        )
        ax.fill_between(xs, lo, hi, color=color, alpha=0.12, lw=0)
        n, _ = fit_power(xs, pred)
        lines.append(f"  Hamrock-Dowson {which} film at these loads{tag}: ~ {x}^{n:.3f}")
        rows.append((label, f"Hamrock-Dowson {which}", n, float("nan"), len(xs)))
    ref = theory.scaling_exponents().get("sev2013_film_speed")
    if ref is not None:  # a slope to compare with, through the largest-beta central film
        k = int(np.argmax(xs))
        yc = g["film_center"].to_numpy(dtype=float)[k]
        span = np.array([xs.min(), xs.max()])
        n = ref["exponent"]
        axs[1].plot(
            span,
            yc * (span / xs[k]) ** n,
            ":",
            color=color,
            lw=1,
            label=f"similarity slope beta^{n:g} (dotted)" if first else None,
        )
        lines.append(f"  similarity theory (Snoeijer, Eggers & Venner 2013): film ~ {x}^{n:g}")
    delta = -g["hc"].to_numpy(dtype=float)
    if np.all(delta > 0):
        dry = [theory.hertz_load(d, a, b) for d, a, b in zip(delta, Rx, Ry, strict=True)]
        axs[2].plot(xs, dry, "--", color=color, lw=1, label="Hertz, dry (dashed)" if first else None)


def _radii(scene: dict):
    ind = (scene or {}).get("indenter", {})
    kind = ind.get("type")
    if kind == "Sphere":
        return float(ind["R"]), float(ind["R"])
    if kind == "Ellipsoid":
        return float(ind["Rx"]), float(ind["Ry"])
    return None


def _write_md(path, x, rows, lines):
    out = [
        f"# Master curves: fitted power laws against {x}",
        "",
        "| curve | quantity | exponent (all cases) | exponent (upper half) | cases |",
        "|---|---|---|---|---|",
    ]
    for label, q, n_all, n_up, k in rows:
        up = "" if not np.isfinite(n_up) else f"{n_up:.3f}"
        out.append(f"| {label or '-'} | {q} | {n_all:.3f} | {up} | {k} |")
    out += ["", "```", *lines, "```", ""]
    from femehl.output._files import write_atomic

    text = "\n".join(out)
    write_atomic(path, lambda tmp: tmp.write_text(text), "write the fitted exponents")
