"""The Stribeck curve of a rough line contact over five decades of speed (issue 43, part 4).

The scene of ``examples/stribeck_curve.py`` (a cylinder on a rough Winkler foundation under a
constant load, Greenwood-Tripp asperities with mu_b = 0.1) at 26 speed factors from 1e-3 to
1e2, each run in the automatic mode (no mesh, no dt) to its steady state, as
``femehl stribeck`` runs them: a Dask sweep, two workers.  Writes ``stribeck.md`` (the curve,
the regimes, the wall time and the cost per point) and ``stribeck.png`` here.

Run::

    python benchmarks/stribeck.py
"""

from __future__ import annotations

import pathlib
import shutil
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "examples"))

from _machine import header  # noqa: E402
from _stribeck_report import case_walls, finish, summary  # noqa: E402

SPEEDS, NUM, WORKERS = (1e-3, 1e2), 26, 2


def main():
    import stribeck_curve as example

    from femehl.studies.stribeck import stribeck

    out = pathlib.Path(tempfile.mkdtemp(prefix="femehl-stribeck-"))
    t0 = time.perf_counter()
    curve = stribeck(example.SCENE, SPEEDS, NUM, out=out, workers=WORKERS, progress=False)
    wall = time.perf_counter() - t0
    walls = list(case_walls(out, "fluid.beta").values())
    shutil.copy(curve.attrs["png"], HERE / "stribeck.png")
    lines = [
        "# The Stribeck curve of a rough line contact (`benchmarks/stribeck.py`)",
        "",
        header("stribeck.py"),
        "",
        f"The scene of `examples/stribeck_curve.py` at {NUM} speed factors from {SPEEDS[0]:g} to "
        f"{SPEEDS[1]:g} (five decades), each in the automatic mode to its steady state at t = 20, "
        f"as `femehl stribeck` runs them (a local Dask cluster, {WORKERS} workers).",
        "",
        *summary(curve, wall, walls, example.MU_B),
        "",
        "| speed | beta | friction coefficient | central film / sigma | asperities' share | regime "
        "| steady |",
        "|---|---|---|---|---|---|---|",
    ]
    for _, r in curve.iterrows():
        lines.append(
            f"| {r['speed']:.3g} | {r['beta']:.4g} | {r['friction_coefficient']:.5f} | "
            f"{r['film_over_sigma']:.4f} | {r['asperity_share']:.4g} | {r['regime']} | {r['steady']} |"
        )
    finish(lines, "stribeck", out)


if __name__ == "__main__":
    main()
