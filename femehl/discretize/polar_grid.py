"""The paper's uniform polar grid on [0, pi] x [0, L] (Eq. 14) and its polar cells.

Node (i, j) sits at theta_i = i dtheta (i = 0 .. m-1, theta_{m-1} = pi) and
r_j = j dr (j = 0 .. n-1, r_{n-1} = L); arrays are shaped (m, n).  The
half plane y >= 0 is computed; y < 0 is its mirror image (Eq. 17b).

Each node carries a uniform pressure on its polar cell
[theta_i -+ dtheta/2] x [r_j -+ dr/2], clipped to [0, pi] x [0, L]; the cell
is the straight-edged quadrilateral BCDE of the paper's Fig. 4 (a triangle
at r = 0), so the cells tile the polygonal disk exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import RegularGridInterpolator

from femehl.errors import SceneError
from femehl.problem.scene import check_positive

__all__ = ["PolarGrid"]


@dataclass(frozen=True)
class PolarGrid:
    """Uniform (theta, r) grid of the half disk of radius ``L``."""

    L: float
    dr: float
    dtheta: float

    def __post_init__(self):
        check_positive("dr", self.dr, "Use e.g. dr = 0.05 (coarse) or 0.01 (the paper).")
        check_positive("dtheta", self.dtheta, "Use e.g. dtheta = pi/30; pi/dtheta must be an integer.")
        nr = self.L / self.dr
        nt = math.pi / self.dtheta
        if abs(nr - round(nr)) > 1e-6 * nr or round(nr) < 4:
            raise SceneError(
                f"L/dr = {nr:.6g} must be an integer >= 4: pick dr = L/n, "
                f"e.g. {self.L / max(4, round(nr)):g}."
            )
        if abs(nt - round(nt)) > 1e-6 * nt or round(nt) < 2:
            raise SceneError(
                f"pi/dtheta = {nt:.6g} must be an integer >= 2: pick dtheta = pi/n, "
                f"e.g. pi/{max(2, round(nt))}."
            )

    @property
    def m(self) -> int:
        return int(round(math.pi / self.dtheta)) + 1

    @property
    def n(self) -> int:
        return int(round(self.L / self.dr)) + 1

    @property
    def theta(self) -> np.ndarray:
        return np.linspace(0.0, math.pi, self.m)

    @property
    def r(self) -> np.ndarray:
        return np.linspace(0.0, self.L, self.n)

    def mesh(self):
        """``(TH, RR)`` arrays of shape (m, n)."""
        return np.meshgrid(self.theta, self.r, indexing="ij")

    def xy(self) -> np.ndarray:
        """Node coordinates, shape (m*n, 2), C order over (i, j)."""
        th, rr = self.mesh()
        return np.column_stack([(rr * np.cos(th)).ravel(), (rr * np.sin(th)).ravel()])

    def cells(self) -> np.ndarray:
        """Vertices B, C, D, E of every node's polar cell, shape (m*n, 4, 2)."""
        th, rr = self.mesh()
        t_lo = np.clip(th - self.dtheta / 2, 0.0, math.pi)
        t_hi = np.clip(th + self.dtheta / 2, 0.0, math.pi)
        r_lo = np.clip(rr - self.dr / 2, 0.0, self.L)
        r_hi = np.clip(rr + self.dr / 2, 0.0, self.L)
        corners = [(r_lo, t_lo), (r_hi, t_lo), (r_hi, t_hi), (r_lo, t_hi)]
        q = np.stack(
            [np.stack([(r * np.cos(t)).ravel(), (r * np.sin(t)).ravel()], -1) for r, t in corners], axis=1
        )
        return q

    def cell_areas(self) -> np.ndarray:
        """Areas of the polar cells (shoelace of BCDE), shape (m, n)."""
        q = self.cells()
        x, y = q[..., 0], q[..., 1]
        a = 0.5 * np.abs(np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1))
        return a.reshape(self.m, self.n)

    # ---- interpolation of node fields ------------------------------------
    def _interp(self, field, points, outside=0.0):
        f = np.asarray(field, dtype=float).reshape(self.m, self.n)
        pts = np.asarray(points, dtype=float)
        r = np.hypot(pts[:, 0], pts[:, 1])
        th = np.abs(np.arctan2(pts[:, 1], pts[:, 0]))
        inside = r <= self.L * (1 + 1e-12)
        out = np.full(pts.shape[0], outside, dtype=float)
        if np.any(inside):
            it = RegularGridInterpolator((self.theta, self.r), f, method="linear")
            out[inside] = it(np.column_stack([th[inside], np.minimum(r[inside], self.L)]))
        return out

    def pressure_at(self, p, points):
        return self._interp(p, points, 0.0)

    def film_at(self, d, points):
        return self._interp(d, points, np.nan)

    def deflection_at(self, w, points):
        return self._interp(w, points, np.nan)

    def vtk_geometry(self):
        """Points (z = 0), quad cells of the grid, and True: FD fields live on nodes."""
        m, n = self.m, self.n
        pts = np.column_stack([self.xy(), np.zeros(m * n)])
        I, J = np.meshgrid(np.arange(m - 1), np.arange(n - 1), indexing="ij")
        a = (I * n + J).ravel()
        quads = np.column_stack([a, a + 1, a + n + 1, a + n]).astype(np.int64)
        return pts, [("quad", quads)], True

    def centreline(self):
        """Node indices and x of the line y = 0 from x = -L to L: (idx, x)."""
        m, n = self.m, self.n
        left = [(m - 1) * n + j for j in range(n - 1, 0, -1)]  # theta = pi, x < 0
        right = [j for j in range(n)]  # theta = 0, x >= 0
        idx = np.array(left + right)
        x = np.concatenate([-self.r[n - 1 : 0 : -1], self.r])
        return idx, x
