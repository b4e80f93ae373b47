"""Benchmark: how far the lagged pressure-viscosity stays stable and accurate.

``python benchmarks/viscosity.py`` runs the paper case (sphere, beta = 200, h0 = 0.1, to
t = 5: indentation, start-up, steady sliding) on the medium mesh with BDF2 and a Barus
viscosity ``exp(alpha p)`` for increasing ``alpha`` (``alpha p_max`` from 0 to about 16),
at dt = 0.01 and at dt = 0.0025 (the reference: four times smaller steps).  The
viscosity ratio is lagged one step, ``r(p^k)``, so its error is the difference between the
two runs; a run that fails is recorded with its error.  Writes ``viscosity.md`` and
``viscosity.jsonl`` next to this file.

Per row: ``alpha p_max`` at t = 5 and its largest value, the central and minimum film at
t = 5 (dt = 0.01) and their largest relative difference to the reference from t = 0.5 on, the
difference of the isoviscous run for scale, and the wall time against the isoviscous run
at the same dt.  Threads pinned to one.
"""

from __future__ import annotations

import dataclasses
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np  # noqa: E402
from _machine import header  # noqa: E402

HERE = Path(__file__).resolve().parent
ALPHAS = [0.0, 2.5, 5.0, 10.0, 20.0, 40.0, 80.0]
DTS = (0.01, 0.0025)


def run(alpha, dt, model="barus"):
    import femehl

    sc = femehl.presets.paper_sphere()
    visc = None if alpha is None else femehl.Barus(alpha)
    sc = dataclasses.replace(sc, fluid=femehl.Fluid(sc.fluid.beta, viscosity=visc))
    t0 = time.perf_counter()
    try:
        res = femehl.solve(sc, t_end=5.0, dt=dt, mesh="medium", scheme="bdf2", estimate=False, store_every=0)
    except femehl.errors.SolverError as exc:
        return {
            "alpha": alpha,
            "dt": dt,
            "error": f"{type(exc).__name__}: {exc}",
            "wall_s": time.perf_counter() - t0,
        }
    return {
        "alpha": alpha,
        "dt": dt,
        "wall_s": time.perf_counter() - t0,
        "t": res.t.tolist(),
        "film_center": res.film_center.tolist(),
        "film_min": res.film_min.tolist(),
        "p_max": res.p_max.tolist(),
        "load": res.load.tolist(),
    }


#: errors are taken from this time on (the contact formed; the load starts from 0)
T_FROM = 0.5


def _diff(a, b, q):
    """Largest relative difference of q over the coarse run's steps from T_FROM on."""
    ta, tb = np.asarray(a["t"]), np.asarray(b["t"])
    va, vb = np.asarray(a[q]), np.interp(ta, tb, np.asarray(b[q]))
    keep = ta >= T_FROM - 1e-12
    return float(np.max(np.abs(va[keep] - vb[keep]) / np.abs(vb[keep])))


def main():
    rows = []
    iso = {dt: run(None, dt) for dt in DTS}
    for alpha in ALPHAS:
        coarse, ref = run(alpha, DTS[0]), run(alpha, DTS[1])
        row = {"alpha": alpha}
        if "error" in coarse or "error" in ref:
            row["error"] = coarse.get("error") or ref.get("error")
            row["failed_dt"] = DTS[0] if "error" in coarse else DTS[1]
        else:
            row.update(
                alpha_p_max=alpha * coarse["p_max"][-1],
                alpha_p_peak=alpha * max(coarse["p_max"]),
                film_center=coarse["film_center"][-1],
                film_min=coarse["film_min"][-1],
                err_center=_diff(coarse, ref, "film_center"),
                err_min=_diff(coarse, ref, "film_min"),
                err_load=_diff(coarse, ref, "load"),
                wall_ratio=coarse["wall_s"] / iso[DTS[0]]["wall_s"],
            )
        rows.append(row)
        print(json.dumps(row), flush=True)
    iso_err = {q: _diff(iso[DTS[0]], iso[DTS[1]], q) for q in ("film_center", "film_min", "load")}
    (HERE / "viscosity.jsonl").write_text("\n".join(json.dumps(r) for r in rows) + "\n")
    write_md(rows, iso_err, iso)


def write_md(rows, iso_err, iso):
    lines = [
        "# Pressure-dependent viscosity: the lagged scheme's range",
        "",
        header("viscosity.py"),
        "",
        "The paper case (sphere, beta = 200, h0 = 0.1, to t = 5) on the medium mesh "
        f"({iso[DTS[0]].get('elements', '2,982')} elements), BDF2, Barus viscosity "
        "exp(alpha p) lagged one step. Error: the largest relative difference over every step "
        f"between dt = {DTS[0]} and dt = {DTS[1]} from t = {T_FROM} on (the time error of "
        "the run, the lag included). Isoviscous for scale: central film "
        f"{iso_err['film_center']:.1e}, minimum film {iso_err['film_min']:.1e}, "
        f"load {iso_err['load']:.1e}.",
        "",
        "| alpha | alpha p_max (t = 5) | largest alpha p_max | central film | minimum film | "
        "time error: central | minimum | load | wall / isoviscous |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if "error" in r:
            lines.append(
                f"| {r['alpha']:g} | failed at dt = {r['failed_dt']}: {r['error'][:160]} | | | | | | |"
            )
            continue
        lines.append(
            f"| {r['alpha']:g} | {r['alpha_p_max']:.2f} | {r['alpha_p_peak']:.2f} | {r['film_center']:.5g} | "
            f"{r['film_min']:.5g} | "
            f"{r['err_center']:.1e} | {r['err_min']:.1e} | {r['err_load']:.1e} | {r['wall_ratio']:.2f} |"
        )
    (HERE / "viscosity.md").write_text("\n".join(lines) + "\n")


def spike(alpha=40.0, meshes=("coarse", "medium", "fine")):
    """``python benchmarks/viscosity.py spike``: the same case at one alpha on three meshes
    (does the peak pressure converge?); writes ``viscosity_spike.md``."""
    import femehl

    sc = femehl.presets.paper_sphere()
    sc = dataclasses.replace(sc, fluid=femehl.Fluid(sc.fluid.beta, viscosity=femehl.Barus(alpha)))
    lines = [
        f"# Barus alpha = {alpha:g}: the peak pressure under mesh refinement",
        "",
        "Generated by `python benchmarks/viscosity.py spike`: the paper case to t = 5, BDF2, "
        "dt = 0.01, on the ladder meshes.",
        "",
        "| mesh | elements | p_max at t = 5 | where (x, y) | alpha p_max | central film | minimum film |",
        "|---|---|---|---|---|---|---|",
    ]
    for mesh in meshes:
        r = femehl.solve(sc, t_end=5.0, dt=0.01, mesh=mesh, scheme="bdf2", estimate=False, store_every=100)
        x, y = r.final.p_max_at
        lines.append(
            f"| {mesh} | {r.disc.nelements} | {r.p_max[-1]:.4g} | ({x:.3f}, {y:.3f}) | "
            f"{alpha * r.p_max[-1]:.3g} | {r.film_center[-1]:.5g} | {r.film_min[-1]:.5g} |"
        )
        print(lines[-1], flush=True)
    (HERE / "viscosity_spike.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    spike() if sys.argv[1:] == ["spike"] else main()
