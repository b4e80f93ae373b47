"""Friction force and energy budget of a sliding lubricated contact, from a State's fields.

Physics (physical units; docs/design.md section 1): the indenter is at rest in its frame,
the substrate's surface moves at ``-U`` along x, the film ``d = H - W`` lies between the
substrate's surface ``z = W`` and the indenter's ``z = H``.  Lubrication theory gives the
force the film exerts on the indenter along x, whose opposite is the friction force::

    f = int [ eta U / d  +  (d/2) dp/dx  +  p dH/dx ] dA
      = int [ eta U / d  -  (W + d/2) dp/dx ] dA              (by parts, p = 0 on the rim)

(Couette shear, Poiseuille shear, and the pressure acting on the inclined indenter), and
the energy balance ``f U = D_film + P_solid + d/dt(stored energy)`` with the film's
viscous dissipation and the power the pressure delivers to the substrate's surface::

    D_film  = int [ eta U^2 / d  +  d^3 |grad p|^2 / (12 eta) ] dA,
    P_solid = int p (-DW/Dt) dA,     D/Dt = d/dt - U d/dx (the material moves at -U).

Normalized (section 2 of the design: lengths sqrt(R h_inf), films h_inf, pressures
``p0 = 4 pi G sqrt(h_inf/R)``, time ``2 sqrt(R h_inf)/V_ss``), with forces in units of
``f0 = p0 h_inf sqrt(R h_inf)`` and powers in units of ``f0 V_ss``::

    f       = int [ V/(6 beta d)  -  (W + d/2) dp/dx ] dA,
    D_film  = int [ V^2/(6 beta d)  +  (beta/2) d^3 |grad p|^2 ] dA,
    P_solid = (1/2) int p (-dW/dt + 2 V dW/dx) dA.

The friction coefficient is ``mu = (f / load) sqrt(h_inf / R)`` (the load's unit is
``p0 R h_inf``).  Here ``P_solid`` is reported for fields steady in the indenter's frame,
``P_sliding = V int p dW/dx dA = -V int W dp/dx dA``: in steady sliding it is the rate of
viscoelastic dissipation in the substrate (zero for an elastic one, whose operator is
symmetric), and the balance reads ``f V = D_film + P_sliding``.  In a transient it
omits ``-(1/2) int p dW/dt``, the rate of change of the stored elastic energy.

A free indenter (``m hc'' = load - force`` in femehl's units) has the collision budget::

    (1/2) m hc'^2 + force hc + E_el + int 2 D_film dt = const,   E_el = (1/2) int p (-W) dA,

the factor 2 because the powers above are in units of ``f0 V_ss``, twice the unit
``load h_inf / time`` of Newton's law (with the film's Reynolds equation this is an
identity of the continuous problem, so the discrete budget measures the time error).

On a half disk every integrand is even in y and the integrals are doubled.  The same
formulas hold per unit length for line contact in its normalized units.
"""

from __future__ import annotations

import numpy as np

from femehl.elastic.viscoelastic import ENERGETICS_COLUMNS  # the columns the substrate reports
from femehl.errors import SceneError

__all__ = ["ENERGETICS_COLUMNS", "FREE_COLUMNS", "TRIBOLOGY_COLUMNS", "sliding_energetics"]

#: the per-step figures a run on a viscoelastic substrate reports (summary.csv)
#: ... and a run of a free indenter (its collision's energy budget)
FREE_COLUMNS = ("dissipation_film", "elastic_energy")
#: every figure :func:`sliding_energetics` computes
TRIBOLOGY_COLUMNS = (
    "friction",
    "shear_couette",
    "shear_poiseuille",
    "pressure_drag",
    "dissipation_film",
    "power_sliding",
    "elastic_energy",
)


def sliding_energetics(disc, state, beta: float) -> dict:
    """Friction force, film dissipation and sliding power into the substrate of ``state``.

    Parameters
    ----------
    disc : discretization
        The one that produced ``state`` (it must offer ``pressure_gradient()``: the finite
        element disk and line contact do).
    state : femehl.State
    beta : float
        The scene's film parameter.

    Returns
    -------
    dict
        ``friction`` (= ``shear_couette + shear_poiseuille + pressure_drag``), its three
        parts, ``dissipation_film``, ``power_sliding`` and ``elastic_energy``, normalized as
        in the module docstring.
    """
    grad = getattr(disc, "pressure_gradient", None)
    if grad is None:
        raise SceneError(
            f"the friction force needs element pressure gradients, which method "
            f"{getattr(disc, 'method', type(disc).__name__)!r} does not provide: use method='fe'."
        )
    (G, area) = grad()
    p = np.asarray(state.p, dtype=float)[disc.free_index]
    gp = [np.asarray(g @ p).ravel() for g in G]
    d = np.asarray(state.d, dtype=float)
    W = np.asarray(state.w, dtype=float)
    V = float(state.V)
    mult = 2.0 if getattr(disc, "half", False) else 1.0
    a = mult * area
    gx, g2 = gp[0], sum(g * g for g in gp)
    out = {
        "shear_couette": float(a @ (V / (6.0 * beta * d))),
        "shear_poiseuille": float(a @ (0.5 * d * gx)),
        "pressure_drag": float(-(a @ ((W + d) * gx))),
        "dissipation_film": float(a @ (V * V / (6.0 * beta * d) + 0.5 * beta * d**3 * g2)),
        "power_sliding": float(-V * (a @ (W * gx))),
        "elastic_energy": float(0.5 * (a @ (np.asarray(disc.average() @ p).ravel() * -W))),
    }
    out["friction"] = out["shear_couette"] + out["shear_poiseuille"] + out["pressure_drag"]
    return out
