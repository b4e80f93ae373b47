"""Hamrock-Dowson piezoviscous-elastic films and the regime parameters (femehl.reference.theory).

The films are evaluated here in SI units straight from the published form
``H = A U^a G^g W^b (1 - C exp(-D k))`` (``U = eta0 u/(E' Rx)``, ``G = alpha* E'``,
``W = F/(E' Rx^2)``, ``H = h/Rx``), with femehl's Barus coefficient converted by
``Barus.from_si`` and a ``Dimensional``, then compared with femehl's normalized functions.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import femehl
from femehl.errors import SceneError
from femehl.reference import theory

CENTRAL = (2.69, 0.67, 0.53, -0.067, 0.61, 0.73)
MINIMUM = (3.63, 0.68, 0.49, -0.073, 1.0, 0.68)


def _hd_piezo_si(coef, dim, alpha_si, Rx_si, F_si, k):
    """Film in metres from the published form, rigid indenter on an elastic substrate."""
    A, a, g, b, C, D = coef
    E = 2.0 * dim.G * (1.0 + dim.nu)
    E_prime = 2.0 / ((1.0 - dim.nu**2) / E)  # 2/E' = (1 - nu^2)/E + 0 (rigid indenter)
    u = 0.5 * dim.V_ss  # mean of the two surface speeds
    U = dim.eta * u / (E_prime * Rx_si)
    G = alpha_si * E_prime
    W = F_si / (E_prime * Rx_si**2)
    return A * U**a * G**g * W**b * (1.0 - C * math.exp(-D * k)) * Rx_si


def test_material_parameter_by_hand():
    # G = 2 alpha / (pi c sqrt(eps)); alpha = 10, c = 1, eps = 1e-3:
    # sqrt(1e-3) = 0.0316227766, pi * that = 0.0993458827, 20 / that = 201.3168
    assert theory.hd_material_parameter(10.0) == pytest.approx(201.3168, rel=1e-6)
    # nu = 0.25: c = 1.5, eps = 1e-4: 2 * 4 / (pi * 1.5 * 0.01) = 169.7653
    assert theory.hd_material_parameter(4.0, nu=0.25, eps=1e-4) == pytest.approx(169.7653, rel=1e-6)
    assert theory.hd_material_parameter(0.0) == 0.0


@pytest.mark.parametrize("nu", [0.5, 0.3])
def test_material_parameter_matches_si(nu):
    dim = femehl.Dimensional(R=0.01, G=2.0e5, eta=0.5, V_ss=0.01, h_inf=5.0e-6, nu=nu)
    alpha_si = 2.0e-6  # 1/Pa: large, a soft contact's pressures are small
    alpha = femehl.Barus.from_si(alpha_si, dim).alpha
    E_prime = 2.0 * (2.0 * dim.G * (1.0 + nu)) / (1.0 - nu**2)
    G = theory.hd_material_parameter(alpha, nu=nu, eps=dim.h_inf / dim.R)
    assert G == pytest.approx(alpha_si * E_prime, rel=1e-12)


@pytest.mark.parametrize("which, coef", [("central", CENTRAL), ("minimum", MINIMUM)])
@pytest.mark.parametrize("nu", [0.5, 0.3])
def test_piezo_films_match_si(which, coef, nu):
    dim = femehl.Dimensional(R=5.0e-3, G=1.0e5, eta=0.1, V_ss=5.0e-3, h_inf=4.0e-6, nu=nu)
    alpha_si, F_si = 5.0e-6, 0.03
    eps = dim.h_inf / dim.R
    h_si = _hd_piezo_si(coef, dim, alpha_si, dim.R, F_si, k=1.0)
    alpha = femehl.Barus.from_si(alpha_si, dim).alpha
    F = F_si / dim.force
    d = theory.hd_piezo_film(dim.beta, F, alpha, which, nu=nu, eps=eps)
    assert d == pytest.approx(h_si / dim.h_inf, rel=1e-12)
    named = theory.hd_piezo_central_film if which == "central" else theory.hd_piezo_minimum_film
    assert named(dim.beta, F, alpha, nu=nu, eps=eps) == pytest.approx(d, rel=1e-15)


def test_piezo_ellipsoid_matches_si():
    dim = femehl.Dimensional(R=1.0e-2, G=3.0e5, eta=0.2, V_ss=1.0e-2, h_inf=2.0e-6, nu=0.5)
    Rx, Ry = 0.5, 2.0
    k = theory.ellipticity(Rx, Ry)
    alpha_si, F_si = 1.0e-6, 0.4
    h_si = _hd_piezo_si(MINIMUM, dim, alpha_si, Rx * dim.R, F_si, k=k)
    alpha = femehl.Barus.from_si(alpha_si, dim).alpha
    d = theory.hd_piezo_minimum_film(dim.beta, F_si / dim.force, alpha, Rx=Rx, Ry=Ry, eps=dim.h_inf / dim.R)
    assert d == pytest.approx(h_si / dim.h_inf, rel=1e-12)


def test_piezo_central_by_hand():
    # beta = 200, F = 4/(3 pi) = 0.4244132, alpha = 10, eps = 1e-3, sphere (k = 1):
    # U = (pi/24) 1e-6 / 200 = 6.544985e-10, W = (pi/2) 1e-4.5 F = 2.108185e-5, G = 201.3168
    # H_c = 2.69 U^0.67 G^0.53 W^-0.067 (1 - 0.61 e^-0.73) = 4.566592e-5, d_c = H_c / eps
    U, W, G = 6.544985e-10, 2.108185e-5, 201.3168
    H = 2.69 * U**0.67 * G**0.53 * W**-0.067 * (1.0 - 0.61 * math.exp(-0.73))
    assert H == pytest.approx(4.566592e-5, rel=1e-6)
    d = theory.hd_piezo_central_film(200.0, 4.0 / (3.0 * math.pi), 10.0)
    assert d == pytest.approx(H / 1e-3, rel=1e-6)


@pytest.mark.parametrize("which", ["central", "minimum"])
def test_piezo_eps_power(which):
    p = theory.hd_piezo_eps_power(which)
    assert p == pytest.approx({"central": -0.0255, "minimum": 0.0055}[which], abs=1e-12)
    d1 = theory.hd_piezo_film(300.0, 0.4, 7.0, which, eps=1e-4)
    d2 = theory.hd_piezo_film(300.0, 0.4, 7.0, which, eps=1e-2)
    assert d2 / d1 == pytest.approx(100.0**p, rel=1e-12)


def test_alpha_to_zero_vanishes_like_its_power():
    F = theory.hertz_load(1.0)
    for which, g in (("central", 0.53), ("minimum", 0.49)):
        assert theory.hd_piezo_film(200.0, F, 0.0, which) == 0.0
        d = theory.hd_piezo_film(200.0, F, np.array([1e-6, 2e-6]), which)
        assert d[1] / d[0] == pytest.approx(2.0**g, rel=1e-12)
    # there the isoviscous formula is the one that applies
    assert theory.hd_elastic_regime(200.0, F, 1e-3) == "isoviscous-elastic"
    assert theory.hd_elastic_regime(200.0, F, 0.0) == "isoviscous-elastic"
    assert theory.hd_elastic_regime(200.0, F, 40.0) == "piezoviscous-elastic"


def test_regime_parameters_by_hand_and_eps_free():
    beta, F, alpha = 200.0, 4.0 / (3.0 * math.pi), 10.0
    g_V, g_E = theory.hd_regime_parameters(beta, F, alpha)
    # g_E = (pi/2)^(8/3) F^(8/3) beta^2 / (pi/24)^2 = 3.334159 * 0.1017272 * 4e4 / 0.01713473
    assert g_E == pytest.approx(3.334159 * 0.1017272 * 4.0e4 / 0.01713473, rel=1e-5)
    assert g_E == pytest.approx(7.91783e5, rel=1e-5)
    # g_V = (2 alpha/pi) (pi/2)^3 F^3 beta^2 / (pi/24)^2 = 6.366198 * 3.875785 * 0.07644808 * 4e4 / ...
    assert g_V == pytest.approx(6.366198 * 3.875785 * 0.07644808 * 4.0e4 / 0.01713473, rel=1e-5)
    for eps in (1e-4, 1e-2):
        U, W = theory.hd_groups(beta, F, eps=eps)
        G = theory.hd_material_parameter(alpha, eps=eps)
        assert G * W**3 / U**2 == pytest.approx(g_V, rel=1e-12)
        assert W ** (8.0 / 3.0) / U**2 == pytest.approx(g_E, rel=1e-12)
    g_V0, _ = theory.hd_regime_parameters(beta, F, 0.0)
    assert g_V0 == 0.0


def test_vectorized():
    beta = np.array([100.0, 200.0, 1000.0])
    alpha = np.array([[0.0], [5.0]])
    d = theory.hd_piezo_central_film(beta, 0.42, alpha)
    assert d.shape == (2, 3)
    assert np.all(d[0] == 0.0)
    for j, b in enumerate(beta):
        assert d[1, j] == pytest.approx(theory.hd_piezo_central_film(float(b), 0.42, 5.0), rel=1e-14)
    assert isinstance(theory.hd_piezo_minimum_film(200.0, 0.42, 5.0), float)
    g_V, g_E = theory.hd_regime_parameters(beta, 0.42, alpha)
    assert g_V.shape == g_E.shape == (2, 3)
    regimes = theory.hd_elastic_regime(200.0, 0.42, np.array([0.5, 50.0]))
    assert list(regimes) == ["isoviscous-elastic", "piezoviscous-elastic"]
    assert isinstance(theory.hd_elastic_regime(200.0, 0.42, 5.0), str)


@pytest.mark.parametrize("alpha", [-1.0, float("nan"), float("inf"), "10", None, [], True])
def test_bad_alpha(alpha):
    with pytest.raises(SceneError, match="alpha"):
        theory.hd_piezo_central_film(200.0, 0.42, alpha)
    with pytest.raises(SceneError, match="alpha"):
        theory.hd_material_parameter(alpha)
    with pytest.raises(SceneError, match="alpha"):
        theory.hd_regime_parameters(200.0, 0.42, alpha)


def test_other_bad_input():
    with pytest.raises(SceneError, match="central.*minimum"):
        theory.hd_piezo_film(200.0, 0.42, 5.0, "exit")
    with pytest.raises(SceneError, match="beta"):
        theory.hd_piezo_minimum_film(0.0, 0.42, 5.0)
    with pytest.raises(SceneError, match="Load"):
        theory.hd_piezo_minimum_film(200.0, -0.1, 5.0)
    with pytest.raises(SceneError, match="nu"):
        theory.hd_material_parameter(5.0, nu=0.7)
    with pytest.raises(SceneError, match="eps"):
        theory.hd_piezo_central_film(200.0, 0.42, 5.0, eps=2.0)
    with pytest.raises(SceneError, match="central.*minimum"):
        theory.hd_piezo_eps_power("side")
    with pytest.raises(SceneError, match="Rx"):
        theory.hd_regime_parameters(200.0, 0.42, 5.0, Rx=0.0)
    with pytest.raises(SceneError, match="beta"):
        theory.hd_elastic_regime(-5.0, 0.42, 5.0)
