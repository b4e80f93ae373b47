"""Benchmark: a free sphere thrown at a soft half space through the film (collision, rebound).

``python benchmarks/free_indenter.py`` runs the sphere (``Motion(mass=m, hc_dot0=-1)``,
no applied force, hc(0) = 0.5) at beta = 1000 on an incompressible half space (L = 3)
for several masses, BDF2, on the coarse mesh at dt = 0.01 and, for the time error, at
dt = 0.005; writes ``free_indenter.md`` next to this file: approach and rebound speed,
restitution coefficient, deepest indentation, thinnest film and when, wall time.

The mass is in femehl's units: the film force scale times (time scale)^2 / (length
scale); a heavier sphere carries more momentum into the film (a larger Stokes number)
and rebounds more.  Threads pinned to one.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")

from _machine import header  # noqa: E402

HERE = Path(__file__).resolve().parent
MASSES = [0.005, 0.02, 0.05, 0.2, 0.5]
BETA = 1000.0


def t_end(m):
    """Long enough for the rebound to finish (the contact time grows like sqrt(m))."""
    return 3.0 + 4.0 * m**0.5


def run(m, dt):
    import femehl
    from femehl.problem.scene import Constant, Domain, Fluid, Motion, Scene

    sc = Scene(
        fluid=Fluid(BETA),
        motion=Motion(gap=Constant(0.5), velocity=0.0, mass=m, hc_dot0=-1.0),
        domain=Domain(3.0),
    )
    t0 = time.perf_counter()
    try:
        res = femehl.solve(
            sc, t_end=t_end(m), dt=dt, mesh="coarse", scheme="bdf2", estimate=False, store_every=0
        )
    except femehl.errors.SolverError as exc:
        res = getattr(exc, "result", None)
        stop = f"{type(exc).__name__} at t = {exc.t:.3g}"
        out = {"m": m, "dt": dt, "stopped": stop, "wall_s": time.perf_counter() - t0}
        if res is None or res.nsteps < 2:
            return {**out, "error": str(exc)[:200]}
        return {**out, "v_end": float(res.hc_dot[-1]), "elements": res.info.get("elements"), **res.impact()}
    wall = time.perf_counter() - t0
    return {
        "m": m,
        "dt": dt,
        "wall_s": wall,
        "v_end": float(res.hc_dot[-1]),
        "elements": res.info["elements"],
        **res.impact(),
    }


def main():
    rows = []
    for m in MASSES:
        a, b = run(m, 0.01), run(m, 0.005)
        rows.append((a, b))
        print(a, b, flush=True)
    lines = [
        "# A free sphere thrown at a soft half space: collision and rebound",
        "",
        header("free_indenter.py"),
        "",
        f"Sphere, incompressible half space, beta = {BETA:g}, L = 3, hc(0) = 0.5, thrown at "
        "dhc/dt = -1 with no applied force, to t = 3 + 4 sqrt(m); the coarse ladder mesh on L = 3 "
        f"({rows[0][0].get('elements', '?')} elements), BDF2. Newton's law is one more row of "
        "each step's system "
        "(`femehl.Motion(mass=...)`). Restitution: fastest rebound / fastest approach; the time "
        "error: dt = 0.01 against 0.005.",
        "",
        "| mass | t_end | restitution | time error of it | rebound speed | deepest hc (t) | "
        "thinnest film (t) | speed at the end | wall s (dt = 0.01) | stopped |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for a, b in rows:
        if "error" in a or "error" in b:
            lines.append(f"| {a['m']:g} | | failed: {(a.get('error') or b.get('error'))} | | | | | | | |")
            continue
        err = abs(a["restitution"] - b["restitution"])
        lines.append(
            f"| {a['m']:g} | {t_end(a['m']):.2f} | {a['restitution']:.3f} | {err:.1e} | {a['v_out']:.3f} | "
            f"{a['hc_min']:.3f} ({a['t_hc_min']:.2f}) | {a['film_min']:.4g} ({a['t_film_min']:.2f}) | "
            f"{a['v_end']:.3f} | {a['wall_s']:.0f} | {a.get('stopped', '')} |"
        )
    (HERE / "free_indenter.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
