"""A rubber slider's friction-speed curve
=======================================

A glass ball (R = 10 mm) pressed by a constant load onto a lubricated rubber, a standard
linear solid (relaxed shear modulus 0.1 MPa, unrelaxed 1 MPa, relaxation time 10 ms), and
slid at speeds from 1 mm/s to 0.1 m/s.  At every speed femehl runs the load ramp, the
sliding start and the steady sliding (to t = 8 in normalized time), and reports the
friction coefficient ``mu = friction / load`` with its parts: the film's shear and the
pressure acting on the inclined ball, and the viscoelastic hysteresis in the rubber
(:mod:`femehl.solver.energetics`).  The rubber's dissipation peaks where the time a material point
spends in the contact, ``2 a / V``, is near its retardation time (the Deborah number
``De = 2 V tau_c / a``, the distance the rubber travels in one retardation time over
the contact radius, of order one); slower, the rubber is relaxed and soft, faster, it is
glassy and stiff, and elastic in both limits.

Run::

    python examples/rubber_slider.py

Output: one run folder per speed (summary.csv with the friction columns, fields.pvd) and
``friction_speed.png`` / ``friction_speed.csv`` in ``femehl-out/rubber_slider``.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import femehl
from femehl.api import run_to_folder
from femehl.problem.scene import Dimensional, Domain, Motion, Scene, Sphere, Table, TanhStart

R, G_INF, G0, TAU = 0.01, 1.0e5, 1.0e6, 0.01  # m, Pa, Pa, s
ETA, H_INF, NU = 1.0, 1.0e-4, 0.5  # Pa s, m (length scale), -
SPEEDS = (1e-3, 3e-3, 1e-2, 3e-2, 1e-1)  # m/s


def scene(V: float) -> tuple[Scene, Dimensional]:
    """The ball on the rubber at sliding speed ``V`` [m/s], load ramped over t = 1."""
    dim = Dimensional(R=R, G=G_INF, eta=ETA, V_ss=V, h_inf=H_INF, nu=NU)
    F = 4.0 / (3.0 * math.pi)  # normalized: the relaxed Hertz load of an indentation h_inf
    sc = Scene(
        indenter=Sphere(1.0),
        substrate=femehl.Viscoelastic.from_si(G0, TAU, dim),
        fluid=femehl.Fluid(dim.beta),
        motion=Motion(gap=0.1, velocity=TanhStart(1.0, 1.0, 1.0), load=Table((0.0, 1.0), (0.0, F))),
        domain=Domain(3.0),
    )
    return sc, dim


def main(out="femehl-out/rubber_slider", speeds=SPEEDS, t_end: float = 8.0, mesh: str = "coarse", dt=0.04):
    """Run every speed; print and return the friction-speed table (one dict per speed)."""
    out = Path(out)
    rows = []
    for V in speeds:
        t0 = time.perf_counter()
        sc, dim = scene(V)
        res = run_to_folder(
            sc, out / f"V_{V:.0e}", method="fe", mesh=mesh, t_end=t_end, dt=dt, scheme="bdf2",
            store_every=50, overwrite=True, log=lambda *a: None,
        )  # fmt: skip
        load, f, v = float(res.load[-1]), float(res.friction[-1]), float(res.V[-1])
        scale = math.sqrt(H_INF / R)  # mu = (friction / load) sqrt(h_inf / R), femehl.solver.energetics
        row = {
            "V": V,
            "beta": sc.fluid.beta,
            "De": 2.0 * sc.substrate.tau_creep,  # 2 V tau_c / a, normalized (V = 1, a ~ 1)
            "mu": f / load * scale,
            # steady sliding: f V = D_film + P_solid, so each dissipation / V is a friction part
            "mu_rubber": float(res.power_sliding[-1]) / v / load * scale,
            "mu_film": float(res.dissipation_film[-1]) / v / load * scale,
            "film_center_m": float(dim.to_si("height", res.film_center[-1])),
            "film_min_m": float(dim.to_si("height", res.film_min[-1])),
            "wall_s": time.perf_counter() - t0,
        }
        rows.append(row)
        print(
            f"V = {V:.0e} m/s (beta {row['beta']:.3g}, De {row['De']:.3g}): mu = {row['mu']:.4f} "
            f"(rubber {row['mu_rubber']:.4f}, film {row['mu_film']:.4f}), central film "
            f"{row['film_center_m'] * 1e6:.3g} um, minimum film {row['film_min_m'] * 1e6:.3g} um "
            f"[{row['wall_s']:.1f} s]"
        )
    _write(out, rows)
    return rows


def _write(out, rows):
    import csv

    import matplotlib.pyplot as plt

    with open(out / "friction_speed.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    V = [r["V"] for r in rows]
    ax.semilogx(V, [r["mu"] for r in rows], "o-", label="total")
    ax.semilogx(V, [r["mu_rubber"] for r in rows], "s--", label="viscoelastic hysteresis")
    ax.semilogx(V, [r["mu_film"] for r in rows], "^:", label="viscous film")
    ax.set_xlabel("sliding speed V [m/s]")
    ax.set_ylabel("friction coefficient")
    ax.set_title("Glass ball on a lubricated rubber (SLS)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "friction_speed.png", dpi=130)
    plt.close(fig)


if __name__ == "__main__":
    main()
