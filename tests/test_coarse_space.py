"""The fast path's two-level preconditioner: the coarse P1 space and the coarse correction.

What is checked, and why these bounds:

* the coarse space interpolates linear functions exactly (P1 interpolation is exact for
  them: 1e-12 is rounding), has about the requested number of coarse nodes (the greedy
  selection adjusts its spacing five times, to within 15 %: bound 25 %) and keeps the
  fine mesh's grading (coarse spacing in the fitted mesh's fine contact band well below
  that near the rim);
* the blocked product ``C @ Z`` is the column-by-column product, and with sparse columns
  the product of the same columns made dense (the same sums in another order, the
  skipped far blocks exact zeros: 1e-12 relative);
* the coarse correction cuts the Krylov iterations of fresh solves (no recycling) of the
  paper case's systems: measured 11-13 -> 6-8 on three meshes (780 to 2,904 unknowns);
  the bound asks for at least a quarter fewer on every sampled system.
"""

from __future__ import annotations

import numpy as np
import pytest

from femehl.api import make_stepper, run_loop
from femehl.discretize.fe_disk import FEDisc
from femehl.discretize.fitted import fitted_disk
from femehl.elastic.coarse import coarse_prolongation, node_sizes
from femehl.elastic.hmatrix import FastCompliance
from femehl.problem.presets import paper_sphere
from femehl.solver.linsolve import PermutedLU, TwoLevel, nested_dissection


@pytest.fixture(scope="module")
def sphere():
    return paper_sphere()


@pytest.fixture(scope="module")
def disc(sphere):
    return FEDisc(sphere, mesh=fitted_disk(sphere, 5.0, 1.0), operator="dense")


@pytest.mark.parametrize("m", [60, 200])
def test_coarse_space_interpolates_linear_functions(disc, m):
    P, verts = coarse_prolongation(disc.mesh, disc.areas, disc.free, m)
    assert P.shape == (disc.n, verts.size)
    assert abs(verts.size - m) <= 0.25 * m
    assert np.all(np.isin(verts, disc.free))  # coarse free vertices are fine free nodes
    assert np.all(np.diff(P.tocsc().indptr) > 0)  # every coarse function reaches fine nodes
    rows = np.isclose(np.asarray(P.sum(axis=1)).ravel(), 1.0)  # no coarse rim vertex
    assert rows.mean() > 0.8
    x, y = disc.nodes[:, 0], disc.nodes[:, 1]
    f = 0.3 + 1.7 * x - 0.4 * y
    got = P @ f[verts]
    assert np.max(np.abs(got[rows] - f[disc.free][rows])) <= 1e-12


def test_coarse_space_keeps_the_grading(disc):
    """Coarse vertices are denser where the fitted mesh is fine (the contact band)."""
    _, verts = coarse_prolongation(disc.mesh, disc.areas, disc.free, 150)
    h = node_sizes(disc.mesh, disc.areas)
    fine = h <= np.quantile(h[disc.free], 0.25)
    coarse = h >= np.quantile(h[disc.free], 0.75)
    # coarse vertices per area, in the finest and the coarsest quarter of the mesh
    area = lambda sel: np.sum(h[sel] ** 2)  # noqa: E731
    dens = lambda sel: np.isin(np.flatnonzero(sel), verts).sum() / area(sel)  # noqa: E731
    assert dens(fine) > 3 * dens(coarse)


def test_blocked_product_is_the_columnwise_product(sphere):
    d = FEDisc(sphere, mesh=fitted_disk(sphere, 5.0, 1.41), operator="dense")
    C = FastCompliance(d, coarse=False)
    Z = np.random.default_rng(7).standard_normal((d.n, 40))  # more than one block of 32
    cols = np.column_stack([C @ Z[:, k] for k in range(Z.shape[1])])
    assert np.max(np.abs(C @ Z - cols)) <= 1e-12 * np.max(np.abs(cols))


def test_sparse_columns_product_is_the_columnwise_product(sphere):
    """``C @ P`` of the coarse space's sparse columns (space order: the far blocks of
    vanishing sources skipped, 10-73 % of them per block of columns on this mesh; the near
    product sparse) is the column-by-column product, which skips nothing."""
    d = FEDisc(sphere, mesh=fitted_disk(sphere, 5.0, 1.41), operator="dense")
    C = FastCompliance(d)
    P = C.coarse[0].tocsc()  # about 100 columns: four blocks
    cols = np.column_stack([C @ P[:, k].toarray().ravel() for k in range(P.shape[1])])
    assert np.max(np.abs(C @ P - cols)) <= 1e-12 * np.max(np.abs(cols))


def test_coarse_product_follows_the_compliance_factor(sphere):
    """``C *= k`` (a compressible substrate) scales the stored ``C P`` too."""
    d = FEDisc(sphere, mesh=fitted_disk(sphere, 5.0, 1.41), operator="dense")
    C = FastCompliance(d)
    P, CP = C.coarse
    before = CP.copy()
    C *= 1.4
    P2, CP2 = C.coarse
    assert np.allclose(CP2, 1.4 * before, rtol=1e-6)
    ref = C @ P[:, :5].toarray()
    assert np.max(np.abs(CP2[:, :5] - ref)) <= 1e-6 * np.max(np.abs(ref))  # float32 storage


def _gcr_iterations(apply, precondition, b, rtol=1e-9, maxit=100):
    """Fresh GCR (no recycling) iterations to a relative residual rtol."""
    Q, r, bn, k = [], b.copy(), np.linalg.norm(b), 0
    while np.linalg.norm(r) > rtol * bn and k < maxit:
        q = apply(precondition(r))
        for _ in range(2):
            for qq in Q:
                q -= (qq @ q) * qq
        q /= np.linalg.norm(q)
        Q.append(q)
        r -= (q @ r) * q
        k += 1
    return k


def test_coarse_correction_cuts_iterations(sphere):
    st = make_stepper(sphere, "fe", mesh=fitted_disk(sphere, 5.0, 1.0), operator="fast", scheme="bdf2")
    assert st.C.coarse is not None
    caught = []
    solve = st.solver.solve

    def spy(op, rhs, t):
        caught.append((t, op, rhs[0].copy()))
        return solve(op, rhs, t)

    st.solver.solve = spy
    run_loop(st, 0.3, 0.01, store_every=0)
    for t, op, b in caught[5::8]:
        A = lambda z, op=op: op.D @ z + op.G @ (op.C @ z)  # noqa: E731
        An = op.near_matrix()
        near = PermutedLU(An, nested_dissection(An), t)
        two = TwoLevel(near, *op.coarse_system(), t)
        n_near = _gcr_iterations(A, near.solve, b)
        n_two = _gcr_iterations(A, two.solve, b)
        assert n_two <= 0.75 * n_near, (t, n_near, n_two)
