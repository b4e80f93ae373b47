"""Writers that consume States or a finished Result: CSV, VTK series, PNGs.

Nothing here steps a solver.  :class:`RunWriter` is the callback a run
hands each State to, so files appear while the run goes; :func:`write_all`
writes the same from a finished :class:`~femehl.result.Result`.
"""

from __future__ import annotations

import pathlib

from .plots import centreline_png, profile_times, quicklook_png
from .series import SeriesWriter
from .table import COLUMNS, SummaryWriter, write_summary

__all__ = ["RunWriter", "write_all", "SeriesWriter", "SummaryWriter", "centreline_png",
           "quicklook_png", "write_summary", "COLUMNS", "profile_times"]


class RunWriter:
    """Callback writing each State as it comes: summary row always, fields every ``every`` steps.

    Parameters
    ----------
    folder : path-like
    disc : discretization of the run (``stepper.disc``)
    every : int, default: 10
        Write the field series every ``every`` steps (0: never).
    """

    def __init__(self, folder, disc, every: int = 10):
        self.folder = pathlib.Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.summary = SummaryWriter(self.folder / "summary.csv")
        self.series = SeriesWriter(self.folder, disc) if every else None
        self.every = every
        self.last = None

    def __call__(self, state):
        self.summary.write(state)
        if self.series is not None and state.step % self.every == 0:
            self.series.write(state)
        self.last = state

    def close(self):
        """Write the last state's fields (if not written) and close the CSV."""
        if self.series is not None and self.last is not None and self.last.step % self.every:
            self.series.write(self.last)
        self.summary.close()


def write_all(result, folder) -> pathlib.Path:
    """Summary CSV, centreline PNG, quick-look PNG and VTK series of a finished Result."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    write_summary(result, folder / "summary.csv")
    series = SeriesWriter(folder, result.disc)
    for s in result.states:
        series.write(s)
    if result.states:
        centreline_png(result, folder / "centreline.png")
        quicklook_png(result, folder / "fields.png")
    return folder
