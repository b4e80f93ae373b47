"""A steel ball dropped on a soft gel through a viscous liquid
=============================================================

A steel ball (R = 2 mm) moves under its own weight and inertia toward a soft gel
(shear modulus 10 kPa, incompressible) through a glycerol-water mixture (0.05 Pa s).  It
arrives 50 um above the gel at speed U, squeezes the liquid out, dents the gel, and
bounces back (an elastohydrodynamic collision).  femehl solves Newton's law for the ball
as one more row of each step's linear system (``Motion(mass=..., force=..., hc_dot0=...)``),
with the Reynolds cavitation condition (a liquid cannot hold the suction behind a
receding ball).  For each approach speed it reports the Stokes number
``St = m U / (6 pi eta R^2)``, the coefficient of restitution, the deepest indentation,
the thinnest film and the collision's energy budget (:mod:`femehl.solver.energetics`).

Scales (:class:`femehl.Dimensional`): lengths and films in units of ``h = 50 um`` and
``sqrt(R h)``; the reference speed ``V_ss = U`` sets the time scale; the mass, the
weight and ``dhc/dt`` are converted with ``dim.mass``, ``dim.force`` and
``dim.approach_speed``.

Run::

    python examples/ball_drop.py

Output: one run folder per speed (summary.csv with ``hc_dot``, the energy columns,
fields.pvd) in ``femehl-out/ball_drop``.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from femehl.api import run_to_folder
from femehl.problem.scene import Constant, Dimensional, Domain, Fluid, Motion, Scene, Sphere

R, G, ETA = 2e-3, 1.0e4, 0.05  # m, Pa, Pa s
RHO_BALL, RHO_LIQUID, GRAVITY = 7800.0, 1200.0, 9.81  # kg/m^3, m/s^2
GAP = 5e-5  # m: the ball's height above the gel at the start (also the film scale)
SPEEDS = (0.02, 0.05, 0.1)  # m/s: approach speed at the start


def scene(U: float) -> tuple[Scene, Dimensional]:
    """The ball arriving at ``U`` [m/s], GAP above the gel, with its weight minus buoyancy."""
    dim = Dimensional(R=R, G=G, eta=ETA, V_ss=U, h_inf=GAP)
    volume = 4.0 / 3.0 * math.pi * R**3
    weight = (RHO_BALL - RHO_LIQUID) * volume * GRAVITY
    motion = Motion(
        gap=Constant(1.0),  # GAP / h
        velocity=0.0,
        mass=RHO_BALL * volume / dim.mass,
        force=weight / dim.force,
        hc_dot0=-U / dim.approach_speed,
    )
    sc = Scene(
        indenter=Sphere(1.0), fluid=Fluid(dim.beta, cavitation="reynolds"), motion=motion, domain=Domain(3.0)
    )
    return sc, dim


def main(
    out="femehl-out/ball_drop", speeds=SPEEDS, mesh: str = "coarse", dt: float = 0.002, t_end: float = 1.0
):
    """Run every approach speed; print and return one dict of figures per speed."""
    rows = []
    for U in speeds:
        t0 = time.perf_counter()
        sc, dim = scene(U)
        res = run_to_folder(
            sc, Path(out) / f"U_{U:g}", method="fe", mesh=mesh, t_end=t_end, dt=dt, scheme="bdf2",
            store_every=25, overwrite=True, log=lambda *a: None,
        )  # fmt: skip
        imp = res.impact()
        m = sc.motion.mass
        work = np.concatenate(
            [[0.0], np.cumsum(np.diff(res.t) * (res.dissipation_film[1:] + res.dissipation_film[:-1]))]
        )
        budget = 0.5 * m * res.hc_dot**2 + sc.motion.applied_force(0.0) * res.hc + res.elastic_energy + work
        row = {
            "U": U,
            "St": RHO_BALL * 4.0 / 3.0 * math.pi * R**3 * U / (6.0 * math.pi * ETA * R**2),
            "beta": sc.fluid.beta,
            "restitution": imp["restitution"],
            "impact_speed_m_s": -float(dim.to_si("approach_speed", imp["v_in"])),
            "indentation_um": -float(dim.to_si("height", imp["hc_min"])) * 1e6,
            "film_min_um": float(dim.to_si("height", imp["film_min"])) * 1e6,
            "energy_drift": float(np.max(np.abs(budget - budget[0])) / abs(budget[0])),
            "wall_s": time.perf_counter() - t0,
        }
        rows.append(row)
        print(
            f"U = {U:g} m/s (St {row['St']:.3g}, beta {row['beta']:.3g}): hits at "
            f"{row['impact_speed_m_s']:.3g} m/s, restitution {row['restitution']:.3f}, indents "
            f"{row['indentation_um']:.0f} um, thinnest film {row['film_min_um']:.2f} um, energy budget "
            f"closes to {row['energy_drift']:.1e}  [{row['wall_s']:.1f} s]"
        )
    return rows


if __name__ == "__main__":
    main()
