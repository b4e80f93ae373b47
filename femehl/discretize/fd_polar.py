"""The paper-faithful polar finite differences (Wu, Hui et al. 2022, section 3).

The Reynolds equation in polar form (Eq. 13) on a uniform (theta, r) grid: forward first
and central second differences, the coefficients lagged one step, Eq. 20 rebuilt from
Eq. 15, the boundary nodes eliminated, the polar cell influence of Eq. 24 with the mirror
half, and the (p, w) system of Eq. 26 solved by a dense LU per step.  The stencil, the
boundary conditions and the measured stability (coarse grids rupture at the exit):
docs/design.md section 5.
"""

from __future__ import annotations

import math
import time

import numpy as np
import scipy.sparse as sp

from femehl.discretize import register_method
from femehl.discretize.polar_grid import PolarGrid
from femehl.elastic.kernels import quad_influence
from femehl.errors import SceneError

__all__ = ["FDDisc"]


def _expansion(grid: PolarGrid):
    """Sparse E (m*n, nfree): full node values from the free interior unknowns."""
    m, n = grid.m, grid.n
    fi = np.arange(1, m - 1)
    fj = np.arange(1, n - 1)
    nfree = fi.size * fj.size
    I, J = np.meshgrid(np.arange(m), np.arange(n), indexing="ij")
    src_i = np.clip(I, 1, m - 2)  # mirror rows theta = 0, pi (Eq. 17b)
    src_j = np.maximum(J, 1)  # centre p_{i,0} = p_{i,1}  (Eq. 17a)
    keep = (J < n - 1).ravel()  # p = 0 on r = L            (Eq. 18a)
    rows = np.arange(m * n)[keep]
    cols = ((src_i - 1) * (n - 2) + (src_j - 1)).ravel()[keep]
    E = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(m * n, nfree))
    interior = ((I > 0) & (I < m - 1) & (J > 0) & (J < n - 1)).ravel()
    return E, np.flatnonzero(interior)


def _forward_diff(grid: PolarGrid, rows):
    """Sparse forward differences d/dr and d/dtheta at node indices ``rows``."""
    n = grid.n
    k = rows.size
    ar = np.arange(k)
    one = np.ones(k)
    Dr = sp.csr_matrix(
        (np.r_[one, -one] / grid.dr, (np.r_[ar, ar], np.r_[rows + 1, rows])), shape=(k, grid.m * n)
    )
    Dt = sp.csr_matrix(
        (np.r_[one, -one] / grid.dtheta, (np.r_[ar, ar], np.r_[rows + n, rows])), shape=(k, grid.m * n)
    )
    return Dr, Dt


@register_method("fd")
class FDDisc:
    """The paper's uniform polar grid of the half disk, with its operators.

    Parameters
    ----------
    scene : femehl.Scene
        Its indenter must be symmetric in y (the grid is the half plane y >= 0).
    dr : float, default: 0.0125
        Radial step (L/dr must be an integer).  The default is the coarsest grid found
        to carry the paper case through its sliding start-up (docs/design.md section 5).
    dtheta : float, default: pi/36
        Azimuthal step (pi/dtheta must be an integer).
    """

    dimension = 2
    #: the grid is the half disk y >= 0 (outputs mirror it)
    half = True
    default_linear_solver = "lu"

    def __init__(self, scene, dr: float = 0.0125, dtheta: float = math.pi / 36):
        t0 = time.perf_counter()
        if not getattr(scene.indenter, "symmetric_y", False):
            raise SceneError(
                "the FD solver computes the half plane y >= 0 and mirrors it (paper Eq. 17b), so "
                f"it needs an indenter symmetric in y; {type(scene.indenter).__name__} is not. "
                "Use method='fe' (it meshes the full disk for such shapes)."
            )
        from femehl.problem.cavitation import cavitation_model

        cav = cavitation_model(getattr(scene, "cavitation", None))
        if cav is not None and cav.changes_step:
            raise SceneError(
                "the FD reference is the paper's full-Sommerfeld scheme: use method='fe' for the "
                f"{cav.name!r} cavitation condition (the FD reference takes 'half-sommerfeld', a "
                "post-processing of its full-Sommerfeld step)."
            )
        if getattr(scene, "viscosity", None) is not None:
            raise SceneError(
                "the FD reference keeps the paper's isoviscous non-conservative form (its Eq. 13b "
                "has no viscosity gradient): use method='fe' for a pressure-dependent viscosity."
            )
        self.scene = scene
        self.grid = grid = PolarGrid(scene.domain.L, dr, dtheta)
        m, n = grid.m, grid.n
        self.E, self.rows = _expansion(grid)
        self.free_index = self.rows
        self.n = int(self.E.shape[1])
        th, rr = grid.mesh()
        self.r = rr.ravel()
        self.theta = th.ravel()
        self.nodes = self.film_points = grid.xy()
        self.shape = self.gap(self.nodes)
        self.node_average = None  # the film points are the nodes
        self.area = grid.cell_areas().ravel()
        self.load_weights = 2.0 * (self.E.T @ self.area)  # whole plane
        Dr, Dt = _forward_diff(grid, self.rows)
        ri = self.r[self.rows]
        self._G = (
            sp.diags(np.cos(self.theta[self.rows])) @ Dr - sp.diags(np.sin(self.theta[self.rows]) / ri) @ Dt
        ).tocsr()
        self._S = sp.csr_matrix(
            (np.ones(self.rows.size), (np.arange(self.rows.size), self.rows)), shape=(self.rows.size, m * n)
        )
        self.info = {
            "dr": grid.dr,
            "dtheta": grid.dtheta,
            "m": m,
            "n": n,
            "nodes": m * n,
            "unknowns": self.n,
            "setup_s": time.perf_counter() - t0,
        }

    def gap(self, points):
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        return np.asarray(self.scene.indenter.gap(pts[:, 0], pts[:, 1]), dtype=float)

    def expand(self, p_free):
        return self.E @ p_free

    # ---- Reynolds operators (Eq. 15, 21) -------------------------------------------------
    def poiseuille(self, d, m, dm_dd):
        """``-L(m)``: interior rows x free unknowns, coefficients lagged."""
        g = self.grid
        nm, n = g.m, g.n
        D = d.reshape(nm, n)
        d_r = np.empty_like(D)
        d_r[:, :-1] = (D[:, 1:] - D[:, :-1]) / g.dr
        d_r[:, -1] = d_r[:, -2]
        d_t = np.empty_like(D)
        d_t[:-1, :] = (D[1:, :] - D[:-1, :]) / g.dtheta
        d_t[-1, :] = d_t[-2, :]
        rows = self.rows
        r = self.r[rows]
        mm = m[rows]
        N = mm / r + dm_dd[rows] * d_r.ravel()[rows]  # Eq. 13b
        M = dm_dd[rows] * d_t.ravel()[rows]
        cr2 = 1.0 / g.dr**2
        ct2 = 1.0 / (r * r * g.dtheta**2)
        c_jp = N / g.dr + mm * cr2
        c_jm = mm * cr2
        c_ip = mm * ct2 + M / (r * r * g.dtheta)
        c_im = mm * ct2
        c_0 = -(c_jp + c_jm + c_ip + c_im)
        k = rows.size
        ar = np.arange(k)
        Lfull = sp.csr_matrix(
            (
                -np.concatenate([c_0, c_jp, c_jm, c_ip, c_im]),
                (np.tile(ar, 5), np.concatenate([rows, rows + 1, rows - 1, rows + n, rows - n])),
            ),
            shape=(k, nm * n),
        )
        return (Lfull @ self.E).tocsr()

    def couette(self):
        return -self._G

    def squeeze(self):
        return self._S

    # ---- substrate primitives ------------------------------------------------------------
    def average(self):
        return self.E

    def _bilinear(self, points):
        """Sparse rows (npts x nodes) of the bilinear interpolation in (theta, r)."""
        g = self.grid
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        r = np.hypot(pts[:, 0], pts[:, 1])
        th = np.abs(np.arctan2(pts[:, 1], pts[:, 0]))
        inside = np.flatnonzero(r <= g.L * (1 + 1e-12))
        u = th[inside] / g.dtheta
        v = np.minimum(r[inside], g.L) / g.dr
        i = np.minimum(np.floor(u).astype(int), g.m - 2)
        j = np.minimum(np.floor(v).astype(int), g.n - 2)
        a, b = u - i, v - j
        rows = np.repeat(inside, 4)
        cols = np.column_stack(
            [i * g.n + j, i * g.n + j + 1, (i + 1) * g.n + j, (i + 1) * g.n + j + 1]
        ).ravel()
        vals = np.column_stack([(1 - a) * (1 - b), (1 - a) * b, a * (1 - b), a * b]).ravel()
        return sp.csr_matrix((vals, (rows, cols)), shape=(pts.shape[0], g.m * g.n))

    def pressure_rows(self, points):
        return (self._bilinear(points) @ self.E).tocsr()

    def boussinesq(self):
        """Dense ``chi E``: polar cells and their mirror images (Eq. 24-25)."""
        return self.boussinesq_rows(self.nodes)

    def boussinesq_rows(self, points):
        cells = self.grid.cells()
        chi = quad_influence(points, cells)
        mirror = cells.copy()
        mirror[..., 1] *= -1.0
        chi += quad_influence(points, mirror)
        return np.asarray(self.E.T @ chi.T).T

    def _cell_triangles(self):
        q = self.grid.cells()
        return np.concatenate([q[:, [0, 1, 2], :], q[:, [0, 2, 3], :]])  # (2 m n, 3, 2)

    def radial_kernel(self, kernel):
        """``chi_g E``: a radial kernel ``singular/r - R`` integrated over every polar cell
        (two triangles) and its mirror image; sparse for a kernel with a short cut-off."""
        return self.radial_kernel_rows(kernel, self.nodes)

    def radial_kernel_rows(self, kernel, points):
        from femehl.elastic.kernels import radial_influence

        X = radial_influence(points, self._cell_triangles(), kernel, mirror_y=True)
        nc = X.shape[1] // 2
        if sp.issparse(X):
            X = X.tocsc()
            return ((X[:, :nc] + X[:, nc:]) @ self.E).tocsr()
        return np.asarray(self.E.T @ (X[:, :nc] + X[:, nc:]).T).T

    def outside(self, points):
        """True where a point lies beyond the domain r <= L."""
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        return np.hypot(pts[:, 0], pts[:, 1]) > self.grid.L * (1.0 + 1e-9)

    # ---- fields for results and writers -----------------------------------------------
    def pressure_at(self, p, points):
        return self.grid.pressure_at(p, points)

    def film_at(self, d, points):
        return self.grid.film_at(d, points)

    def deflection_at(self, w, points):
        return self.grid.deflection_at(w, points)

    def vtk_geometry(self):
        return self.grid.vtk_geometry()

    def centreline(self):
        return self.grid.centreline()
