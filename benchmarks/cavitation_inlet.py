"""Benchmark: is the domain of the steady-sliding cavitation cases large enough?

``python benchmarks/cavitation_inlet.py`` runs the steady-sliding cases of
``cavitation.py`` (the sphere at beta = 200 and 1000, the paper's motion to t = 8, BDF2 at
dt = 0.01, scene-fitted meshes) with JFO cavitation on domains of radius L = 3 and 4, and
writes ``cavitation_inlet.md``: the rim is where the film is fully flooded (theta = 1), so
a domain too small starves the inlet and thins the film.  Threads pinned to one.
"""

from __future__ import annotations

import dataclasses
import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")

from _machine import header  # noqa: E402

HERE = Path(__file__).resolve().parent


def run(beta, L):
    import femehl

    sc = femehl.presets.paper_sphere(beta=beta)
    sc = dataclasses.replace(sc, fluid=femehl.Fluid(beta, cavitation="jfo"), domain=femehl.Domain(L))
    t0 = time.perf_counter()
    opts = dict(mesh="fitted", scheme="bdf2", estimate=False, store_every=10**6)
    res = femehl.solve(sc, t_end=8.0, dt=0.01, **opts)
    s = res.final
    return res.info["elements"], s.film_min, s.film_center, s.load, time.perf_counter() - t0


def main():
    lines = [
        "# Steady sliding with JFO cavitation: the domain's size",
        "",
        header("cavitation_inlet.py"),
        "",
        "The sphere on the incompressible half space, the paper's motion to t = 8, BDF2 at "
        'dt = 0.01, scene-fitted meshes, `cavitation="jfo"`; the rim is fully flooded. '
        "Change: L = 4 against L = 3.",
        "",
        "| beta | L | elements | minimum film | central film | load | wall s |",
        "|---|---|---|---|---|---|---|",
    ]
    for beta in (200.0, 1000.0):
        rows = {L: run(beta, L) for L in (3.0, 4.0)}
        for L, (ne, fmin, fc, load, wall) in rows.items():
            lines.append(f"| {beta:g} | {L:g} | {ne} | {fmin:.6g} | {fc:.6g} | {load:.6g} | {wall:.0f} |")
        a, b = rows[3.0], rows[4.0]
        lines.append(
            f"| | change | | {b[1] / a[1] - 1:+.2%} | {b[2] / a[2] - 1:+.2%} | {b[3] / a[3] - 1:+.2%} | |"
        )
        print(beta, rows, flush=True)
    (HERE / "cavitation_inlet.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
