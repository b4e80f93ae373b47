"""Benchmark: a free sphere's collision by two independent discretizations (FE and FD).

``python benchmarks/free_indenter_fd.py`` throws the sphere of ``free_indenter.py``
(beta = 1000, incompressible half space, L = 3, hc(0) = 0.5, dhc/dt = -1, mass 0.02)
and solves it with the finite elements (coarse and medium ladder meshes) and with the
paper's polar finite differences (dr = 0.03 and 0.02, dtheta = pi/24), the same BDF2
Newton row and dt = 0.01; writes ``free_indenter_fd.md`` next to this file: restitution,
thinnest film, wall time, and the FD restitution extrapolated to dr -> 0 (first order in
dr). Threads pinned to one.
"""

from __future__ import annotations

import math
import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")

from _machine import header  # noqa: E402

HERE = Path(__file__).resolve().parent
MASS = 0.02
RUNS = [
    ("fe", {"mesh": "coarse"}),
    ("fe", {"mesh": "medium"}),
    ("fd", {"dr": 0.03, "dtheta": math.pi / 24}),
    ("fd", {"dr": 0.02, "dtheta": math.pi / 24}),
]


def run(method, opts):
    import femehl
    from femehl.problem.scene import Constant, Domain, Fluid, Motion, Scene

    sc = Scene(
        fluid=Fluid(1000.0),
        motion=Motion(gap=Constant(0.5), velocity=0.0, mass=MASS, hc_dot0=-1.0),
        domain=Domain(3.0),
    )
    t0 = time.perf_counter()
    r = femehl.solve(
        sc, t_end=3.0 + 4.0 * MASS**0.5, dt=0.01, method=method, scheme="bdf2", estimate=False,
        store_every=0, **opts,
    )  # fmt: skip
    return {**r.impact(), "wall_s": time.perf_counter() - t0}


def main():
    rows = [(m, o, run(m, o)) for m, o in RUNS]
    for r in rows:
        print(r, flush=True)
    (e3, e2) = (rows[2][2]["restitution"], rows[3][2]["restitution"])
    extrap = e2 + (e2 - e3) * 0.02 / (0.03 - 0.02)  # first order in dr
    lines = [
        "# A free sphere's collision: finite elements against the polar finite differences",
        "",
        header("free_indenter_fd.py"),
        "",
        f"The thrown sphere of `free_indenter.md` (mass {MASS:g}, beta = 1000, L = 3, hc(0) = 0.5, "
        "dhc/dt = -1, no applied force), BDF2, dt = 0.01, the same Newton row; the FD is the paper's "
        "polar scheme (an independent discretization of the film and the Boussinesq integral).",
        "",
        "| method | grid | restitution | thinnest film | wall s |",
        "|---|---|---|---|---|",
    ]
    for m, o, r in rows:
        grid = ", ".join(f"{k} = {v:.4g}" for k, v in o.items()) if m == "fd" else o["mesh"]
        lines.append(f"| {m} | {grid} | {r['restitution']:.4f} | {r['film_min']:.4g} | {r['wall_s']:.0f} |")
    fe = rows[1][2]["restitution"]
    lines += [
        "",
        f"FD extrapolated to dr -> 0 (first order): {extrap:.4f}, {extrap / fe - 1:+.2%} from the FE "
        f"medium mesh's {fe:.4f}. The thinnest film during the impact (at the rim of the dimple) is "
        "not converged on these grids (its value doubles from the coarse to the medium mesh); the "
        "restitution is.",
    ]
    (HERE / "free_indenter_fd.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
