"""The surface Green's function of an elastic layer on a rigid base (normalized units).

A layer of thickness ``h`` multiplies the half space's transform by ``K(k h)`` (bonded or
frictionless base, :func:`layer_factor`); its kernel is ``g = c (1/r - R(r))``, ``R``
tabulated once per (nu, bonded) (:class:`LayerTable`, :class:`LayerKernel`) and ``1/r``
beyond a cut-off of a few tens of ``h``.  The thin limits: :func:`winkler_limit`,
:func:`thin_layer_factor`.  The conventions, the formulas and their references, the
tabulation and its errors: docs/design.md section 14.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy import special

__all__ = [
    "layer_factor",
    "one_minus_factor",
    "LayerTable",
    "LayerKernel",
    "layer_table",
    "winkler_limit",
    "thin_layer_factor",
    "decay_rate",
]

#: |g| / c below this times 1/h is taken as zero (the kernel's cut-off)
CUTOFF_TOL = 1e-14
_T_MAX = 24.0  # 1 - K(t) < 1e-17 beyond (bonded, any nu; frictionless)
_RHO_1 = 12.0  # fine grid up to here
_D1 = 0.0025
_D2 = 0.04


def _kappa(nu):
    return 3.0 - 4.0 * nu


def layer_factor(t, nu=0.5, bonded=True):
    """``K(t)``, ``t = k h``: the layer's compliance over the half space's at wavenumber k.

    Parameters
    ----------
    t : array_like
        ``k h`` >= 0.
    nu : float
        Poisson ratio (ignored for a frictionless base).
    bonded : bool
        Bonded (True) or frictionless (False) rigid base.

    Returns
    -------
    numpy.ndarray
    """
    return 1.0 - one_minus_factor(t, nu, bonded)


def one_minus_factor(t, nu=0.5, bonded=True):
    """``1 - K(t)``, written without overflow or cancellation for large t."""
    t = np.asarray(t, dtype=float)
    out = np.empty_like(t)
    small = t < 0.5
    ts, tl = t[small], t[~small]
    e2 = np.exp(-2.0 * tl)
    if bonded:
        ka = _kappa(nu)
        out[small] = 1.0 - (2 * ka * np.sinh(2 * ts) - 4 * ts) / (
            2 * ka * np.cosh(2 * ts) + 1 + ka * ka + 4 * ts * ts
        )
        e4 = e2 * e2
        out[~small] = (2 * ka * e4 + (1 + ka * ka + 4 * tl * tl + 4 * tl) * e2) / (
            ka * (1 + e4) + (1 + ka * ka + 4 * tl * tl) * e2
        )
    else:
        out[small] = 1.0 - (np.cosh(2 * ts) - 1) / (np.sinh(2 * ts) + 2 * ts)
        out[~small] = 2 * (1 + 2 * tl - e2) * e2 / (1 - e2 * e2 + 4 * tl * e2)
    return out


def slope_at_zero(nu=0.5, bonded=True) -> float:
    """``K'(0)``: ``(1 - 2 nu) / (2 (1 - nu)^2)`` bonded, ``1/2`` frictionless."""
    return (1.0 - 2.0 * nu) / (2.0 * (1.0 - nu) ** 2) if bonded else 0.5


def winkler_limit(h, nu=0.5, bonded=True) -> float:
    """The normalized ``Winkler(k)`` a thin compressible layer tends to: ``1/(2 pi c K'(0) h)``.

    Infinite for a bonded incompressible layer (use :func:`thin_layer_factor`).
    """
    s = slope_at_zero(nu, bonded)
    c = 2.0 * (1.0 - nu)
    return math.inf if s == 0.0 else 1.0 / (2.0 * math.pi * c * s * h)


def thin_layer_factor(h) -> float:
    """``a`` in the thin bonded incompressible layer's ``w = a lap p``: ``4 pi h^3 / 3``."""
    return 4.0 * math.pi * h**3 / 3.0


def decay_rate(nu=0.5, bonded=True) -> float:
    """``y``: ``g(r)`` decays like ``exp(-y r / h)`` (smallest |Im| of K's poles)."""
    ka = _kappa(nu)

    def newton(z):
        for _ in range(100):
            f = 2 * ka * np.cosh(2 * z) + 1 + ka * ka + 4 * z * z
            df = 4 * ka * np.sinh(2 * z) + 8 * z
            if not bonded:
                f, df = np.sinh(2 * z) + 2 * z, 2 * np.cosh(2 * z) + 2
            step = f / df
            z = z - step
            if abs(step) < 1e-14 * max(1.0, abs(z)):
                return z
        return None

    best = math.inf
    guesses = (0.5 + 1j, 1 + 1.5j, 0.3 + 0.8j, 1 + 0.8j, 0.05 + 0.8j, 0.05 + 1.2j, 1.1 + 2.1j, 2 + 2j)
    for guess in guesses:  # Newton from a few starts: the nearest poles to the real axis
        z = newton(complex(guess))
        if z is not None and abs(z.imag) > 1e-6:
            best = min(best, abs(z.imag))
    return best


def _nodes(t_max, width, ng=16):
    x, w = np.polynomial.legendre.leggauss(ng)
    a = np.arange(0.0, t_max + 0.5 * width, width)
    hw = 0.5 * np.diff(a)
    t = (a[:-1, None] + hw[:, None] * (x[None, :] + 1.0)).ravel()
    return t, (hw[:, None] * w[None, :]).ravel()


def _j2_over_x(x, j0, j1):
    """``J2(x)/x`` from ``J0, J1`` (recurrence) where x > 2, the series below."""
    out = np.empty_like(x)
    big = x > 2.0
    xb = x[big]
    out[big] = (2.0 * j1[big] / xb - j0[big]) / xb
    xs = x[~big]
    q = xs * xs / 4.0
    # J2(x)/x = (x/8) sum_k (-q)^k / (k! (k+2)!) * 2 ; 14 terms: < 1e-17 for x <= 2
    term = xs / 8.0
    acc = term.copy()
    for k in range(1, 15):
        term = term * (-q) / (k * (k + 2))
        acc += term
    out[~big] = acc
    return out


def hankel_table(rho, nu=0.5, bonded=True, width=None, block=256):
    """``Rh, Rh', Fh, Fh'`` at ``rho`` by panel Gauss-Legendre quadrature in t.

    ``width`` is the panel width in t (16 nodes each); default: 16 nodes per
    half oscillation of ``J0(t max(rho))``.
    """
    rho = np.asarray(rho, dtype=float)
    if width is None:
        width = min(0.25, math.pi / max(float(rho.max()), 1.0))
    t, w = _nodes(_T_MAX, width)
    f = one_minus_factor(t, nu, bonded) * w
    out = np.empty((4, rho.size))
    for s in range(0, rho.size, block):
        r = rho[s : s + block, None]
        x = r * t[None, :]
        j0, j1 = special.j0(x), special.j1(x)
        out[0, s : s + block] = j0 @ f
        out[1, s : s + block] = -(j1 @ (f * t))
        with np.errstate(divide="ignore", invalid="ignore"):
            j1x = np.where(x > 1e-8, j1 / x, 0.5)
        out[2, s : s + block] = j1x @ f
        out[3, s : s + block] = -(_j2_over_x(x, j0, j1) @ (f * t))
    return out


def _cubic_coefficients(dx, f, df):
    """Per-interval Horner coefficients (c0, c1, c2, c3) in s = local coordinate in [0, 1)
    of the cubic Hermite interpolant of values f and slopes df on a uniform grid."""
    m0, m1 = dx * df[:-1], dx * df[1:]
    d = f[1:] - f[:-1]
    c = np.stack([f[:-1], m0, 3.0 * d - 2.0 * m0 - m1, -2.0 * d + m0 + m1], axis=1)
    return np.vstack([c, [f[-1], m1[-1], 0.0, 0.0]])  # the last node, for s = 0 there


def _horner(x, x0, dx, c):
    """Evaluate the piecewise cubic of :func:`_cubic_coefficients` at x (clamped to the grid)."""
    u = (x - x0) * (1.0 / dx)
    np.clip(u, 0.0, c.shape[0] - 1.0, out=u)
    i = u.astype(np.intp)
    u -= i
    ci = c[i]
    out = ci[..., 3] * u
    out += ci[..., 2]
    out *= u
    out += ci[..., 1]
    out *= u
    out += ci[..., 0]
    return out


class LayerTable:
    """``Rh(rho)`` and ``Fh(rho)`` of one (nu, bonded), ``rho = r / h`` (docs/design.md section 14)."""

    def __init__(self, nu=0.5, bonded=True):
        self.nu, self.bonded = float(nu), bool(bonded)
        self.q = slope_at_zero(nu, bonded)
        y = decay_rate(nu, bonded)
        self.decay = y
        rho_max = _RHO_1 + max(30.0, 1.15 * math.log(1.0 / CUTOFF_TOL) / min(y, 2.0))
        r1 = np.arange(0.0, _RHO_1 + 0.5 * _D1, _D1)
        r2 = np.arange(_RHO_1, rho_max + _D2, _D2)
        R1, dR1, F1, dF1 = hankel_table(r1, nu, bonded)
        R2, dR2, F2, dF2 = hankel_table(r2, nu, bonded)
        # beyond rho_1: the differences from the far forms 1/rho and 1/rho - q/rho^2
        D = 1.0 / r2 - R2
        dD = -1.0 / r2**2 - dR2
        E = 1.0 / r2 - self.q / r2**2 - F2
        dE = -1.0 / r2**2 + 2.0 * self.q / r2**3 - dF2
        big = np.maximum(np.abs(D), np.abs(E)) > CUTOFF_TOL
        last = int(np.flatnonzero(big)[-1]) if big.any() else 0
        if last > r2.size - 10:
            raise RuntimeError("layer kernel table too short: the Green's function has not decayed")
        self.rho_cut = float(r2[min(last + 2, r2.size - 1)])
        n2 = min(last + 3, r2.size)
        self._c1 = (_cubic_coefficients(_D1, R1, dR1), _cubic_coefficients(_D1, F1, dF1))
        self._c2 = (
            _cubic_coefficients(_D2, D[:n2], dD[:n2]),
            _cubic_coefficients(_D2, E[:n2], dE[:n2]),
        )
        self.R0 = float(R1[0])

    def _eval(self, rho, which):
        rho = np.asarray(rho, dtype=float)
        if rho.size and float(rho.max()) < _RHO_1:  # the common case: one table, no masks
            return _horner(rho.copy(), 0.0, _D1, self._c1[which])
        out = np.empty_like(rho)
        near = rho < _RHO_1
        out[near] = _horner(rho[near], 0.0, _D1, self._c1[which])
        rf = rho[~near]
        corr = _horner(rf.copy(), _RHO_1, _D2, self._c2[which])
        corr[rf >= self.rho_cut] = 0.0
        base = 1.0 / rf if which == 0 else 1.0 / rf - self.q / rf**2
        out[~near] = base - corr
        return out

    def R(self, rho):
        """``Rh(rho) = int (1 - K(t)) J0(t rho) dt``."""
        return self._eval(rho, 0)

    def F(self, rho):
        """``Fh(rho) = (1/rho^2) int_0^rho s Rh(s) ds``."""
        return self._eval(rho, 1)


@functools.lru_cache(maxsize=16)
def layer_table(nu=0.5, bonded=True) -> LayerTable:
    """The cached :class:`LayerTable` of (nu, bonded)."""
    return LayerTable(nu, bonded)


class LayerKernel:
    """``g(r) / c = 1/r - R(r)`` of a layer of thickness ``h``, in the radial-kernel protocol.

    The protocol of :func:`femehl.elastic.kernels.radial_triangle_pairs`: the kernel is
    ``singular / r - smooth(r)`` with ``smooth`` analytic on the length ``scale``;
    beyond ``cutoff`` it is zero (``smooth = singular / r``), and there
    ``smooth_edge(r) = singular / r - tail / r^2``.  ``smooth_edge`` is
    ``(1/r^2) int_0^r s smooth(s) ds``.
    """

    singular = 1.0

    def __init__(self, h, nu=0.5, bonded=True):
        self.h = float(h)
        self.table = layer_table(float(nu), bool(bonded))
        self.scale = self.h
        self.cutoff = self.table.rho_cut * self.h
        self.tail = self.table.q * self.h

    def smooth(self, r):
        return self.table.R(np.asarray(r) / self.h) / self.h

    def smooth_edge(self, r):
        return self.table.F(np.asarray(r) / self.h) / self.h
