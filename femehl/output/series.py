"""Field time series a user opens in ParaView or pyvista: one .vtu per stored step + a .pvd index.

Written as the run goes: every stored state adds its .vtu and rewrites the
small .pvd index (atomically), so an interrupted run leaves a readable
series.  Pressure is point data (with ``cavitated``, 1 where the pressure is held at 0
or, half-Sommerfeld, was clipped, for a run with a cavitation condition; a half-Sommerfeld
run's files carry the field data ``HalfSommerfeldClipped = 1`` and, as an XML comment, how
to read them: :attr:`femehl.problem.cavitation.HalfSommerfeld.note`);
film thickness ``d``, deflection ``w`` and
rigid gap ``h = d + w`` are point data on the FD grid (its unknowns live on
nodes) and cell data on FE meshes (they live on elements).  Coordinates are
normalized; z = 0.  A half-disk run (computed on y >= 0) is written as the
mirrored full disk (:func:`femehl.output.mirror.mirror_half`: the nodes on
y = 0 are shared, not duplicated), so ParaView shows the whole contact; the
field data ``MirroredHalfDisk = 1`` says so (``mirror=False`` writes the half
disk as computed, ``MirroredHalfDisk = 0``).

Each .vtu is written atomically (temporary file + rename) and carries its time
as ``TimeValue`` field data, so the index can be rebuilt from the files alone
(:func:`scan_series`) if the .pvd is damaged or missing.  Files are numbered
on from ``next_index``: a writer never reuses the name of a file present.
"""

from __future__ import annotations

import os
import pathlib
import re
import xml.etree.ElementTree as ET
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from femehl.output.mirror import mirror_half

__all__ = ["SeriesWriter", "field_value", "grid_cells", "read_index", "scan_series", "vtu_time"]


def grid_cells(disc):
    """(points (n, 3), [(cell type, connectivity)], fields-on-nodes flag) of a discretization.

    Each discretization describes its own geometry (``disc.vtk_geometry()``).
    """
    return disc.vtk_geometry()


class SeriesWriter:
    """Write States of one discretization to ``folder/fields_NNNNNN.vtu`` + ``fields.pvd``.

    Parameters
    ----------
    folder : path-like
        Output folder (created).
    disc : FEDisc or PolarGrid
        The discretization the states live on.
    stem : str, default: "fields"
    mirror : bool, default: True
        Write a half-disk run as the mirrored full disk.
    """

    def __init__(self, folder, disc, stem: str = "fields", mirror: bool = True):
        self.folder = pathlib.Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.disc = disc
        self.stem = stem
        self.points, self.cells, self.on_nodes = grid_cells(disc)
        self.mirrored = bool(mirror) and bool(getattr(disc, "half", False))
        self._source = None
        if self.mirrored:
            self.points, self.cells, self._source = mirror_half(self.points, self.cells)
        from femehl.problem.cavitation import cavitation_model

        self.cavitation = cavitation_model(getattr(getattr(disc, "scene", None), "cavitation", None))
        self.roughness = getattr(getattr(disc, "scene", None), "roughness", None)
        self.entries: list[tuple[float, str]] = []
        self.next_index = 0  # number of the next file (never one present)

    @property
    def pvd_path(self) -> pathlib.Path:
        return self.folder / f"{self.stem}.pvd"

    def write(self, state) -> pathlib.Path:
        name = f"{self.stem}_{self.next_index:06d}.vtu"
        p, d, w = (np.asarray(a, dtype=float) for a in (state.p, state.d, state.w))
        if self.mirrored:
            p = p[self._source]
            d, w = (a[self._source] if self.on_nodes else np.concatenate([a, a]) for a in (d, w))
        h = d + w
        if self.on_nodes:
            point_data = {"pressure": p, "film": d, "deflection": w, "gap": h}
            cell_data = {}
        else:
            point_data = {"pressure": p}
            cell_data = {"film": [d], "deflection": [w], "gap": [h]}
        cav = cavitated_nodes(self.disc, state)
        if cav is not None:  # a run with a cavitation condition: 1 where p is held at 0
            point_data["cavitated"] = cav[self._source] if self.mirrored else cav
        if self.cavitation is not None:  # the condition's own nodal fields (JFO: gas, theta)
            for k, v in self.cavitation.point_fields(self.disc, state).items():
                point_data[k] = v[self._source] if self.mirrored else v
        if self.roughness is not None:  # the asperities' share of the pressure
            for k, v in self.roughness.point_fields(self.disc, state).items():
                point_data[k] = v[self._source] if self.mirrored else v
        mesh = meshio.Mesh(
            self.points,
            self.cells,
            point_data=point_data,
            cell_data=cell_data,
            field_data={"TimeValue": np.array([state.t])},
        )
        path = self.folder / name
        tmp = path.with_name(path.name + ".tmp")
        meshio.write(tmp, mesh, file_format="vtu", binary=True)
        fields = {"TimeValue": float(state.t), "MirroredHalfDisk": int(self.mirrored)}
        note = None
        if self.cavitation is not None:
            fields.update(self.cavitation.field_data)
            note = self.cavitation.note
        _add_field_data(tmp, fields, note)
        os.replace(tmp, path)
        self.next_index += 1
        self.entries.append((state.t, name))
        self._write_index()
        return path

    def _write_index(self):
        lines = [
            '<?xml version="1.0"?>',
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
            "  <Collection>",
        ]
        for t, name in self.entries:
            lines.append(f'    <DataSet timestep="{t:.12g}" group="" part="0" file={quoteattr(name)}/>')
        lines += ["  </Collection>", "</VTKFile>", ""]
        tmp = self.pvd_path.with_suffix(".pvd.tmp")
        tmp.write_text("\n".join(lines))
        os.replace(tmp, self.pvd_path)


_GRID_TAG = b"<UnstructuredGrid>"
_TIME_RE = re.compile(rb'Name="TimeValue"[^>]*>\s*([^<\s]+)\s*<')


def cavitated_nodes(disc, state):
    """1.0 at the cavitated nodes of ``state`` (``y < 0``: held at p = 0 with a multiplier
    that keeps them there, or negative and joining the set at the next step; half-Sommerfeld:
    the nodes whose full-Sommerfeld pressure was clipped), 0.0 elsewhere; None for a
    full-Sommerfeld run (no complementarity variable)."""
    y = state.own.get("p_aux")
    if y is None:
        return None
    return disc.expand((np.asarray(y) < 0.0).astype(float))


def _add_field_data(path: pathlib.Path, values: dict, note: str | None = None) -> None:
    """Put scalar field data (``TimeValue`` ...) in a .vtu (meshio's writer leaves it out),
    and ``note`` as an XML comment before it (how to read the fields, e.g. half-Sommerfeld;
    a String array would be unreadable to meshio)."""
    data = path.read_bytes()
    arrays = b"".join(
        (
            f'<DataArray type="{"Int32" if isinstance(v, int) else "Float64"}" Name="{k}" '
            f'NumberOfTuples="1" format="ascii">{v!r}</DataArray>\n'
        ).encode()
        for k, v in values.items()
    )
    comment = b"" if not note else f"\n<!-- {note.replace('--', '-')} -->".encode()
    block = comment + b"\n<FieldData>\n" + arrays + b"</FieldData>"
    i = data.find(_GRID_TAG)
    if i >= 0:
        i += len(_GRID_TAG)
        path.write_bytes(data[:i] + block + data[i:])


def _read_ends(path: pathlib.Path):
    try:
        with open(path, "rb") as fh:
            head = fh.read(4096)
            fh.seek(max(0, path.stat().st_size - 64))
            return head, fh.read()
    except OSError:
        return b"", b""


def vtu_time(path) -> float | None:
    """The ``TimeValue`` of a .vtu written here; None if absent or the file is not complete."""
    head, tail = _read_ends(pathlib.Path(path))
    m = _TIME_RE.search(head)
    if m is None or not tail.rstrip().endswith(b"</VTKFile>"):
        return None
    try:
        return float(m.group(1))
    except ValueError:
        return None


def field_value(path, name: str) -> float | None:
    """A scalar field-data value (e.g. ``MirroredHalfDisk``) of a .vtu written here, or None."""
    head, _ = _read_ends(pathlib.Path(path))
    m = re.search(rb'Name="' + re.escape(name.encode()) + rb'"[^>]*>\s*([^<\s]+)\s*<', head)
    if m is None:
        return None
    try:
        return float(m.group(1))
    except ValueError:
        return None


def _complete(path: pathlib.Path) -> bool:
    head, tail = _read_ends(path)
    return head.startswith(b"<?xml") and tail.rstrip().endswith(b"</VTKFile>")


def read_index(folder, stem: str = "fields") -> dict:
    """``{file name: time}`` of the .pvd index; empty if it is missing or damaged."""
    pvd = pathlib.Path(folder) / f"{stem}.pvd"
    try:
        root = ET.parse(pvd).getroot()
    except (ET.ParseError, OSError):
        return {}
    out = {}
    for ds in root.iter("DataSet"):
        try:
            t = float(ds.get("timestep"))
        except (TypeError, ValueError):
            continue
        if ds.get("file"):
            out[ds.get("file")] = t
    return out


def scan_series(folder, stem: str = "fields") -> list[tuple[int, str, float | None]]:
    """The ``stem_NNNNNN.vtu`` files present as ``(number, name, time)``, by number.

    The time is the file's own ``TimeValue``, else (a complete file without one) the
    time the .pvd index gives it, else None: a damaged file or one of unknown time.
    """
    folder = pathlib.Path(folder)
    pattern = re.compile(rf"{re.escape(stem)}_(\d+)\.vtu$")
    index = read_index(folder, stem)
    out = []
    for path in folder.glob(f"{stem}_*.vtu"):
        m = pattern.match(path.name)
        if m is None or not path.is_file():
            continue
        t = vtu_time(path)
        if t is None and _complete(path):  # written before files carried their time
            t = index.get(path.name)
        out.append((int(m.group(1)), path.name, t))
    return sorted(out)
