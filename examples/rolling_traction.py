"""Rolling and sliding on a rubber: rolling resistance and traction
=================================================================

A rigid cylinder on a lubricated rubber (a standard linear solid on a Winkler foundation,
relaxed compliance twice the unrelaxed one), in line contact, normalized units.  Both
surfaces move: ``Motion(velocity=V, slide_roll=SRR)`` sets their sum ``V`` (twice the
entrainment speed) and the slide-to-roll ratio ``SRR = (U_s - U_i)/U_e`` (2: the paper's
pure sliding, 0: pure rolling).  The film sees the entrainment only; the rubber's memory
moves with its own surface, ``U_s = V (1 + SRR/2)/2``; the Couette shear with the sliding
speed ``V SRR/2``.

1. **Rolling resistance against the Deborah number.**  Pure rolling at several relaxation
   times: the friction force (the rolling resistance: the film's Poiseuille shear and the
   pressure on the inclined cylinder; no Couette shear) peaks where the rubber crosses the
   contact in about one retardation time, ``De = 2 U_s tau_c / a`` of order one.  Each run
   (the automatic mode, to a steady state) is overlaid on the steady solution computed
   without time stepping (:mod:`femehl.reference.viscoelastic_line`).
2. **A traction curve.**  At one relaxation time, friction against SRR, as a mini-traction
   machine measures it: the Couette part grows with the sliding speed, the hysteresis
   part with the rubber's own speed.

Run::

    python examples/rolling_traction.py

Output: ``rolling_traction.png`` and ``rolling_traction.csv`` in ``femehl-out/rolling_traction``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

import femehl
from femehl.problem.line import LineScene
from femehl.problem.scene import Motion, RampHold, TanhStart
from femehl.reference.viscoelastic_line import steady_viscoelastic_line

K, BETA, HC, L, V = 1.0, 10.0, -0.5, 2.0, 1.0  # foundation, film parameter, clearance, domain, speed
TAUS = (0.01, 0.1, 0.3, 1.0, 3.0, 30.0)  # relaxation times of the rolling runs
SRRS = (0.0, 0.5, 1.0, 2.0)  # slide-to-roll ratios of the traction curve (at TAU_TRACTION)
TAU_TRACTION = 1.0


def rubber(tau: float) -> femehl.Viscoelastic:
    """Unrelaxed compliance 1, relaxed 2 (``tau_c = 2 tau``), on the Winkler foundation k."""
    return femehl.Viscoelastic(G0=1.0, G_inf=0.5, tau=tau)


def scene(tau: float, srr: float):
    """Indent to hc = -0.5 over t = 1, then roll/slide at V = tanh(t - 1) with ``srr``."""
    motion = Motion(gap=RampHold(0.1, HC, 1.0), velocity=TanhStart(1.0, 1.0), slide_roll=srr)
    return LineScene(k=K, beta=BETA, viscoelastic=rubber(tau), motion=motion, L=L)


def run(tau: float, srr: float, t_end: float) -> dict:
    """One automatic run to ``t_end`` and the steady reference; the friction's parts."""
    t0 = time.perf_counter()
    r = femehl.solve(scene(tau, srr), t_end=t_end, tol=1e-2)
    wall = time.perf_counter() - t0
    ref = steady_viscoelastic_line(K, BETA, HC, L, V, rubber(tau), slide_roll=srr)
    u_s = 0.5 * V * (1.0 + 0.5 * srr)
    return {
        "tau": tau,
        "SRR": srr,
        "De": 2.0 * u_s * rubber(tau).tau_creep / np.sqrt(-2.0 * HC),  # a: the overlap half width
        "friction": float(r.friction[-1]),
        "couette": float(r.shear_couette[-1]),
        "poiseuille": float(r.shear_poiseuille[-1]),
        "pressure_drag": float(r.pressure_drag[-1]),
        "hysteresis_power": float(r.power_sliding[-1]),
        "friction_reference": ref.friction,
        "load": float(r.load[-1]),
        "wall_s": wall,
    }


def main(out="femehl-out/rolling_traction", taus=TAUS, srrs=SRRS, t_end: float = 12.0) -> dict:
    """Run the rolling sweep and the traction curve; print, write a CSV and a PNG."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rolling = [run(tau, 0.0, t_end) for tau in taus]
    done = {r["tau"]: r for r in rolling}
    traction = [
        done[TAU_TRACTION] if srr == 0.0 and TAU_TRACTION in done else run(TAU_TRACTION, srr, t_end)
        for srr in srrs
    ]
    for row in rolling + [r for r in traction if r["SRR"] != 0.0 or TAU_TRACTION not in done]:
        off = row["friction"] / row["friction_reference"] - 1.0
        print(
            f"tau {row['tau']:<5g} SRR {row['SRR']:<4g} De {row['De']:8.3g}: friction {row['friction']:.5f} "
            f"(Couette {row['couette']:.5f}, Poiseuille {row['poiseuille']:.5f}, pressure "
            f"{row['pressure_drag']:.5f}), {off:+.1e} off the steady solution [{row['wall_s']:.1f} s]"
        )
    _write(out, rolling, traction)
    return {"rolling": rolling, "traction": traction}


def _write(out, rolling, traction):
    import csv

    import matplotlib.pyplot as plt

    with open(out / "rolling_traction.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rolling[0]))
        w.writeheader()
        w.writerows(rolling + traction)
    fig, (a, b) = plt.subplots(1, 2, figsize=(9.5, 3.8))
    taus = np.logspace(np.log10(min(r["tau"] for r in rolling)), np.log10(max(r["tau"] for r in rolling)), 25)
    ref = [steady_viscoelastic_line(K, BETA, HC, L, V, rubber(t), slide_roll=0.0).friction for t in taus]
    scale = rolling[0]["De"] / rolling[0]["tau"]
    a.semilogx(taus * scale, ref, "-", color="0.6", label="steady solution")
    a.semilogx([r["De"] for r in rolling], [r["friction"] for r in rolling], "o", label="femehl runs")
    a.set_xlabel("Deborah number 2 U_s tau_c / a")
    a.set_ylabel("rolling resistance (normalized)")
    a.set_title("Pure rolling")
    a.legend()
    srr = [r["SRR"] for r in traction]
    b.plot(srr, [r["friction"] for r in traction], "o-", label="friction")
    b.plot(srr, [r["couette"] for r in traction], "s--", label="Couette shear")
    b.plot(srr, [r["poiseuille"] + r["pressure_drag"] for r in traction], "^:", label="Poiseuille + pressure")
    b.set_xlabel("slide-to-roll ratio SRR")
    b.set_title(f"Traction at tau = {TAU_TRACTION:g}")
    b.legend()
    fig.tight_layout()
    fig.savefig(out / "rolling_traction.png", dpi=130)
    plt.close(fig)


if __name__ == "__main__":
    main()
