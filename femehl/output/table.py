"""The summary CSV: one row per step, written and flushed as the run goes.

The columns are :data:`COLUMNS`; a run with a cavitation condition adds the condition's
(:func:`columns_for`: ``cavitated_area`` and, for the Reynolds condition, ``full_film_source``,
for half-Sommerfeld ``load_full``; see :mod:`femehl.problem.cavitation`), read from ``state.info``.
"""

from __future__ import annotations

import csv
import pathlib

__all__ = ["COLUMNS", "ERROR_COLUMNS", "SummaryWriter", "add_error_columns", "columns_for", "read_summary"]

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


def columns_for(scene, disc=None) -> tuple:
    """The summary columns of a run of ``scene`` on ``disc``: :data:`COLUMNS` and
    :func:`extra_columns`."""

    return COLUMNS + extra_columns(scene, disc)


def extra_columns(scene, disc=None) -> tuple:
    """The per-step figures beyond :data:`COLUMNS` a run of ``scene`` on ``disc`` reports:
    its cavitation condition's, the friction force and its parts where ``disc`` has
    pressure gradients (:data:`femehl.solver.energetics.FRICTION_COLUMNS`), then its
    substrate's (``substrate.columns``, e.g. a viscoelastic solid's sliding energy budget)
    and a free indenter's; read from ``state.info``."""
    from femehl.problem.cavitation import cavitation_columns
    from femehl.solver.energetics import FREE_COLUMNS, FRICTION_COLUMNS, SIDE_COLUMNS

    if scene is None:
        return ()
    cols = cavitation_columns(scene)
    if hasattr(disc, "pressure_gradient"):
        cols += FRICTION_COLUMNS + (SIDE_COLUMNS if getattr(disc, "dimension", 1) == 2 else ())
    cols += tuple(getattr(getattr(scene, "roughness", None), "columns", ()))
    cols += tuple(getattr(getattr(scene, "substrate", None), "columns", ()))
    if getattr(getattr(scene, "motion", None), "free", False):  # a free indenter's energy budget
        cols += FREE_COLUMNS
    return tuple(dict.fromkeys(cols))


def _row(state, extra=()):
    info = state.info or {}
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
        *(float(info.get(c, float("nan"))) for c in extra),
    )


class SummaryWriter:
    """Write one CSV row per State (normalized units) to ``path``, flushed at once; header first.

    ``append=True`` continues an existing file (the header is written only to a new or
    empty one).  ``columns``: :data:`COLUMNS` and any of a cavitation condition's
    (:func:`columns_for`), these read from ``state.info``.
    """

    def __init__(self, path, append: bool = False, columns=COLUMNS):
        self.columns = tuple(columns)
        if self.columns[: len(COLUMNS)] != COLUMNS:
            raise ValueError(f"summary columns must start with {COLUMNS}, got {self.columns}")
        self._extra = self.columns[len(COLUMNS) :]
        self.path = pathlib.Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        new = not append or not self.path.is_file() or self.path.stat().st_size == 0
        self._fh = open(self.path, "a" if append else "w", newline="")  # noqa: SIM115 - kept open
        self._csv = csv.writer(self._fh)
        if new:
            self._csv.writerow(self.columns)
        self._fh.flush()

    def write(self, state):
        self._csv.writerow([f"{v:.10g}" for v in _row(state, self._extra)])
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
    columns = COLUMNS + tuple(c for c in s if c not in COLUMNS)
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(columns)
        for i in range(len(s["t"])):
            w.writerow([f"{s[c][i]:.10g}" for c in columns])
    return path


#: the error-estimate columns added at the end of a run that has an estimate: for each
#: headline quantity the estimated relative error (``err_<name>``) and its space and time
#: parts (``err_<name>_space``, ``err_<name>_time``).  Empty where not estimated.
ERROR_QUANTITIES = ("load", "film_center", "film_min")
ERROR_COLUMNS = tuple(c for q in ERROR_QUANTITIES for c in (f"err_{q}", f"err_{q}_space", f"err_{q}_time"))


#: a resumed run's folder keeps the estimate of its earlier part here until its end
EARLIER_ESTIMATE = "summary_estimate_before_resume.csv"


def add_error_columns(path, estimate) -> pathlib.Path:
    """Rewrite the summary CSV at ``path`` with :data:`ERROR_COLUMNS` from ``estimate``.

    ``estimate`` is a Result's (:class:`~femehl.accuracy.estimate.Estimate`); rows
    at times before its span (a resumed run's earlier part) keep the estimate they had
    (:data:`EARLIER_ESTIMATE`, saved when the run was resumed), else get empty cells.
    The new file replaces the old one atomically.
    """
    import numpy as np

    path = pathlib.Path(path)
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    if not rows:
        return path
    header = [c for c in rows[0] if c not in ERROR_COLUMNS]
    keep = [i for i, c in enumerate(rows[0]) if c not in ERROR_COLUMNS]
    ts = np.asarray(estimate.t, dtype=float)
    span = 1e-9 * max(1.0, abs(ts[-1]))

    def cells(t):
        out = []
        for q in ERROR_QUANTITIES:
            for part in ("total", "space", "time"):
                v = estimate[q][part]
                inside = ts[0] - span <= t <= ts[-1] + span
                out.append("" if v is None or not inside else f"{float(np.interp(t, ts, v)):.4g}")
        return out

    before = _earlier_estimate(path)
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header + list(ERROR_COLUMNS))
        for row in rows[1:]:
            t = float(row[0])
            new = cells(t)
            if t <= ts[0] + span and row[0] in before:  # a resumed run: its earlier part's
                new = [before[row[0]].get(c, "") for c in ERROR_COLUMNS]
            w.writerow([row[i] for i in keep] + new)
    tmp.replace(path)
    path.with_name(EARLIER_ESTIMATE).unlink(missing_ok=True)
    return path


def _earlier_estimate(path) -> dict:
    """``{t cell: {column: cell}}`` of the estimate a resumed run's earlier part had."""
    earlier = pathlib.Path(path).with_name(EARLIER_ESTIMATE)
    if not earlier.is_file():
        return {}
    with open(earlier, newline="") as fh:
        rows = list(csv.reader(fh))
    if not rows:
        return {}
    return {r[0]: dict(zip(rows[0][1:], r[1:], strict=False)) for r in rows[1:] if r}


def read_summary(path) -> dict:
    """The columns of a summary CSV as float arrays (empty cells: NaN); ``{}`` columns if empty.

    Raises :class:`~femehl.errors.OutputError` if the file is missing, unreadable, or is
    not a femehl summary (no ``t`` column).
    """
    import numpy as np

    from femehl.errors import OutputError

    path = pathlib.Path(path)
    try:
        with open(path, newline="") as fh:
            rows = list(csv.reader(fh))
    except OSError as exc:
        raise OutputError(f"cannot read {path} ({exc.strerror}): give the folder of a femehl run.") from None
    except (UnicodeDecodeError, csv.Error):
        raise OutputError(f"{path} is not a femehl summary CSV (not text).") from None
    if not rows or rows[0][:1] != ["t"]:
        raise OutputError(f"{path} is not a femehl summary CSV (its first column is not t).")
    header, body = rows[0], [r for r in rows[1:] if len(r) == len(rows[0])]

    def num(cell):
        try:
            return float(cell)
        except ValueError:
            return float("nan")

    cols = {name: np.array([num(r[i]) for r in body], dtype=float) for i, name in enumerate(header)}
    return cols
