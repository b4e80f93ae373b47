"""Benchmark: the JFO, Reynolds and half-Sommerfeld conditions against full Sommerfeld.

``python benchmarks/cavitation.py`` runs, without a condition, with
``Fluid(cavitation="jfo")``, ``"reynolds"`` and ``"half-sommerfeld"`` (BDF2, dt = 0.01):

* the paper case (sphere, beta = 200, L = 2, to t = 5) on the coarse, medium and fine
  ladder meshes (convergence under refinement);
* steady sliding of the sphere at beta = 200 and 1000 on L = 3 (the paper's motion to
  t = 8) on scene-fitted meshes;

and writes ``cavitation.md`` next to this file: minimum film and where, central film,
load (half-Sommerfeld: clipped, and the full-Sommerfeld load of the same solution beside
it), cavitated area, the Reynolds condition's full-film source, JFO's mass balance (the
largest relative imbalance of any step) and lowest filling, the most negative stored
pressure (relative to the peak), wall time.  Threads pinned to one.
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
CASES = [
    ("paper case", 200.0, 2.0, 5.0, "coarse"),
    ("paper case", 200.0, 2.0, 5.0, "medium"),
    ("paper case", 200.0, 2.0, 5.0, "fine"),
    ("steady sliding", 200.0, 3.0, 8.0, "fitted"),
    ("steady sliding", 1000.0, 3.0, 8.0, "fitted"),
]


def run(beta, L, t_end, mesh, cavitation):
    import femehl

    sc = femehl.presets.paper_sphere(beta=beta)
    sc = dataclasses.replace(sc, fluid=femehl.Fluid(beta, cavitation=cavitation), domain=femehl.Domain(L))
    t0 = time.perf_counter()
    res = femehl.solve(sc, t_end=t_end, dt=0.01, mesh=mesh, scheme="bdf2", estimate=False, store_every=1)
    wall = time.perf_counter() - t0
    p_neg = min(float(s.p.min()) for s in res.states) / float(res.p_max.max())
    x, y = res.final.film_min_at
    return {
        "elements": res.info["elements"],
        "film_min": res.film_min[-1],
        "at": (x, y),
        "film_center": res.film_center[-1],
        "load": res.load[-1],
        "area": res.final.info.get("cavitated_area", 0.0),
        "load_full": res.final.info.get("load_full"),
        "source": res.final.info.get("full_film_source"),
        "imbalance": _largest(res, "mass_imbalance"),
        "theta_min": _smallest(res, "theta_min"),
        "p_neg": p_neg,
        "wall": wall,
    }


def _largest(res, name):
    return max(s.info[name] for s in res.states) if name in res.final.info else None


def _smallest(res, name):
    return min(s.info[name] for s in res.states) if name in res.final.info else None


CONDITIONS = (
    ("full Sommerfeld", None),
    ("JFO", "jfo"),
    ("Reynolds", "reynolds"),
    ("half-Sommerfeld", "half-sommerfeld"),
)


def _cell(v, fmt):
    return "" if v is None else format(v, fmt)


def main():
    lines = [
        "# JFO, Reynolds and half-Sommerfeld cavitation against full Sommerfeld",
        "",
    ]
    rows = []
    for name, beta, L, t_end, mesh in CASES:
        runs = {label: run(beta, L, t_end, mesh, cav) for label, cav in CONDITIONS}
        rows.append((name, beta, L, t_end, mesh, runs))
        print(name, beta, mesh, *(r["film_min"] for r in runs.values()), flush=True)
    lines += [
        header("cavitation.py"),
        "",
        "Sphere, incompressible half space, the paper's motion (indent to hc = -1 over t <= 1, "
        "slide at V = tanh(t - 1)), BDF2 at dt = 0.01; values at t_end. The cavitated set is "
        "lagged one step (`femehl.problem.cavitation`). Half-Sommerfeld is the full-Sommerfeld run with "
        "its negative pressures clipped after each solve: the same films, its load the clipped "
        "field's, with the full-Sommerfeld load of the same solution beside it (load before "
        "clipping); its cavitated area is that of the clipped nodes. Full-film source: the "
        "Reynolds condition's multiplier summed over the held nodes, the volume per unit time "
        "it adds to the full-film balance (the liquid created where the film reforms plus the "
        "cavity's gas growth and outflow through the rim; here mostly the gas leaving through "
        "the rim, see "
        "`femehl.problem.cavitation.ReynoldsCavitation`). Most negative pressure: the lowest stored over "
        "every step, relative to the peak (full Sommerfeld: its sub-ambient lobe; Reynolds: the "
        "one-step transient of a node joining the set; half-Sommerfeld: 0). JFO "
        "(`femehl.problem.cavitation.JFOCavitation`, mass-conserving): mass imbalance is the largest "
        "over every step of the discrete liquid balance d(liquid volume)/dt + net outflow, "
        "relative to the size of its terms; lowest filling is the smallest film content theta "
        "of a cavitated node over every step.",
        "",
        "| case | beta | L | t_end | mesh (elements) | condition | minimum film (x, y) | central film | "
        "load | load before clipping | cavitated area | full-film source | mass imbalance | "
        "lowest filling | most negative p / p_max | wall s |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, beta, L, t_end, mesh, runs in rows:
        for label, r in runs.items():
            lines.append(
                f"| {name} | {beta:g} | {L:g} | {t_end:g} | {mesh} ({r['elements']}) | {label} | "
                f"{r['film_min']:.5g} ({r['at'][0]:.3f}, {r['at'][1]:.3f}) | {r['film_center']:.5g} | "
                f"{r['load']:.5g} | {_cell(r['load_full'], '.5g')} | {r['area']:.3g} | "
                f"{_cell(r['source'], '.4g')} | {_cell(r['imbalance'], '.1e')} | "
                f"{_cell(r['theta_min'], '.3f')} | {r['p_neg']:.2e} | {r['wall']:.1f} |"
            )
        full = runs["full Sommerfeld"]
        for label in ("JFO", "Reynolds", "half-Sommerfeld"):
            r = runs[label]
            lines.append(
                f"| | | | | | {label} / full | {r['film_min'] / full['film_min']:.4f} | "
                f"{r['film_center'] / full['film_center']:.4f} | {r['load'] / full['load']:.4f} | | | | "
                f"| | | {r['wall'] / full['wall']:.2f} |"
            )
    (HERE / "cavitation.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
