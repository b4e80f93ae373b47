"""femehl.auto.solve_to_tolerance on a few scenes at tol = 1e-2: cost, estimated and true error.

True errors are against benchmarks/auto_reference.json (benchmarks/auto_reference.py);
scenes without a reference show "n/a".  Writes benchmarks/auto_results.md.

Run:  OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/auto.py [scene ...]
"""

from __future__ import annotations

import json
import os
import pathlib
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).parents[1]))

import femehl  # noqa: E402
from femehl import Ellipsoid, Motion, RampHold, Scene, TanhStart  # noqa: E402
from femehl.auto import QUANTITIES, solve_to_tolerance  # noqa: E402

HERE = pathlib.Path(__file__).parent
T_END, TOL = 1.5, 1e-2


def scenes() -> dict:
    """The benchmark scenes (the first two have a reference)."""
    ell = Motion(gap=RampHold(0.1, -0.5, 1.0), velocity=TanhStart(1.0, 1.0))
    return {
        "sphere": femehl.presets.paper_sphere(),
        "ellipsoid": Scene(indenter=Ellipsoid(0.5, 2.0), motion=ell),
        "ellipsoid_rotated": Scene(indenter=Ellipsoid(2.0, 0.5), motion=ell),
        "sphere_beta20": femehl.presets.paper_sphere(beta=20.0),
    }


def true_error(res, ref, q) -> tuple[float, float]:
    """Largest relative error of ``q`` against the reference over the steps t > 0, and the
    fraction of those steps where the estimated total is >= half the true error."""
    qr = np.interp(res.t[1:], ref["t"], ref[q])
    scale = np.maximum(np.abs(qr), 0.1 if q == "load" else 0.0)
    true = np.abs(getattr(res, q)[1:] - qr) / scale
    return float(np.max(true)), float(np.mean(res.estimate[q]["total"][1:] >= 0.5 * true))


def row(name, scene, refs) -> str:
    t0 = time.perf_counter()
    res = solve_to_tolerance(scene, t_end=T_END, tol=TOL, store_every=0, max_elements=13_000)
    wall = time.perf_counter() - t0
    a = res.info["auto"]
    cells = []
    for q in QUANTITIES:
        est = float(np.max(res.estimate[q]["total"])) if res.estimate else float("nan")
        tru = "n/a"
        if name in refs and res.estimate:
            err, share = true_error(res, refs[name], q)
            tru = f"{err:.2%} ({share:.0%})"
        cells.append(f"{est:.2%} / {tru}")
    runs = " | ".join("/".join(map(str, a[k])) for k in ("elements", "steps", "rejected_steps"))
    line = f"| {name} | {a['reached']} | {wall:.0f} | {runs} | " + " | ".join(cells) + " |"
    print(line, flush=True)
    return line


def machine() -> str:
    model = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    model = next((s.split(":", 1)[1].strip() for s in model.splitlines() if s.startswith("Model name")), "?")
    return f"nproc = {os.cpu_count()}, {model}, OMP/OPENBLAS threads = {os.environ.get('OMP_NUM_THREADS')}"


def main(names) -> None:
    refs = json.loads((HERE / "auto_reference.json").read_text())
    head = [
        f"# solve_to_tolerance at tol = {TOL:g}, t_end = {T_END:g}",
        "",
        f"Machine: {machine()} (shared with another job: wall times are loaded).",
        "Columns per quantity: max over t of the estimated total / true relative error (in",
        "parentheses: the share of steps where the estimate is >= half the true error).",
        "elements, steps, rejected: per level run (coarse to fine).",
        "",
        "| scene | reached | wall s | elements | steps | rejected | load | film_center | film_min |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    print("\n".join(head), flush=True)
    lines = [row(n, scenes()[n], refs) for n in names]
    (HERE / "auto_results.md").write_text("\n".join(head + lines) + "\n")


if __name__ == "__main__":
    main(sys.argv[1:] or list(scenes()))
