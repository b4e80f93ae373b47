"""The fast (hierarchical) elastic operator: accuracy, analytic limits, solver behaviour.

Tolerances: the fast operator's default ``operator_tol = 1e-6`` is a relative operator
error; it gives p = 11 at admissibility 2.5, whose error over 64 random vectors measures
9.4e-8 on the fitted paper mesh of :func:`test_fast_matches_dense` (2,988 elements) and
1.9e-7 to 4.9e-7 from 11,450 to 514,644 elements against exact rows
(``benchmarks/fast_operator.md``, ``error``), about 1e-8 for a smooth vector.  Tests hold
it to the stated 1e-6 (not to the measured figure), and films of a short run to 1e-6 as
the issue asks of the paper case (the whole case: ``benchmarks/fast_operator.md``,
agreement).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.special import ellipe

import femehl
from femehl.discretize.fe_disk import FEDisc
from femehl.discretize.fitted import fitted_disk
from femehl.elastic.hmatrix import (
    ETA,
    FastCompliance,
    FastOptions,
    H2Operator,
    _cheb,
    _grid,
    _kernel_blocks,
    _lagrange,
    _low_rank,
    order_for,
    sampled_error,
)
from femehl.elastic.kernels import triangle_influence
from femehl.errors import SceneError
from femehl.problem.presets import paper_sphere

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="module")
def sphere():
    return paper_sphere()


def _rel(a, b):
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


@pytest.mark.parametrize("half", [True, False], ids=["half-disk", "full-disk"])
def test_fast_matches_dense(sphere, half):
    """Half disk (mirror images) and full disk: fast C z against the dense exact C z."""
    dm = fitted_disk(sphere, 5.0, 1.0 if half else 1.41, half=half)
    disc = FEDisc(sphere, mesh=dm, operator="dense")
    dense = disc.boussinesq()
    fast = FastCompliance(disc)
    assert fast.H.n_far > 0, "the mesh must be large enough to have admissible blocks"
    rng = np.random.default_rng(3)
    z = rng.standard_normal(disc.n)
    smooth = np.maximum(0.0, 1.0 - np.hypot(*disc.nodes[disc.free].T) ** 2)
    for v in (z, smooth):
        assert _rel(fast @ v, dense @ v) <= 1e-6
    Z = np.column_stack([z, smooth])
    assert _rel(fast @ Z, dense @ Z) <= 1e-6  # several columns at once


def test_default_error_holds_past_small_meshes(sphere):
    """The default's error against exact rows on 11,450 elements (beyond the dense
    comparisons above), over 64 random vectors (one vector's error scatters by a factor
    of 5): the stated 1e-6 must hold (measured 1.9e-7; the order 9 of earlier sessions
    5.3e-7)."""
    disc = FEDisc(sphere, mesh=fitted_disk(sphere, 5.0, 0.5), operator="fast")
    assert disc.nelements > 10_000
    C = FastCompliance(disc, coarse=False)
    Z = np.random.default_rng(7).standard_normal((disc.n, 64))
    assert sampled_error(disc, C, {"random": Z})["random"] <= 1e-6


def test_single_precision_factors_keep_one_linear_map(sphere):
    """At the default tolerance the far factors are stored in single precision but every
    product and sum is in double: the operator stays linear to double rounding (no
    single-precision floor under a Krylov residual), and the column product (factors
    cast a chunk at a time) is the same map as the vector product."""
    disc = FEDisc(sphere, mesh=fitted_disk(sphere, 5.0, 1.0), operator="dense")
    fast = FastCompliance(disc)
    assert fast.H.n_far > 0
    assert {V.dtype for *_, V in fast.H._far_groups} == {np.dtype(np.float32)}
    rng = np.random.default_rng(11)
    a, b = rng.standard_normal((2, disc.n))
    # double rounding of a sum over ~10^4 terms: far below single precision (6e-8)
    assert _rel(fast @ (a + 2.0 * b), fast @ a + 2.0 * (fast @ b)) <= 1e-13
    assert _rel(fast @ np.column_stack([a, b])[:, 1], fast @ b) <= 1e-13
    tight = FastCompliance(disc, 1e-8)
    assert {V.dtype for *_, V in tight.H._far_groups} == {np.dtype(np.float64)}


def test_tighter_tolerance_is_more_accurate(sphere):
    disc = FEDisc(sphere, mesh=fitted_disk(sphere, 5.0, 1.0), operator="dense")
    dense = disc.boussinesq()
    z = np.random.default_rng(5).standard_normal(disc.n)
    errs = {tol: _rel(FastCompliance(disc, tol) @ z, dense @ z) for tol in (1e-4, 1e-8)}
    assert errs[1e-4] <= 1e-4
    assert errs[1e-8] <= 1e-8
    assert order_for(1e-8) > order_for(1e-6) > order_for(1e-4)


def test_truncation_and_order_overrides(sphere):
    """The experiment overrides (:class:`FastOptions`): a finer truncation keeps more rank
    and is no less accurate against the dense operator; a larger admissibility keeps fewer
    near entries; ranks rounded up to a step are no fewer; they reach the operator through
    ``operator_tol``; bad values get femehl's error naming the range."""
    disc = FEDisc(sphere, mesh=fitted_disk(sphere, 5.0, 1.0), operator="dense")
    dense = disc.boussinesq()
    z = np.random.default_rng(5).standard_normal(disc.n)
    coarse = FastCompliance(disc, FastOptions(svd_ratio=100.0), coarse=False)
    fine = FastCompliance(disc, FastOptions(svd_ratio=0.01), coarse=False)
    assert fine.info["svd_ratio"] == 0.01 and fine.H.p == order_for(1e-6)
    assert fine.info["far_rank_mean"] > coarse.info["far_rank_mean"]
    assert _rel(fine @ z, dense @ z) <= _rel(coarse @ z, dense @ z)
    assert FastCompliance(disc, FastOptions(p=6), coarse=False).H.p == 6
    wide = FastCompliance(disc, FastOptions(eta=4.0), coarse=False)
    assert wide.info["eta"] == 4.0 and wide.info["near_nnz"] < fine.info["near_nnz"]
    stepped = FastCompliance(disc, FastOptions(rank_step=8), coarse=False)
    assert stepped.info["rank_step"] == 8 and stepped.H.nbytes > FastCompliance(disc, coarse=False).H.nbytes
    via_solve = FEDisc(sphere, mesh=disc.dm, operator="fast", operator_tol=FastOptions(p=7))
    assert via_solve.boussinesq().H.p == 7 and via_solve.fast_options.tol == 1e-6
    bad = ({"p": 1}, {"p": 9.5}, {"p": True}, {"svd_ratio": 0.0}, {"svd_ratio": float("nan")}, {"eta": 0.1})
    for kwargs in bad + ({"eta": "2"}, {"rank_step": 0}, {"tol": 1.0}):
        with pytest.raises(SceneError, match="p must|svd_ratio must|eta must|rank_step must|operator_tol"):
            FastOptions(**kwargs)
    for value in ("small", True, [1e-6]):
        with pytest.raises(SceneError, match="operator_tol must be"):
            FastCompliance(disc, value)


def _admissible_grids(n, p, seed):
    """Chebyshev grids of ``n`` random box pairs at the fast operator's admissibility."""
    rng = np.random.default_rng(seed)
    lo = rng.uniform(-1.0, 1.0, (n, 2))
    hi = lo + rng.uniform(0.1, 1.0, (n, 2))
    diam = np.hypot(*(hi - lo).T)
    angle = rng.uniform(0.0, 2.0 * np.pi, n)
    # the source box at distance diam / ETA from the target box along a random direction
    shift = (2.0 * diam + diam / ETA)[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    nodes = _cheb(p)
    return _grid(lo, hi, nodes), _grid(lo + shift, hi + shift, nodes)


def test_coupling_kernel_and_interpolation_pieces():
    """The compiled coupling kernel against 1 / |x - y| written out; the Lagrange basis
    is 1 at its own node and 0 at the others, and sums to 1 anywhere."""
    p = 7
    gt, gs = _admissible_grids(3, p, seed=4)
    K = _kernel_blocks(gt, gs)
    b, i, j = 2, 3 * p + 5, 6 * p + 1  # target node (3, 5), source node (6, 1)
    exact = 1.0 / np.hypot(gt[b, 3, 0] - gs[b, 6, 0], gt[b, 5, 1] - gs[b, 1, 1])
    assert K[b, i, j] == pytest.approx(exact, rel=1e-15)
    nodes = _cheb(p)
    assert np.allclose(_lagrange(nodes, nodes), np.eye(p), atol=1e-14)
    s = np.linspace(-1.0, 1.0, 101)
    assert np.allclose(_lagrange(s, nodes).sum(axis=1), 1.0, atol=1e-13)


@pytest.mark.parametrize("width", [32, 8], ids=["range-finder", "full-svd-fallback"])
def test_coupling_compression_bounded_by_the_full_svd(width):
    """The couplings' random range finder (``_low_rank``): every block's truncation error
    is at most 1.1 times the full SVD's bound (``tol`` times its largest singular value:
    the range residual is accepted at 0.1 of it), every block is returned once, and at a
    width below the blocks' ranks (about 14 at p = 11) the full SVD takes them."""
    p, tol = 11, 3e-7
    gt, gs = _admissible_grids(40, p, seed=5)
    K = _kernel_blocks(gt, gs)
    s_full = np.linalg.svd(K, compute_uv=False)
    seen, widths = np.zeros(K.shape[0], int), set()
    for blocks, u, s, vt in _low_rank(K, tol, width):
        seen[blocks] += 1
        widths.add(s.shape[1])
        for n, b in enumerate(blocks):
            r = max(1, int((s[n] > tol * s[n, 0]).sum()))
            err = np.linalg.norm(K[b] - (u[n, :, :r] * s[n, :r]) @ vt[n, :r], 2)
            assert err <= 1.1 * tol * s_full[b, 0]
    assert np.all(seen == 1)
    assert widths == {p * p} if width == 8 else width in widths


def test_uniform_pressure_on_a_disk():
    """X 1 over a triangulated disk of radius a against 2 pi a (centre) and 4 a E(r^2/a^2).

    The polygonal disk misses the area ``dA = pi a^2 - area(polygon)`` near r = a, so at a
    point at distance >= delta from the rim the exact integral differs from the circle's by
    at most ``dA / delta``: that bound is the tolerance (no fitted constant).
    """
    from skfem import MeshTri

    a = 0.5
    m = MeshTri.init_circle(5)  # 4,096 triangles: the dense check costs 1 s (33 s at 6)
    p = m.p * a
    tri = np.transpose(p[:, m.t], (2, 1, 0))
    cen = tri.mean(axis=1)
    ne = tri.shape[0]
    H = H2Operator(cen, tri, np.arange(ne), ne, p=order_for(1e-6))
    assert H.n_far > 0
    u = H @ np.ones(ne)
    x1, x2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    area = 0.5 * np.abs(x1[:, 0] * x2[:, 1] - x1[:, 1] * x2[:, 0]).sum()
    deficit = np.pi * a**2 - area
    assert 0 < deficit < 1e-3 * np.pi * a**2
    r = np.hypot(cen[:, 0], cen[:, 1])
    inside = r <= 0.8 * a
    delta = a - r[inside]
    exact = 4.0 * a * ellipe((r[inside] / a) ** 2)
    assert np.all(np.abs(u[inside] - exact) <= deficit / delta + 1e-6 * exact)
    # the centre: 2 pi a
    centre = triangle_influence(np.zeros((1, 2)), tri).sum()
    # (the missing slivers lie at distance a cos(pi / sides) .. a from the centre)
    assert abs(centre - 2 * np.pi * a) <= deficit / (0.99 * a)
    # and the fast operator agrees with the exact dense integrals to its tolerance
    exact_dense = triangle_influence(cen, tri).sum(axis=1)
    assert _rel(u, exact_dense) <= 1e-6


@pytest.fixture(scope="module")
def ladder_runs(sphere):
    """The first 12 steps of the paper case with the fast operator on two meshes."""
    out = {}
    for level in (1.41, 0.71):
        dm = fitted_disk(sphere, 5.0, level)
        out[level] = femehl.solve(
            sphere, t_end=0.12, dt=0.01, mesh=dm, scheme="bdf2", operator="fast", estimate=False
        )
    return out


def test_krylov_iterations_bounded_under_refinement(ladder_runs):
    """Four times the elements must not need many more iterations per step.

    A preconditioner that ignored the elastic coupling (the near-field diagonal only) needs
    24 -> 28 iterations from scratch over the same refinement; from scratch to 1e-9 the
    near-field sparse LU needs 11-13 and, with the coarse correction before it, 6-8 on 780
    to 2,904 unknowns (tests/test_coarse_space.py); with recycling about 4-5 per step in
    these first steps (benchmarks/fast_operator.md).  Bound: the finer mesh within 1.5 x + 1 of the coarser.
    """
    its = {}
    for level, res in ladder_runs.items():
        assert res.info["operator"] == "fast"
        its[level] = res.info["krylov_iterations"] / res.nsteps
    assert ladder_runs[0.71].info["elements"] >= 3 * ladder_runs[1.41].info["elements"]
    assert its[0.71] <= 1.5 * its[1.41] + 1.0
    assert its[0.71] <= 15


def test_memory_grows_linearly(ladder_runs):
    """Bytes per element of the fast operator within 1.6 x over a 4 x refinement (dense: 4 x)."""
    per = {lv: r.info["operator_bytes"] / r.info["elements"] for lv, r in ladder_runs.items()}
    assert per[0.71] <= 1.6 * per[1.41]


def test_short_run_agrees_with_dense(sphere):
    """Load and films of 20 steps of the paper case: fast against dense to 1e-6."""
    dm = fitted_disk(sphere, 5.0, 1.0)
    runs = {
        op: femehl.solve(sphere, t_end=0.2, dt=0.01, mesh=dm, scheme="bdf2", operator=op, estimate=False)
        for op in ("dense", "fast")
    }
    assert runs["fast"].info["operator"] == "fast" and runs["dense"].info["operator"] == "dense"
    for q in ("load", "film_center", "film_min"):
        a, b = np.asarray(getattr(runs["dense"], q)), np.asarray(getattr(runs["fast"], q))
        scale = np.maximum(np.abs(a), 1e-3 * np.abs(a).max())
        assert np.max(np.abs(a - b) / scale) <= 1e-6, q


def test_auto_picks_by_size(sphere):
    """ "auto" is dense below the crossover and fast above it (no operator is built here)."""
    from femehl.discretize import fe_disk

    small = FEDisc(sphere, mesh="coarse")
    large = FEDisc(sphere, mesh=fitted_disk(sphere, 5.0, 0.45))
    assert small.nelements < fe_disk.FAST_CROSSOVER <= large.nelements
    assert (small.operator, large.operator) == ("dense", "fast")
    assert FEDisc(sphere, mesh="coarse", operator="fast").operator == "fast"


@pytest.mark.parametrize(
    "options, match",
    [
        ({"operator": "bogus"}, "operator must be one of"),
        ({"operator": "fast", "operator_tol": 0.0}, "operator_tol must be"),
        ({"operator": "fast", "operator_tol": "small"}, "operator_tol must be"),
        ({"operator": "fast", "linear_solver": "lu"}, "needs the dense elastic operator"),
    ],
)
def test_bad_operator_options(sphere, options, match):
    with pytest.raises(SceneError, match=match):
        femehl.solve(sphere, t_end=0.02, dt=0.01, mesh="coarse", estimate=False, **options)


def test_operator_keeps_a_run_automatic():
    from femehl.api import is_automatic

    scene = paper_sphere()
    assert is_automatic(scene, None, None, {"operator": "fast"})
    assert not is_automatic(scene, None, None, {"mesh": "coarse", "operator": "fast"})


def test_cli_operator_flag(tmp_path, capsys):
    from femehl.cli import main

    out = tmp_path / "run"
    argv = ["run", "--mesh", "coarse", "--operator", "fast", "--dt", "0.01", "--t-end", "0.03", "--quiet"]
    assert main([*argv, "--out", str(out)]) == 0
    assert (out / "summary.csv").is_file()
    assert "operator=fast" in capsys.readouterr().err


def test_scene_file_operator(tmp_path, capsys):
    """``[run] operator = ...`` reaches the run; a bad value is femehl's error naming the choices."""
    from femehl.cli import main

    text = (EXAMPLES / "paper_sphere.toml").read_text()
    good = tmp_path / "fast.toml"
    good.write_text(text.replace('mesh = "medium"', 'mesh = "coarse"\noperator = "fast"'))
    out = tmp_path / "run"
    assert main(["run", str(good), "--t-end", "0.03", "--quiet", "--out", str(out)]) == 0
    assert "operator=fast" in capsys.readouterr().err
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace('mesh = "medium"', 'mesh = "coarse"\noperator = "quick"'))
    assert main(["run", str(bad), "--t-end", "0.03", "--quiet", "--out", str(tmp_path / "b")]) != 0
    assert "operator must be one of" in capsys.readouterr().err
