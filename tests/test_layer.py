"""``femehl.Layer``: an elastic layer of finite thickness on a rigid base.

Every check goes through a route independent of the code under test:

* the transform factor K(t) against a numerical solution of the layer's boundary-value
  problem (a Fourier mode of the load is a plane-strain problem; the Navier equations as a
  first-order system across the layer, a matrix exponential, the boundary conditions);
* the tabulated Green's function against mpmath quadrature and the direct Hankel sum;
* the triangle integrals against subdivided-triangle Gauss rules and a uniform disk
  pressure against its exact Hankel integral;
* the limits: h -> inf (the half space), h -> 0 (Winkler, thin incompressible layer).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import scipy.integrate as si
import scipy.linalg as sl
import scipy.special as ss

import femehl
from femehl.discretize.fe_disk import FEDisc
from femehl.elastic import kernels
from femehl.elastic.layer_kernel import (
    LayerKernel,
    hankel_table,
    layer_factor,
    layer_table,
    thin_layer_factor,
    winkler_limit,
)
from femehl.errors import SceneError, SceneFileError
from femehl.problem.scenefile import scene_from_mapping


# ---- 1. K(t) against the boundary-value problem -----------------------------------------
def k_bvp(t, nu, bonded=True):
    """K(t) of a plane-strain Fourier mode e^{ikx} (k = G = 1) on a layer of thickness t.

    State y = (U, W, S, T): displacements u_x = U, u_z = W, stresses sigma_xz = S,
    sigma_zz = T; Navier equations y' = A y (written with lambda/(lambda + 2G) and
    1/(lambda + 2G), finite at nu = 1/2).  Base z = -t: U = W = 0 (bonded) or W = S = 0
    (frictionless); top z = 0: S = 0, T = -1.  K = -W(0) G k / (1 - nu).
    """
    a = nu / (1 - nu)
    b = (1 - 2 * nu) / (2 * (1 - nu))
    c4 = 2 / (1 - nu)
    ik = 1j
    A = np.array([[0, -ik, 1, 0], [-ik * a, 0, 0, b], [c4, 0, 0, -ik * a], [0, 0, -ik, 0]])
    M = sl.expm(A * t)
    cols = [2, 3] if bonded else [0, 3]
    x = np.linalg.solve(M[np.ix_([2, 3], cols)], [0.0, -1.0])
    return -(M[1, cols] @ x).real / (1 - nu)


@pytest.mark.parametrize("nu", [-0.5, 0.0, 0.3, 0.45, 0.5])
@pytest.mark.parametrize("bonded", [True, False])
def test_factor_matches_boundary_value_problem(nu, bonded):
    t = np.array([0.01, 0.1, 0.5, 1.0, 2.0, 5.0])
    ref = np.array([k_bvp(x, nu, bonded) for x in t])
    # the matrix exponential is exact to round-off; 1e-11 leaves room for its e^{2t} growth
    assert np.allclose(layer_factor(t, nu, bonded), ref, rtol=1e-11, atol=1e-14)


def test_factor_limits():
    t = np.array([1e-3])
    for nu in (0.0, 0.3):  # oedometric slope
        assert layer_factor(t, nu)[0] / t[0] == pytest.approx((1 - 2 * nu) / (2 * (1 - nu) ** 2), rel=1e-5)
    assert layer_factor(t, 0.5)[0] / t[0] ** 3 == pytest.approx(2 / 3, rel=1e-5)  # thin incompressible
    assert layer_factor(t, 0.3, False)[0] / t[0] == pytest.approx(0.5, rel=1e-5)
    assert np.allclose(layer_factor(np.array([30.0, 200.0]), 0.3), 1.0, atol=1e-12)


# ---- 2. the tabulated Green's function ----------------------------------------------------
def test_table_against_mpmath_and_direct_sum():
    mpmath = pytest.importorskip("mpmath")
    T = layer_table(0.5, True)
    ka = 1.0
    for rho in (0.0, 3.0, 25.0):

        def f(t, rho=rho):
            K = (2 * ka * mpmath.sinh(2 * t) - 4 * t) / (2 * ka * mpmath.cosh(2 * t) + 1 + ka**2 + 4 * t**2)
            return (1 - K) * mpmath.besselj(0, t * rho)

        ref = float(mpmath.quad(f, mpmath.linspace(0, 30, 121)))
        assert T.R(np.array([rho]))[0] == pytest.approx(ref, abs=1e-12)
    # interpolation error off the grid: <= 2e-12 of R(0) (the module's statement)
    rho = np.random.default_rng(0).uniform(0.0, 1.1 * T.rho_cut, 600)
    ref = hankel_table(rho, 0.5, True)
    assert np.max(np.abs(T.R(rho) - ref[0])) <= 2e-12 * T.R0
    assert np.max(np.abs(T.F(rho) - ref[2])) <= 2e-12 * T.R0
    # F = (1/rho^2) int_0^rho s R ds (the polar integrals rely on it)
    for r in (0.5, 4.0, 20.0):
        q = si.quad(lambda s: s * T.R(np.array([s]))[0], 0, r, limit=200)[0]
        assert T.F(np.array([r]))[0] == pytest.approx(q / r**2, rel=1e-9)


@pytest.mark.parametrize("nu, y", [(0.5, 0.739085), (0.3, 0.912785), (0.0, 1.189617)])
def test_green_function_decays_exponentially(nu, y):
    T = layer_table(nu, True)
    assert T.decay == pytest.approx(y, rel=1e-5)
    rho = np.array([8.0, 12.0, 16.0])
    d = np.abs(1.0 / rho - hankel_table(rho, nu)[0])
    rate = -np.diff(np.log(d)) / np.diff(rho)
    # g ~ exp(-y rho) rho^(-1/2): the measured log slope tends to y from above
    assert np.all(rate > y) and rate[-1] == pytest.approx(y, rel=0.06)
    far = np.array([T.rho_cut, 2 * T.rho_cut])
    assert np.allclose(T.R(far), 1.0 / far, rtol=0, atol=1e-14)


# ---- 5. uniform pressure on a disk: the primitive against the exact Hankel integral -----
def _polar_disk(a, nr, nt):
    r = np.linspace(0, a, nr + 1)
    th = np.linspace(0, 2 * np.pi, nt + 1)
    R, TH = np.meshgrid(r, th, indexing="ij")
    P = np.stack([R * np.cos(TH), R * np.sin(TH)], -1)
    tri = [np.stack([P[0, 0], P[1, j], P[1, j + 1]]) for j in range(nt)]
    for i in range(1, nr):
        for j in range(nt):
            tri.append(np.stack([P[i, j], P[i + 1, j], P[i + 1, j + 1]]))
            tri.append(np.stack([P[i, j], P[i + 1, j + 1], P[i, j + 1]]))
    return np.array(tri)


def _disk_hankel(r, a, h, nu):
    """int_disk (1/r - R) dA = 2 pi a int K(k h) J1(k a) J0(k r) / k dk (half space: 2 pi a at 0)."""
    f = lambda k: layer_factor(np.array([k * h]), nu)[0] * ss.j1(k * a) * ss.j0(k * r) / k  # noqa: E731
    g = lambda k: ss.j1(k * a) * ss.j0(k * r) / k  # noqa: E731
    return 2 * np.pi * a * (si.quad(f, 0, 200, limit=4000)[0] + si.quad(g, 200, 4000, limit=20000)[0])


@pytest.mark.parametrize("h", [0.2, 1.0, 5.0])
def test_uniform_disk_pressure(h):
    a, nu = 1.0, 0.5
    tri = _polar_disk(a, 24, 96)
    pts = np.array([[0.0, 0.0], [0.5, 0.0], [0.9, 0.1], [1.5, 0.0], [3.0, 0.0]])
    X = kernels.radial_influence(pts, tri, LayerKernel(h, nu))
    num = np.asarray(X.sum(axis=1)).ravel()
    ref = np.array([_disk_hankel(np.hypot(*p), a, h, nu) for p in pts])
    # the polygon (96 sides) misses 1 - (96/2pi) sin(2pi/96) = 7e-4 of the disk's area:
    # that is the error of both the 1/r and the layer sums, at every radius
    scale = np.abs(ref).max()
    assert np.allclose(num, ref, rtol=2e-3, atol=1e-3 * scale)


# ---- 6. element size: exact whatever the triangle's size relative to h --------------------
def _subdivide(tri, n):
    P0, P1, P2 = tri
    out = []
    for a in range(n):
        for b in range(n - a):

            def p(i, j):
                return P0 + (P1 - P0) * i / n + (P2 - P0) * j / n

            out.append([p(a, b), p(a + 1, b), p(a, b + 1)])
            if a + b < n - 1:
                out.append([p(a + 1, b), p(a + 1, b + 1), p(a, b + 1)])
    return np.array(out)


@pytest.mark.parametrize("size", [0.05, 0.3, 2.0, 8.0])
def test_triangle_integral_any_size(size):
    ker = LayerKernel(1.0, 0.3)
    tri = np.array([[0.0, 0.0], [1.0, 0.2], [0.3, 0.9]]) * size
    rng = np.random.default_rng(3)
    pts = (
        np.r_[[[0.3, 0.3], [0.0, 0.0], [0.5, 0.1], [1.5, 0.5], [0.3, -0.01]], rng.uniform(-1, 2, (6, 2))]
        * size
    )
    i, j = np.arange(len(pts)), np.zeros(len(pts), int)
    got = kernels.radial_triangle_pairs(pts, tri[None], i, j, ker)
    # reference: the 7-point rule on sub-triangles of diameter <= h/20 (its error <= 1e-13)
    sub = _subdivide(tri, max(4, int(np.ceil(size * 1.3 / 0.05))))
    ii, jj = np.repeat(i, len(sub)), np.tile(np.arange(len(sub)), len(pts))
    smooth = np.bincount(ii, kernels._smooth_gauss(pts, sub, ii, jj, ker), minlength=len(pts))
    ref = kernels.singular_pairs(pts, tri[None], i, j) - smooth
    area = kernels.triangle_areas(tri[None])[0]
    # relative to the triangle's area over h (the scale of the smooth part): round-off
    assert np.max(np.abs(got - ref)) <= 1e-10 * area


# ---- the FE operator: limits --------------------------------------------------------------
@pytest.fixture(scope="module")
def coarse():
    return FEDisc(femehl.presets.paper_sphere(), mesh="coarse")


def test_thick_layer_is_the_half_space(coarse):
    C0 = coarse.boussinesq()
    diffs = []
    for h in (100.0, 1000.0):
        C = femehl.Layer(h).compliance_operator(coarse)
        diffs.append(np.abs(C - C0).max() / np.abs(C0).max())
    # C - C0 = -X_R P with R ~ R(0)/h = 1.77/h: O(contact/h), and it falls like 1/h
    assert diffs[0] < 1e-2
    assert diffs[1] == pytest.approx(diffs[0] / 10, rel=0.05)


def test_rows_agree_with_operator(coarse):
    # a thick layer's operator takes the low-rank smooth part (interpolation error <= 1e-9
    # of R(0) per pair), an intermediate one the FFT grid (<= 1e-8), its rows the direct
    # quadrature; thinner ones the pairs within the cut-off (dense or sparse), rows and all
    forms = {}
    for sub, tol in (
        (femehl.Layer(1.0), 1e-7),
        (femehl.Layer(0.3), 5e-8),
        (femehl.Layer(0.02, nu=0.3), 1e-12),
        (femehl.Layer(0.005, nu=0.3), 1e-12),
    ):
        C = sub.compliance_operator(coarse)
        forms[sub.thickness] = coarse.info["radial_kernel"]
        C = C.toarray() if hasattr(C, "toarray") else C
        rows = sub.deflection_rows(coarse, coarse.centroids[:12])
        rows = rows.toarray() if hasattr(rows, "toarray") else rows
        assert np.allclose(rows, C[:12], rtol=0, atol=tol * np.abs(C).max())
    assert sub.deflection_rows(coarse, [[0.0, 0.0]]).shape == (1, coarse.n)
    assert forms == {
        1.0: "dense, low-rank smooth part",
        0.3: "dense, grid smooth part",
        0.02: "dense, pairs within the cut-off",
        0.005: "sparse",
    }


def _gaussian(points, s):
    return np.exp(-np.sum(np.asarray(points) ** 2, axis=1) / s**2)


@pytest.mark.parametrize("h, tol", [(0.01, 0.01), (0.003, 0.002)])
def test_thin_compressible_layer_is_winkler(coarse, h, tol):
    nu, s = 0.3, 0.5
    p = _gaussian(coarse.nodes[coarse.free], s)
    sub = femehl.Layer(h, nu=nu)
    C = sub.compliance_operator(coarse)
    assert hasattr(C, "nnz")  # a thin layer's operator is sparse
    w = C @ p
    w_winkler = (coarse.average() @ p) / winkler_limit(h, nu)
    # K(t) = K'(0) t (1 + O(t^2)): relative error about (h/s)^2 ~ 4e-4 .. 4e-5, plus where
    # the kernel (width ~h) reaches past an element edge (centroids lie >= ~0.01 inside)
    assert np.max(np.abs(w - w_winkler)) <= tol * np.abs(w_winkler).max()


def test_thin_incompressible_layer_hankel():
    """w = (4 pi h^3/3) lap p for a Gaussian p = exp(-r^2/s^2), exactly in Hankel space."""
    # the next order of K(t) = 2t^3/3 (1 + O(t^2)): measured error 14 (h/s)^2 of the peak
    # 4a/s^2 (12 % at h/s = 0.1, 3.4 % at 0.05, 0.57 % at 0.02, 0.14 % at 0.01): within 1 %
    # for h <= 0.025 s, within 5 % for h <= 0.06 s
    s = 1.0
    for h, tol in ((0.05, 0.04), (0.02, 0.007)):
        for r in (0.0, 0.7, 1.5):

            def f(k, h=h, r=r):
                return (
                    layer_factor(np.array([k * h]), 0.5)[0]
                    * np.pi
                    * s**2
                    * np.exp(-((k * s) ** 2) / 4)
                    * ss.j0(k * r)
                )

            w = -si.quad(f, 0, 60, limit=400)[0]  # c = 1
            lap = (4 * r**2 / s**4 - 4 / s**2) * np.exp(-(r**2) / s**2)
            assert abs(w - thin_layer_factor(h) * lap) <= tol * 4 * thin_layer_factor(h) / s**2


def test_fe_operator_gaussian_against_hankel(coarse):
    """The FE layer operator on a smooth pressure against the exact Hankel deflection."""
    s, h, nu = 0.7, 0.5, 0.5
    p = _gaussian(coarse.nodes[coarse.free], s)
    pts = np.array([[0.0, 0.0], [0.4, 0.2], [0.8, 0.0], [1.3, 0.5]])
    w = femehl.Layer(h, nu).deflection_rows(coarse, pts) @ p
    ref = []
    for pt in pts:
        r = np.hypot(*pt)

        def f(k, r=r):
            pk = np.pi * s**2 * np.exp(-((k * s) ** 2) / 4)  # the transform of p
            return layer_factor(np.array([k * h]), nu)[0] * pk * ss.j0(k * r)

        ref.append(si.quad(f, 0, 80, limit=400)[0])
    # discretization: the element average of the P1 pressure; measured 2.1 % of the peak on
    # the coarse mesh, 1.0 % on the medium one (h = 0.2: 3.6 %, 1.5 %): second order
    assert np.allclose(w, ref, rtol=0, atol=0.03 * np.abs(ref).max())


def test_fd_operator_matches_its_half_space_for_thick_layers():
    import math as m

    sc = femehl.presets.paper_sphere()
    from femehl.discretize.fd_polar import FDDisc

    fd = FDDisc(sc, dr=0.2, dtheta=m.pi / 6)
    C0 = fd.boussinesq()
    C = femehl.Layer(1e4).compliance_operator(fd)
    assert np.abs(C - C0).max() <= 1e-3 * np.abs(C0).max()


def test_winkler_run_limit():
    """A thin compressible layer runs like femehl.Winkler(k) (short approach, coarse mesh)."""
    h, nu = 0.004, 0.3
    base = femehl.Scene(
        substrate=femehl.Layer(h, nu=nu),
        fluid=femehl.Fluid(200.0),
        motion=femehl.Motion(gap=femehl.RampHold(0.1, -0.1, 1.0), velocity=0.0),
        domain=femehl.Domain(2.0),
    )
    run = dict(t_end=0.6, dt=0.05, mesh="coarse", linear_solver="lu")
    a = femehl.solve(base, **run)
    b = femehl.solve(dataclasses.replace(base, substrate=femehl.Winkler(winkler_limit(h, nu))), **run)
    # the operators on the film points agree to O((h/a)^2) (a ~ 0.3 the pressure's length):
    # loads and deflections w = d - shape to 1e-3.  (The central *film* d = hc + w at the
    # origin node is a small difference of large terms, and the layer reads the element
    # averages around the node where Winkler reads the nodal pressure: not compared.)
    assert np.allclose(a.load, b.load, rtol=1e-3)
    wa = [s.d - a.disc.shape for s in a.states]
    wb = [s.d - b.disc.shape for s in b.states]
    for x, y in zip(wa, wb, strict=True):
        assert np.abs(x - y).max() <= 1e-3 * np.abs(y).max() + 1e-12


# ---- 7. bad input, scene files, refused combinations --------------------------------------
@pytest.mark.parametrize(
    "kw, msg",
    [
        (dict(thickness=0.0), "> 0"),
        (dict(thickness=-1.0), "> 0"),
        (dict(thickness=math.inf), "finite"),
        (dict(thickness=math.nan), "finite"),
        (dict(thickness="1"), "real number"),
        (dict(thickness=1.0, nu=0.6), r"\(-1, 0.5\]"),
        (dict(thickness=1.0, nu=-1.0), r"\(-1, 0.5\]"),
        (dict(thickness=1.0, nu=math.nan), "finite"),
        (dict(thickness=1.0, bonded=1), "True"),
        (dict(thickness=1.0, bonded="yes"), "True"),
    ],
)
def test_bad_layer(kw, msg):
    with pytest.raises(SceneError, match=msg):
        femehl.Layer(**kw)


def test_layer_in_scene_files(tmp_path):
    sc, _ = scene_from_mapping(
        {"substrate": {"kind": "layer", "thickness": 0.5, "nu": 0.4}}, tmp_path / "a.toml"
    )
    assert sc.substrate == femehl.Layer(0.5, 0.4, True)
    with pytest.raises(SceneFileError, match="does not take"):
        scene_from_mapping({"substrate": {"kind": "layer", "thickness": 0.5, "h": 1}}, tmp_path / "a.toml")
    with pytest.raises(SceneFileError, match="> 0"):
        scene_from_mapping({"substrate": {"kind": "layer", "thickness": -0.5}}, tmp_path / "a.toml")
    si_tab = dict(R=0.01, G=1e5, eta=1.0, V_ss=1e-3, h_inf=1e-5, nu=0.45, h0=1e-6)
    sc, _ = scene_from_mapping({"si": {**si_tab, "layer_thickness": 2e-4}}, tmp_path / "b.toml")
    dim = femehl.Dimensional(0.01, 1e5, 1.0, 1e-3, 1e-5, 0.45)
    assert sc.substrate == femehl.Layer(2e-4 / dim.length, nu=0.45)
    with pytest.raises(SceneFileError, match="layer_thickness"):
        scene_from_mapping({"si": {**si_tab, "layer_thickness": 0.0}}, tmp_path / "b.toml")


def test_refused_combinations(tmp_path):
    sc = dataclasses.replace(femehl.presets.paper_sphere(), substrate=femehl.Layer(0.5))
    with pytest.raises(SceneError, match="operator='dense'"):
        FEDisc(sc, mesh="coarse", operator="fast")
    assert FEDisc(sc, mesh="coarse", operator="auto").operator == "dense"
    # a viscoelastic layer relaxes the layer's dense operator: no fast one either
    visco = dataclasses.replace(sc, substrate=femehl.Viscoelastic(2.0, 1.0, elastic=femehl.Layer(0.5)))
    with pytest.raises(SceneError, match="operator='dense'"):
        FEDisc(visco, mesh="coarse", operator="fast")
    # line contact takes a Winkler foundation only
    with pytest.raises(SceneFileError, match="winkler"):
        scene_from_mapping(
            {"indenter": {"kind": "cylinder"}, "substrate": {"kind": "layer", "thickness": 0.5}},
            tmp_path / "c.toml",
        )
    from femehl.discretize.fe_line import LineDisc
    from femehl.problem.line import LineScene

    with pytest.raises(SceneError, match="method='fe'"):
        femehl.Layer(0.5).compliance_operator(LineDisc(LineScene(k=1.0)))
    with pytest.raises(SceneError, match="LineScene"):
        femehl.solve(sc, method="line", t_end=0.1, dt=0.05)


def test_exported():
    assert femehl.Layer is femehl.elastic.Layer
    assert femehl.elastic.SUBSTRATES["layer"] is femehl.Layer


def test_grid_smooth_part_matches_direct(coarse):
    """The FFT-grid smooth part (intermediate thickness) against the direct quadrature."""
    ker = LayerKernel(0.3, 0.5)
    P = coarse.P[:, coarse.free]
    rows = np.arange(0, coarse.nelements, 97)
    G = kernels.smooth_grid_apply(coarse.centroids, coarse.tri, ker, P, mirror_y=True)
    XR = kernels.smooth_matrix(coarse.centroids[rows], coarse.tri, ker, mirror_y=True)
    ref = np.asarray(P.T @ XR.T).T
    # local Lagrange degree 11 on a grid of spacing h/6: measured 6e-9 .. 1e-8 (medium mesh)
    assert np.abs(G[rows] - ref).max() <= 5e-8 * np.abs(ref).max()


def test_thick_layer_run_approaches_the_half_space():
    """The paper case (indentation to t = 0.5, coarse mesh) on Layer(h) -> HalfSpace as h grows."""
    sc = femehl.presets.paper_sphere()
    run = dict(t_end=0.5, dt=0.05, mesh="coarse", linear_solver="lu")
    ref = femehl.solve(sc, **run)
    err = []
    for h in (100.0, 1000.0):
        r = femehl.solve(dataclasses.replace(sc, substrate=femehl.Layer(h)), **run)
        err.append(np.abs(r.load - ref.load).max() / np.abs(ref.load).max())
    # the layer is stiffer by O(contact/h): load 8.3e-3 at h = 100, ten times less at 1000
    assert err[0] < 1.5e-2
    assert err[1] == pytest.approx(err[0] / 10, rel=0.1)
