"""How well the time budget predicts a run: :func:`femehl.accuracy.auto.predicted_wall` replayed.

Every automatic sequence recorded in ``auto_runs.jsonl`` (``benchmarks/auto.py``) and
``stress_auto.jsonl`` (``benchmarks/stress_auto.py``) keeps the level, cells, steps and wall
time of each of its runs.  For each run after the first, ``predicted_wall`` is given the
runs before it (as the automatic mode has them when it decides) and the run's actual
cells (the automatic mode has the ladder's estimate; this separates the cost model from
the cell count); the table gives predicted / actual wall time.  No run is made.  Above
1 the budget stops early (a run that would have fitted is not started); below 1 a run
overruns its prediction (a run in memory is abandoned at the deadline, a candidate in a
run folder finishes late).  Writes ``time_budget.md`` here.

Run::

    python benchmarks/time_budget.py
"""

from __future__ import annotations

import json
import pathlib

import numpy as np
from _machine import header

from femehl.accuracy.auto import COST_EXPONENT, COST_EXPONENT_RANGE, predicted_wall

HERE = pathlib.Path(__file__).resolve().parent
SOURCES = ("auto_runs.jsonl", "stress_auto.jsonl")
#: runs at least this long are the ones a budget is about
LONG_S = 20.0


class _Run:
    def __init__(self, level, elements, steps, wall):
        self.info = {"level": level, "elements": elements, "wall": wall}
        self.nsteps = steps


def replay() -> list[dict]:
    """One row per run after the first of every recorded sequence."""
    rows = []
    for name in SOURCES:
        for line in (HERE / name).read_text().splitlines():
            rec = json.loads(line)
            a = rec.get("auto") or {}
            if rec.get("kind", "auto") != "auto" or "wall" not in a or "steps" not in a:
                continue
            runs = []
            table = zip(a["levels"], a["elements"], a["steps"], a["wall"], strict=True)
            for level, cells, steps, wall in table:
                if runs:
                    guess = predicted_wall(runs, cells, level)
                    rows.append(dict(source=name, cells=cells, wall=wall, ratio=guess / wall))
                runs.append(_Run(level, cells, steps, wall))
    return rows


def _stats(r: np.ndarray) -> str:
    return f"{np.median(r):.2f} | {r.min():.2f} | {r.max():.2f} | {int((r < 1).sum())} of {r.size}"


def main() -> None:
    rows = replay()
    lines = [
        "# The time budget's prediction of a run, replayed",
        "",
        header("time_budget.py"),
        "",
        "`femehl.accuracy.auto.predicted_wall` (cost exponent fitted on the last two runs within "
        f"{COST_EXPONENT_RANGE}, {COST_EXPONENT} after one run) against the recorded wall times "
        f"of the automatic sequences in {', '.join(SOURCES)}: predicted / actual, per run after "
        "the first.  No run is made here; "
        "the wall times are those recorded (shared 2-core machine).",
        "",
        "| runs | count | median | min | max | under 1 |",
        "|---|---|---|---|---|---|",
    ]
    ratio = np.array([r["ratio"] for r in rows])
    walls = np.array([r["wall"] for r in rows])
    for label, keep in (("all", np.ones_like(ratio, bool)), (f"longer than {LONG_S:g} s", walls > LONG_S)):
        lines.append(f"| {label} | {int(keep.sum())} | {_stats(ratio[keep])} |")
    under = sorted((r for r in rows if r["wall"] > LONG_S and r["ratio"] < 1), key=lambda r: r["ratio"])
    lines += [
        "",
        "The largest ratios are the pilots right after the first run, whose wall time includes "
        "the imports and the first compilations; the smallest are mostly the runs near the "
        "switch from the dense to the fast operator (at 8,000 cells: its set-up); over 20 s and "
        "under 1: " + ", ".join(f"{r['cells']} cells {r['ratio']:.2f}" for r in under) + ".",
    ]
    text = "\n".join(lines) + "\n"
    (HERE / "time_budget.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
