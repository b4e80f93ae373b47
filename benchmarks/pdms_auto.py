"""The automatic mode on the rough PDMS ball at one speed: what a run without ``[run]`` costs.

``examples/pdms_ball.toml`` without its ``[run]`` table (the default path: femehl chooses
the meshes and steps) at 0.01 m/s to t = 8, tol 5e-2, as ``femehl run`` runs it.  One record
per call is appended to ``pdms_auto.jsonl`` (the runs' cells, steps, walls, estimates, the
Krylov iterations and preconditioner factorizations of the last run, peak memory, and the
commit, or ``--label`` naming the femehl imported when it is not this checkout's, e.g. an
older one on PYTHONPATH); ``pdms_auto.md`` is the table of all records.

Run::

    python benchmarks/pdms_auto.py [--label TEXT] [--tol 0.05]
"""

from __future__ import annotations

import argparse
import json
import pathlib
import resource
import sys
import time

import tomllib

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _machine import header, load_average, provenance  # noqa: E402

SCENE = HERE.parent / "examples" / "pdms_ball.toml"
T_END = 8.0
RECORDS = HERE / "pdms_auto.jsonl"


def run(tol: float, label: str | None) -> dict:
    import femehl
    from femehl.problem.scenefile import scene_from_mapping

    raw = tomllib.loads(SCENE.read_text())
    raw.pop("run", None)  # the default path
    scene, _ = scene_from_mapping(raw, SCENE)
    last = {}
    t0 = time.perf_counter()
    result = femehl.solve(scene, t_end=T_END, tol=tol, store_every=0, on_run=lambda r: last.update(r.info))
    wall = time.perf_counter() - t0
    auto = result.info["auto"]
    record = {
        **provenance(),
        "label": label,
        "femehl": str(pathlib.Path(femehl.__file__).parent),
        "tol": tol,
        "reached": auto["reached"],
        "estimate": auto["total"],
        "cells": auto["elements"],
        "steps": auto["steps"],
        "run_walls": [round(w, 1) for w in auto["wall"]],
        "estimate_walls": [round(w, 1) for w in auto["estimate_wall"]],
        "krylov_iterations": last.get("krylov_iterations"),
        "factorizations": last.get("factorizations"),
        "wall": round(wall, 1),
        "peak_mib": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024),
        "load_average": round(load_average(), 2),
    }
    with RECORDS.open("a") as f:
        f.write(json.dumps(record) + "\n")
    return record


def table() -> str:
    records = [json.loads(line) for line in RECORDS.read_text().splitlines() if line.strip()]
    rows = [
        "| date | commit | tol | reached, estimate | cells | steps | run walls s "
        "| Krylov its / LUs (last run) | wall s | peak MiB | load |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in records:
        who = r["label"] if r.get("label") else r.get("commit", "?")
        rows.append(
            f"| {r['date']} | {who} | {r['tol']:g} | {r['reached']}, {100 * r['estimate']:.2f} % "
            f"| {' / '.join(map(str, r['cells']))} | {' / '.join(map(str, r['steps']))} "
            f"| {' / '.join(map(str, r['run_walls']))} | {r['krylov_iterations']} / {r['factorizations']} "
            f"| {r['wall']} | {r['peak_mib']} | {r['load_average']} |"
        )
    return "\n".join(
        [
            "# The automatic mode on the rough PDMS ball (`benchmarks/pdms_auto.py`)",
            "",
            header("pdms_auto.py"),
            "",
            f"`examples/pdms_ball.toml` without `[run]`, 0.01 m/s, to t = {T_END:g}: the default path. "
            "Runs labelled as made side by side ran at the same time, one per core (their ratio "
            "holds, their absolute times are of a loaded machine).",
            "",
            *rows,
            "",
        ]
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tol", type=float, default=5e-2)
    ap.add_argument("--label", default=None, help="what to call this run in the table")
    ap.add_argument("--table", action="store_true", help="only rewrite pdms_auto.md from the records")
    args = ap.parse_args(argv)
    if not args.table:
        print(json.dumps(run(args.tol, args.label)))
    (HERE / "pdms_auto.md").write_text(table())


if __name__ == "__main__":
    main()
