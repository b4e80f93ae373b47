"""Dry contact of a rigid sphere and an elastic half space through a Greenwood-Tripp rough interface.

An independent reference (numpy/scipy only) for the zero-speed limit of femehl's mixed-lubrication
solver, in femehl's normalized units (docs/design.md sections 1-2: lengths in the plane by
``sqrt(R h_inf)``, heights by ``h_inf``, pressure by ``p0 = 4 pi G sqrt(h_inf/R)``)::

    d(r) = hc + r^2/2 + c int int p(x') / |x - x'| dA'      mean separation; c = 1 (incompressible)
    p(r) = K F_n(d(r) / sigma)                              asperity pressure, n = 5/2 (GT 1970)
    F_n(t) = (2 pi)^(-1/2) int_t^inf (s - t)^n exp(-s^2/2) ds,   dF_n/dt = -n F_{n-1}
    load = 2 pi int_0^L p r dr;   Hertz limit (sigma -> 0, K large): hc = -1 gives load 4/(3 pi)
    K = (8 sqrt(2)/15) pi (n_a beta_a sigma_s)^2 sqrt(sigma_s/beta_a) E'/p0,   E'/p0 = 1/(pi sqrt(h_inf/R))

``sigma`` is the combined rms roughness over ``h_inf``; ``K`` the asperity stiffness over ``p0`` (GT 1970:
asperity density ``n_a``, radius ``beta_a``, summit rms ``sigma_s``, plane-strain modulus ``E' = 4 G`` at
``nu = 0.5``; :func:`gt_stiffness`).  Roughness matters through ``alpha = sigma/a_H^2`` (``sigma* R/a_H*^2``;
Greenwood & Tripp 1967; Johnson, Contact Mechanics 1985, section 13.7) and, weakly, ``kappa = K/a_H``.

Method: piecewise-linear ``p`` on a uniform grid of ``[0, L]`` (zero beyond ``L``), the ring kernel
``4 r' K(k)/(r + r')`` integrated exactly per element (Gauss-Legendre, and a product rule for its
logarithm next to the target), collocation at the nodes; Newton with a backtracking line search.
"""

from __future__ import annotations

import functools
import math
import numbers
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipkm1, eval_sh_legendre

from femehl.errors import SceneError, SolverError

__all__ = [
    "RoughContact",
    "boussinesq_operator",
    "default_radius",
    "greenwood_tripp",
    "greenwood_tripp_derivative",
    "gt_stiffness",
    "rough_sphere_contact",
    "rough_sphere_contact_load",
]

#: ``F_n(T_EDGE)`` is the neglected pressure's scale: ``F_{5/2}(7.5) = 6e-16`` (``F_{5/2}(0) = 0.617``).
T_EDGE = 7.5

# F_n by Gauss-Legendre: 96 nodes reproduce F_n (n = -1/2 ... 3) to 5e-14 (relative) on t in [-1000, 37]
# against mpmath's 40-digit parabolic cylinder function; t < -10 uses the s form (branch point outside
# [-9, 9]), t > 40 gives 0 (F_n(40) ~ exp(-800)).
_GL_X, _GL_W = np.polynomial.legendre.leggauss(96)
_T_SPLIT = -10.0
_S_CUT = 9.0  # exp(-81/2) = 2.6e-18: the Gaussian beyond |s| = 9 is below double precision of F

# Element quadrature of the ring kernel (see _unit_operator): Q Gauss-Legendre nodes on [0, 1] for the
# elements away from the target, Q_NEAR nodes and product weights of int_0^1 f(s) (-ln s) ds (exact for
# degree < Q_NEAR) for the two touching it.  Entries agree with 30-digit quadrature to 1e-13.
_Q, _Q_NEAR = 10, 24


def _rule(q):
    """Gauss-Legendre on [0, 1] and the product weights of ``-ln s`` at the same nodes."""
    x, w = np.polynomial.legendre.leggauss(q)
    s, w = 0.5 * (x + 1.0), 0.5 * w
    mom = [1.0] + [(-1.0) ** k / (k * (k + 1.0)) for k in range(1, q)]  # int_0^1 P*_k(s) (-ln s) ds
    wlog = w * sum((2 * k + 1) * eval_sh_legendre(k, s) * mom[k] for k in range(q))
    return s, w, wlog


_S, _WS, _ = _rule(_Q)
_SN, _WN, _WLOG = _rule(_Q_NEAR)
# (2/pi) K(k') = sum a_m^2 m1^m, a_m = (1/2)_m/m!: the coefficient of -ln(m1)/2 in K(k), m1 = 1 - k^2
_LOG_COEF = [1.0, 1.0 / 4.0, 9.0 / 64.0, 25.0 / 256.0, 1225.0 / 16384.0, 3969.0 / 65536.0]

_MAX_N = 6000  # a dense (n + 1)^2 matrix: 288 MB at 6000


# ---------------------------------------------------------------------------- input checks


def _real(name, value, hint, *, positive=True):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise SceneError(f"{name} must be a real number, got {value!r}. {hint}")
    value = float(value)
    if not math.isfinite(value):
        raise SceneError(f"{name} must be finite, got {value!r}. {hint}")
    if positive and value <= 0.0:
        raise SceneError(f"{name} must be positive, got {value!r}. {hint}")
    return value


def _order(order, minimum):
    hint = "Pass the Greenwood-Tripp order n, e.g. 2.5 (GT 1970) or 1.5 (GW)."
    order = _real("order", order, hint, positive=False)
    if order < minimum:
        raise SceneError(f"order must be >= {minimum}, got {order!r}. Pass order=2.5 (GT) or 1.5 (GW).")
    return order


# ---------------------------------------------------------------------------- Greenwood-Tripp


def _gt(t: np.ndarray, n: float) -> np.ndarray:
    """``F_n(t)`` for ``n >= -1/2`` by Gauss-Legendre (no closed form used)."""
    out = np.zeros_like(t)  # t > 40: F_n(t) < exp(-800), zero in double precision
    hi = (t >= _T_SPLIT) & (t <= 40.0)
    lo = t < _T_SPLIT
    if np.any(hi):
        # x = s - t = u^2: F = (2 pi)^(-1/2) exp(-t^2/2) int_0^U 2 u^(2n+1) exp(-u^2 (u^2 + 2t)/2) du, an
        # entire integrand for n = k/2; U^2 (U^2 + 2t)/2 = 40 cuts it at exp(-40) of its peak.
        th = t[hi][:, None]
        U = np.sqrt(np.sqrt(th * th + 80.0) - th)
        u = 0.5 * U * (_GL_X + 1.0)
        g = 2.0 * u ** (2.0 * n + 1.0) * np.exp(-0.5 * u * u * (u * u + 2.0 * th))
        with np.errstate(under="ignore"):
            out[hi] = 0.5 * U[:, 0] * (g @ _GL_W) * np.exp(-0.5 * t[hi] ** 2) / math.sqrt(2.0 * math.pi)
    if np.any(lo):
        # t < -10: the weight exp(-s^2/2) on [-9, 9], (s - t)^n smooth there
        tl = t[lo][:, None]
        s = _S_CUT * _GL_X
        g = (s - tl) ** n * np.exp(-0.5 * s * s)
        out[lo] = _S_CUT * (g @ _GL_W) / math.sqrt(2.0 * math.pi)
    return out


def greenwood_tripp(t, n: float = 2.5):
    """The Greenwood-Tripp function ``F_n(t) = (2 pi)^(-1/2) int_t^inf (s - t)^n exp(-s^2/2) ds``.

    The ``n``-th moment of a unit Gaussian above ``t``: ``K F_{5/2}(d/sigma)`` is the asperity pressure
    at mean separation ``d`` (Greenwood & Tripp 1970), ``F_{3/2}`` Greenwood-Williamson's.  Evaluated by
    96-point Gauss-Legendre quadrature after ``s - t = u^2``: relative error below 5e-14 for n in
    [-1/2, 3] and every real ``t`` down to underflow (``t ~ 38``; measured against mpmath).  Vectorized;
    a float for scalar ``t``.  ``n >= -1/2``.
    """
    n = _order(n, -0.5)
    arr = np.asarray(t, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise SceneError(f"t must be finite, got {t!r}. Pass finite separations d/sigma.")
    out = _gt(np.atleast_1d(arr).ravel(), n).reshape(arr.shape)
    return float(out) if out.ndim == 0 else out


def greenwood_tripp_derivative(t, n: float = 2.5):
    """``dF_n/dt = -n F_{n-1}(t)`` (differentiate under the integral); ``n >= 1/2``."""
    n = _order(n, 0.5)
    return -n * greenwood_tripp(t, n - 1.0)


def gt_stiffness(R, G, h_inf, density, radius, summit_rms, nu=0.5):
    """``K`` of ``p = K F_{5/2}(d/sigma)`` in femehl's pressure unit, from SI inputs.

    Greenwood & Tripp (1970) for two rough surfaces (the form used in mixed-EHL models)::

        p* = (8 sqrt(2)/15) pi (n_a beta_a sigma_s)^2 sqrt(sigma_s/beta_a) E' F_{5/2}(d*/sigma*)

    with ``n_a = density`` the asperity density [1/m^2], ``beta_a = radius`` the asperity radius [m],
    ``sigma_s = summit_rms`` the rms of summit heights [m] and ``E' = E/(1 - nu^2) = 2 G/(1 - nu)`` the
    plane-strain modulus of the substrate (the sphere is rigid).  Some authors' ``E'`` is twice this;
    check the source of the GT data.  femehl's ``p0 = 4 pi G sqrt(h_inf/R)`` whatever ``nu`` (a
    compressible substrate has the kernel factor ``2 (1 - nu)``: pass ``compliance=2 (1 - nu)`` to
    :func:`rough_sphere_contact`), so ``E'/p0 = 1/(2 pi (1 - nu) sqrt(h_inf/R))``, ``1/(pi sqrt(h_inf/R))``
    at ``nu = 0.5``.  The argument's ``sigma`` is ``sigma*/h_inf``, ``sigma*`` the combined rms roughness.
    """
    R = _real("R", R, "Pass the sphere's radius in metres.")
    G = _real("G", G, "Pass the substrate's shear modulus in pascals.")
    h_inf = _real("h_inf", h_inf, "Pass femehl's film scale h_inf in metres.")
    density = _real("density", density, "Pass the asperity density n_a in 1/m^2.")
    radius = _real("radius", radius, "Pass the asperity radius beta_a in metres.")
    summit_rms = _real("summit_rms", summit_rms, "Pass the rms of the summit heights sigma_s in metres.")
    nu = _real("nu", nu, "Pass Poisson's ratio in (-1, 0.5].", positive=False)
    if not -1.0 < nu <= 0.5:
        raise SceneError(f"nu must be in (-1, 0.5], got {nu!r}. Pass nu=0.5 for an incompressible substrate.")
    e_prime = 2.0 * G / (1.0 - nu)
    p0 = 4.0 * math.pi * G * math.sqrt(h_inf / R)
    k_si = (8.0 * math.sqrt(2.0) / 15.0) * math.pi * (density * radius * summit_rms) ** 2
    return k_si * math.sqrt(summit_rms / radius) * e_prime / p0


# ---------------------------------------------------------------------------- elastic operator


def _ring_kernel(r, rho):
    """``4 rho K(k)/(r + rho)``, ``k^2 = 4 r rho/(r + rho)^2`` (int over the ring of 1/distance).

    ``K`` from ``1 - k^2 = ((r - rho)/(r + rho))^2`` (``ellipkm1``): forming ``k^2`` first loses
    ``1e-16/(1 - k^2)`` relative near the diagonal (2e-9 in the last entry at n = 40)."""
    return 4.0 * rho * ellipkm1(((r - rho) / (r + rho)) ** 2) / (r + rho)


@functools.lru_cache(maxsize=4)
def _unit_operator(n: int) -> np.ndarray:
    """``A[i, j] = int phi_j(rho) 4 rho K(k(i, rho))/(i + rho) d rho`` on the grid ``0, 1, ..., n``.

    The kernel is homogeneous of degree 0 in ``(r, rho)``, so on spacing ``h`` the operator is ``h A``.
    Elements not touching node i: Q-point Gauss-Legendre (the log singularity is at least one element
    away: error ~ (3 + sqrt 8)^(-2Q) relative).  The two elements touching node i: the kernel is split as
    ``g_log(rho) (-ln|i - rho|) + g_reg(rho)`` with ``g_log = 4 rho c(m1)/(i + rho)``, ``c`` the log's
    coefficient in ``K`` (six terms of ``(2/pi) K(k')``), the log part by the product weights.
    """
    A = np.zeros((n + 1, n + 1))
    A[0, :] = 2.0 * math.pi  # r = 0: the kernel is 2 pi; int phi_j = 1 (1/2 at both ends)
    A[0, 0] = A[0, n] = math.pi
    left = np.arange(n, dtype=float)  # element e = [e, e + 1]
    rho = left[:, None] + _S[None, :]  # (n, Q)
    N1 = _S[None, :]
    N0 = 1.0 - N1
    block = max(1, 2_000_000 // (n * _Q))
    for i0 in range(1, n + 1, block):
        rows = np.arange(i0, min(n + 1, i0 + block))
        r = rows.astype(float)[:, None, None]
        G = _ring_kernel(r, rho[None])  # (b, n, Q)
        c0 = np.einsum("ieq,q->ie", G * N0[None], _WS)
        c1 = np.einsum("ieq,q->ie", G * N1[None], _WS)
        for e in (rows - 1, rows):  # the touching elements: below
            ok = e < n
            c0[np.flatnonzero(ok), e[ok]] = 0.0
            c1[np.flatnonzero(ok), e[ok]] = 0.0
        A[rows, :n] += c0
        A[rows, 1:] += c1
    # the two elements touching node i, all i at once: e = i - 1 (|i - x| = 1 - s) and e = i (= s)
    for first, dist, wlog in ((1, 1.0 - _SN, _WLOG[::-1]), (0, _SN, _WLOG)):
        i = np.arange(1, n + first, dtype=float)[:, None]  # targets with that element inside [0, n]
        e = i - first
        x = e + _SN[None, :]  # -ln(1 - s) has the mirrored weights (the nodes are symmetric)
        m1 = ((i - x) / (i + x)) ** 2
        g_log = 4.0 * x * sum(a * m1**k for k, a in enumerate(_LOG_COEF)) / (i + x)
        g_reg = _ring_kernel(i, x) + g_log * np.log(dist)
        ii, ee = i[:, 0].astype(int), e[:, 0].astype(int)
        A[ii, ee] += g_reg @ (_WN * (1.0 - _SN)) + g_log @ (wlog * (1.0 - _SN))
        A[ii, ee + 1] += g_reg @ (_WN * _SN) + g_log @ (wlog * _SN)
    A.setflags(write=False)
    return A


def boussinesq_operator(L: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``(r, A)``: nodes ``r_i = i L/n`` and ``(A p)_i = int int p(x')/|x_i - x'| dA'`` for the
    piecewise-linear ``p`` of nodal values ``p_j`` (zero beyond ``L``)."""
    L = _real("L", L, "Pass the outer radius of the pressure, e.g. L=2.")
    n = _grid(n)
    h = L / n
    return h * np.arange(n + 1), h * _unit_operator(n)


def _grid(n):
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, numbers.Integral):
        raise SceneError(f"n must be an integer (the number of radial elements), got {n!r}. Pass e.g. n=800.")
    n = int(n)
    if not 16 <= n <= _MAX_N:
        raise SceneError(
            f"n must be in [16, {_MAX_N}] (the number of radial elements; the operator is dense), got {n}. "
            "Pass e.g. n=800."
        )
    return n


def _load_weights(r: np.ndarray) -> np.ndarray:
    """``w`` with ``w @ p = 2 pi int_0^L p r dr`` exactly for piecewise-linear ``p``."""
    h = r[1] - r[0]
    w = np.zeros_like(r)
    w[:-1] += h / 6.0 * (2.0 * r[:-1] + r[1:])
    w[1:] += h / 6.0 * (r[:-1] + 2.0 * r[1:])
    return 2.0 * math.pi * w


# ---------------------------------------------------------------------------- the contact


@dataclass(frozen=True, eq=False)
class RoughContact:
    """The solution of :func:`rough_sphere_contact` (normalized units).

    ``r`` the nodes on ``[0, L]``, ``p`` the asperity pressure and ``d`` the mean separation there;
    ``load = 2 pi int p r dr`` (exact for the piecewise-linear ``p``); ``central_separation = d(0)``;
    ``edge_pressure = p(L)`` (the pressure neglected beyond ``L`` starts there); ``residual`` the final
    ``max |R|`` and ``iterations`` Newton's.  The other fields echo the arguments.
    """

    hc: float
    sigma: float
    K: float
    order: float
    compliance: float
    L: float
    r: np.ndarray
    p: np.ndarray
    d: np.ndarray
    load: float
    central_separation: float
    max_pressure: float
    edge_pressure: float
    iterations: int
    residual: float

    def pressure(self, r):
        """The piecewise-linear pressure at ``r`` (zero beyond ``L``); a float for scalar ``r``."""
        x = np.abs(np.asarray(r, dtype=float))
        out = np.where(x <= self.L, np.interp(x, self.r, self.p), 0.0)
        return float(out) if out.ndim == 0 else out


def default_radius(hc: float, sigma: float) -> float:
    """``L`` with ``hc + L^2/2 = T_EDGE sigma``: the separation there is at least ``7.5 sigma`` (the
    deflection only adds to it), so ``p(L) <= K F_n(7.5)``; at least 1.2 (the Hertz radius is ~1)."""
    return max(1.2, math.sqrt(2.0 * max(T_EDGE * sigma - hc, 0.0)))


def _start(hc, r, sigma, K, order, compliance):
    """Newton's start: ``max(d_Hertz, sigma t)`` with ``K F_n(t) = p_Hertz`` (``t = 7.5`` outside).

    ``d_Hertz`` is the smooth contact's separation at the same ``hc`` (zero on ``r < a = sqrt(-hc)``):
    the limit of small ``alpha``, where the asperities only add the separation ``sigma t`` that carries
    the Hertz pressure.  For ``hc >= 0`` (no Hertz contact) the rigid gap ``hc + r^2/2``.  Measured on
    hc in [-10, 0.5], sigma in [1e-3, 3], K in [1e-2, 1e4], n = 3/2 and 5/2: 3-9 Newton iterations for
    hc < 0 (mean 6.2), up to 17 for hc >= 0 with stiff asperities."""
    g = hc + 0.5 * r * r
    if hc >= 0.0:
        return g.copy()
    a = math.sqrt(-hc)
    x = np.minimum(r / a, 1.0)
    # Hertz (Johnson 1985, eq. 3.41-3.42 times pi): int int p/|x - x'| dA' is a^2 - r^2/2 on r <= a and
    # ((2 a^2 - r^2) asin(a/r) + a sqrt(r^2 - a^2))/pi beyond
    out = r > a
    w = np.full_like(r, -hc) - 0.5 * r * r
    ro = r[out]
    w[out] = ((2.0 * a * a - ro * ro) * np.arcsin(a / ro) + a * np.sqrt(ro * ro - a * a)) / math.pi
    d_h = np.maximum(g + w, 0.0)
    p_h = (2.0 * a / (math.pi**2 * compliance)) * np.sqrt(np.maximum(1.0 - x * x, 0.0))
    # t with K F_n(t) = p_H, interpolated on a grid of t (F_n decreases); t = T_EDGE where p_H = 0
    tt = np.linspace(-20.0, T_EDGE, 2001)
    Ft = K * _gt(tt, order)
    t = np.interp(-p_h, -Ft, tt)  # interpolate the decreasing F as an increasing function of -F
    return np.maximum(d_h, sigma * t)


def _residual(d, g, A, sigma, K, order):
    p = K * _gt(d / sigma, order)
    return p, d - g - A @ p


def _solve(g, A, sigma, K, order, starts, tol, max_iter):
    """Newton with backtracking on ``|R|_2`` for ``R(d) = d - g - A K F_n(d/sigma)``, from the start of
    smallest residual.  Stops at ``max|R| <= max(tol min(1, sigma), 16 eps max(1, max|g|))`` (the second
    is the rounding floor of ``R``)."""
    scale = max(tol * min(1.0, sigma), 16.0 * np.finfo(float).eps * max(1.0, float(np.max(np.abs(g)))))
    best = None
    for d0 in starts:
        p, R = _residual(d0, g, A, sigma, K, order)
        if best is None or np.linalg.norm(R) < best[3]:
            best = (d0.copy(), p, R, np.linalg.norm(R))
    d, p, R, norm = best
    res = float(np.max(np.abs(R)))
    eye = np.eye(len(d))
    for it in range(1, max_iter + 1):
        if res <= scale:
            return d, p, it - 1, res
        dp = -(K / sigma) * order * _gt(d / sigma, order - 1.0)
        step = np.linalg.solve(eye - A * dp[None, :], -R)
        lam = 1.0
        while True:
            p_new, R_new = _residual(d + lam * step, g, A, sigma, K, order)
            norm_new = np.linalg.norm(R_new)
            if norm_new <= (1.0 - 1e-4 * lam) * norm or lam < 1e-6:
                break
            lam *= 0.5
        d, p, R, norm = d + lam * step, p_new, R_new, norm_new
        res = float(np.max(np.abs(R)))
        if lam < 1e-6 and res > scale:
            break
    if res <= scale:
        return d, p, max_iter, res
    raise SolverError(
        f"Newton did not reach max|R| <= {scale:.3g} in {it} iterations (max|R| = {res:.3g}). "
        "Refine the grid (larger n) so the contact edge is resolved, or raise tol."
    )


def rough_sphere_contact(
    hc,
    sigma,
    K,
    L=None,
    n: int = 800,
    tol: float = 1e-10,
    *,
    order: float = 2.5,
    compliance: float = 1.0,
    max_iter: int = 60,
    start: np.ndarray | None = None,
) -> RoughContact:
    """The GT rough contact at the sphere's tip position ``hc`` (``< 0``: indentation).

    ``sigma`` the combined rms roughness, ``K`` the asperity stiffness (:func:`gt_stiffness`), ``order``
    the GT exponent (2.5; 1.5 is Greenwood-Williamson), ``compliance`` the kernel factor ``2 (1 - nu)``.
    ``L`` the outer radius (default :func:`default_radius`: ``p(L) <= K F_n(7.5)``), ``n`` the number of
    uniform radial elements (a uniform grid: the operator is computed once per ``n`` for every ``L``,
    and the GT pressure is smooth, so the load converges at order 2; measured).  Newton stops at
    ``max |R| <= tol min(1, sigma)`` (``R`` the separation equation's residual in units of ``h_inf``;
    rounding floor ``16 eps max|hc + r^2/2|``); it starts from :func:`_start` or from ``start`` (e.g. a
    neighbouring solution's ``d``), whichever has the smaller residual.  Bad input raises
    :class:`~femehl.errors.SceneError`, a Newton failure :class:`~femehl.errors.SolverError`.
    """
    hc = _real("hc", hc, "Pass the tip position in units of h_inf (e.g. hc=-1).", positive=False)
    sigma = _real("sigma", sigma, "Pass the combined rms roughness in units of h_inf (smooth: small sigma).")
    K = _real("K", K, "Pass the asperity stiffness in units of p0 (see gt_stiffness).")
    order = _order(order, 0.5)
    compliance = _real("compliance", compliance, "Pass 1 (incompressible) or 2 (1 - nu).")
    tol = _real("tol", tol, "Pass a residual tolerance such as 1e-10.")
    L = default_radius(hc, sigma) if L is None else _real("L", L, "Pass the outer radius, e.g. L=2.")
    if isinstance(max_iter, bool) or not isinstance(max_iter, numbers.Integral) or max_iter < 1:
        raise SceneError(f"max_iter must be a positive integer, got {max_iter!r}. Pass e.g. max_iter=60.")
    r, A = boussinesq_operator(L, n)
    A = compliance * A
    g = hc + 0.5 * r * r
    starts = [_start(hc, r, sigma, K, order, compliance)]
    if start is not None:
        d0 = np.asarray(start, dtype=float)
        if d0.shape != r.shape or not np.all(np.isfinite(d0)):
            raise SceneError(f"start must be {r.size} finite separations (one per node). Pass start=None.")
        starts.append(d0)
    d, p, its, res = _solve(g, A, sigma, K, order, starts, tol, int(max_iter))
    return RoughContact(
        hc=hc,
        sigma=sigma,
        K=K,
        order=order,
        compliance=compliance,
        L=float(L),
        r=r,
        p=p,
        d=d,
        load=float(_load_weights(r) @ p),
        central_separation=float(d[0]),
        max_pressure=float(np.max(p)),
        edge_pressure=float(p[-1]),
        iterations=its,
        residual=res,
    )


def rough_sphere_contact_load(
    F, sigma, K, L=None, n: int = 800, tol: float = 1e-10, **kwargs
) -> RoughContact:
    """The GT rough contact carrying the load ``F`` (normalized): ``hc`` by brentq on the load.

    The load decreases with ``hc``; the bracket grows from the Hertz value ``-(3 pi c F/4)^(2/3)``
    (``c`` the compliance).  ``L`` defaults to :func:`default_radius` of the bracket's lower end, fixed
    for the whole search; each solve may start from the nearest solved ``hc``'s separation shifted by
    the change of ``hc``.  ``hc`` is found to ``1e-12 max(1, |hc_H|)``, the load to ~1e-12 relative.
    Other keyword arguments as :func:`rough_sphere_contact` (not ``start``).
    """
    if "start" in kwargs:
        raise SceneError("start is chosen by the load search itself. Drop the start argument.")
    F = _real("F", F, "Pass a positive load in femehl's units (the paper's Hertz load is 4/(3 pi)).")
    sigma = _real("sigma", sigma, "Pass the combined rms roughness in units of h_inf (smooth: small sigma).")
    compliance = _real("compliance", kwargs.get("compliance", 1.0), "Pass 1 (incompressible) or 2 (1 - nu).")
    hc_h = -((0.75 * math.pi * compliance * F) ** (2.0 / 3.0))
    step = max(0.25 * abs(hc_h), 2.0 * sigma)
    cache = {}

    def solve(hc, L_):
        key = (hc, L_)
        if key not in cache:
            start = None
            if cache:
                near = min(cache.values(), key=lambda c: abs(c.hc - hc) if c.L == L_ else math.inf)
                if near.L == L_:
                    start = near.d + (hc - near.hc)
            cache[key] = rough_sphere_contact(hc, sigma, K, L_, n, tol, start=start, **kwargs)
        return cache[key]

    lo, hi = hc_h, hc_h
    L_lo = default_radius(lo, sigma) if L is None else L
    while solve(lo, L_lo).load < F:  # indent further until the load exceeds F
        lo -= step
        step *= 2.0
        L_lo = default_radius(lo, sigma) if L is None else L
    L_fix = L_lo
    step = max(0.25 * abs(hc_h), 2.0 * sigma)
    while solve(hi, L_fix).load > F:
        hi += step
        step *= 2.0
    root = brentq(
        lambda hc: solve(hc, L_fix).load - F,
        lo,
        hi,
        xtol=1e-12 * max(1.0, abs(hc_h)),
        rtol=1e-14,
        maxiter=200,
    )
    return solve(root, L_fix)
