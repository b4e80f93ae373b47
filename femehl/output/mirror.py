"""The mirrored full disk of a half-disk mesh (the series and the pictures show the whole contact).

A half-disk run (the indenter symmetric in y) computes y >= 0 only.  :func:`mirror_half`
adds the image (x, -y) of every node off the mirror line y = 0 and of every cell (vertex
order reversed, so the images keep their orientation); nodes *on* the line are their own
images.  Used by :mod:`femehl.output.series` (the VTK files) and
:mod:`femehl.output.snapshot` (the pictures); it imports neither.
"""

from __future__ import annotations

import numpy as np

__all__ = ["mirror_half"]

#: nodes with |y| below this fraction of the mesh size are on the mirror line
_ON_LINE = 1e-9


def mirror_half(points, cells):
    """The full disk of a half-disk mesh: ``(points, cells, source)``.

    Parameters
    ----------
    points : (n, 3) array
        Nodes of the half disk (y >= 0).
    cells : list of (cell type, (m, k) int array)
        Its cells.

    Returns
    -------
    points : (n + n_off, 3) array
        The nodes, then the images of the nodes off the line y = 0.
    cells : list of (cell type, (2 m, k) int array)
        The cells, then their images (vertex order reversed).
    source : (n + n_off,) int array
        For each full-disk node, the half-disk node whose values it carries.
    """
    points = np.asarray(points, dtype=float)
    n = points.shape[0]
    scale = float(np.max(np.abs(points[:, :2]))) if n else 1.0
    off = np.flatnonzero(points[:, 1] > _ON_LINE * max(scale, 1e-300))
    image = np.arange(n)
    image[off] = n + np.arange(off.size)
    flipped = points[off].copy()
    flipped[:, 1] *= -1.0
    out_cells = [(kind, np.vstack([c, image[c][:, ::-1]])) for kind, c in cells]
    return np.vstack([points, flipped]), out_cells, np.concatenate([np.arange(n), off])
