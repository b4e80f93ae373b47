"""What the two finite-element discretizations share: P1 pressure, P0 film (scikit-fem).

The weak-form operators (see :mod:`femehl.discretize.forms`) on the free nodes, the element
average ``P`` of a P1 field, the nodal average of an element field (for the film check)
and the node weights ``int phi_q`` (the load), built once from a mesh and its bases.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from skfem import asm

from femehl.discretize.forms import couette, film_diffusion, squeeze

__all__ = ["P1P0", "GasTransport"]


class GasTransport:
    """Row operators of a P1 nodal gas film ``v`` (volume per area) on the free nodes (JFO).

    In the film's mass balance the liquid content is ``c = d - v`` (``d`` the gap on the
    elements, ``v`` the gas in it, :class:`femehl.problem.cavitation.JFOCavitation`).  The Couette
    row of the content is written element by element as fluxes between the element's
    node pairs, ``F_ij = V (b_i c_j - b_j c_i)/nv - delta_ij (c_j - c_i)`` with
    ``b_i = int_e dphi_i/dx`` and the node values ``c_k`` of the content in that element
    (antisymmetric in ``i, j``: the liquid is conserved).  With ``c_k = d_e`` (a full
    film) the diffusion vanishes and ``F`` is the Galerkin Couette term of the P0 film,
    unchanged; ``delta_ij = max(0, V b_i, V b_j)/nv`` is the element's discrete upwinding
    (Kuzmin's low-order flux), which makes the content's transport monotone.  On a
    cavitated node inside the cavity (no full neighbour) ``c_k = dbar_k - v_k``, ``dbar_k =
    (M d)_k / m_k`` the mean gap of the node's cell (``m_k = int phi_k``, so ``m_k c_k`` is
    exactly the content the node's row holds): the content, not only the gas, is carried
    upwind, so it stays >= 0 however the gap varies from element to element.  On the
    cavity's first row of nodes (beside a full node) ``c_k = d_e - v_k``.

    That splits into (i) the P0 Couette row of ``d`` (the full film's, unchanged), (ii)
    ``-B v`` with

        B(V, c0) = V K - |V| D_sign(V) + c0 diag(m),        c0 = a0/dt,

    ``K = Bx P`` the Galerkin Couette operator of a P1 field and ``D`` the assembled
    element upwinding (symmetric, zero row sums: an M-matrix ``B``), and (iii) a
    correction of the cavitated nodes' gap from ``d_e`` to ``dbar_k``
    (:meth:`correction`), taken at the step's lagged film: sparse, explicit, and in flux
    form, so it changes no conservation.
    """

    def __init__(self, elements, b, mass, free, n):
        self.t = elements  # (nv, ne) node indices
        self.b = b  # (nv, ne) int_e dphi/dx
        self.nv = elements.shape[0]
        self.mass = mass  # (n,) int phi_q on the free nodes
        self.free = free
        self.n = n
        nn = int(elements.max()) + 1
        self.slot = np.full(nn, -1, dtype=np.int64)  # node -> free index, -1 on the rim
        self.slot[free] = np.arange(free.size)
        ne = b.shape[1]
        nodes, elems = elements.ravel(), np.tile(np.arange(ne), self.nv)
        X = sp.csr_matrix((b.ravel(), (nodes, elems)), shape=(nn, ne))  # int_e dphi/dx
        P = sp.csr_matrix((np.full(b.size, 1.0 / self.nv), (elems, nodes)), shape=(ne, nn))
        K = (X @ P).tocsr()
        self.K = K[free][:, free].tocsr()
        self._dl = {s: self._pairs(s) for s in (1, -1)}  # (nv, nv, ne) per sign of V
        self.upwind = {s: self._element_upwinding(s)[free][:, free].tocsr() for s in (1, -1)}
        inc = sp.csr_matrix((np.ones(b.size), (nodes, elems)), shape=(nn, ne))
        self.neighbours = (inc @ inc.T)[free][:, free].astype(bool).astype(np.int64).tocsr()  # mesh graph

    def _pairs(self, sign):
        """``delta_ij`` for unit ``|V|`` of each element's node pairs, (nv, nv, ne)."""
        sb = sign * self.b / self.nv
        dl = np.maximum(0.0, np.maximum(sb[:, None, :], sb[None, :, :]))
        idx = np.arange(self.nv)
        dl[idx, idx, :] = 0.0
        return dl

    def _element_upwinding(self, sign):
        dl = self._dl[sign]
        t = self.t
        nn = self.slot.size
        rows = np.broadcast_to(t[:, None, :], dl.shape).ravel()
        cols = np.broadcast_to(t[None, :, :], dl.shape).ravel()
        Dd = sp.csr_matrix((dl.ravel(), (rows, cols)), shape=(nn, nn))
        return (Dd - sp.diags(np.asarray(Dd.sum(axis=1)).ravel())).tocsr()

    def operator(self, V: float, c0: float):
        """``B(V, c0)`` (sparse CSR, free nodes x free nodes)."""
        B = sp.diags(c0 * self.mass)
        if V != 0.0:
            B = B + V * self.K - abs(V) * self.upwind[1 if V > 0 else -1]
        return B.tocsr()

    def correction(self, V: float, switched, d, dbar):
        """The rows' flux change when the cavitated nodes' gap is ``dbar_k``, not ``d_e``.

        ``switched`` (bool, free nodes) the cavitated set, ``d`` the element film and
        ``dbar`` the nodal cell means (free nodes) it is taken from.  Returns the rows'
        change (free nodes); its sum is 0 up to the rim's rows (flux form).
        """
        out = np.zeros(self.n)
        if V == 0.0 or not np.any(switched):
            return out
        switched = np.asarray(switched, dtype=bool)
        # only inside the cavity: a node beside a full one keeps d_e (the rupture front's
        # rows stay those of the gas alone, whose lagged set then settles)
        interior = switched & (self.neighbours @ (~switched).astype(np.int64) == 0)
        k = self.slot[self.t]  # (nv, ne) free index or -1
        on = np.zeros(k.shape, dtype=bool)
        inside = k >= 0
        on[inside] = interior[k[inside]]
        if not on.any():
            return out
        delta = np.zeros(k.shape)
        delta[on] = np.asarray(dbar)[k[on]] - np.broadcast_to(d, k.shape)[on]
        e = np.flatnonzero(on.any(axis=0))  # the elements that touch the set
        b, D, dl = self.b[:, e], delta[:, e], abs(V) * self._dl[1 if V > 0 else -1][:, :, e]
        # F_ij = V (b_i D_j - b_j D_i)/nv - dl_ij (D_j - D_i), summed over j
        F = V * (b * D.sum(axis=0) - D * b.sum(axis=0)) / self.nv
        F -= np.einsum("ije,je->ie", dl, D) - dl.sum(axis=1) * D
        rows = k[:, e]
        ok = rows >= 0
        np.add.at(out, rows[ok], F[ok])
        return out


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

    def gas_transport(self):
        """The operators of a P1 gas film carried by the sliding surface (JFO cavitation).

        Built once, see :class:`GasTransport`: the Galerkin Couette operator of a P1 field
        ``K = Bx P`` (``K[q, j] = int phi_j dq/dx``, exactly what the Couette term does to the
        element average), its discrete-upwind diffusion for either sign of V, and the
        lumped mass ``int phi_q`` of the free nodes.
        """
        if getattr(self, "_gas", None) is None:
            X = asm(couette, self.basis0, self.basis).tocsr()  # int_e dphi_q/dx, every node
            t = self.basis.mesh.t
            cols = np.tile(np.arange(t.shape[1]), t.shape[0])
            b = np.asarray(X[t.ravel(), cols]).ravel().reshape(t.shape)
            self._gas = GasTransport(t, b, self.node_weight[self.free].copy(), self.free, self.n)
        return self._gas

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
