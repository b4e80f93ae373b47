"""The fields of one stored time on the whole contact, for pictures and the VTK series.

A half-disk run (the indenter symmetric in y) computes y >= 0 only.  Users want to see
the whole contact, so the series and the maps show the mirrored full disk:
:func:`mirror_half` adds the image (x, -y) of every node off the mirror line y = 0 and
of every cell (vertex order reversed, so the images keep their orientation); nodes *on*
the line are their own images, so the full mesh has no duplicate points and is one
connected mesh in ParaView.  Point fields follow the node map, cell fields are repeated.

:class:`Snapshot` is what a picture needs at one time: points, triangles (quads of the
polar grid split in two), pressure at the points, film thickness at the triangles (FE:
element values) or at the points (FD: nodal values), and where the minimum film is.
It is built from a :class:`~femehl.state.State` (:func:`snapshot`) or read back from a
run folder's series (:func:`read_snapshot`), so ``femehl plot maps RUN --t 2`` draws the
same picture as the run did.
"""

from __future__ import annotations

import logging
import pathlib
from dataclasses import dataclass

import numpy as np

from femehl.errors import OutputError
from femehl.output.mirror import mirror_half
from femehl.output.series import cavitated_nodes, field_value, scan_series

logger = logging.getLogger("femehl")

__all__ = ["Snapshot", "damaged_files", "mirror_half", "read_snapshot", "snapshot", "stored_times"]


@dataclass(frozen=True)
class Snapshot:
    """Fields of one time on the whole contact (normalized units)."""

    t: float
    points: np.ndarray  # (n, 2)
    triangles: np.ndarray  # (m, 3)
    pressure: np.ndarray  # (n,) at the points
    film: np.ndarray  # (m,) at the triangles, or (n,) at the points
    film_on_points: bool
    film_min: float
    film_min_at: tuple[float, float]
    mirrored: bool
    L: float
    cavitated: np.ndarray | None = None  # (n,) 1 where p is held at 0 (a cavitation condition)
    clipped: bool = False  # half-Sommerfeld: the cavitated nodes are those whose p < 0 was clipped

    @property
    def film_at_points(self) -> np.ndarray:
        """The film at the points (FE element values averaged to their nodes)."""
        if self.film_on_points:
            return self.film
        s = np.zeros(self.points.shape[0])
        c = np.zeros(self.points.shape[0])
        np.add.at(s, self.triangles.ravel(), np.repeat(self.film, 3))
        np.add.at(c, self.triangles.ravel(), 1.0)
        return s / np.maximum(c, 1.0)


def _triangles(cells):
    """Triangles of the 2-D cells (quads split along a diagonal); the cell of each triangle."""
    tris, owner, at = [], [], 0
    for kind, c in cells:
        c = np.asarray(c, dtype=np.int64)
        if kind == "triangle":
            tris.append(c)
            owner.append(at + np.arange(c.shape[0]))
        elif kind == "quad":
            tris += [c[:, [0, 1, 2]], c[:, [0, 2, 3]]]
            owner += [at + np.arange(c.shape[0])] * 2
        else:
            raise OutputError(
                f"maps and the centreline need a 2-D mesh (triangles or quads), this run has "
                f"{kind!r} cells: a line-contact run has no maps; see its line.png (p and d "
                "along x, the cavitated interval shaded) and history.png."
            )
        at += c.shape[0]
    return np.vstack(tris), np.concatenate(owner)


def _degenerate(tris, pts):
    """Triangles of zero area (a quad at the polar grid's centre collapses to one)."""
    a, b, c = (pts[tris[:, k]] for k in range(3))
    return np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])) <= 0


def _build(
    t,
    points,
    cells,
    pressure,
    film,
    on_points,
    mirrored,
    L,
    film_min=None,
    film_min_at=None,
    cav=None,
    clipped=False,
):
    tris, owner = _triangles(cells)
    pts = np.asarray(points, dtype=float)[:, :2]
    keep = ~_degenerate(tris, pts)
    tris, owner = tris[keep], owner[keep]
    film = np.asarray(film, dtype=float)
    film = film if on_points else film[owner]
    if film_min is None:  # the smallest stored film value and where it is
        k = int(np.argmin(film))
        where = pts[k] if on_points else pts[tris[k]].mean(axis=0)
        film_min, film_min_at = float(film[k]), (float(where[0]), float(where[1]))
    return Snapshot(
        float(t),
        pts,
        tris,
        np.asarray(pressure, dtype=float),
        film,
        bool(on_points),
        float(film_min),
        (float(film_min_at[0]), float(film_min_at[1])),
        bool(mirrored),
        float(L),
        None if cav is None else np.asarray(cav, dtype=float),
        bool(clipped),
    )


def snapshot(disc, state) -> Snapshot:
    """The :class:`Snapshot` of ``state`` (full disk: a half-disk run is mirrored)."""
    points, cells, on_points = disc.vtk_geometry()
    p, d = np.asarray(state.p, dtype=float), np.asarray(state.d, dtype=float)
    cav = cavitated_nodes(disc, state)
    half = bool(getattr(disc, "half", False))
    if half:
        points, full_cells, source = mirror_half(points, cells)
        p = p[source]
        d = d[source] if on_points else np.concatenate([d, d])
        cav = None if cav is None else cav[source]
        cells = full_cells
    L = float(np.max(np.hypot(points[:, 0], points[:, 1])))
    fmin, at = state.film_min, tuple(state.film_min_at)
    from femehl.problem.cavitation import clips_pressure

    clipped = clips_pressure(getattr(disc, "scene", None))
    return _build(state.t, points, cells, p, d, on_points, half, L, fmin, at, cav, clipped)


# ---- reading a run folder ----------------------------------------------------------------
def stored_times(folder) -> list[tuple[float, pathlib.Path]]:
    """``(t, path)`` of the complete field files of a run folder, by time."""
    folder = pathlib.Path(folder)
    return sorted((t, folder / name) for _, name, t in scan_series(folder) if t is not None)


def check_run_folder(folder) -> pathlib.Path:
    """``folder`` as a Path if it is a directory holding a femehl run (summary.csv)."""
    folder = pathlib.Path(folder)
    if not folder.is_dir():
        raise OutputError(
            f"{folder} is not a folder: give the output folder of a femehl run (--out of femehl run)."
        )
    if not (folder / "summary.csv").is_file():
        raise OutputError(
            f"{folder} holds no femehl run (no summary.csv): give the folder femehl run wrote "
            "(default runs/<scene name>)."
        )
    return folder


def damaged_files(folder) -> list[str]:
    """The names of the field files of a run folder that are incomplete or of unknown time
    (a run stopped while writing one, a truncated copy): they are never drawn."""
    return [name for _, name, t in scan_series(folder) if t is None]


def read_snapshot(
    folder, t: float | None = None, summary: dict | None = None, *, what: str = "fields", report: bool = True
) -> Snapshot:
    """The stored fields of a run folder at the stored time nearest ``t`` (default: the last).

    An adaptive run stores at the times its steps reach (1.9555, 2.0339, ...): ``t`` need
    not be one of them; the nearest is drawn and, with ``report``, the logger ``"femehl"``
    says which (``maps at t = 2.0339 (nearest stored to 2)``).  A damaged field file (an
    incomplete ``.vtu``) is never drawn: the last readable time is, and the warning names
    the damaged file.  ``what`` names the picture in those reports.

    Raises :class:`~femehl.errors.OutputError` if the folder has no readable field
    series, ``t`` is outside the stored range (the message gives the range), or the
    file to draw cannot be read.  ``summary``: the folder's ``summary.csv`` columns if
    already read (an animation reads them once).
    """
    import meshio

    from femehl.output.table import read_summary

    folder = check_run_folder(folder)
    files = stored_times(folder)
    damaged = damaged_files(folder)
    if not files:
        if damaged:
            raise OutputError(
                f"{folder} has no readable field file: {', '.join(damaged)} "
                f"{'is' if len(damaged) == 1 else 'are'} damaged (incomplete); rerun the case "
                "(femehl run --overwrite) to write the fields again."
            )
        raise OutputError(
            f"{folder} has no field series (fields_*.vtu): the run stored no fields "
            "(store_every = 0); rerun with --store-every N."
        )
    ts = np.array([f[0] for f in files])
    if t is None:
        k = ts.size - 1
    else:
        try:
            t = float(t)
        except (TypeError, ValueError):
            raise OutputError(f"t must be a number, got {t!r}.") from None
        eps = 1e-9 * max(1.0, abs(t)) if np.isfinite(t) else 0.0
        if not np.isfinite(t) or t < ts[0] - eps or t > ts[-1] + eps:
            raise OutputError(
                f"no stored fields at t = {t:g} in {folder}: the series holds "
                f"{ts.size} time(s) from {ts[0]:g} to {ts[-1]:g}; give --t in that range "
                "(the nearest stored time is drawn)."
            )
        k = int(np.argmin(np.abs(ts - t)))
        if report and abs(ts[k] - t) > eps:
            logger.info("femehl: %s at t = %.5g (nearest stored to %g)", what, ts[k], t)
    if report and damaged:
        number = {name: n for n, name, _ in scan_series(folder)}
        later = [d for d in damaged if number[d] > number[files[k][1].name]]
        if later:  # a damaged file after the one drawn: it may have been the time asked for
            logger.warning(
                "femehl: %s damaged (incomplete: a run stopped while writing it, or a truncated "
                "copy) and not drawn; %s at t = %.5g from %s, the %s readable stored time",
                ", ".join(later) + (" is" if len(later) == 1 else " are"),
                what,
                ts[k],
                files[k][1].name,
                "last" if k == ts.size - 1 else "nearest",
            )
    try:
        mesh = meshio.read(files[k][1])
    except (Exception, SystemExit) as exc:  # noqa: BLE001 - meshio raises many kinds, and exits on some
        raise OutputError(
            f"cannot read {files[k][1]} ({type(exc).__name__}: {exc}); the file is damaged: draw "
            "another stored time (--t), or rerun the case (femehl run --overwrite)."
        ) from None
    cells = [(c.type, c.data) for c in mesh.cells]
    if "pressure" not in mesh.point_data:
        raise OutputError(f"{files[k][1]} has no pressure field: it was not written by femehl.")
    on_points = "film" in mesh.point_data
    if not on_points and "film" not in mesh.cell_data:
        raise OutputError(f"{files[k][1]} has no film field: it was not written by femehl.")
    film = mesh.point_data["film"] if on_points else np.concatenate(mesh.cell_data["film"])
    mirrored = _mirrored(files[k][1])
    L = float(np.max(np.hypot(mesh.points[:, 0], mesh.points[:, 1])))
    fmin = None
    where = None
    rows = read_summary(folder / "summary.csv") if summary is None else summary
    has = all(c in rows for c in ("t", "film_min", "film_min_x", "film_min_y"))
    if has and rows["t"].size:  # the true minimum film (nodes and origin included) from the table
        j = int(np.argmin(np.abs(rows["t"] - ts[k])))
        if abs(rows["t"][j] - ts[k]) <= 1e-9 * max(1.0, abs(ts[k])):
            fmin, where = rows["film_min"][j], (rows["film_min_x"][j], rows["film_min_y"][j])
    cav = mesh.point_data.get("cavitated")
    clipped = bool(field_value(files[k][1], "HalfSommerfeldClipped") or 0)
    p = mesh.point_data["pressure"]
    return _build(ts[k], mesh.points, cells, p, film, on_points, mirrored, L, fmin, where, cav, clipped)


def _mirrored(path) -> bool:
    v = field_value(path, "MirroredHalfDisk")
    return bool(v) if v is not None else False
