"""Classical soft-EHL predictions in femehl's normalized variables.

Users compare femehl's steady-sliding master curves (film thickness against ``beta`` at
fixed indentation) with the classical formulas collected here, each rewritten in the
normalization femehl uses (Wu, Hui et al., J. Mech. Phys. Solids 2022; docs/design.md
sections 1-2).

Conventions
-----------
Dimensional problem (indenter frame; the substrate slides at speed ``V_ss`` under a rigid
indenter, so only one surface moves)::

    div( d^3/(12 eta) grad p ) = -(V/2) dd/dx + dd/dt,   d = h - w,   h = hc + s(x, y)
    w = -(c/(4 pi G)) int p(x') / dist(x, x') dA',       c = 2 (1 - nu)  (c = 1: incompressible)

Normalized variables (lengths in the plane by ``sqrt(R h_inf)``, films by ``h_inf``)::

    p = p* / (4 pi G sqrt(h_inf/R)),   F = F* / (4 pi G sqrt(R) h_inf^(3/2))
    beta = (2/3) (h_inf^2/R) (pi G) / (eta V_ss)

``R`` is femehl's normalizing radius; an ellipsoid's radii of curvature ``Rx`` (along the
sliding direction x) and ``Ry`` are given in units of ``R``, so ``Rx = Ry = 1`` is the
paper's unit sphere.  Steady sliding is at ``V = 1`` and the paper's indentation is
``hc = -1``.  Large ``beta`` means slow sliding or a soft substrate: thin films.

The normalized problem has two parameters (``beta`` and the indentation or the load), the
dimensional Hamrock-Dowson groups three (``U``, ``W`` and the ratio ``eps = h_inf/R``), so
every Hamrock-Dowson function takes ``eps`` as a parameter (default
:data:`DEFAULT_EPS` ``= 1e-3``).  The film depends on it only through a small residual
power (:func:`hd_eps_power`); :func:`hd_film_band` gives the spread over ``eps`` in
``[1e-4, 1e-2]``.

Functions
---------
=================================  =================================================================
:func:`hd_central_film`            Hamrock & Dowson (1978) isoviscous-elastic central film ``d_c``
:func:`hd_minimum_film`            Hamrock & Dowson (1978) isoviscous-elastic minimum film ``d_min``
:func:`hd_film`                    either of the two, by name
:func:`hd_eps_power`               the residual power of ``eps`` in a Hamrock-Dowson film
:func:`hd_film_band`               the band of a Hamrock-Dowson film over a range of ``eps``
:func:`hd_groups`                  the Hamrock-Dowson groups ``U``, ``W`` of a normalized state
:func:`hd_material_parameter`      the material group ``G = alpha E'`` of femehl's Barus ``alpha``
:func:`hd_piezo_central_film`      Hamrock & Dowson (1977) piezoviscous-elastic central film ``d_c``
:func:`hd_piezo_minimum_film`      Hamrock & Dowson (1977) piezoviscous-elastic minimum film ``d_min``
:func:`hd_piezo_film`              either of the two, by name
:func:`hd_piezo_eps_power`         the residual power of ``eps`` in a piezoviscous-elastic film
:func:`hd_regime_parameters`       Hamrock's regime parameters ``g_V``, ``g_E`` (independent of ``eps``)
:func:`hd_elastic_regime`          isoviscous- or piezoviscous-elastic: which formula gives more film
:func:`ellipticity`                the ellipticity ``k = a_y/a_x`` of the Hertz contact ellipse
:func:`hertz_load`                 the dry Hertz load at indentation ``delta`` (sphere, ellipsoid)
:func:`scaling_exponents`          large-``beta`` film exponents, with their sources
=================================  =================================================================

Every function is vectorized over its array arguments (numpy broadcasting) and returns a
float for scalar input.  Invalid input (a non-positive ``beta`` or load, a non-finite
value, ``nu`` outside (-1, 0.5]) raises :class:`femehl.errors.SceneError` with a message
that says what to change.
"""

from __future__ import annotations

import math
import numbers

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from femehl.errors import SceneError

__all__ = [
    "DEFAULT_EPS",
    "ELASTIC_REGIMES",
    "EPS_RANGE",
    "ellipticity",
    "hd_central_film",
    "hd_eps_power",
    "hd_film",
    "hd_film_band",
    "hd_groups",
    "hd_elastic_regime",
    "hd_material_parameter",
    "hd_minimum_film",
    "hd_piezo_central_film",
    "hd_piezo_eps_power",
    "hd_piezo_film",
    "hd_piezo_minimum_film",
    "hd_regime_parameters",
    "hertz_load",
    "scaling_exponents",
]

#: Default ratio ``eps = h_inf/R`` of the Hamrock-Dowson functions: the geometric middle
#: of :data:`EPS_RANGE` (films of ~10 um under a ~1 cm sphere).
DEFAULT_EPS = 1e-3

#: The range of ``eps = h_inf/R`` that :func:`hd_film_band` spans by default.
EPS_RANGE = (1e-4, 1e-2)

HD1978 = (
    "B. J. Hamrock and D. Dowson, 'Elastohydrodynamic lubrication of elliptical contacts "
    "for materials of low elastic modulus I - fully flooded conjunction', "
    "ASME J. Lubr. Technol. 100 (1978) 236-245"
)
HD1977 = (
    "B. J. Hamrock and D. Dowson, 'Isothermal elastohydrodynamic lubrication of point contacts, "
    "Part III - fully flooded results', ASME J. Lubr. Technol. 99 (1977) 264-276"
)
SEV2013 = (
    "J. H. Snoeijer, J. Eggers and C. H. Venner, 'Similarity theory of lubricated "
    "Hertzian contacts', Phys. Fluids 25 (2013) 101705"
)

# name -> (A, a, b, C, D) of  H = A U^a W^b (1 - C exp(-D k))
_HD_FITS = {
    "central": (7.32, 0.64, -0.22, 0.72, 0.28),
    "minimum": (7.43, 0.65, -0.21, 0.85, 0.31),
}

# name -> (A, a, g, b, C, D) of  H = A U^a G^g W^b (1 - C exp(-D k))
_HD_PIEZO_FITS = {
    "central": (2.69, 0.67, 0.53, -0.067, 0.61, 0.73),
    "minimum": (3.63, 0.68, 0.49, -0.073, 1.0, 0.68),
}

_K_METHODS = ("hertz", "hamrock_brewe", "hd1977")


# ---------------------------------------------------------------------------- input checks


def _array(name: str, value, hint: str, *, positive: bool = True, allow_zero: bool = False) -> np.ndarray:
    """``value`` as a float array; SceneError if not real, not finite or not positive."""
    if isinstance(value, (bool, np.bool_, str, bytes)):
        raise SceneError(f"{name} must be a real number or an array of them, got {value!r}. {hint}")
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise SceneError(
            f"{name} must be a real number or an array of them, got {type(value).__name__}. {hint}"
        ) from None
    if arr.size == 0:
        raise SceneError(f"{name} is an empty array. {hint}")
    if not np.all(np.isfinite(arr)):
        raise SceneError(f"{name} must be finite, got {value!r}. {hint}")
    if positive:
        bad = arr < 0 if allow_zero else arr <= 0
        if np.any(bad):
            worst = float(arr[bad].flat[0])
            sign = "non-negative" if allow_zero else "positive"
            raise SceneError(f"{name} must be {sign}, got {worst:g}. {hint}")
    return arr


def _scalar(name: str, value, hint: str) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise SceneError(f"{name} must be a real number, got {value!r}. {hint}")
    v = float(value)
    if not math.isfinite(v):
        raise SceneError(f"{name} must be finite, got {value!r}. {hint}")
    return v


def _nu(nu) -> float:
    v = _scalar("Poisson ratio nu", nu, "Give nu in (-1, 0.5]; 0.5 is the incompressible substrate.")
    if not (-1.0 < v <= 0.5):
        raise SceneError(
            f"Poisson ratio nu must lie in (-1, 0.5], got {v:g}. Give e.g. nu=0.5 (incompressible)."
        )
    return v


def _eps(eps) -> np.ndarray:
    arr = _array(
        "eps = h_inf/R",
        eps,
        "Give the ratio of the film scale to the radius, a small positive number such as 1e-3.",
    )
    if np.any(arr >= 1.0):
        raise SceneError(
            f"eps = h_inf/R must be < 1 (a thin film under a large radius), got {float(arr.max()):g}. "
            "Give e.g. eps=1e-3."
        )
    return arr


def _which(which: str) -> tuple:
    if which not in _HD_FITS:
        raise SceneError(f"Unknown Hamrock-Dowson film {which!r}: use 'central' or 'minimum'.")
    return _HD_FITS[which]


def _which_piezo(which: str) -> tuple:
    if which not in _HD_PIEZO_FITS:
        raise SceneError(f"Unknown Hamrock-Dowson film {which!r}: use 'central' or 'minimum'.")
    return _HD_PIEZO_FITS[which]


def _out(x):
    x = np.asarray(x, dtype=float)
    return float(x) if x.ndim == 0 else x


_BETA_HINT = "beta = (2/3)(h_inf^2/R)(pi G)/(eta V_ss) is a positive number, e.g. beta=200."
_LOAD_HINT = (
    "The normalized load F = F*/(4 pi G sqrt(R) h_inf^(3/2)) must be > 0 "
    "(e.g. the Hertz load at hc = -1, hertz_load(1.0) = 4/(3 pi))."
)
_ALPHA_HINT = (
    "alpha is femehl's Barus coefficient (eta = eta0 exp(alpha p), p in units of "
    "4 pi G sqrt(h_inf/R)), >= 0; femehl.Barus.from_si(alpha_SI, dim).alpha converts an SI value."
)
_R_HINT = "Give radii of curvature in units of R, e.g. Rx=1.0, Ry=1.0 for the unit sphere."


# ------------------------------------------------------------------------------ ellipticity


def _ratio_of_m(m):
    """``B/A`` of a Hertz ellipse of eccentricity squared ``m`` (``A <= B`` the gap coefficients).

    ``B/A = (E/(1 - m) - K) / (K - E)`` with ``K = ellipk(m)``, ``E = ellipe(m)`` (Johnson,
    Contact Mechanics, 1985, section 4.2, Eq. 3.61 with a rigid second body); the series
    ``1 + 3m/4 + ...`` is used for ``m < 1e-6`` to avoid the cancellation in ``K - E``.
    """
    if m < 1e-6:
        num = 0.5 + 9.0 * m / 16.0
        den = 0.5 + 3.0 * m / 16.0
        return num / den
    K, E = ellipk(m), ellipe(m)
    return (E / (1.0 - m) - K) / (K - E)


def _k_minus_e_over_m(m):
    """``(K(m) - E(m)) / m``, by its series for small ``m``."""
    if m < 1e-6:
        return 0.5 * math.pi * (0.5 + 3.0 * m / 16.0 + 15.0 * m * m / 128.0)
    return (ellipk(m) - ellipe(m)) / m


def _eccentricity_sq(rho: float) -> float:
    """Eccentricity squared ``m = 1 - (b/a)^2`` of the Hertz ellipse for ``rho = R_big/R_small >= 1``."""
    if rho - 1.0 <= 1e-14:
        return 0.0
    hi = 1.0 - 1e-15
    if _ratio_of_m(hi) <= rho:  # beyond double precision: a contact ~1e7 times longer than wide
        raise SceneError(
            f"The radius ratio {rho:g} is too extreme for the Hertz ellipse; "
            "keep max(Rx, Ry)/min(Rx, Ry) <= 1e12."
        )
    return brentq(
        lambda m: _ratio_of_m(m) - rho, 0.0, hi, xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500
    )


def ellipticity(Rx=1.0, Ry=1.0, method: str = "hertz"):
    r"""Ellipticity ``k = a_y / a_x`` of the contact ellipse of the gap ``x^2/(2 Rx) + y^2/(2 Ry)``.

    ``a_x`` is the semi-axis along the sliding (entrainment) direction x and ``a_y`` the
    transverse one; this is Hamrock & Dowson's ellipticity parameter ``k = a/b`` (their
    ``a`` is the semi-axis transverse to the rolling direction, ``b`` the one along it),
    so ``k > 1`` for ``Ry > Rx`` (the long axis across the sliding direction) and ``k = 1``
    for a sphere.

    Parameters
    ----------
    Rx, Ry : float or array_like
        Radii of curvature along and across the sliding direction (units of ``R``); only
        their ratio matters.
    method : {'hertz', 'hamrock_brewe', 'hd1977'}
        ``'hertz'`` (default): exact, from Hertz theory.  With ``A = 1/(2 max(Rx, Ry))``,
        ``B = 1/(2 min(Rx, Ry))`` and ``m = 1 - (minor/major)^2`` the root of
        ``B/A = (E(m)/(1 - m) - K(m)) / (K(m) - E(m))`` (``K``, ``E`` the complete elliptic
        integrals in scipy's parameter convention, ``ellipk(m)``, ``ellipe(m)``; Johnson,
        *Contact Mechanics*, Cambridge University Press 1985, section 4.2), the axis ratio
        is ``sqrt(1 - m)``; ``k = 1/sqrt(1 - m)`` for ``Ry >= Rx`` and ``sqrt(1 - m)``
        otherwise.  Exactly 1 for a sphere.
        ``'hamrock_brewe'``: ``k = 1.0339 (Ry/Rx)^0.636`` (B. J. Hamrock and D. E. Brewe,
        'Simplified solution for stresses and deformations', J. Lubr. Technol. 105 (1983)
        171-177; the citation is not confirmed here).  Checked here against the exact
        value: within 2.2 % for ``1.5 <= Ry/Rx <= 10``, 3.4 % at the sphere (where it gives
        1.0339) and 6 % at ``Ry/Rx = 100``.
        ``'hd1977'``: ``k = 1.03 (Ry/Rx)^0.64``, the simplified expression of the
        Hamrock-Dowson point-contact series (B. J. Hamrock and D. Dowson, 'Isothermal
        elastohydrodynamic lubrication of point contacts, Part III - fully flooded
        results', J. Lubr. Technol. 99 (1977) 264-276; confirmed from the ASME abstract
        page of that paper).  Both approximations give ``k = 1.03...`` for a sphere, not 1.

    Returns
    -------
    float or ndarray
        The ellipticity ``k``.

    Raises
    ------
    SceneError
        If a radius is not finite and positive, or ``method`` is unknown.
    """
    rx = _array("Rx", Rx, _R_HINT)
    ry = _array("Ry", Ry, _R_HINT)
    if method == "hamrock_brewe":
        return _out(1.0339 * (ry / rx) ** 0.636)
    if method == "hd1977":
        return _out(1.03 * (ry / rx) ** 0.64)
    if method != "hertz":
        raise SceneError(f"Unknown ellipticity method {method!r}: use one of {', '.join(_K_METHODS)}.")
    rx, ry = np.broadcast_arrays(rx, ry)
    k = np.empty(rx.shape)
    for i in np.ndindex(rx.shape):
        big, small = max(rx[i], ry[i]), min(rx[i], ry[i])
        axis = math.sqrt(1.0 - _eccentricity_sq(big / small))  # minor/major <= 1
        k[i] = 1.0 / axis if ry[i] >= rx[i] else axis
    return _out(k)


# -------------------------------------------------------------------------------- Hertz load


def hertz_load(delta, Rx=1.0, Ry=None, nu=0.5):
    r"""Dry Hertz load at indentation ``delta`` (``hc = -delta``), in femehl's normalized units.

    Sphere (``Ry`` omitted or equal to ``Rx``)::

        F = 4 sqrt(Rx) delta^(3/2) / (3 pi c),   c = 2 (1 - nu)

    so ``F = 4/(3 pi)`` for the paper's unit sphere at ``hc = -1`` (the load of
    ``p_H = (2/pi^2) sqrt(1 - r^2)``).  Conversion: the dimensional Hertz law
    ``F* = (4/3) E* sqrt(R*) delta*^(3/2)`` with ``E* = E/(1 - nu^2) = 4 G/c`` for a
    rigid indenter on an elastic half space (docs/design.md section 7:
    ``F* = (16/3) G sqrt(R*) delta*^(3/2)`` for ``nu = 1/2``), ``R* = Rx R``,
    ``delta* = delta h_inf`` and ``F = F*/(4 pi G sqrt(R) h_inf^(3/2))``.  Equivalently:
    femehl's normalized elasticity ``w = -c int p/dist dA`` is the dimensional one with
    ``G = 1/(4 pi)``, i.e. ``E* = 1/(pi c)``.

    Ellipsoid (gap ``x^2/(2 Rx) + y^2/(2 Ry)``): exact Hertz solution (Johnson, *Contact
    Mechanics*, Cambridge University Press 1985, section 4.2).  With the gap coefficients
    ``A = 1/(2 max(Rx, Ry)) <= B = 1/(2 min(Rx, Ry))``, the eccentricity squared
    ``m = 1 - (minor/major)^2`` solves ``B/A = (E(m)/(1 - m) - K(m)) / (K(m) - E(m))``
    (see :func:`ellipticity`); the major semi-axis ``a``, the peak pressure ``p0`` and the
    load follow from ``delta = p0 b K(m)/E*`` and ``A = p0 b (K - E)/(E* m a^2)``::

        a^2 = delta (K - E) / (A m K),   F = (2/3) pi a b p0 = (2/3) pi A E* m a^3 / (K - E)

    with ``b = a sqrt(1 - m)`` and ``E* = 1/(pi c)``.  For ``m -> 0``, ``(K - E)/m -> pi/4``
    and this tends to the sphere law; at fixed shape ``F`` scales as ``delta^(3/2)``.

    Parameters
    ----------
    delta : float or array_like
        Indentation depth in units of ``h_inf`` (``delta >= 0``; the paper's is 1).
    Rx : float, default: 1.0
        Radius of curvature along x (units of ``R``); the sphere's radius.
    Ry : float, optional
        Radius of curvature along y; default ``Rx`` (a sphere).
    nu : float, default: 0.5
        Poisson ratio of the substrate, in (-1, 0.5].

    Returns
    -------
    float or ndarray
        The normalized load ``F = int p dA``.

    Raises
    ------
    SceneError
        If ``delta`` is negative or not finite, a radius is not positive, or ``nu`` is out
        of range.
    """
    d = _array(
        "Indentation delta",
        delta,
        "Give the indentation depth delta = -hc >= 0 in units of h_inf (the paper's is 1).",
        allow_zero=True,
    )
    rx = _scalar("Rx", Rx, _R_HINT)
    ry = rx if Ry is None else _scalar("Ry", Ry, _R_HINT)
    if rx <= 0 or ry <= 0:
        raise SceneError(f"Radii of curvature must be positive, got Rx={rx:g}, Ry={ry:g}. {_R_HINT}")
    c = 2.0 * (1.0 - _nu(nu))
    e_star = 1.0 / (math.pi * c)
    big, small = max(rx, ry), min(rx, ry)
    m = _eccentricity_sq(big / small)
    if m == 0.0:
        return _out(4.0 * math.sqrt(rx) * d**1.5 / (3.0 * math.pi * c))
    A = 1.0 / (2.0 * big)
    km = _k_minus_e_over_m(m)  # (K - E)/m
    a3 = (d * km / (A * ellipk(m))) ** 1.5  # a^2 = delta (K - E)/(A m K)
    return _out((2.0 / 3.0) * math.pi * A * e_star * a3 / km)


# ------------------------------------------------------------------------ Hamrock & Dowson


def hd_groups(beta, load, Rx=1.0, nu=0.5, eps=DEFAULT_EPS):
    r"""Hamrock-Dowson speed and load groups ``(U, W)`` of a normalized femehl state.

    Hamrock & Dowson define ``U = eta u/(E' Rx*)``, ``W = F*/(E' Rx*^2)``, ``H = h*/Rx*``
    with ``u`` the mean (entrainment) velocity of the two surfaces, ``Rx*`` the
    effective radius along the entrainment direction and ``E'`` twice the combined
    plane-strain modulus, ``2/E' = (1 - nu_a^2)/E_a + (1 - nu_b^2)/E_b``.  For femehl's
    rigid indenter on an elastic half space: ``E' = 2E/(1 - nu^2) = 4G/(1 - nu) = 8G/c``
    (``8G`` incompressible, with ``E = 3G``), ``u = V_ss/2`` (one surface moving),
    ``Rx* = Rx R``.  Inserting ``eta V_ss = (2/3) pi G h_inf^2/(R beta)`` and
    ``F* = 4 pi G sqrt(R) h_inf^(3/2) F``::

        U = (pi c / (24 Rx)) eps^2 / beta,    W = (pi c / (2 Rx^2)) eps^(3/2) F,    eps = h_inf/R

    Parameters
    ----------
    beta : float or array_like
        The ``beta`` of femehl's normalization (> 0).
    load : float or array_like
        Normalized load ``F`` (> 0).
    Rx : float or array_like, default: 1.0
        Radius of curvature along the sliding direction (units of ``R``).
    nu : float, default: 0.5
        Poisson ratio of the substrate.
    eps : float or array_like, default: DEFAULT_EPS
        ``h_inf/R``.

    Returns
    -------
    U : float or ndarray
        The speed group ``eta u/(E' Rx*)``, broadcast over the inputs.
    W : float or ndarray
        The load group ``F*/(E' Rx*^2)``, broadcast over the inputs.

    Raises
    ------
    SceneError
        If ``beta`` or ``load`` is not positive, or another input is invalid.
    """
    b = _array("beta", beta, _BETA_HINT)
    f = _array("Load F", load, _LOAD_HINT)
    rx = _array("Rx", Rx, _R_HINT)
    e = _eps(eps)
    c = 2.0 * (1.0 - _nu(nu))
    U = math.pi * c / (24.0 * rx) * e**2 / b
    W = math.pi * c / (2.0 * rx**2) * e**1.5 * f
    U, W = np.broadcast_arrays(U, W)
    return _out(U), _out(W)


def hd_eps_power(which: str = "central") -> float:
    r"""Residual power of ``eps = h_inf/R`` in a Hamrock-Dowson film in femehl units.

    With ``H = A U^a W^b f(k)`` and the groups of :func:`hd_groups`, the normalized film
    ``d = h*/h_inf = H Rx/eps`` is::

        d = A Rx (pi c/(24 Rx))^a (pi c/(2 Rx^2))^b f(k)  beta^(-a) F^b  eps^(2a + 3b/2 - 1)

    so ``d`` depends on ``eps`` only through ``eps^(2a + 1.5 b - 1)``: central film
    ``2(0.64) - 1.5(0.22) - 1 = -0.05``, minimum film ``2(0.65) - 1.5(0.21) - 1 = -0.015``.
    Over ``eps`` in [1e-4, 1e-2] this is a factor ``10^0.1 = 1.26`` (central) and
    ``10^0.03 = 1.07`` (minimum).

    Parameters
    ----------
    which : {'central', 'minimum'}
        Which Hamrock-Dowson film.

    Returns
    -------
    float
        The power ``2a + 1.5 b - 1``.
    """
    _, a, b, _, _ = _which(which)
    return 2.0 * a + 1.5 * b - 1.0


def hd_film(beta, load, which="central", Rx=1.0, Ry=1.0, nu=0.5, eps=DEFAULT_EPS, k=None):
    r"""Hamrock & Dowson (1978) isoviscous-elastic film, in units of ``h_inf``.

    Formulas (the "low elastic modulus", isoviscous-elastic or soft-EHL regime of
    elliptical point contacts; fully flooded, Newtonian, isoviscous fluid)::

        H_min = 7.43 U^0.65 W^-0.21 (1 - 0.85 exp(-0.31 k))
        H_c   = 7.32 U^0.64 W^-0.22 (1 - 0.72 exp(-0.28 k))

    Source: B. J. Hamrock and D. Dowson, 'Elastohydrodynamic lubrication of elliptical
    contacts for materials of low elastic modulus I - fully flooded conjunction', ASME J.
    Lubr. Technol. 100 (1978) 236-245.  Regime: fully flooded, isothermal, Newtonian,
    isoviscous fluid between solids that deform much more than the film is thick while
    the pressures stay too low to raise the viscosity (rubber, elastomers, gels).  This is
    femehl's model except perhaps at the exit: EHL solutions of that series usually
    impose a cavitation (Reynolds) condition there (not checked for the 1978 paper),
    while femehl models no cavitation and lets ``p`` go below ambient, which can shift
    the minimum film.  The fits are curve fits to numerical solutions over a finite
    range of ``U``, ``W`` and ``k``; the Hamrock-Dowson point-contact series covers
    ellipticities from 1 (ball on plate) to 8 (approaching line contact) (abstract of
    Part III, below).  The range and the accuracy stated in the 1978 paper itself could
    not be checked here (no accessible copy); use the formulas as an estimate of the
    trend and of the size of the films, not as a reference to a few percent.  ``k < 1``
    (the long axis along the sliding direction, ``Ry < Rx``) is an extrapolation.

    What was confirmed, and where: the form ``H = A U^a G^g W^b (1 - ... exp(-... k))``
    of the Hamrock-Dowson point-contact series and ``k = 1.03 (Ry/Rx)^0.64`` (so ``k``
    grows with ``Ry/Rx``: the transverse over the entrainment-direction semi-axis), from
    the ASME abstract page of B. J. Hamrock and D. Dowson, 'Isothermal
    elastohydrodynamic lubrication of point contacts, Part III - fully flooded results',
    J. Lubr. Technol. 99 (1977) 264-276 (hard EHL,
    ``H_min = 3.63 U^0.68 G^0.49 W^-0.073 (1 - exp(-0.68 k))``); the groups
    ``U = eta u/(E' Rx*)``, ``W = F*/(E' Rx*^2)``, ``H = h*/Rx*`` with ``u`` the mean of
    the two surface speeds, from public implementations of that series (the sciforge
    crate on docs.rs; a ball-bearing model following Hamrock's 1994 textbook, GitHub
    HenriqueBaron/tcc-modelo); the ellipticity factor ``(1 - 0.85 exp(-0.31 k))`` of the
    isoviscous-elastic minimum film, from a public transcription (GitHub jl293/tribopy)
    of the regime-chart form ``8.70 g_E^0.67 (1 - 0.85 exp(-0.31 k))`` (Esfahanian and
    Hamrock, 1991; original not checked).  NOT confirmed: the coefficients 7.43 and 7.32, the exponents 0.65,
    -0.21, 0.64, -0.22 and the central-film factor ``(1 - 0.72 exp(-0.28 k))``; they are
    the values commonly quoted for the 1978 paper (e.g. in B. J. Hamrock, *Fundamentals of
    Fluid Film Lubrication*, NASA RP-1255, 1991; not checked here).

    Conversion to femehl's normalization (:func:`hd_groups`, :func:`hd_eps_power`)::

        E' = 8G/c (c = 2(1 - nu); E' = 8G incompressible),  u = V_ss/2,  Rx* = Rx R
        U = (pi c/(24 Rx)) eps^2/beta,  W = (pi c/(2 Rx^2)) eps^(3/2) F,  d = H Rx/eps

    hence ``d ~ beta^-0.64 F^-0.22 eps^-0.05`` (central) and
    ``d ~ beta^-0.65 F^-0.21 eps^-0.015`` (minimum).

    Parameters
    ----------
    beta : float or array_like
        The ``beta`` of femehl's normalization (> 0).
    load : float or array_like
        Normalized load ``F = int p dA`` (> 0); at steady sliding with ``hc = -1`` and
        large ``beta`` it tends to :func:`hertz_load` ``(1.0, Rx, Ry)``.
    which : {'central', 'minimum'}
        Which film.
    Rx, Ry : float, default: 1.0
        Radii of curvature along and across the sliding direction (units of ``R``).
    nu : float, default: 0.5
        Poisson ratio of the substrate, in (-1, 0.5].
    eps : float or array_like, default: DEFAULT_EPS
        ``h_inf/R``, the free ratio the normalized problem does not fix.
    k : float, optional
        Ellipticity; default :func:`ellipticity` ``(Rx, Ry)`` (exact Hertz, 1 for a sphere).

    Returns
    -------
    float or ndarray
        The film thickness ``d`` in units of ``h_inf``, broadcast over ``beta``, ``load``
        and ``eps``.

    Raises
    ------
    SceneError
        If ``beta`` or ``load`` is not positive, ``which`` is unknown, or another input is
        invalid.
    """
    A, a, b, C, D = _which(which)
    U, W = hd_groups(beta, load, Rx=Rx, nu=nu, eps=eps)
    if k is None:
        k = ellipticity(Rx, Ry)
    kk = _array("Ellipticity k", k, "Give k > 0, or leave k=None to take it from Rx and Ry.")
    rx = _array("Rx", Rx, _R_HINT)
    e = _eps(eps)
    H = A * np.asarray(U) ** a * np.asarray(W) ** b * (1.0 - C * np.exp(-D * kk))
    return _out(H * rx / e)


def hd_central_film(beta, load, Rx=1.0, Ry=1.0, nu=0.5, eps=DEFAULT_EPS, k=None):
    r"""Hamrock & Dowson (1978) isoviscous-elastic central film ``d_c`` in units of ``h_inf``.

    ``H_c = 7.32 U^0.64 W^-0.22 (1 - 0.72 exp(-0.28 k))``, converted as in :func:`hd_film`
    (which documents the source, the regime, what was and was not confirmed, and each
    conversion step)::

        d_c = 7.32 Rx (pi c/(24 Rx))^0.64 (pi c/(2 Rx^2))^-0.22 (1 - 0.72 exp(-0.28 k))
              * beta^-0.64 F^-0.22 eps^-0.05

    Parameters
    ----------
    beta : float or array_like
        The ``beta`` of femehl's normalization (> 0).
    load : float or array_like
        Normalized load ``F`` (> 0).
    Rx, Ry : float, default: 1.0
        Radii of curvature along and across the sliding direction (units of ``R``).
    nu : float, default: 0.5
        Poisson ratio of the substrate.
    eps : float or array_like, default: DEFAULT_EPS
        ``h_inf/R``.
    k : float, optional
        Ellipticity; default from ``Rx``, ``Ry`` (exact Hertz).

    Returns
    -------
    float or ndarray
        ``d_c``.

    Raises
    ------
    SceneError
        If ``beta`` or ``load`` is not positive, or another input is invalid.

    Examples
    --------
    The paper's case (unit sphere, ``hc = -1``, ``beta = 200``) with the Hertz load:

    >>> from femehl import theory
    >>> round(theory.hd_central_film(200.0, theory.hertz_load(1.0)), 4)
    0.0472
    """
    return hd_film(beta, load, "central", Rx=Rx, Ry=Ry, nu=nu, eps=eps, k=k)


def hd_minimum_film(beta, load, Rx=1.0, Ry=1.0, nu=0.5, eps=DEFAULT_EPS, k=None):
    r"""Hamrock & Dowson (1978) isoviscous-elastic minimum film ``d_min`` in units of ``h_inf``.

    ``H_min = 7.43 U^0.65 W^-0.21 (1 - 0.85 exp(-0.31 k))``, converted as in :func:`hd_film`
    (which documents the source, the regime, what was and was not confirmed, and each
    conversion step)::

        d_min = 7.43 Rx (pi c/(24 Rx))^0.65 (pi c/(2 Rx^2))^-0.21 (1 - 0.85 exp(-0.31 k))
                * beta^-0.65 F^-0.21 eps^-0.015

    Parameters
    ----------
    beta : float or array_like
        The ``beta`` of femehl's normalization (> 0).
    load : float or array_like
        Normalized load ``F`` (> 0).
    Rx, Ry : float, default: 1.0
        Radii of curvature along and across the sliding direction (units of ``R``).
    nu : float, default: 0.5
        Poisson ratio of the substrate.
    eps : float or array_like, default: DEFAULT_EPS
        ``h_inf/R``.
    k : float, optional
        Ellipticity; default from ``Rx``, ``Ry`` (exact Hertz).

    Returns
    -------
    float or ndarray
        ``d_min``.

    Raises
    ------
    SceneError
        If ``beta`` or ``load`` is not positive, or another input is invalid.
    """
    return hd_film(beta, load, "minimum", Rx=Rx, Ry=Ry, nu=nu, eps=eps, k=k)


def hd_film_band(beta, load, which="central", eps_range=EPS_RANGE, Rx=1.0, Ry=1.0, nu=0.5, k=None):
    r"""Band ``(low, high)`` of a Hamrock-Dowson film over ``eps = h_inf/R`` in ``eps_range``.

    The film is ``eps^p`` times a function of ``beta`` and the load, with ``p`` from
    :func:`hd_eps_power` (-0.05 central, -0.015 minimum), so it is monotonic in ``eps``
    and its extremes are at the ends of the range: for the default [1e-4, 1e-2] the band
    is a factor 1.26 wide (central) and 1.07 (minimum).

    Parameters
    ----------
    beta : float or array_like
        The ``beta`` of femehl's normalization (> 0).
    load : float or array_like
        Normalized load ``F`` (> 0).
    which : {'central', 'minimum'}
        Which film.
    eps_range : (float, float), default: EPS_RANGE
        The range of ``h_inf/R`` considered.
    Rx, Ry : float, default: 1.0
        Radii of curvature (units of ``R``).
    nu : float, default: 0.5
        Poisson ratio of the substrate.
    k : float, optional
        Ellipticity; default from ``Rx``, ``Ry``.

    Returns
    -------
    low : float or ndarray
        The smallest film over the range.
    high : float or ndarray
        The largest film over the range.

    Raises
    ------
    SceneError
        If ``eps_range`` is not two valid values, or another input is invalid.
    """
    try:
        e0, e1 = eps_range
    except (TypeError, ValueError):
        raise SceneError(
            f"eps_range must be two numbers (low, high), got {eps_range!r}; e.g. (1e-4, 1e-2)."
        ) from None
    d0 = np.asarray(hd_film(beta, load, which, Rx=Rx, Ry=Ry, nu=nu, eps=e0, k=k))
    d1 = np.asarray(hd_film(beta, load, which, Rx=Rx, Ry=Ry, nu=nu, eps=e1, k=k))
    return _out(np.minimum(d0, d1)), _out(np.maximum(d0, d1))


# ------------------------------------------------------------- Hamrock & Dowson: piezoviscous


def hd_material_parameter(alpha, nu=0.5, eps=DEFAULT_EPS):
    r"""Hamrock-Dowson material group ``G = alpha* E'`` of femehl's Barus coefficient ``alpha``.

    femehl's Barus law is ``eta = eta0 exp(alpha p)`` with ``p`` in units of the pressure
    scale ``p_s = 4 pi G_s sqrt(h_inf/R)`` (docs/design.md sections 2 and 11; ``G_s`` the
    substrate's shear modulus), so the SI coefficient is ``alpha* = alpha / p_s``
    (:meth:`femehl.Barus.from_si` is the inverse).  With ``E' = 8 G_s/c``
    (:func:`hd_groups`, ``c = 2(1 - nu)``)::

        G = alpha* E' = (alpha / (4 pi G_s sqrt(eps))) (8 G_s / c) = 2 alpha / (pi c sqrt(eps))

    e.g. ``G = 20.13 alpha`` for an incompressible substrate at ``eps = 1e-3``.  The shear
    modulus cancels; ``eps = h_inf/R`` does not (the normalized problem leaves it free, see
    the module docstring).  For comparison: a mineral oil on steel (``alpha* ~ 2e-8 /Pa``,
    ``E' ~ 2.3e11 Pa``) has ``G ~ 4600``; femehl's moderate ``alpha p_max <= 4`` at
    ``eps = 1e-3`` is ``G <~ 400``.

    Parameters
    ----------
    alpha : float or array_like
        femehl's Barus coefficient (>= 0; ``femehl.Barus(alpha).alpha``).
    nu : float, default: 0.5
        Poisson ratio of the substrate, in (-1, 0.5].
    eps : float or array_like, default: DEFAULT_EPS
        ``h_inf/R``.

    Returns
    -------
    float or ndarray
        ``G``, broadcast over ``alpha`` and ``eps``.

    Raises
    ------
    SceneError
        If ``alpha`` is negative or not finite, or another input is invalid.
    """
    a = _array("Barus alpha", alpha, _ALPHA_HINT, allow_zero=True)
    e = _eps(eps)
    c = 2.0 * (1.0 - _nu(nu))
    return _out(2.0 * a / (math.pi * c * np.sqrt(e)))


def hd_piezo_eps_power(which: str = "central") -> float:
    r"""Residual power of ``eps = h_inf/R`` in a piezoviscous-elastic film in femehl units.

    With ``H = A U^a G^g W^b f(k)``, ``U ~ eps^2``, ``W ~ eps^(3/2)``, ``G ~ eps^(-1/2)``
    (:func:`hd_groups`, :func:`hd_material_parameter`) and ``d = H Rx/eps`` the film goes
    as ``eps^(2a + 1.5 b - 0.5 g - 1)``: central ``2(0.67) - 1.5(0.067) - 0.5(0.53) - 1 =
    -0.0255``, minimum ``2(0.68) - 1.5(0.073) - 0.5(0.49) - 1 = +0.0055``: over ``eps`` in
    [1e-4, 1e-2] a factor 1.12 (central) and 1.03 (minimum).

    Parameters
    ----------
    which : {'central', 'minimum'}
        Which film.

    Returns
    -------
    float
        The power ``2a + 1.5 b - 0.5 g - 1``.
    """
    _, a, g, b, _, _ = _which_piezo(which)
    return 2.0 * a + 1.5 * b - 0.5 * g - 1.0


def hd_piezo_film(beta, load, alpha, which="central", Rx=1.0, Ry=1.0, nu=0.5, eps=DEFAULT_EPS, k=None):
    r"""Hamrock & Dowson (1977) piezoviscous-elastic (hard EHL) film, in units of ``h_inf``.

    Formulas (fully flooded, isothermal, Newtonian; Barus-type viscosity rise; elliptical
    point contacts)::

        H_min = 3.63 U^0.68 G^0.49 W^-0.073 (1 - exp(-0.68 k))
        H_c   = 2.69 U^0.67 G^0.53 W^-0.067 (1 - 0.61 exp(-0.73 k))

    with ``H = h*/Rx*``, ``U = eta0 u/(E' Rx*)``, ``G = alpha* E'``, ``W = F*/(E' Rx*^2)``
    and ``k`` the ellipticity (transverse over entrainment-direction semi-axis).

    Source: B. J. Hamrock and D. Dowson, 'Isothermal elastohydrodynamic lubrication of
    point contacts, Part III - fully flooded results', ASME J. Lubr. Technol. 99 (1977)
    264-276.  Confirmed here: ``H_min`` with its coefficients, from the ASME abstract page
    of that paper (which also gives ``k = 1.03 (Ry/Rx)^0.64``).  ``H_c`` with its
    coefficients is the central-film companion commonly quoted with it (B. J. Hamrock,
    *Fundamentals of Fluid Film Lubrication*, NASA RP-1255, 1991; Hamrock, Schmid and
    Jacobson, 2004; not checked there): confirmed only from public implementations of the
    Hamrock-Dowson formulas (the ``sciforge-core`` crate on docs.rs; the Python
    ``tribology`` package), not from the paper.

    Range of validity (Part III abstract): ``k`` from 1 (ball on plate) to 8 (approaching
    line contact); ``U`` over nearly two orders of magnitude and ``W`` over one order
    around hard-EHL values; material groups of bronze, steel and silicon nitride with
    paraffinic and naphthenic mineral oils (``G`` of a few thousand).  Thirty-four
    numerical cases were fitted.  Stated accuracy: none could be found in the accessible
    sources (the paper itself was not accessible).  An optical experiment
    (Koye and Winer, J. Lubr. Technol. 103 (1981) 284) found minimum films 30 % above
    ``H_min`` on average.  Soft EHL with a moderate ``alpha`` lies outside that range:
    ``G <~ 400`` (:func:`hd_material_parameter`) against ``G ~ 4600`` for steel on a
    mineral oil, and the Hertz load of the unit sphere at ``hc = -1`` is
    ``W = 2.1e-5`` at ``eps = 1e-3``, about 50 times a 10 N load on a 10 mm steel ball
    (``W = 4.3e-7``): the formulas are extrapolated there (``benchmarks/hamrock_dowson.md``
    compares them with femehl).

    ``alpha -> 0``: ``G -> 0`` and the film vanishes like ``alpha^0.53`` (central) or
    ``alpha^0.49`` (minimum).  The formulas describe films that the viscosity rise makes,
    so they do not apply there: the isoviscous-elastic formulas (:func:`hd_film`) do.
    ``alpha = 0`` is accepted and returns 0.  :func:`hd_elastic_regime` says which of
    the two formulas applies.

    Conversion to femehl's normalization (:func:`hd_groups`, :func:`hd_material_parameter`)::

        U = (pi c/(24 Rx)) eps^2/beta,  W = (pi c/(2 Rx^2)) eps^(3/2) F,
        G = 2 alpha/(pi c sqrt(eps)),  d = H Rx/eps

    so ``d_c ~ beta^-0.67 alpha^0.53 F^-0.067 eps^-0.0255`` and
    ``d_min ~ beta^-0.68 alpha^0.49 F^-0.073 eps^0.0055`` (:func:`hd_piezo_eps_power`).

    Parameters
    ----------
    beta : float or array_like
        The ``beta`` of femehl's normalization (> 0, formed with the ambient viscosity).
    load : float or array_like
        Normalized load ``F = int p dA`` (> 0).
    alpha : float or array_like
        femehl's Barus coefficient (>= 0).
    which : {'central', 'minimum'}
        Which film.
    Rx, Ry : float, default: 1.0
        Radii of curvature along and across the sliding direction (units of ``R``).
    nu : float, default: 0.5
        Poisson ratio of the substrate, in (-1, 0.5].
    eps : float or array_like, default: DEFAULT_EPS
        ``h_inf/R``.
    k : float, optional
        Ellipticity; default :func:`ellipticity` ``(Rx, Ry)`` (exact Hertz, 1 for a sphere).

    Returns
    -------
    float or ndarray
        The film thickness ``d`` in units of ``h_inf``, broadcast over ``beta``, ``load``,
        ``alpha`` and ``eps``.

    Raises
    ------
    SceneError
        If ``beta`` or ``load`` is not positive, ``alpha`` is negative, ``which`` is
        unknown, or another input is invalid.
    """
    A, a, g, b, C, D = _which_piezo(which)
    U, W = hd_groups(beta, load, Rx=Rx, nu=nu, eps=eps)
    G = hd_material_parameter(alpha, nu=nu, eps=eps)
    if k is None:
        k = ellipticity(Rx, Ry)
    kk = _array("Ellipticity k", k, "Give k > 0, or leave k=None to take it from Rx and Ry.")
    rx = _array("Rx", Rx, _R_HINT)
    e = _eps(eps)
    H = A * np.asarray(U) ** a * np.asarray(G) ** g * np.asarray(W) ** b * (1.0 - C * np.exp(-D * kk))
    return _out(H * rx / e)


def hd_piezo_central_film(beta, load, alpha, Rx=1.0, Ry=1.0, nu=0.5, eps=DEFAULT_EPS, k=None):
    r"""Hamrock & Dowson (1977) piezoviscous-elastic central film ``d_c`` in units of ``h_inf``.

    ``H_c = 2.69 U^0.67 G^0.53 W^-0.067 (1 - 0.61 exp(-0.73 k))``, converted as in
    :func:`hd_piezo_film` (which gives the source, what was confirmed, the range of
    validity and why the formula does not apply as ``alpha -> 0``).

    Parameters
    ----------
    beta : float or array_like
        The ``beta`` of femehl's normalization (> 0).
    load : float or array_like
        Normalized load ``F`` (> 0).
    alpha : float or array_like
        femehl's Barus coefficient (>= 0).
    Rx, Ry : float, default: 1.0
        Radii of curvature (units of ``R``).
    nu : float, default: 0.5
        Poisson ratio of the substrate.
    eps : float or array_like, default: DEFAULT_EPS
        ``h_inf/R``.
    k : float, optional
        Ellipticity; default from ``Rx``, ``Ry`` (exact Hertz).

    Returns
    -------
    float or ndarray
        ``d_c``.

    Raises
    ------
    SceneError
        If an input is invalid (see :func:`hd_piezo_film`).

    Examples
    --------
    The unit sphere under the Hertz load of ``hc = -1`` at ``beta = 200``, ``alpha = 10``:

    >>> from femehl import theory
    >>> round(theory.hd_piezo_central_film(200.0, theory.hertz_load(1.0), 10.0), 4)
    0.0457
    """
    return hd_piezo_film(beta, load, alpha, "central", Rx=Rx, Ry=Ry, nu=nu, eps=eps, k=k)


def hd_piezo_minimum_film(beta, load, alpha, Rx=1.0, Ry=1.0, nu=0.5, eps=DEFAULT_EPS, k=None):
    r"""Hamrock & Dowson (1977) piezoviscous-elastic minimum film ``d_min`` in units of ``h_inf``.

    ``H_min = 3.63 U^0.68 G^0.49 W^-0.073 (1 - exp(-0.68 k))``, converted as in
    :func:`hd_piezo_film` (which gives the source, what was confirmed, the range of
    validity and why the formula does not apply as ``alpha -> 0``).

    Parameters
    ----------
    beta : float or array_like
        The ``beta`` of femehl's normalization (> 0).
    load : float or array_like
        Normalized load ``F`` (> 0).
    alpha : float or array_like
        femehl's Barus coefficient (>= 0).
    Rx, Ry : float, default: 1.0
        Radii of curvature (units of ``R``).
    nu : float, default: 0.5
        Poisson ratio of the substrate.
    eps : float or array_like, default: DEFAULT_EPS
        ``h_inf/R``.
    k : float, optional
        Ellipticity; default from ``Rx``, ``Ry`` (exact Hertz).

    Returns
    -------
    float or ndarray
        ``d_min``.

    Raises
    ------
    SceneError
        If an input is invalid (see :func:`hd_piezo_film`).
    """
    return hd_piezo_film(beta, load, alpha, "minimum", Rx=Rx, Ry=Ry, nu=nu, eps=eps, k=k)


def hd_regime_parameters(beta, load, alpha, Rx=1.0, nu=0.5):
    r"""Hamrock's regime parameters ``(g_V, g_E)`` of a normalized femehl state.

    Hamrock and Dowson chart the four regimes of fluid-film lubrication (isoviscous-rigid,
    piezoviscous-rigid, isoviscous-elastic, piezoviscous-elastic) on the viscosity and
    elasticity parameters (B. J. Hamrock, *Fundamentals of Fluid Film Lubrication*, NASA
    RP-1255, 1991; Esfahanian and Hamrock 1991; neither checked here: the definitions are
    those of the task brief and of a public transcription, GitHub jl293/tribopy)::

        g_V = G W^3 / U^2,     g_E = W^(8/3) / U^2

    (the film parameter is ``g_H = H W^2/U^2``).  With the groups of :func:`hd_groups` and
    :func:`hd_material_parameter` the ratio ``eps = h_inf/R`` cancels from both::

        g_E = (pi c/(2 Rx^2))^(8/3) (pi c/(24 Rx))^-2 F^(8/3) beta^2
        g_V = (2 alpha/(pi c)) (pi c/(2 Rx^2))^3 (pi c/(24 Rx))^-2 F^3 beta^2

    so, unlike the films, the regime is fixed by femehl's normalized state and ``alpha``
    alone.  Large ``g_E`` is elastic, large ``g_V`` piezoviscous; the published regime
    boundaries could not be checked here (see :func:`hd_elastic_regime`).

    Parameters
    ----------
    beta : float or array_like
        The ``beta`` of femehl's normalization (> 0).
    load : float or array_like
        Normalized load ``F`` (> 0).
    alpha : float or array_like
        femehl's Barus coefficient (>= 0).
    Rx : float or array_like, default: 1.0
        Radius of curvature along the sliding direction (units of ``R``).
    nu : float, default: 0.5
        Poisson ratio of the substrate.

    Returns
    -------
    g_V : float or ndarray
        The viscosity parameter (0 for ``alpha = 0``).
    g_E : float or ndarray
        The elasticity parameter.

    Raises
    ------
    SceneError
        If ``beta`` or ``load`` is not positive, ``alpha`` is negative, or another input is
        invalid.
    """
    b = _array("beta", beta, _BETA_HINT)
    f = _array("Load F", load, _LOAD_HINT)
    a = _array("Barus alpha", alpha, _ALPHA_HINT, allow_zero=True)
    rx = _array("Rx", Rx, _R_HINT)
    c = 2.0 * (1.0 - _nu(nu))
    u_coef = math.pi * c / (24.0 * rx)
    w_coef = math.pi * c / (2.0 * rx**2)
    g_E = w_coef ** (8.0 / 3.0) * f ** (8.0 / 3.0) * b**2 / u_coef**2
    g_V = 2.0 * a / (math.pi * c) * w_coef**3 * f**3 * b**2 / u_coef**2
    g_V, g_E = np.broadcast_arrays(g_V, g_E)
    return _out(g_V), _out(g_E)


#: the two elastic regimes :func:`hd_elastic_regime` tells apart
ELASTIC_REGIMES = ("isoviscous-elastic", "piezoviscous-elastic")


def hd_elastic_regime(beta, load, alpha, Rx=1.0, Ry=1.0, nu=0.5, eps=DEFAULT_EPS, k=None):
    r"""Isoviscous- or piezoviscous-elastic: which Hamrock-Dowson minimum film is the larger.

    The criterion is derived here, not taken from a published chart: a viscosity that
    rises with pressure can only thicken the film, and each formula is an asymptote of
    its own regime (the isoviscous-elastic one as ``G -> 0``, the piezoviscous-elastic
    one where the viscosity rise sets the film), so the state is placed in the regime
    whose formula predicts the larger minimum film, :func:`hd_minimum_film` (1978) or
    :func:`hd_piezo_minimum_film` (1977).  The two are equal where
    ``alpha^0.49 ~ beta^0.03 F^-0.137 eps^-0.0205`` (times a constant; for the unit
    sphere under the Hertz load of ``hc = -1`` at ``eps = 1e-3``: ``alpha = 9.1`` at
    ``beta = 200``, 10.1 at ``beta = 1000``), which is not a line of constant
    ``g_V/g_E``.  Hamrock and Dowson's regime charts (Esfahanian and Hamrock, 'Fluid-film
    lubrication regimes revisited', Tribol. Trans. 34 (1991); citation and content not
    checked here) bound the regimes in the ``(g_V, g_E)`` plane with their own, refitted
    formulas; those boundaries could not be checked, so the rigid regimes (small
    ``g_E``) are not classified: the function assumes an elastic contact (check that the
    deflection is much larger than the film).

    Parameters
    ----------
    beta : float or array_like
        The ``beta`` of femehl's normalization (> 0).
    load : float or array_like
        Normalized load ``F`` (> 0).
    alpha : float or array_like
        femehl's Barus coefficient (>= 0).
    Rx, Ry : float, default: 1.0
        Radii of curvature (units of ``R``).
    nu : float, default: 0.5
        Poisson ratio of the substrate.
    eps : float or array_like, default: DEFAULT_EPS
        ``h_inf/R``.
    k : float, optional
        Ellipticity; default from ``Rx``, ``Ry`` (exact Hertz).

    Returns
    -------
    str or ndarray of str
        ``"isoviscous-elastic"`` or ``"piezoviscous-elastic"`` (:data:`ELASTIC_REGIMES`).

    Raises
    ------
    SceneError
        If an input is invalid.
    """
    iso = np.asarray(hd_minimum_film(beta, load, Rx=Rx, Ry=Ry, nu=nu, eps=eps, k=k))
    piezo = np.asarray(hd_piezo_minimum_film(beta, load, alpha, Rx=Rx, Ry=Ry, nu=nu, eps=eps, k=k))
    iso, piezo = np.broadcast_arrays(iso, piezo)
    label = np.where(piezo > iso, ELASTIC_REGIMES[1], ELASTIC_REGIMES[0])
    return str(label) if label.ndim == 0 else label


# ---------------------------------------------------------------------- scaling exponents


def scaling_exponents() -> dict:
    r"""Large-``beta`` scaling exponents of the steady-sliding films, with their sources.

    Each entry maps a name to a dict with ``exponent`` (float), ``variable`` (what the
    film is a power of, everything else fixed), ``source`` (full citation) and
    ``statement`` (one line).  At fixed indentation the load tends to the Hertz load as
    ``beta`` grows, so the load factor is a constant there and the films scale as the
    ``beta`` exponents below.

    Entries:

    - ``hd_central_beta`` = -0.64 and ``hd_minimum_beta`` = -0.65: ``d ~ beta^-a`` from
      ``H ~ U^a``, ``U ~ 1/beta`` (:func:`hd_groups`); empirical fits (see :func:`hd_film`
      for what was confirmed).
    - ``hd_central_load`` = -0.22 and ``hd_minimum_load`` = -0.21: the load factor.
    - ``hd_central_eps`` = -0.05 and ``hd_minimum_eps`` = -0.015: the residual dependence on
      ``h_inf/R`` (:func:`hd_eps_power`).
    - ``sev2013_film_speed`` = 3/5: Snoeijer, Eggers & Venner (2013), abstract: 'a fluid
      film develops between the two solids, whose thickness scales as U^(3/5)', U the
      relative speed, at fixed load and materials; with ``beta ~ 1/(eta V_ss)`` and
      ``h_inf`` fixed this is ``d ~ beta^(-3/5)``.  The asymptotic theory is built on the
      two-dimensional (line) contact (Wu et al. 2022 describe it as a sliding rigid
      cylinder); the abstract states that its results for a soft sphere against a hard
      wall agree with experiment and numerics, but gives no separate point-contact
      exponent for the central and the exit (minimum) film.

    Not included (not confirmed from the sources found): a distinct asymptotic exponent
    for the point-contact minimum (exit) film, and the prefactors and load exponents of
    the similarity theory.

    Returns
    -------
    dict
        ``{name: {"exponent", "variable", "source", "statement"}}``.
    """
    hd_c, hd_m = _HD_FITS["central"], _HD_FITS["minimum"]
    return {
        "hd_central_beta": {
            "exponent": -hd_c[1],
            "variable": "beta",
            "source": HD1978,
            "statement": "Central film d_c ~ beta^-0.64 at fixed load (H_c ~ U^0.64, U ~ 1/beta).",
        },
        "hd_minimum_beta": {
            "exponent": -hd_m[1],
            "variable": "beta",
            "source": HD1978,
            "statement": "Minimum film d_min ~ beta^-0.65 at fixed load (H_min ~ U^0.65, U ~ 1/beta).",
        },
        "hd_central_load": {
            "exponent": hd_c[2],
            "variable": "load",
            "source": HD1978,
            "statement": "Central film d_c ~ F^-0.22 at fixed beta (H_c ~ W^-0.22, W ~ F).",
        },
        "hd_minimum_load": {
            "exponent": hd_m[2],
            "variable": "load",
            "source": HD1978,
            "statement": "Minimum film d_min ~ F^-0.21 at fixed beta (H_min ~ W^-0.21, W ~ F).",
        },
        "hd_central_eps": {
            "exponent": hd_eps_power("central"),
            "variable": "eps",
            "source": HD1978 + "; derived here (femehl.reference.theory.hd_eps_power)",
            "statement": "d_c ~ (h_inf/R)^(2*0.64 - 1.5*0.22 - 1) = (h_inf/R)^-0.05 at fixed beta and F.",
        },
        "hd_minimum_eps": {
            "exponent": hd_eps_power("minimum"),
            "variable": "eps",
            "source": HD1978 + "; derived here (femehl.reference.theory.hd_eps_power)",
            "statement": "d_min ~ (h_inf/R)^(2*0.65 - 1.5*0.21 - 1) = (h_inf/R)^-0.015 at fixed beta and F.",
        },
        "sev2013_film_speed": {
            "exponent": -3.0 / 5.0,
            "variable": "beta",
            "source": SEV2013,
            "statement": (
                "Film thickness ~ U^(3/5) (asymptotic, large deformation; derived for the 2D contact, "
                "stated to agree for a soft sphere), i.e. d ~ beta^(-3/5) at fixed load."
            ),
        },
    }
