"""Friction force and energy budget of a sliding and rolling lubricated contact, from a State.

The friction force ``f = int [S/(6 beta d) - (W + d/2) dp/dx] dA`` (``S`` the sliding
speed), the film's viscous dissipation, the power the pressure delivers to the moving
substrate (its viscoelastic dissipation in a steady state) and a free indenter's collision
budget, in normalized units (half disks doubled; per unit length for line contact).  The
derivation, the balance ``f U_s - (shear on the indenter) U_i = D_film + P_sliding`` and
the friction coefficient: docs/design.md section 15 ("The friction force and the energy budget").
"""

from __future__ import annotations

import numpy as np

from femehl.elastic.viscoelastic import ENERGETICS_COLUMNS  # the columns the substrate reports
from femehl.errors import SceneError

__all__ = [
    "ENERGETICS_COLUMNS",
    "FREE_COLUMNS",
    "FRICTION_COLUMNS",
    "SIDE_COLUMNS",
    "TRIBOLOGY_COLUMNS",
    "sliding_energetics",
]

#: the per-step figures every run on a discretization with pressure gradients reports (the
#: finite-element disk and line contact): the friction force and its three parts
FRICTION_COLUMNS = ("friction", "shear_couette", "shear_poiseuille", "pressure_drag")
#: ... and a disk's: the force across the motion (zero on a half disk, by symmetry)
SIDE_COLUMNS = ("side_force",)
#: the per-step figures a run on a viscoelastic substrate reports (summary.csv)
#: ... and a run of a free indenter (its collision's energy budget)
FREE_COLUMNS = ("dissipation_film", "elastic_energy")
#: every figure :func:`sliding_energetics` computes
TRIBOLOGY_COLUMNS = (
    "friction",
    "side_force",
    "shear_couette",
    "shear_poiseuille",
    "pressure_drag",
    "dissipation_film",
    "power_sliding",
    "elastic_energy",
)


def sliding_energetics(
    disc, state, beta: float, speeds=None, liquid=None, p_solid=None, gap=None, solid_friction=0.0
) -> dict:
    """Friction force, film dissipation and sliding power into the substrate of ``state``.

    Parameters
    ----------
    disc : discretization
        The one that produced ``state`` (it must offer ``pressure_gradient()``: the finite
        element disk and line contact do).
    state : femehl.State
    beta : float
        The scene's film parameter.
    speeds : (float, float), optional
        The surfaces' speeds ``(U_i, U_s)`` along -x of the indenter and the substrate at
        ``state.t`` (:meth:`femehl.Motion.surface_speeds`); default ``(0, state.V)``, pure
        sliding (the paper).
    liquid : array, optional
        The liquid's share of each element's film (a mass-conserving cavity's filling,
        :meth:`femehl.problem.cavitation.JFOCavitation.liquid_fraction`): the Couette shear
        and its dissipation act on it; default the whole film.
    p_solid, gap, solid_friction : optional
        A rough contact's (:meth:`femehl.problem.roughness.AsperityContact.budget`): the
        asperities' share of the pressure on the free nodes (the film's is ``p - p_solid``),
        the film's mean gap per film point (default ``state.d``) and the asperities'
        friction force, added to ``friction``. The budget then has two more terms:
        ``dissipation_solid = solid_friction * S`` and ``power_roughness``
        ``= U_s int (h_T - d) dp_film/dx dA``, the film pressure's power into the substrate's
        rough layer (the part ``d - h_T`` of the separation the asperities take, carried
        at ``U_s``; docs/design.md section 18).

    Returns
    -------
    dict
        ``friction`` (= ``shear_couette + shear_poiseuille + pressure_drag``: the force along
        x on the indenter's axis), its three parts, ``dissipation_film``, ``power_sliding``
        (the pressure's power into the moving substrate, ``U_s int p dW/dx dA``) and
        ``elastic_energy``, normalized as in docs/design.md section 15; on a disk also
        ``side_force``, the force across the motion ``-int (W + d/2) dp/dy dA`` (0 on a
        half disk, by symmetry).  The shear force on
        the indenter's surface is ``shear_couette + shear_poiseuille``; in a steady state
        ``friction U_s - (shear_couette + shear_poiseuille) U_i = dissipation_film + power_sliding``.
    """
    grad = getattr(disc, "pressure_gradient", None)
    if grad is None:
        raise SceneError(
            f"the friction force needs element pressure gradients, which method "
            f"{getattr(disc, 'method', type(disc).__name__)!r} does not provide: use method='fe'."
        )
    (G, area) = grad()
    p = np.asarray(state.p, dtype=float)[disc.free_index]
    gp = [np.asarray(g @ p).ravel() for g in G]  # the pressure on the indenter: film and asperities
    pf = p if p_solid is None else p - np.asarray(p_solid, dtype=float)
    gf = gp if p_solid is None else [np.asarray(g @ pf).ravel() for g in G]  # the film's
    d = np.asarray(state.d, dtype=float)
    h = d if gap is None else np.asarray(gap, dtype=float)  # the film's mean gap
    W = np.asarray(state.w, dtype=float)
    Ui, Us = (0.0, float(state.V)) if speeds is None else (float(speeds[0]), float(speeds[1]))
    S = Us - Ui  # the sliding speed
    mult = 2.0 if getattr(disc, "half", False) else 1.0
    a = mult * area
    gx, fx, f2 = gp[0], gf[0], sum(g * g for g in gf)
    couette = S / (6.0 * beta * h) * (1.0 if liquid is None else np.asarray(liquid, dtype=float))
    out = {
        "shear_couette": float(a @ couette),
        "shear_poiseuille": float(a @ (0.5 * h * fx)),
        "pressure_drag": float(-(a @ ((W + d) * gx))),
        "dissipation_film": float(a @ (S * couette + 0.5 * beta * h**3 * f2)),
        "power_sliding": float(-Us * (a @ (W * gx))),
        "elastic_energy": float(0.5 * (a @ (np.asarray(disc.average() @ p).ravel() * -W))),
    }
    out["friction"] = out["shear_couette"] + out["shear_poiseuille"] + out["pressure_drag"] + solid_friction
    if p_solid is not None:
        out["dissipation_solid"] = float(solid_friction * S)
        out["power_roughness"] = float(Us * (a @ ((h - d) * fx)))
    if len(gp) > 1:  # across the motion: Poiseuille shear and pressure (no Couette along y)
        side = (W + d) * gp[1] - 0.5 * h * gf[1]
        out["side_force"] = 0.0 if getattr(disc, "half", False) else float(-(a @ side))
    return out
