"""femehl.reference.theory against independent computations.

The Hamrock-Dowson films are evaluated here in SI units straight from the published form
(``H = A U^a W^b (1 - C exp(-D k))`` with ``U = eta u/(E' Rx)``, ``W = F/(E' Rx^2)``,
``H = h/Rx``), then converted to femehl's normalization by hand; the ellipsoid Hertz load
is checked against a direct numerical evaluation of the Boussinesq displacement of a
Hertz elliptical pressure (no elliptic integrals).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from femehl.errors import SceneError
from femehl.reference import theory

# ----------------------------------------------------------------- SI <-> femehl by hand


def _si_to_femehl(G, eta, V, R, h_inf, F_si):
    beta = (2.0 / 3.0) * (h_inf**2 / R) * math.pi * G / (eta * V)
    F = F_si / (4.0 * math.pi * G * math.sqrt(h_inf / R) * R * h_inf)
    return beta, F, h_inf / R


def _hd_si(coef, G, nu, eta, V, Rx_si, F_si, k):
    """Film in metres from the Hamrock-Dowson form, rigid indenter on an elastic body."""
    A, a, b, C, D = coef
    E = 2.0 * G * (1.0 + nu)
    E_prime = 2.0 / ((1.0 - nu**2) / E)  # 2/E' = (1 - nu_a^2)/E_a + 0 (rigid body b)
    u = 0.5 * (V + 0.0)  # mean of the two surface speeds: substrate V, indenter 0
    U = eta * u / (E_prime * Rx_si)
    W = F_si / (E_prime * Rx_si**2)
    H = A * U**a * W**b * (1.0 - C * math.exp(-D * k))
    return H * Rx_si


CENTRAL = (7.32, 0.64, -0.22, 0.72, 0.28)
MINIMUM = (7.43, 0.65, -0.21, 0.85, 0.31)


def test_hd_central_sphere_matches_si():
    G, nu, eta, V, R, h_inf, F_si = 2.0e4, 0.5, 0.05, 2.0e-3, 5.0e-3, 4.0e-6, 0.02
    h_si = _hd_si(CENTRAL, G, nu, eta, V, R, F_si, k=1.0)
    beta, F, eps = _si_to_femehl(G, eta, V, R, h_inf, F_si)
    d = theory.hd_central_film(beta, F, eps=eps)
    assert d == pytest.approx(h_si / h_inf, rel=1e-12)
    assert theory.hd_film(beta, F, "central", eps=eps) == pytest.approx(h_si / h_inf, rel=1e-12)


@pytest.mark.parametrize("nu", [0.5, 0.3, 0.0])
def test_hd_minimum_compressible_ellipsoid_matches_si(nu):
    G, eta, V, R, h_inf, F_si = 5.0e5, 0.2, 1.0e-2, 1.0e-2, 2.0e-6, 0.5
    Rx, Ry = 0.5, 2.0  # in units of R
    k = 1.0339 * (Ry / Rx) ** 0.636
    h_si = _hd_si(MINIMUM, G, nu, eta, V, Rx * R, F_si, k=k)
    beta, F, eps = _si_to_femehl(G, eta, V, R, h_inf, F_si)
    d = theory.hd_minimum_film(beta, F, Rx=Rx, Ry=Ry, nu=nu, eps=eps, k=k)
    assert d == pytest.approx(h_si / h_inf, rel=1e-12)
    # the same through the approximate ellipticity helper
    assert theory.ellipticity(Rx, Ry, method="hamrock_brewe") == pytest.approx(k, rel=1e-15)


def test_hd_groups_match_si():
    G, nu, eta, V, R, h_inf, F_si = 1.0e5, 0.4, 0.01, 0.05, 2.0e-2, 1.0e-5, 0.3
    E_prime = 2.0 * 2.0 * G * (1.0 + nu) / (1.0 - nu**2)
    beta, F, eps = _si_to_femehl(G, eta, V, R, h_inf, F_si)
    U, W = theory.hd_groups(beta, F, Rx=1.0, nu=nu, eps=eps)
    assert U == pytest.approx(eta * (V / 2.0) / (E_prime * R), rel=1e-12)
    assert W == pytest.approx(F_si / (E_prime * R**2), rel=1e-12)


@pytest.mark.parametrize("which, a, b", [("central", 0.64, -0.22), ("minimum", 0.65, -0.21)])
def test_eps_residual_power(which, a, b):
    p = 2.0 * a + 1.5 * b - 1.0  # d = H Rx/eps, U ~ eps^2, W ~ eps^1.5
    e1, e2 = 3.0e-4, 7.0e-3
    d1 = theory.hd_film(150.0, 0.4, which, eps=e1)
    d2 = theory.hd_film(150.0, 0.4, which, eps=e2)
    assert math.log(d1 / d2) / math.log(e1 / e2) == pytest.approx(p, abs=1e-12)
    assert theory.hd_eps_power(which) == pytest.approx(p, abs=1e-15)
    lo, hi = theory.hd_film_band(150.0, 0.4, which)
    assert hi / lo == pytest.approx(100.0 ** abs(p), rel=1e-12)
    assert lo <= theory.hd_film(150.0, 0.4, which) <= hi


def test_eps_powers_values():
    assert theory.hd_eps_power("central") == pytest.approx(-0.05, abs=1e-12)
    assert theory.hd_eps_power("minimum") == pytest.approx(-0.015, abs=1e-12)


def test_beta_and_load_exponents_and_scaling_dict():
    ex = theory.scaling_exponents()
    for which in ("central", "minimum"):
        d = [theory.hd_film(beta, F, which) for beta, F in [(100.0, 0.4), (1000.0, 0.4), (100.0, 0.8)]]
        slope_beta = math.log(d[1] / d[0]) / math.log(10.0)
        slope_load = math.log(d[2] / d[0]) / math.log(2.0)
        assert slope_beta == pytest.approx(ex[f"hd_{which}_beta"]["exponent"], abs=1e-12)
        assert slope_load == pytest.approx(ex[f"hd_{which}_load"]["exponent"], abs=1e-12)
        assert ex[f"hd_{which}_eps"]["exponent"] == pytest.approx(theory.hd_eps_power(which))
    assert ex["hd_central_beta"]["exponent"] == -0.64
    assert ex["hd_minimum_beta"]["exponent"] == -0.65
    assert ex["sev2013_film_speed"]["exponent"] == pytest.approx(-0.6)
    for entry in ex.values():
        assert set(entry) == {"exponent", "variable", "source", "statement"}
        assert entry["source"] and entry["statement"]


# -------------------------------------------------------------------------------- Hertz


def test_hertz_sphere():
    assert theory.hertz_load(1.0) == pytest.approx(4.0 / (3.0 * math.pi), rel=1e-15)
    d = np.array([0.0, 0.25, 1.0, 2.0, 9.0])
    assert np.allclose(theory.hertz_load(d), 4.0 / (3.0 * math.pi) * d**1.5, rtol=1e-14, atol=0)
    # compressible: compliance 2(1 - nu) divides the load
    assert theory.hertz_load(1.0, nu=0.25) == pytest.approx(4.0 / (3.0 * math.pi) / 1.5, rel=1e-14)


def test_hertz_sphere_matches_si():
    G, R, h_inf, delta_si, Rs = 3.0e4, 1.0e-2, 5.0e-6, 7.0e-6, 2.5
    F_si = (16.0 / 3.0) * G * math.sqrt(Rs * R) * delta_si**1.5  # incompressible Hertz
    F = F_si / (4.0 * math.pi * G * math.sqrt(h_inf / R) * R * h_inf)
    assert theory.hertz_load(delta_si / h_inf, Rx=Rs) == pytest.approx(F, rel=1e-13)


@pytest.mark.parametrize("rel", [1e-2, 1e-4, 1e-7, 1e-10])
def test_hertz_ellipsoid_tends_to_sphere(rel):
    sphere = theory.hertz_load(1.3, 0.8)
    assert theory.hertz_load(1.3, 0.8, 0.8 * (1.0 + rel)) == pytest.approx(sphere, rel=2.0 * rel)
    assert theory.hertz_load(1.3, 0.8, 0.8 * (1.0 - rel)) == pytest.approx(sphere, rel=2.0 * rel)


def test_hertz_ellipsoid_scaling_and_symmetry():
    d = np.array([0.5, 1.0, 2.0])
    F = theory.hertz_load(d, 0.5, 3.0)
    assert np.allclose(F / F[1], d**1.5, rtol=1e-13)
    assert theory.hertz_load(1.0, 3.0, 0.5) == pytest.approx(F[1], rel=1e-13)  # same ellipse, rotated
    # Johnson's equivalent sphere sqrt(Rx Ry) is close for moderate ratios (a few percent)
    assert theory.hertz_load(1.0, 1.0, 2.0) == pytest.approx(theory.hertz_load(1.0, math.sqrt(2.0)), rel=0.03)


def _boussinesq_of_hertz_ellipse(ax, ay, x0, y0, n=512):
    """``int p/dist dA`` at (x0, y0) inside the ellipse for ``p = sqrt(1 - x^2/ax^2 - y^2/ay^2)``.

    Polar coordinates about the field point: the radial integral of the pressure along
    each ray is done in closed form, the angular one by the (spectrally accurate)
    periodic trapezoidal rule.
    """
    th = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    c, s = np.cos(th), np.sin(th)
    c2 = c**2 / ax**2 + s**2 / ay**2
    c1 = x0 * c / ax**2 + y0 * s / ay**2
    c0 = 1.0 - x0**2 / ax**2 - y0**2 / ay**2
    R2 = c0 / c2 + (c1 / c2) ** 2
    Rr = np.sqrt(R2)
    u0 = c1 / c2
    radial = np.sqrt(c2) * 0.5 * (R2 * math.pi / 2.0 - u0 * np.sqrt(R2 - u0**2) - R2 * np.arcsin(u0 / Rr))
    return radial.mean() * 2.0 * math.pi


@pytest.mark.parametrize("ax, ay", [(0.8, 1.5), (2.0, 0.7), (1.0, 1.0)])
def test_hertz_ellipsoid_against_direct_boussinesq(ax, ay):
    # Displacement of an elliptical Hertz pressure (p0 = 1): w = L - M x^2 - N y^2 inside.
    pts = [(0.0, 0.0), (0.4 * ax, 0.0), (0.0, 0.4 * ay), (0.3 * ax, -0.5 * ay), (-0.6 * ax, 0.2 * ay)]
    w = np.array([_boussinesq_of_hertz_ellipse(ax, ay, x, y) for x, y in pts])
    L = w[0]
    M = (L - w[1]) / pts[1][0] ** 2
    N = (L - w[2]) / pts[2][1] ** 2
    for (x, y), wi in zip(pts[3:], w[3:], strict=True):
        assert wi == pytest.approx(L - M * x**2 - N * y**2, rel=1e-12)  # it is a Hertz field
    # femehl: |w| = int p/dist (c = 1) and |w| = delta - s in contact, s = x^2/(2Rx) + y^2/(2Ry)
    delta, Rx, Ry = L, 1.0 / (2.0 * M), 1.0 / (2.0 * N)
    load = 2.0 / 3.0 * math.pi * ax * ay  # int p dA for p0 = 1
    assert theory.hertz_load(delta, Rx, Ry) == pytest.approx(load, rel=1e-10)
    assert theory.ellipticity(Rx, Ry) == pytest.approx(ay / ax, rel=1e-10)


def test_ellipticity():
    assert theory.ellipticity(1.0, 1.0) == 1.0
    assert theory.ellipticity(2.0, 2.0) == 1.0
    assert theory.ellipticity(1.0, 4.0) * theory.ellipticity(4.0, 1.0) == pytest.approx(1.0, rel=1e-13)
    ratios = np.array([1.5, 2.0, 5.0, 10.0])
    exact = theory.ellipticity(1.0, ratios)
    approx = theory.ellipticity(1.0, ratios, method="hamrock_brewe")
    assert np.all(np.abs(approx / exact - 1.0) < 0.03)
    assert theory.ellipticity(1.0, 2.0, method="hd1977") == pytest.approx(1.03 * 2.0**0.64)
    # default film uses the exact ellipticity: a sphere has k = 1
    d = theory.hd_central_film(50.0, 0.3)
    assert d == pytest.approx(theory.hd_central_film(50.0, 0.3, k=1.0), rel=1e-15)


# ------------------------------------------------------------------------ vectorization


def test_vectorized_over_beta_and_load():
    beta = np.array([10.0, 100.0, 1000.0])
    load = np.array([[0.2], [0.5]])
    for fn in (theory.hd_central_film, theory.hd_minimum_film):
        d = fn(beta, load)
        assert isinstance(d, np.ndarray) and d.shape == (2, 3)
        for i in range(2):
            for j in range(3):
                dij = fn(float(beta[j]), float(load[i, 0]))
                assert isinstance(dij, float)
                assert d[i, j] == pytest.approx(dij, rel=1e-15)
    lo, hi = theory.hd_film_band(beta, load, "minimum")
    assert lo.shape == hi.shape == (2, 3) and np.all(lo < hi)
    U, W = theory.hd_groups(beta, 0.4)
    assert U.shape == W.shape == (3,)
    assert isinstance(theory.hertz_load(1.0), float)


# ---------------------------------------------------------------------------- bad input


@pytest.mark.parametrize("beta", [0.0, -5.0, float("nan"), float("inf"), [1.0, -1.0], "200"])
def test_bad_beta(beta):
    with pytest.raises(SceneError, match="beta") as err:
        theory.hd_central_film(beta, 0.4)
    assert "beta=200" in str(err.value) or "beta must" in str(err.value)


@pytest.mark.parametrize("load", [0.0, -0.1, np.array([0.4, 0.0]), float("nan")])
def test_bad_load(load):
    with pytest.raises(SceneError, match="oad") as err:
        theory.hd_minimum_film(200.0, load)
    assert "hertz_load" in str(err.value)


def test_other_bad_input():
    with pytest.raises(SceneError, match="'central' or 'minimum'"):
        theory.hd_film(200.0, 0.4, "average")
    with pytest.raises(SceneError, match="nu"):
        theory.hd_central_film(200.0, 0.4, nu=0.7)
    with pytest.raises(SceneError, match="eps"):
        theory.hd_central_film(200.0, 0.4, eps=2.0)
    with pytest.raises(SceneError, match="eps"):
        theory.hd_central_film(200.0, 0.4, eps=0.0)
    with pytest.raises(SceneError, match="Indentation delta"):
        theory.hertz_load(-1.0)
    with pytest.raises(SceneError, match="Rx"):
        theory.hertz_load(1.0, Rx=0.0)
    with pytest.raises(SceneError, match="method"):
        theory.ellipticity(1.0, 2.0, method="guess")
    with pytest.raises(SceneError, match="eps_range"):
        theory.hd_film_band(200.0, 0.4, eps_range=1e-3)
