"""Line contact: P1 pressure on a 1-D mesh of [-L, L], film on elements (scikit-fem).

The 1-D normalized Reynolds equation ``beta (m p')' = -V d' + dd/dt`` with ``m = d^3``
in weak form: find p in P1, p(-L) = p(L) = 0, such that for every P1 test function q

    beta int m p' q'  +  V int d q'  +  int (dd/dt) q  = 0,

(the Couette term integrated by parts; its boundary term vanishes since q(+-L) = 0),
with the forms of :mod:`femehl.discretize.forms`.  The film points are the element centroids
``(x_e, 0)``; the shape is the scene's rigid gap
the indenter's ``line_gap`` (the cylinder ``x^2/2`` or a profile).  The load is per unit length,
``int p dx``.  Only local substrates (Winkler, rigid) have a line operator; with them
no dense matrix is built anywhere.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp
from skfem import Basis, ElementLineP0, ElementLineP1, MeshLine

from femehl.discretize import register_method
from femehl.discretize._p1p0 import P1P0
from femehl.errors import SceneError

__all__ = ["LineDisc"]


@register_method("line")
class LineDisc(P1P0):
    """A 1-D mesh of ``[-L, L]`` for a line contact (a scene on a
    :class:`femehl.problem.line.LineDomain`, e.g. :func:`femehl.problem.line.LineScene`).

    Parameters
    ----------
    scene : femehl.Scene
    n_elements : int, default: 400
        Number of P1 elements.
    grading : "uniform", float or callable, default: 3.0
        Mesh grading, see :func:`femehl.problem.line.line_nodes`.  The default makes elements 3
        times smaller over the contact (``|x| <= fine``) than at the ends.
    fine : float, optional
        Half width of the fine zone; default ``min(L, a + 0.5)`` with ``a`` the dry
        contact half width (:func:`femehl.problem.line.contact_halfwidth`), or ``L/2``.
    """

    dimension = 1
    default_linear_solver = "lu"

    def __init__(self, scene, n_elements: int = 400, grading=3.0, fine=None):
        from femehl.problem.line import contact_halfwidth, line_nodes

        t0 = time.perf_counter()
        if getattr(scene, "default_method", None) != "line":
            raise SceneError(
                "method 'line' needs a line contact (femehl.line.LineScene(...), a scene on a "
                f"LineDomain), got a scene on {type(getattr(scene, 'domain', None)).__name__}: "
                "use method 'fe' or 'fd' for a 2-D scene."
            )
        self.scene = scene
        L = scene.domain.L
        if fine is None and not isinstance(grading, str):
            a = contact_halfwidth(scene)
            fine = 0.5 * L if a is None else min(L, a + 0.5)
        x = line_nodes(L, n_elements, grading, fine)
        self.mesh = MeshLine(x)
        self.basis = b1 = Basis(self.mesh, ElementLineP1())
        self.basis0 = b0 = b1.with_element(ElementLineP0())
        t = self.mesh.t
        self.x = self.mesh.p[0].copy()
        self.xc = self.x[t].mean(axis=0)
        ne, nn = t.shape[1], self.x.size
        self.nelements, self.nnodes = ne, nn
        self.L = L
        self.nodes = np.column_stack([self.x, np.zeros(nn)])
        self.film_points = np.column_stack([self.xc, np.zeros(ne)])
        self._build_forms(b1, b0, np.setdiff1d(np.arange(nn), self.mesh.boundary_nodes()))
        self.shape = self.gap(self.film_points)
        self.node_shape = self.gap(self.nodes)
        self.load_weights = self.node_weight[self.free]
        self.info = {
            "elements": ne,
            "nodes": nn,
            "unknowns": self.n,
            "grading": grading if not callable(grading) else "callable",
            "h_min": float(np.diff(self.x).min()),
            "h_max": float(np.diff(self.x).max()),
            "imposed_load": scene.motion.load_controlled,
            "setup_s": time.perf_counter() - t0,
        }

    def gap(self, points):
        return self.scene.indenter.line_gap(np.asarray(points, dtype=float).reshape(-1, 2)[:, 0])

    # ---- substrate primitives (the Reynolds operators come from P1P0) ----------------
    def pressure_rows(self, points):
        """Sparse rows of the P1 interpolation in x at ``points`` (0 outside [-L, L])."""
        xq = np.asarray(points, dtype=float).reshape(-1, 2)[:, 0]
        inside = np.flatnonzero(np.abs(xq) <= self.L)
        j = np.clip(np.searchsorted(self.x, xq[inside]) - 1, 0, self.nnodes - 2)
        a = (xq[inside] - self.x[j]) / (self.x[j + 1] - self.x[j])
        R = sp.csr_matrix(
            (np.r_[1.0 - a, a], (np.r_[inside, inside], np.r_[j, j + 1])), shape=(xq.size, self.nnodes)
        )
        return R[:, self.free]

    def boussinesq(self):
        raise SceneError(
            "line contact has no half-space operator: the cylinder's plane-strain "
            "deflection is not modeled here; use a Winkler (or rigid) substrate."
        )

    def boussinesq_rows(self, points):
        return self.boussinesq()

    def outside(self, points):
        """True where a point lies beyond the domain |x| <= L."""
        return np.abs(np.asarray(points, dtype=float).reshape(-1, 2)[:, 0]) > self.L * (1.0 + 1e-9)

    # ---- fields for results and writers -----------------------------------------------

    def _cell_value(self, values, points):
        xq = np.asarray(points, dtype=float).reshape(-1, 2)[:, 0]
        out = np.full(xq.size, np.nan)
        ok = np.abs(xq) <= self.L
        e = np.clip(np.searchsorted(self.x, xq[ok]) - 1, 0, self.nelements - 1)
        out[ok] = np.asarray(values)[e]
        return out

    def vtk_geometry(self):
        """Points on y = z = 0, line cells, and False: film fields live on elements."""
        pts = np.column_stack([self.x, np.zeros((self.nnodes, 2))])
        return pts, [("line", self.mesh.t.T.astype(np.int64))], False

    def centreline(self, n: int = 401):
        x = np.linspace(-self.L, self.L, n)
        return np.column_stack([x, np.zeros_like(x)])
