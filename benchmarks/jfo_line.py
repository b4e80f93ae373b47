"""Benchmark: 1-D mass-conserving cavitation against the exact steady solution.

``python benchmarks/jfo_line.py`` runs femehl's transient line-contact solver
(``LineScene(cavitation="jfo")``, and ``"reynolds"`` beside it) to its steady state on
uniform meshes of 200 to 1600 elements, and compares with the independent exact steady
solution of :mod:`femehl.reference.line_jfo_steady` (quadrature and shooting; its own uncertainty
<= 2e-9):

* ``b1``: the cylinder ``x^2/2`` on a Winkler foundation (k = 1, beta = 10, hc = -0.5):
  the film ruptures behind the contact and the cavity runs to the outlet (JFO = Reynolds);
* ``c1``: a rigid textured slider (:func:`~femehl.reference.line_jfo_steady.pocket_slider`, a
  cos^2 pocket three films deep, hc = 0.1, beta = 1): rupture entering the pocket and
  reformation inside it;
* ``c2``: the same slider on a stiff Winkler foundation (k = 100, beta = 10).

Each run goes to t = 300 (steps of 0.5; the steady state does not depend on the step,
and JFO's cavity content settles over many transport times).  Reported: the load's
relative error, the largest pressure error relative to the peak, the cavity's first and
last nodes against the exact rupture and reformation points, the liquid flux before the
cavity and after it (JFO: equal; Reynolds creates liquid where the film reforms), and
wall time.  Writes ``jfo_line.md`` and ``jfo_line.json`` next to this file.
"""

from __future__ import annotations

import json
import math
import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np  # noqa: E402
from _machine import header  # noqa: E402

HERE = Path(__file__).resolve().parent
SIZES = (200, 400, 800, 1600)


def cases():
    from femehl.problem.scene import Constant, Motion, RampHold, TanhStart
    from femehl.reference.line_jfo_steady import pocket_slider

    profile, kinks = pocket_slider()
    pocket = Motion(gap=Constant(0.1), velocity=TanhStart(1.0, 1.0))
    cylinder = Motion(gap=RampHold(h0=0.1, h_end=-0.5, t1=1.0), velocity=TanhStart(1.0, 1.0))
    return [
        (
            "b1 cylinder, Winkler",
            dict(k=1.0, beta=10.0, motion=cylinder),
            dict(profile=None, hc=-0.5, k=1.0, beta=10.0),
        ),
        (
            "c1 pocket, rigid",
            dict(k=1e9, beta=1.0, motion=pocket, profile=profile),
            dict(profile=profile, hc=0.1, k=math.inf, beta=1.0, kinks=kinks),
        ),
        (
            "c2 pocket, Winkler",
            dict(k=100.0, beta=10.0, motion=pocket, profile=profile),
            dict(profile=profile, hc=0.1, k=100.0, beta=10.0, kinks=kinks),
        ),
    ]


def reference(model, **kw):
    from femehl.reference.line_jfo_steady import steady_jfo, steady_reynolds

    return (steady_jfo if model == "jfo" else steady_reynolds)(V=1.0, L=2.0, **kw)


def run(scene_kw, model, n):
    import femehl
    from femehl.problem.line import LineScene

    sc = LineScene(L=2.0, cavitation=model, **scene_kw)
    t0 = time.perf_counter()
    res = femehl.solve(sc, t_end=300.0, dt=0.5, n_elements=n, grading="uniform", estimate=False)
    wall = time.perf_counter() - t0
    s, x = res.final, res.disc.x
    held = res.disc.expand((s.own["p_aux"] < 0).astype(float)) > 0
    beta = scene_kw["beta"]
    q = beta * s.d**3 * np.diff(s.p) / np.diff(x) + s.d  # -J per element, V = 1
    xe = 0.5 * (x[:-1] + x[1:])
    film = ~(held[:-1] | held[1:])
    inlet = film & (xe > x[held].max() + 0.05)
    outlet = film & (xe < x[held].min() - 0.02)
    return {
        "load": s.load,
        "p": s.p,
        "x": x,
        "p_max": float(s.p.max()),
        "cavity": (float(x[held].min()), float(x[held].max())),
        "q_in": float(q[inlet].mean()),
        "q_out": float(q[outlet].mean()) if outlet.any() else None,
        "wall": wall,
        "h": float(np.diff(x).max()),
    }


def main():
    rows, raw = [], []
    for name, scene_kw, ref_kw in cases():
        for model in ("jfo", "reynolds"):
            ref = reference(model, **ref_kw)
            for n in SIZES:
                r = run(scene_kw, model, n)
                perr = float(np.abs(r["p"] - ref.pressure(r["x"])).max() / ref.p.max())
                rup = ref.rupture[0] if ref.rupture else None
                ref_ = ref.reformation[0] if ref.reformation else None
                row = {
                    "case": name,
                    "model": model,
                    "n": n,
                    "load": r["load"],
                    "load_ref": ref.load,
                    "load_err": r["load"] / ref.load - 1.0,
                    "p_err": perr,
                    "cavity": r["cavity"],
                    "rupture_ref": rup,
                    "reformation_ref": ref_,
                    "q_in": r["q_in"],
                    "q_out": r["q_out"],
                    "h": r["h"],
                    "wall": r["wall"],
                }
                rows.append(row)
                raw.append(row)
                print(name, model, n, f"{row['load_err']:.2e}", f"{perr:.2e}", r["cavity"], flush=True)
    lines = [
        "# 1-D mass-conserving (JFO) cavitation against the exact steady solution",
        "",
        header("jfo_line.py"),
        "",
        "femehl's transient line contact (P1 pressure, P0 film, `LineScene(cavitation=...)`) run "
        "to its steady state (t = 300, dt = 0.5) on uniform meshes, against the independent "
        "exact steady solution `femehl.reference.line_jfo_steady` (quadrature and shooting, its own "
        "uncertainty <= 2e-9). Load error: relative. Pressure error: the largest over the "
        "nodes, relative to the exact peak. Cavity: femehl's first and last cavitated node "
        "(h is the element size) against the exact reformation and rupture points. Liquid "
        "flux -J = beta d^3 p' + V d in the film before the cavity (inlet side) and after it "
        "(outlet side, where the film reforms): JFO carries the same liquid through the "
        "cavity; Reynolds (Swift-Stieber, p = p' = 0 at both ends of the cavity) does not.",
        "",
        "| case | condition | elements | load | exact load | load error | pressure error | "
        "cavity nodes | exact reformation, rupture | h | flux in | flux out | wall s |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        refo = "-" if r["reformation_ref"] is None else f"{r['reformation_ref']:.4f}"
        out = "-" if r["q_out"] is None else f"{r['q_out']:.8f}"
        lines.append(
            f"| {r['case']} | {r['model']} | {r['n']} | {r['load']:.8f} | {r['load_ref']:.8f} | "
            f"{r['load_err']:.2e} | {r['p_err']:.2e} | [{r['cavity'][0]:.4f}, {r['cavity'][1]:.4f}] | "
            f"{refo}, {r['rupture_ref']:.4f} | {r['h']:.4f} | {r['q_in']:.8f} | {out} | {r['wall']:.1f} |"
        )
    (HERE / "jfo_line.md").write_text("\n".join(lines) + "\n")
    for r in raw:
        r["cavity"] = list(r["cavity"])
    (HERE / "jfo_line.json").write_text(json.dumps(raw, indent=1) + "\n")


if __name__ == "__main__":
    main()
