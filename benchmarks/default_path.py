"""The default path's cost, paired against an older source tree: the README's main job
(``femehl run``, run folder and pictures included) and the automatic solve at tol = 1e-2 of
benchmark scenes (``auto_scenes.py``; the paper case, ``femehl.solve(paper, t_end=5,
tol=1e-2)``, is issue 42's "at most 15 s"), no output, each a whole process, the two trees
in turn pair by pair.  Writes ``default_path.md`` and appends the records to
``default_path.jsonl``.

    python benchmarks/default_path.py --before SRC [--pairs 3] [--scenes paper,punch]

``SRC``: an older checkout's source tree (``git worktree add DIR REV``, or ``git archive REV
femehl | tar x -C DIR``), run with ``PYTHONPATH=SRC``; the current tree is this checkout's.
Each solve also reports where its time went (elastic operator, LUs, Krylov solves,
companions) from ``res.info``.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import first_run
from _machine import HERE, header, provenance

ROOT = HERE.parent
JSONL = HERE / "default_path.jsonl"
BLAS_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "FEMEHL_BLAS_THREADS")

SOLVE = r"""
import json, resource, sys, time
sys.path.insert(0, sys.argv[2])
from auto_scenes import SCENES
import femehl
factory, t_end = SCENES[sys.argv[1]]
scene = factory()
t0 = time.perf_counter()
res = femehl.solve(scene, t_end=t_end, tol=1e-2, store_every=0)
wall = time.perf_counter() - t0
i, a = res.info, res.info["auto"]
keys = ("elastic_build_s", "factorizations", "factor_s", "krylov_iterations", "krylov_s", "operator_storage")
print(json.dumps({
    "wall_s": wall, "runs_s": a["wall"], "companions_s": a["estimate_wall"], "cells": a["elements"],
    "steps": a["steps"], "estimate": a["total"], "film_min_end": float(res.film_min[-1]),
    "peak_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, **{k: i.get(k) for k in keys},
}))
"""


def _env(src: str) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in BLAS_VARS and k != "PYTHONPATH"}
    env.update(PYTHONPATH=src, MPLBACKEND="Agg")
    return env


def run_cli(src: str) -> float:
    """The README's ``femehl run`` (a fresh folder), its whole-process wall time."""
    return first_run.run({}, src)


def run_solve(src: str, scene: str = "paper") -> dict:
    """A benchmark scene's automatic solve in a fresh process: its figures and whole wall time."""
    t0 = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-c", SOLVE, scene, str(HERE)],
        cwd=tempfile.gettempdir(),
        env=_env(src),
        check=True,
        capture_output=True,
    )
    rec = json.loads(done.stdout.decode().strip().splitlines()[-1])
    rec.update(scene=scene, process_s=time.perf_counter() - t0)
    return rec


def _row(label: str, r: dict) -> str:
    comp = sum(r["companions_s"])
    return (
        f"| {label} | {r['wall_s']:.1f} | {' / '.join(f'{w:.1f}' for w in r['runs_s'])} | {comp:.1f} | "
        f"{r['elastic_build_s']:.1f} | {r['factorizations']} / {r['factor_s']:.1f} | "
        f"{r['krylov_iterations']} / {r['krylov_s']:.1f} | {r.get('operator_storage') or '-'} | "
        f"{' / '.join(map(str, r['steps']))} | {100 * r['estimate']:.2f} % | {r['peak_mib']:.0f} |"
    )


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--before", required=True, help="an older source tree (PYTHONPATH)")
    p.add_argument("--pairs", type=int, default=3)
    p.add_argument("--scenes", default="paper", help="comma-separated scenes of auto_scenes.py")
    args = p.parse_args(argv)
    scenes = args.scenes.split(",")
    now, before = str(ROOT), str(pathlib.Path(args.before).resolve())
    run_cli(now), run_cli(before)  # compile both trees' numba caches first: not timed
    cli, solves = [], []
    for i in range(args.pairs):
        cli.append((run_cli(now), run_cli(before)))
        for name in scenes:
            solves.append((run_solve(now, name), run_solve(before, name)))
            a, b = solves[-1]
            print(f"pair {i + 1}: {name} {a['wall_s']:.1f} / {b['wall_s']:.1f} s", flush=True)
        print(f"pair {i + 1}: femehl run {cli[-1][0]:.1f} / {cli[-1][1]:.1f} s", flush=True)
    with open(JSONL, "a") as fh:
        for c, cb in cli:
            fh.write(json.dumps({**provenance(), "before": before, "cli": [c, cb]}) + "\n")
        for a, b in solves:
            fh.write(json.dumps({**provenance(), "before": before, "solve": [a, b]}) + "\n")
    med = statistics.median
    by_scene = {n: [(a["wall_s"], b["wall_s"]) for a, b in solves if a["scene"] == n] for n in scenes}
    lines = [
        "# The default path, paired against an older tree",
        "",
        header("default_path.py") + f" Before: `{os.path.basename(before)}`.",
        "",
        "Whole processes, the current tree and the older one in turn (a pair each). `femehl run`: the "
        "README's main job with its run folder and pictures. Solve: `femehl.solve(scene, t_end, "
        "tol=1e-2, store_every=0)` of a scene of `auto_scenes.py`, its wall time from inside (the paper "
        "case: issue 42's target, at most 15 s).",
        "",
        "| pair | femehl run now (s) | before (s) | ratio |",
        "| --- | --- | --- | --- |",
        *(f"| {i + 1} | {c:.1f} | {cb:.1f} | {c / cb:.3f} |" for i, (c, cb) in enumerate(cli)),
        "",
        "| scene | pairs: solve now / before (s) | median ratio | median now / before (s) |",
        "| --- | --- | --- | --- |",
        *(
            f"| {n} | {', '.join(f'{a:.1f} / {b:.1f}' for a, b in w)} | {med(a / b for a, b in w):.3f} | "
            f"{med(a for a, _ in w):.1f} / {med(b for _, b in w):.1f} |"
            for n, w in by_scene.items()
        ),
        "",
        f"Median ratio of femehl run {med(c / cb for c, cb in cli):.3f} (median {med(c for c, _ in cli):.1f} "
        f"against {med(cb for _, cb in cli):.1f} s).",
        "",
        "Where each solve's time went (the last run's elastic operator, LUs and Krylov solves; the "
        "companions of both runs):",
        "",
        "| scene, pair | wall (s) | runs (s) | companions (s) | operator (s) | LUs / s "
        "| Krylov iterations / s | C stored | steps | estimate | peak MiB |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
        *(
            row
            for i, (a, b) in enumerate(solves)
            for row in (
                _row(f"{a['scene']} {i // len(scenes) + 1}, now", a),
                _row(f"{a['scene']} {i // len(scenes) + 1}, before", b),
            )
        ),
        "",
    ]
    (HERE / "default_path.md").write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
