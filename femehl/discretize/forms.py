"""The weak form of the Reynolds equation, in scikit-fem forms (docs/design.md, section 4).

Find p in P1, p = 0 on r = L, such that for every P1 test function q

    beta int (d^k)^3 grad p . grad q  +  V int d^{k+1} dq/dx  +  int (d^{k+1} - d^k)/dt q  = 0

(the Couette term -V dd/dx integrated by parts; its boundary term vanishes on
r = L where q = 0 and on the mirror line y = 0 where n_x = 0).  d lives on
elements (P0), so with d = h - w the three forms below are all the solver
needs:

    K(d^k)[q, p] = int (d^k)^3 grad p . grad q           ``film_diffusion``
    Bx[q, e]     = int_e dq/dx                           ``couette``
    M[q, e]      = int_e q                               ``squeeze``
"""

from __future__ import annotations

from skfem import BilinearForm
from skfem.helpers import dot, grad

__all__ = ["film_diffusion", "couette", "squeeze"]


@BilinearForm
def film_diffusion(p, q, w):
    """Poiseuille flux: d^3 grad p . grad q (d^3 passed as ``d3``, element-constant)."""
    return w["d3"] * dot(grad(p), grad(q))


@BilinearForm
def couette(d, q, w):
    """Couette flux of an element-constant film d against dq/dx."""
    return d * q.grad[0]


@BilinearForm
def squeeze(d, q, w):
    """Mass of an element-constant film d against q."""
    return d * q
