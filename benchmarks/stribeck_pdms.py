"""The Stribeck curve of a rough PDMS ball on glass in SI units (issue 43, part 4).

``examples/pdms_ball.toml`` (R = 9.5 mm, E = 1.2 MPa, 0.5 N, a glycerol-water film of
0.1 Pa s, combined roughness 0.5 um with Greenwood-Tripp asperities, mu_b = 0.3, Reynolds
cavitation; coarse mesh, adaptive steps) at NUM speeds from LO to HI m/s, each to its steady
state, as ``femehl stribeck examples/pdms_ball.toml --speeds LO HI --num NUM`` runs them (a
local Dask cluster, two workers); then the speeds CHECK again on the medium mesh, the
coarse curve's discretization error.  Writes ``stribeck_pdms.md`` and ``stribeck_pdms.png``
here.

Run::

    python benchmarks/stribeck_pdms.py
"""

from __future__ import annotations

import pathlib
import shutil
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _machine import header  # noqa: E402
from _stribeck_report import case_walls, finish, summary  # noqa: E402

SCENE = HERE.parent / "examples" / "pdms_ball.toml"
SPEEDS, NUM, WORKERS = (1e-8, 1.0), 33, 2
CHECK = (1e-5, 1e-1, 3)  # 1e-5, 1e-3, 1e-1 m/s on the medium mesh
QUANTITIES = ("friction_coefficient", "film_center_m", "asperity_share")


def main():
    from femehl.studies.stribeck import stribeck

    out = pathlib.Path(tempfile.mkdtemp(prefix="femehl-stribeck-pdms-"))
    t0 = time.perf_counter()
    curve = stribeck(SCENE, SPEEDS, NUM, out=out / "coarse", workers=WORKERS, progress=False)
    wall = time.perf_counter() - t0
    wall_of = case_walls(out / "coarse", "si.V_ss")
    walls = list(wall_of.values())
    shutil.copy(curve.attrs["png"], HERE / "stribeck_pdms.png")

    t1 = time.perf_counter()
    lo, hi, n = CHECK
    fine = stribeck(
        SCENE, (lo, hi), n, out=out / "medium", run={"mesh": "medium"}, workers=WORKERS, progress=False
    )
    wall_check = time.perf_counter() - t1
    import numpy as np

    # the same speeds on the coarse curve (logspace(-8, 0, 33) holds 1e-5, 1e-3 and 1e-1)
    coarse_at = curve[[bool(np.isclose(v, fine["speed"], rtol=1e-9).any()) for v in curve["speed"]]]
    assert len(coarse_at) == n, "the check's speeds must be on the curve"

    lines = [
        "# The Stribeck curve of a rough PDMS ball on glass (`benchmarks/stribeck_pdms.py`)",
        "",
        header("stribeck_pdms.py"),
        "",
        f"`examples/pdms_ball.toml` (R = 9.5 mm, E = 1.2 MPa, 0.5 N, eta = 0.1 Pa s, sigma = 0.5 um, "
        f"Greenwood-Tripp asperities with mu_b = 0.3, Reynolds cavitation; coarse mesh, adaptive steps "
        f"step_tol = 1e-2) at {NUM} speeds from {SPEEDS[0]:g} to {SPEEDS[1]:g} m/s, each run to t = 8 "
        f"(seven contact radii of sliding), as `femehl stribeck examples/pdms_ball.toml --speeds "
        f"{SPEEDS[0]:g} {SPEEDS[1]:g} --num {NUM}` runs them (a local Dask cluster, {WORKERS} workers).",
        "",
        *summary(curve, wall, walls, 0.3, " m/s"),
        "",
        "| V_ss [m/s] | Hersey eta U_e R / W | friction coefficient | central film [um] | film / sigma "
        "| asperities' share | regime | steady | wall [s] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for _, r in curve.iterrows():
        w = wall_of.get(float(r["speed"]), float("nan"))
        lines.append(
            f"| {r['speed']:.3g} | {r['hersey']:.3g} | {r['friction_coefficient']:.5f} | "
            f"{r['film_center_m'] * 1e6:.4f} | {r['film_over_sigma']:.3f} | {r['asperity_share']:.4g} | "
            f"{r['regime']} | {r['steady']} | {w:.0f} |"
        )
    lines += [
        "",
        f"## The coarse curve's error: {n} speeds on the medium mesh ({wall_check:.0f} s)",
        "",
        "| V_ss [m/s] | quantity | coarse | medium | difference |",
        "|---|---|---|---|---|",
    ]
    for (_, c), (_, f) in zip(coarse_at.iterrows(), fine.iterrows(), strict=True):
        for q in QUANTITIES:
            a, b = float(c[q]), float(f[q])
            diff = abs(a - b) / max(abs(b), 1e-300) if q != "asperity_share" else abs(a - b)
            unit = "relative" if q != "asperity_share" else "absolute"
            lines.append(f"| {c['speed']:.3g} | {q} | {a:.5g} | {b:.5g} | {diff:.2g} ({unit}) |")
    finish(lines, "stribeck_pdms", out)


if __name__ == "__main__":
    main()
