"""Benchmark: rolling and sliding on the default path (no mesh, no dt), against references.

``python benchmarks/rolling.py`` (or ``femehl bench rolling``) writes ``rolling.md`` next to
this file:

1. Rolling resistance against the Deborah number: a cylinder rolling (SRR = 0) on the
   standard-linear-solid Winkler foundation of ``examples/rolling_traction.py``, eleven
   relaxation times over five decades, each an automatic run to t = 12 against the
   steady solution computed without time stepping (femehl.reference.viscoelastic_line):
   the friction, the load, the hysteresis and the run's own energy budget; wall time per
   point.
2. A traction curve at tau = 1: SRR from -1 to 3, the same checks.
3. The rigid cylinder (k = 1e6, Reynolds outlet) rolling and sliding against Martin's
   closed form (femehl.reference.rigid_cylinder).
4. The paper's sphere on a viscoelastic half space (G0 = 2, tau = 0.5: the plug-in scene of
   ``auto_scenes.py``) sliding and rolling, automatic mode to t = 2 as there (V = tanh 1 =
   0.76): friction and its parts, the hysteresis, the estimate, wall time (no reference: the two
   runs side by side).
"""

from __future__ import annotations

import dataclasses
import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np  # noqa: E402
from _machine import header  # noqa: E402

HERE = Path(__file__).resolve().parent
K, BETA, HC, L, V = 1.0, 10.0, -0.5, 2.0, 1.0


def rubber(tau):
    import femehl

    return femehl.Viscoelastic(G0=1.0, G_inf=0.5, tau=tau)


def line_point(tau: float, srr: float) -> dict:
    import femehl
    from femehl.problem.line import LineScene
    from femehl.problem.scene import Motion, RampHold, TanhStart
    from femehl.reference.viscoelastic_line import steady_viscoelastic_line

    motion = Motion(gap=RampHold(0.1, HC, 1.0), velocity=TanhStart(1.0, 1.0), slide_roll=srr)
    t0 = time.perf_counter()
    r = femehl.solve(LineScene(k=K, beta=BETA, viscoelastic=rubber(tau), motion=motion, L=L), t_end=12.0)
    wall = time.perf_counter() - t0
    ref = steady_viscoelastic_line(K, BETA, HC, L, V, rubber(tau), slide_roll=srr)
    ui, us = r.scene.motion.surface_speeds(12.0)
    budget = r.friction[-1] * us - (r.shear_couette[-1] + r.shear_poiseuille[-1]) * ui
    return {
        "tau": tau,
        "SRR": srr,
        "De": 2.0 * us * rubber(tau).tau_creep / np.sqrt(-2.0 * HC),
        "friction": float(r.friction[-1]),
        "friction_err": float(r.friction[-1] / ref.friction - 1),
        "load_err": float(r.load[-1] / ref.load - 1),
        "P": float(r.power_sliding[-1]),
        "P_err": float(r.power_sliding[-1] / ref.power_sliding - 1),
        "budget_err": float(budget / (r.dissipation_film[-1] + r.power_sliding[-1]) - 1),
        "estimate": float(r.uncertainty("load", 12.0)["total"]),
        "cells": int(r.info.get("elements", r.disc.n + 1)),
        "steps": int(r.nsteps),
        "wall": wall,
    }


def martin(srr: float) -> dict:
    import femehl
    from femehl.problem.line import LineScene
    from femehl.reference.rigid_cylinder import martin_cylinder

    ref = martin_cylinder(0.1, BETA, 1.0, L=2.0)
    mo = femehl.Motion(gap=0.1, velocity=femehl.TanhStart(t1=0.0, T=0.1), slide_roll=srr)
    t0 = time.perf_counter()
    r = femehl.solve(LineScene(k=1e6, beta=BETA, motion=mo, cavitation="reynolds"), t_end=2.0)
    wall = time.perf_counter() - t0
    couette = (r.V[-1] * srr / 2.0) / (6.0 * BETA) * ref.couette_integral
    return {
        "SRR": srr,
        "load_err": float(r.load[-1] / ref.load - 1),
        "drag_err": float(r.pressure_drag[-1] / ref.pressure_drag - 1),
        "poiseuille_err": float(r.shear_poiseuille[-1] / ref.poiseuille - 1),
        "couette": float(r.shear_couette[-1]),
        "couette_ref": float(couette),
        "wall": wall,
    }


def sphere(srr: float) -> dict:
    import femehl
    from femehl.problem.presets import paper_sphere

    sc = paper_sphere()
    sc = dataclasses.replace(
        sc,
        substrate=femehl.Viscoelastic(G0=2.0, tau=0.5),
        motion=dataclasses.replace(sc.motion, slide_roll=srr),
    )
    t0 = time.perf_counter()
    r = femehl.solve(sc, t_end=2.0)
    wall = time.perf_counter() - t0
    ui, us = sc.motion.surface_speeds(2.0)
    return {
        "SRR": srr,
        "friction": float(r.friction[-1]),
        "couette": float(r.shear_couette[-1]),
        "poiseuille": float(r.shear_poiseuille[-1]),
        "drag": float(r.pressure_drag[-1]),
        "hysteresis": float(r.power_sliding[-1] / us),
        "film_min": float(r.film_min[-1]),
        "estimate": float(r.uncertainty("film_min", 2.0)["total"]),
        "cells": r.info.get("elements"),
        "wall": wall,
    }


def main():
    out = [
        "# Rolling and sliding on the default path",
        "",
        header("rolling.py"),
        "",
        "Every run is `femehl.solve(scene, t_end=...)` with no mesh and no dt (the automatic mode, "
        "tol = 1e-2). Errors are relative, against references computed without time stepping.",
        "",
        "## 1. Rolling resistance against the Deborah number (line contact, SLS Winkler, SRR = 0)",
        "",
        "De = 2 U_s tau_c / a, a = 1 the overlap half width; `budget` is `f U_s - T U_i = D_film + "
        "P_sliding` of the run's own fields.",
        "",
        "| tau | De | friction | off | load off | P_sliding off | budget off | estimate | cells | steps "
        "| wall s |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    rows = []
    for tau in np.logspace(-2, 3, 11):
        r = line_point(float(tau), 0.0)
        rows.append(r)
        out.append(
            f"| {r['tau']:.3g} | {r['De']:.3g} | {r['friction']:.5f} | {r['friction_err']:.1e} | "
            f"{r['load_err']:.1e} | {r['P_err']:.1e} | {r['budget_err']:.1e} | {r['estimate']:.2%} | "
            f"{r['cells']} | {r['steps']} | {r['wall']:.1f} |"
        )
        print(out[-1], flush=True)
    peak = max(rows, key=lambda r: r["friction"])
    out += [
        "",
        f"The rolling resistance peaks at De = {peak['De']:.3g} ({peak['friction']:.4f}; "
        f"{rows[0]['friction']:.4f} and {rows[-1]['friction']:.4f} at the ends). Wall time per point: "
        f"{np.median([r['wall'] for r in rows]):.1f} s median, {max(r['wall'] for r in rows):.1f} s at most.",
        "",
        "## 2. Traction curve at tau = 1 (line contact)",
        "",
        "| SRR | friction | off | load off | P_sliding off | budget off | wall s |",
        "|---|---|---|---|---|---|---|",
    ]
    for srr in (-1.0, 0.0, 0.5, 1.0, 2.0, 3.0):
        r = line_point(1.0, srr)
        out.append(
            f"| {srr:g} | {r['friction']:.5f} | {r['friction_err']:.1e} | {r['load_err']:.1e} | "
            f"{r['P_err']:.1e} | {r['budget_err']:.1e} | {r['wall']:.1f} |"
        )
        print(out[-1], flush=True)
    out += [
        "",
        "## 3. Rigid cylinder (k = 1e6, Reynolds outlet) against Martin's closed form",
        "",
        "| SRR | load off | pressure drag off | Poiseuille off | Couette | Couette, closed form | wall s |",
        "|---|---|---|---|---|---|---|",
    ]
    for srr in (0.0, 2.0):
        r = martin(srr)
        out.append(
            f"| {srr:g} | {r['load_err']:.1e} | {r['drag_err']:.1e} | {r['poiseuille_err']:.1e} | "
            f"{r['couette']:.6f} | {r['couette_ref']:.6f} | {r['wall']:.1f} |"
        )
        print(out[-1], flush=True)
    out += [
        "",
        "## 4. The paper's sphere on a viscoelastic half space (G0 = 2, tau = 0.5), t = 2",
        "",
        "`hysteresis` = P_sliding / U_s (the hysteresis part of the friction in a steady state; "
        "here the sliding is still starting, V = 0.76).",
        "",
        "| SRR | friction | Couette | Poiseuille | pressure drag | hysteresis | min film | estimate "
        "| cells | wall s |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for srr in (2.0, 0.0):
        r = sphere(srr)
        out.append(
            f"| {srr:g} | {r['friction']:.5f} | {r['couette']:.5f} | {r['poiseuille']:.5f} | "
            f"{r['drag']:.5f} | {r['hysteresis']:.5f} | {r['film_min']:.5f} | {r['estimate']:.2%} | "
            f"{r['cells']} | {r['wall']:.0f} |"
        )
        print(out[-1], flush=True)
    (HERE / "rolling.md").write_text("\n".join(out) + "\n")
    print(f"wrote {HERE / 'rolling.md'}")


if __name__ == "__main__":
    main()
