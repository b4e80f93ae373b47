"""Finite elements on a triangulated disk: P1 pressure, P0 film (scikit-fem).

The weak form of the Reynolds equation (see :mod:`femehl.discretize.forms`): find p in P1,
p = 0 on r = L, such that for every P1 test function q

    beta int m grad p . grad q  +  V int d dq/dx  +  int (dd/dt) q  = 0,

with the film ``d`` and the mobility ``m`` constant on elements (their values at the
centroids).  So ``poiseuille`` is the stiffness matrix with element coefficient m,
``couette`` is ``Bx[q, e] = int_e dq/dx`` and ``squeeze`` is ``M[q, e] = int_e q``.
The elastic half space is the exact Boussinesq integral of the element-average pressure
over every triangle, at the centroids (:func:`femehl.elastic.kernels.edge_terms`: one exact term
per unique edge), mirrored for a half disk.  A half disk (y >= 0) is used for scenes
symmetric in y; its load is doubled.
"""

from __future__ import annotations

import logging
import time

import numpy as np
import scipy.sparse as sp
from skfem import Basis, ElementTriP0, ElementTriP1

from femehl.discretize import register_method
from femehl.discretize._p1p0 import P1P0
from femehl.discretize.fitted import fitted_disk
from femehl.discretize.mesh import areas, centroids, load_mesh
from femehl.elastic.base import OPERATORS, substrate_operators
from femehl.elastic.hmatrix import DEFAULT_OPERATOR_TOL, FastOptions
from femehl.elastic.kernels import (
    edge_products,
    mesh_edges,
    radial_influence,
    smooth_cost_estimates,
    smooth_grid_apply,
    smooth_lowrank,
    smooth_matrix,
    sparse_radial_influence,
    triangle_influence,
)
from femehl.errors import SceneError

logger = logging.getLogger("femehl")

__all__ = ["FEDisc"]

#: the elastic operator's set-up is reported (it takes seconds) from this many cells on
LONG_SETUP_CELLS = 5_000


#: the mesh name that asks for a mesh fitted to the scene (:func:`femehl.discretize.fitted.fitted_disk`)
FITTED = "fitted"

#: "auto" uses the fast operator from this many elements on (or when the dense one does
#: not fit in memory): the measured crossover of the whole paper case (set-up and steps,
#: BDF2 at dt = 0.01, one BLAS thread, each path in its own process, in turn;
#: ``benchmarks/fast_operator.py crossover``).  With the fast operator's set-up halved
#: (de6fc71): fast / dense 1.11 at 7,998 elements, 0.85 at 11,450 (medians of 2; ratio 1
#: near 9,400).  With the dense ``C`` in single precision (:mod:`femehl.elastic.dense`,
#: feabb35) and the former set-up: 1.44 at 7,998, 1.12 at 11,450, 0.90 at 14,112 (ratio 1
#: near 12,700, the crossover 12,000).  Before it (6a7a811, double precision): 1.15 at
#: 5,766, 0.90 at 7,998, 0.67 at 11,450, and the crossover was 8,000.
#: Re-measured with the dense build and products on both cores (ca3d6df): 1.11 at 7,998,
#: 0.83 at 11,450, 0.55 at 16,116 (ratio 1 near 9,100): the crossover stays.
FAST_CROSSOVER = 9_500


def _horizon(scene) -> float:
    """The span a fitted mesh covers when the run's end is not known: every breakpoint, >= 10."""
    return max([10.0, *scene.motion.breakpoints])


def _looks_like_path(s: str) -> bool:
    return any(ch in s for ch in "/\\.")


@register_method("fe")
class FEDisc(P1P0):
    """A disk mesh with P1 pressure and element-constant film.

    Parameters
    ----------
    scene : femehl.Scene
    mesh : str, path, skfem.MeshTri or DiskMesh, default: "medium"
        A ladder name ("coarse", "medium", "fine", "xfine"), ``"fitted"`` (a gmsh mesh
        refined at this scene's contact, :func:`femehl.discretize.fitted.fitted_disk`, cached), or
        any mesh meshio reads.
    half : bool, optional
        Use the half disk y >= 0; default: True when the indenter is symmetric in y.
    operator : {"auto", "dense", "fast"}, default: "auto"
        The elastic operator: the dense exact matrix, or the hierarchical approximation
        of :mod:`femehl.elastic.hmatrix` (memory and work per product O(N log N), relative
        operator error about ``operator_tol``; its steps are solved by Krylov iterations
        preconditioned with a sparse LU of the near field).  "auto": fast from
        :data:`FAST_CROSSOVER` elements on, or when the dense operator does not fit in
        memory.
    operator_tol : float or femehl.elastic.hmatrix.FastOptions, default: DEFAULT_OPERATOR_TOL
        Relative error of the fast operator (sets its interpolation order); a
        :class:`~femehl.elastic.hmatrix.FastOptions` builds it with other parameters (experiments).
    """

    dimension = 2
    default_linear_solver = "gmres"
    #: options that choose how the operators are computed, not the discretization
    operator_options = ("operator", "operator_tol")

    def __init__(
        self,
        scene,
        mesh="medium",
        half: bool | None = None,
        operator: str = "auto",
        operator_tol: float | FastOptions = DEFAULT_OPERATOR_TOL,
    ):
        t0 = time.perf_counter()
        if not isinstance(operator, str) or operator not in OPERATORS:
            raise SceneError(f"operator must be one of {', '.join(map(repr, OPERATORS))}, got {operator!r}.")
        fast_options = FastOptions.of(operator_tol)
        self.scene = scene
        symmetric = bool(getattr(scene.indenter, "symmetric_y", False))
        if half is not None and not isinstance(half, (bool, np.bool_)):
            raise SceneError(f"half must be True, False or None (automatic), got {half!r}.")
        if half is None:
            half = symmetric if isinstance(mesh, str) and not _looks_like_path(mesh) else None
            half = symmetric if isinstance(mesh, str) and mesh == FITTED else half
        if half and not symmetric:
            raise SceneError(
                "a half-disk mesh needs an indenter symmetric in y; use half=False or a full-disk mesh."
            )
        if isinstance(mesh, str) and mesh == FITTED:
            dm = fitted_disk(scene, _horizon(scene), half=half)
        else:
            dm = load_mesh(mesh, L=scene.domain.L, half=half)
        if dm.half and not symmetric:
            raise SceneError(
                f"mesh {dm.name!r} is a half disk but the indenter is not symmetric "
                "in y: use a full-disk mesh."
            )
        self.dm = dm
        self.mesh = dm.mesh
        self.half = dm.half
        self.L = dm.L
        self.basis = b1 = Basis(self.mesh, ElementTriP1())
        self.basis0 = b0 = b1.with_element(ElementTriP0())
        p, t = self.mesh.p, self.mesh.t
        self.nodes = p.T.copy()
        self.tri = np.transpose(p[:, t], (2, 1, 0))  # (ne, 3, 2)
        self.centroids = centroids(dm)
        self.film_points = self.centroids
        self.areas = areas(dm)
        ne, nn = t.shape[1], p.shape[1]
        r = np.hypot(p[0], p[1])
        self._build_forms(b1, b0, np.flatnonzero(r < self.L * (1.0 - 1e-9)))
        self.shape = self.gap(self.centroids)
        self.node_shape = self.gap(self.nodes)
        mult = 2.0 if self.half else 1.0
        self.load_weights = mult * self.node_weight[self.free]
        self._finder_ = None
        self.operator = self._resolve_operator(operator, ne)
        self.fast_options = fast_options
        self.info = {
            "mesh": dm.name,
            "half": dm.half,
            "elements": ne,
            "nodes": nn,
            "unknowns": self.n,
            "operator": self.operator,
            "setup_s": time.perf_counter() - t0,
        }

    def _resolve_operator(self, operator, ne):
        """The operator to build, checked against the machine's memory."""
        from femehl.discretize.mesh import check_mesh_memory, dense_fits

        sub = self.scene.substrate
        allowed = substrate_operators(sub)
        if operator == "fast" and "fast" not in allowed:
            raise SceneError(
                f"the fast hierarchical operator approximates the half space's 1/r kernel only; "
                f"a {type(sub).__name__} substrate needs operator='dense' (or 'auto')."
            )
        if operator == "auto":
            big = ne >= FAST_CROSSOVER or not dense_fits(ne, self.n)
            operator = "fast" if big and "fast" in allowed else "dense"
            if big and "fast" not in allowed and not dense_fits(ne, self.n):
                raise SceneError(
                    f"mesh {self.dm.name}: {ne} elements need a dense elastic operator that does not "
                    f"fit in this machine's memory, and a {type(sub).__name__} substrate has no fast "
                    "operator: use a coarser mesh (a ladder name or larger mesh sizes)."
                )
        check_mesh_memory(ne, self.n, self.dm.name, operator=operator)
        return operator

    # ---- geometry ------------------------------------------------------------------------
    @property
    def nelements(self) -> int:
        return self.mesh.t.shape[1]

    @property
    def nnodes(self) -> int:
        return self.mesh.p.shape[1]

    def gap(self, points):
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        s = np.asarray(self.scene.indenter.gap(pts[:, 0], pts[:, 1]), dtype=float)
        if s.shape != (pts.shape[0],) or not np.all(np.isfinite(s)):
            raise SceneError(
                "the indenter's gap(x, y) must return finite values of the same shape "
                "as x; check the shape function."
            )
        return s

    # ---- substrate primitives (the Reynolds operators come from P1P0) ----------------
    def _locate(self, points):
        if self._finder_ is None:
            import matplotlib.tri as mtri

            self._tri = mtri.Triangulation(self.mesh.p[0], self.mesh.p[1], self.mesh.t.T)
            self._finder_ = self._tri.get_trifinder()
        pts = np.asarray(points, dtype=float).reshape(-1, 2).copy()
        if self.half:
            pts[:, 1] = np.abs(pts[:, 1])
        return pts, self._finder_(pts[:, 0], pts[:, 1])

    def pressure_rows(self, points):
        """Sparse rows of the P1 interpolation at ``points`` (0 outside the mesh)."""
        pts, e = self._locate(points)
        ok = np.flatnonzero(e >= 0)
        nodes = self.mesh.t[:, e[ok]].T  # (k, 3)
        X = self.nodes[nodes]  # (k, 3, 2)
        T = np.stack([X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]], axis=-1)  # (k, 2, 2)
        lam = np.linalg.solve(T, (pts[ok] - X[:, 0])[..., None])[..., 0] if ok.size else np.zeros((0, 2))
        bary = np.column_stack([1.0 - lam.sum(axis=1), lam])
        rows, cols, vals = np.repeat(ok, 3), nodes.ravel(), bary.ravel()
        R = sp.csr_matrix((vals, (rows, cols)), shape=(pts.shape[0], self.nnodes))
        return R[:, self.free]

    def boussinesq(self):
        """``X P[:, free]``: exact ``int_T dA'/|c_i - x'|`` of the element averages.

        Dense, or with ``operator="fast"`` a :class:`femehl.elastic.hmatrix.FastCompliance`.

        Neither X nor T is stored: with the signed edge incidence S of :func:`mesh_edges`,
        X = T S where T holds one exact term per unique edge, and each row of T is contracted
        with S P as it is made (:func:`femehl.elastic.kernels.edge_products`).  For a half
        disk the mirror images (orientation reversed) add -T_mirror S.
        """
        t0, say = time.perf_counter(), self.nelements >= LONG_SETUP_CELLS
        if say:
            logger.info(
                "femehl: building the %s elastic operator on %d cells ...", self.operator, self.nelements
            )
        if self.operator == "fast":
            from femehl.elastic.hmatrix import FastCompliance

            op = FastCompliance(self, self.fast_options)
        else:
            op = self._dense_boussinesq()
        if say:
            logger.info("femehl: elastic operator built in %.1f s", time.perf_counter() - t0)
        return op

    def _dense_boussinesq(self):
        edges, S = mesh_edges(self.mesh.t, self.nodes)
        return edge_products(self.centroids, self.nodes, edges, S @ self.P[:, self.free], mirror=self.half)

    def radial_kernel(self, kernel):
        """``X_g P[:, free]``, ``X_g[i, e] = int_{T_e} g(|c_i - x'|) dA'``, mirror included.

        ``g = kernel.singular / r - R(r)`` with R smooth (the radial-kernel protocol of
        :func:`femehl.elastic.kernels.radial_triangle_pairs`, e.g. an elastic layer's
        :class:`femehl.elastic.layer_kernel.LayerKernel`).  Sparse (CSR) when the kernel's cut-off
        leaves few pairs (a thin layer), else dense: the exact ``1/r`` part as in
        :meth:`boussinesq` minus the smooth part, by a low-rank Chebyshev interpolation
        where R is smooth over the whole disk (:func:`femehl.elastic.kernels.smooth_lowrank`, a
        thick layer), else on a uniform grid with an FFT convolution
        (:func:`femehl.elastic.kernels.smooth_grid_apply`) or directly, whichever is estimated
        cheaper; directly means the pairs within the cut-off where they are fewer than 80 %
        of all, else :func:`femehl.elastic.kernels.smooth_matrix`.
        """
        X = sparse_radial_influence(self.centroids, self.tri, kernel, mirror_y=self.half)
        P = self.P[:, self.free]
        if X is not None:
            self.info["radial_kernel"] = "sparse"
            return (X @ P).tocsr()

        def singular():
            C = self._dense_boussinesq()
            if kernel.singular != 1.0:
                C *= kernel.singular
            return C

        low = smooth_lowrank(self.centroids, self.tri, kernel, mirror_y=self.half)
        if low is not None:  # a thick layer: R smooth over the whole disk
            self.info["radial_kernel"] = "dense, low-rank smooth part"
            S, K, Q = low
            C = singular()
            C -= S @ (K @ np.asarray((P.T @ Q.T).T))
            return C
        direct, grid = smooth_cost_estimates(self.centroids, self.tri, kernel, self.half, ncols=self.n)
        if grid < direct:  # between: R on a uniform grid, the convolution by FFT
            self.info["radial_kernel"] = "dense, grid smooth part"
            C = singular()
            C -= smooth_grid_apply(self.centroids, self.tri, kernel, P, mirror_y=self.half)
            return C
        # direct: only the pairs within the cut-off if they are fewer (h ~ 1/30 of the disk)
        X = sparse_radial_influence(self.centroids, self.tri, kernel, mirror_y=self.half, dense_fraction=0.8)
        if X is not None:
            self.info["radial_kernel"] = "dense, pairs within the cut-off"
            return np.asarray((X @ P).toarray())
        self.info["radial_kernel"] = "dense, direct smooth part"
        C = singular()
        XR = smooth_matrix(self.centroids, self.tri, kernel, mirror_y=self.half)
        C -= np.asarray(P.T @ XR.T).T
        return C

    def radial_kernel_rows(self, kernel, points):
        """Rows of :meth:`radial_kernel` at arbitrary points (mirror image included)."""
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        X = radial_influence(pts, self.tri, kernel, mirror_y=self.half)
        P = self.P[:, self.free]
        if sp.issparse(X):
            return (X @ P).tocsr()
        return np.asarray(P.T @ X.T).T

    def boussinesq_rows(self, points):
        """Rows of :meth:`boussinesq` at arbitrary points (mirror image included)."""
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        X = triangle_influence(pts, self.tri)
        if self.half:
            X += triangle_influence(pts, self.tri * np.array([1.0, -1.0]))
        return np.asarray(self.P[:, self.free].T @ X.T).T

    def outside(self, points):
        """True where a point lies beyond the domain r <= L."""
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        return np.hypot(pts[:, 0], pts[:, 1]) > self.L * (1.0 + 1e-9)

    # ---- fields for results and writers -----------------------------------------------

    def _cell_value(self, values, points):
        """Element values at points; a point of the disk between the polygonal rim and the
        circle r = L takes its nearest element's value, a point beyond r = L is NaN."""
        pts, e = self._locate(points)
        out = np.full(pts.shape[0], np.nan)
        ok = e >= 0
        out[ok] = np.asarray(values)[e[ok]]
        rim = ~ok & ~self.outside(pts)
        if rim.any():
            from scipy.spatial import cKDTree

            out[rim] = np.asarray(values)[cKDTree(self.centroids).query(pts[rim])[1]]
        return out

    def vtk_geometry(self):
        """Points (z = 0), triangles, and False: film fields live on elements."""
        p = self.mesh.p
        pts = np.column_stack([p[0], p[1], np.zeros(p.shape[1])])
        return pts, [("triangle", self.mesh.t.T.astype(np.int64))], False

    def centreline(self, n: int = 401):
        x = np.linspace(-self.L, self.L, n)
        return np.column_stack([x, np.zeros_like(x)])
