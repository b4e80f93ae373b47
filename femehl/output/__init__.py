"""Writers that consume States or a finished Result: CSV, VTK series, PNGs.

Nothing here steps a solver.  :class:`RunWriter` is the callback a run
hands each State to, so files appear while the run goes; :func:`write_all`
writes the same from a finished :class:`~femehl.output.result.Result`.
:mod:`femehl.output.folder` decides whether a folder may be written (it
refuses one that holds another run unless asked to overwrite or resume), and
:mod:`femehl.output._validation` checks run and command-line options first.
"""

from __future__ import annotations

import pathlib

from femehl.output.folder import check_folder, prepare_folder
from femehl.output.plots import (
    animation_file,
    centreline_png,
    draw_figures,
    history_png,
    line_png,
    maps_png,
    profile_times,
    result_table,
)
from femehl.output.series import SeriesWriter
from femehl.output.snapshot import Snapshot, read_snapshot, snapshot
from femehl.output.table import COLUMNS, SummaryWriter, add_error_columns, columns_for, write_summary

__all__ = [
    "COLUMNS",
    "Snapshot",
    "animation_file",
    "history_png",
    "maps_png",
    "RunWriter",
    "SeriesWriter",
    "SummaryWriter",
    "centreline_png",
    "draw_figures",
    "line_png",
    "check_folder",
    "prepare_folder",
    "profile_times",
    "result_table",
    "read_snapshot",
    "snapshot",
    "write_all",
    "write_summary",
]


class RunWriter:
    """Callback writing each State as it comes: summary row always, fields every ``every`` steps.

    Parameters
    ----------
    folder : path-like
    disc : discretization of the run (``stepper.disc``)
    every : int, default: 10
        Write the field series every ``every`` steps (0: never).
    summary, series : SummaryWriter, SeriesWriter, optional
        Writers to use instead of new ones (a resumed run appends to its files).
    """

    def __init__(self, folder, disc, every: int = 10, *, summary=None, series=None):
        self.folder = pathlib.Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        if summary is None:
            columns = columns_for(getattr(disc, "scene", None), disc)
            summary = SummaryWriter(self.folder / "summary.csv", columns=columns)
        self.summary = summary
        if series is None and every:
            series = SeriesWriter(self.folder, disc)
        self.series = series
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


def write_all(result, folder, *, overwrite: bool = False) -> pathlib.Path:
    """Summary CSV, the PNGs (centreline, maps, history) and VTK series of a finished Result.

    The folder is checked first (:func:`~femehl.output.folder.check_folder`): a path that
    is a file or not writable, or a folder holding another run, is refused with
    :class:`~femehl.errors.OutputError`; ``overwrite=True`` replaces that run's files.
    """
    folder = check_folder(folder, overwrite=overwrite)
    prepare_folder(folder, overwrite=overwrite)
    write_summary(result, folder / "summary.csv")
    if getattr(result, "estimate", None) is not None:
        add_error_columns(folder / "summary.csv", result.estimate)
    series = SeriesWriter(folder, result.disc)
    for s in result.states:
        series.write(s)
    if result.states:
        draw_figures(result, folder)
    return folder
