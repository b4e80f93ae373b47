"""What the two finite-element discretizations share: P1 pressure, P0 film (scikit-fem).

The weak-form operators (see :mod:`femehl.fe.forms`) on the free nodes, the element
average ``P`` of a P1 field, the nodal average of an element field (for the film check)
and the node weights ``int phi_q`` (the load), built once from a mesh and its bases.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from skfem import asm

from ..fe.forms import couette, film_diffusion, squeeze

__all__ = ["P1P0"]


class P1P0:
    """Mixin: call :meth:`_build_forms` once the mesh, its bases and ``free`` are set."""

    def _build_forms(self, basis, basis0, free):
        self.basis, self.basis0 = basis, basis0
        t = basis.mesh.t
        nv, ne = t.shape
        nn = basis.mesh.p.shape[1]
        self.free = self.free_index = free
        self.n = int(free.size)
        rows, elems = t.T.ravel(), np.repeat(np.arange(ne), nv)
        # element average of a P1 field: (P p)_e = mean of its nodal values
        self.P = sp.csr_matrix((np.full(nv * ne, 1.0 / nv), (elems, rows)), shape=(ne, nn))
        # nodal estimate of an element field: mean over the elements around each node
        inc = sp.csr_matrix((np.ones(nv * ne), (rows, elems)), shape=(nn, ne))
        self.node_average = sp.diags(1.0 / np.asarray(inc.sum(axis=1)).ravel()) @ inc
        # element stiffness with unit coefficient; K(m) scales each element by m
        kcoo = film_diffusion.coo_data(basis, d3=basis0.interpolate(np.ones(ne)))
        self._k_rows, self._k_cols = kcoo.indices
        self._k_data = kcoo.data.reshape(-1, ne)  # (entries per element, ne), element last
        Mfull = asm(squeeze, basis0, basis).tocsr()
        self._M = Mfull[free]
        self.node_weight = np.asarray(Mfull.sum(axis=1)).ravel()  # int phi_q

    def expand(self, p_free):
        p = np.zeros(self.basis.mesh.p.shape[1])
        p[self.free] = p_free
        return p

    def poiseuille(self, d, m, dm_dd=None):
        """``K(m)[q, p] = int m grad p . grad q`` on the free nodes, m element-constant."""
        n = self.basis.mesh.p.shape[1]
        K = sp.csr_matrix(((self._k_data * m[None, :]).ravel(), (self._k_rows, self._k_cols)), shape=(n, n))
        return K[self.free][:, self.free]

    def couette(self):
        """``Bx[q, e] = int_e dq/dx`` (free nodes x elements)."""
        return asm(couette, self.basis0, self.basis).tocsr()[self.free]

    def squeeze(self):
        """``M[q, e] = int_e q`` (free nodes x elements)."""
        return self._M

    def pressure_gradient(self):
        """Element gradients of the P1 pressure: one sparse (elements x free nodes) matrix per
        axis, ``(G[i] p)_e = dp/dx_i`` on element e (constant there), and the element measures."""
        if getattr(self, "_grad", None) is None:
            from skfem import BilinearForm

            b0, b1 = self.basis0, self.basis
            measure = np.asarray(asm(squeeze, b0, b1).sum(axis=0)).ravel()  # int_e 1 (sum of int_e phi_q)
            inv = sp.diags(1.0 / measure)
            mats = []
            for i in range(b1.mesh.p.shape[0]):
                form = BilinearForm(lambda d, q, w, i=i: d * q.grad[i])
                mats.append((inv @ asm(form, b0, b1).tocsr()[self.free].T).tocsr())
            self._grad = (tuple(mats), measure)
        return self._grad

    def average(self):
        """The element average of the P1 pressure (elements x free nodes)."""
        return self.P[:, self.free]

    # ---- fields for results (``pressure_rows`` and ``_cell_value`` are the mesh's) -----
    def pressure_at(self, p, points):
        """P1 interpolation of nodal ``p``; 0 outside the mesh (p = 0 beyond the rim)."""
        return np.asarray(self.pressure_rows(points) @ np.asarray(p, dtype=float)[self.free]).ravel()

    def film_at(self, d, points):
        """Element-constant film thickness at ``points`` (NaN beyond the domain)."""
        return self._cell_value(d, points)

    def deflection_at(self, w, points):
        """Element-constant deflection at ``points`` (NaN beyond the domain)."""
        return self._cell_value(w, points)
