"""The summary CSV: one row per step, written and flushed as the run goes."""

from __future__ import annotations

import csv
import pathlib

__all__ = ["COLUMNS", "SummaryWriter"]

COLUMNS = (
    "t",
    "hc",
    "V",
    "load",
    "film_center",
    "film_min",
    "film_min_x",
    "film_min_y",
    "p_max",
    "p_max_x",
    "p_max_y",
)


def _row(state):
    return (
        state.t,
        state.hc,
        state.V,
        state.load,
        state.film_center,
        state.film_min,
        state.film_min_at[0],
        state.film_min_at[1],
        state.p_max,
        state.p_max_at[0],
        state.p_max_at[1],
    )


class SummaryWriter:
    """Write one CSV row per State (normalized units) to ``path``, flushed at once; header first.

    ``append=True`` continues an existing file (the header is written only to a new or
    empty one).
    """

    def __init__(self, path, append: bool = False):
        self.path = pathlib.Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        new = not append or not self.path.is_file() or self.path.stat().st_size == 0
        self._fh = open(self.path, "a" if append else "w", newline="")  # noqa: SIM115 - kept open
        self._csv = csv.writer(self._fh)
        if new:
            self._csv.writerow(COLUMNS)
        self._fh.flush()

    def write(self, state):
        self._csv.writerow([f"{v:.10g}" for v in _row(state)])
        self._fh.flush()

    def close(self):
        if not self._fh.closed:
            self._fh.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def write_summary(result, path):
    """Write a finished Result's per-step table (same columns) to ``path``."""
    s = result.summary()
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(COLUMNS)
        for i in range(len(s["t"])):
            w.writerow([f"{s[c][i]:.10g}" for c in COLUMNS])
    return path
