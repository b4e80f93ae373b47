"""The README's main job as written against the same job with one BLAS thread forced from
outside (``OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1``), in turn, pair by
pair, each as a whole process: femehl limits BLAS itself (docs/design.md section 16), so the
ratio should be about 1 (target <= 1.25).  Writes ``first_run.md``.

    python benchmarks/first_run.py [--pairs 3] [--before SRC --before-pairs 1]

``--before SRC``: also pair an older checkout's source tree (``git archive REV femehl | tar x``
into SRC, run with ``PYTHONPATH=SRC``), e.g. the commit before femehl limited its threads.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

from _machine import HERE, header

ONE = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
BLAS_VARS = (*ONE, "OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE", "FEMEHL_BLAS_THREADS")


def run(env_extra: dict, src: str | None = None) -> float:
    env = {k: v for k, v in os.environ.items() if k not in BLAS_VARS and k != "PYTHONPATH"}
    env.update(env_extra, MPLBACKEND="Agg")
    if src is not None:
        env["PYTHONPATH"] = src
    out = pathlib.Path(tempfile.mkdtemp(prefix="femehl-first-run-"))
    t0 = time.perf_counter()
    subprocess.run(  # from the scratch folder: a checkout in the working directory would shadow SRC
        [sys.executable, "-m", "femehl.cli", "run", "--quiet", "--out", str(out / "run")],
        cwd=out,
        env=env,
        check=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    wall = time.perf_counter() - t0
    shutil.rmtree(out, ignore_errors=True)
    return wall


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--pairs", type=int, default=3)
    p.add_argument("--before", help="an older source tree to pair too (PYTHONPATH)")
    p.add_argument("--before-pairs", type=int, default=1)
    args = p.parse_args(argv)
    rows, before = [], []
    for i in range(args.pairs):
        a = run({})
        b = run(ONE)
        rows.append((a, b))
        print(f"pair {i + 1}: as written {a:.1f} s, one BLAS thread forced {b:.1f} s, ratio {a / b:.3f}")
    for i in range(args.before_pairs if args.before else 0):
        a, b = run({}, args.before), run(ONE, args.before)
        before.append((a, b))
        print(
            f"before, pair {i + 1}: as written {a:.1f} s, one BLAS thread forced {b:.1f} s, ratio {a / b:.3f}"
        )
    ratios = [a / b for a, b in rows]
    lines = [
        "# The README's main job (`femehl run`), as written and with one BLAS thread forced",
        "",
        header("first_run.py"),
        "",
        "| pair | as written (s) | one BLAS thread forced (s) | ratio |",
        "| --- | --- | --- | --- |",
        *(f"| {i + 1} | {a:.1f} | {b:.1f} | {a / b:.3f} |" for i, (a, b) in enumerate(rows)),
        *(
            f"| before ({os.path.basename(args.before)}), {i + 1} | {a:.1f} | {b:.1f} | {a / b:.3f} |"
            for i, (a, b) in enumerate(before)
        ),
        "",
        f"Median ratio {statistics.median(ratios):.3f} (target <= 1.25); median wall as written "
        f"{statistics.median(a for a, _ in rows):.1f} s. The environment's OPENBLAS_CORETYPE / "
        "OPENBLAS_L2_SIZE are removed from both, as on a fresh machine.",
        "",
    ]
    (HERE / "first_run.md").write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
