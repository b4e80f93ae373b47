"""The paper's Figs. 5-7 with both solvers
=======================================

Reproduce the paper's Figs. 5-7 (Wu, Hui et al. 2022) with both femehl solvers on one plot.

Centreline (y = 0) pressure and film thickness of the paper case (beta = 200,
h0 = 0.1):

* Fig. 5, transient normal indentation: t = 0.5, 0.8, 1.0;
* Fig. 6, transient sliding: t = 1.0, 1.5, 2.0 (exit constriction near x = -1);
* Fig. 7, the long-time state at t = t_end (5 in the paper; docs/design.md, section 7: at
  t = 5 the films are still ~1 % from steady).

FE: the default solver on the given ladder mesh.  FD: the paper's polar
finite differences at (dr, pi/N) — it needs dr <= 0.0125 (dtheta = pi/36) to
survive the sliding start-up (its forward differences are downwind at the exit;
dr = 0.025 stops at t = 2.62 with FilmRuptureError).

Run:  python examples/paper_figures.py [out_folder]   (~15 min here: the FD run dominates)
"""

from __future__ import annotations

import math
import pathlib
import sys
import time

import femehl
from femehl.output import centreline_png


def main(
    out="femehl-out/paper_figures",
    t_end=5.0,
    dt=0.02,
    mesh="medium",
    fd_dr=0.0125,
    fd_divisions=36,
    log=print,
):
    """Run both solvers and write fig5.png, fig6.png, fig7.png; return the compared figures."""
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    scene = femehl.presets.paper_sphere(beta=200.0, h0=0.1)
    store = max(1, int(round(0.1 / dt)))
    runs = {}
    for label, kw in (
        ("FE", dict(method="fe", mesh=mesh)),
        ("FD", dict(method="fd", dr=fd_dr, dtheta=math.pi / fd_divisions)),
    ):
        t0 = time.perf_counter()
        runs[label] = femehl.solve(scene, t_end=t_end, dt=dt, store_every=store, **kw)
        log(f"{label}: {time.perf_counter() - t0:.1f} s")
    res = [runs["FE"], runs["FD"]]
    figs = {"fig5": [0.5, 0.8, 1.0], "fig6": [1.0, 1.5, 2.0], "fig7": [t_end]}
    summary = {}
    for name, times in figs.items():
        times = [t for t in times if t <= t_end + 1e-9]
        if times:
            centreline_png(res, out / f"{name}.png", times=times, labels=["FE", "FD"])
    for t in sorted({t for ts in figs.values() for t in ts if t <= t_end + 1e-9}):
        row = {}
        for q in ("load", "film_center", "film_min"):
            a, b = runs["FE"].value_at(q, t), runs["FD"].value_at(q, t)
            row[q] = (a, b)
        summary[t] = row
        log(
            f"t = {t:4.2f}  "
            + "  ".join(
                f"{q}: FE {a:.4f} FD {b:.4f} ({100 * (a - b) / b:+.1f}%)" for q, (a, b) in row.items()
            )
        )
    return summary


if __name__ == "__main__":
    main(*(sys.argv[1:2]))
