"""Field time series a user opens in ParaView or pyvista: one .vtu per stored step + a .pvd index.

Written as the run goes: every stored state adds its .vtu and rewrites the
small .pvd index (atomically), so an interrupted run leaves a readable
series.  Pressure is point data; film thickness ``d``, deflection ``w`` and
rigid gap ``h = d + w`` are point data on the FD grid (its unknowns live on
nodes) and cell data on FE meshes (they live on elements).  Coordinates are
normalized; z = 0.  A half-disk run is written as computed (y >= 0); use
ParaView's Reflect filter (plane Y) to see the whole contact.
"""

from __future__ import annotations

import os
import pathlib
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

__all__ = ["SeriesWriter", "grid_cells"]


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
    """

    def __init__(self, folder, disc, stem: str = "fields"):
        self.folder = pathlib.Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.disc = disc
        self.stem = stem
        self.points, self.cells, self.on_nodes = grid_cells(disc)
        self.entries: list[tuple[float, str]] = []

    @property
    def pvd_path(self) -> pathlib.Path:
        return self.folder / f"{self.stem}.pvd"

    def write(self, state) -> pathlib.Path:
        name = f"{self.stem}_{len(self.entries):06d}.vtu"
        h = state.d + state.w
        if self.on_nodes:
            point_data = {"pressure": state.p, "film": state.d, "deflection": state.w, "gap": h}
            cell_data = {}
        else:
            point_data = {"pressure": state.p}
            cell_data = {"film": [state.d], "deflection": [state.w], "gap": [h]}
        mesh = meshio.Mesh(self.points, self.cells, point_data=point_data, cell_data=cell_data,
                           field_data={"TimeValue": np.array([state.t])})
        path = self.folder / name
        meshio.write(path, mesh, file_format="vtu", binary=True)
        self.entries.append((state.t, name))
        self._write_index()
        return path

    def _write_index(self):
        lines = ['<?xml version="1.0"?>',
                 '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
                 "  <Collection>"]
        for t, name in self.entries:
            lines.append(f'    <DataSet timestep="{t:.12g}" group="" part="0" file={quoteattr(name)}/>')
        lines += ["  </Collection>", "</VTKFile>", ""]
        tmp = self.pvd_path.with_suffix(".pvd.tmp")
        tmp.write_text("\n".join(lines))
        os.replace(tmp, self.pvd_path)
