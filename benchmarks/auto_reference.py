"""Reference solutions for the honesty check of femehl.auto (tests/test_auto.py).

Configuration: FE, BDF2 at the fixed step DT = 0.0025, fitted meshes at levels 1/1.45
and 1/1.45^2 (two and four times the level-1 element count), t_end = 1.5, on the paper
sphere and the ellipsoid scene of the tests.  The reference is the Richardson
extrapolation (order 2 in h, ratio 1.45) of the two levels; its uncertainty is stated
per quantity as max over t of |extrapolated - level 1/1.45^2| relative (the correction
applied), and the BDF2 time error at dt = 0.0025 is ~1e-4 relative (README: 0.1 % at
dt = 0.01, order 2).  Output: benchmarks/auto_reference.json.

Run:  OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/auto_reference.py
"""

from __future__ import annotations

import json
import pathlib
import platform
import time

import numpy as np

import femehl
from femehl import Ellipsoid, Motion, RampHold, Scene, TanhStart
from femehl.discretize.fitted import fitted_disk

T_END = 1.5
DT = 0.0025
RATIO = 1.45
LEVELS = (1 / RATIO, 1 / RATIO**2)
QUANTITIES = ("load", "film_center", "film_min")
OUT = pathlib.Path(__file__).with_name("auto_reference.json")


def scenes() -> dict:
    """The scenes of the honesty check (the same as tests/test_auto.py)."""
    return {
        "sphere": femehl.presets.paper_sphere(),
        "ellipsoid": Scene(
            indenter=Ellipsoid(0.5, 2.0),
            motion=Motion(gap=RampHold(0.1, -0.5, 1.0), velocity=TanhStart(1.0, 1.0)),
        ),
    }


def run_level(scene, level: float) -> dict:
    """One fixed-step BDF2 run on the fitted mesh at ``level``."""
    dm = fitted_disk(scene, T_END, level=level)
    t0 = time.perf_counter()
    res = femehl.solve(scene, t_end=T_END, dt=DT, scheme="bdf2", mesh=dm, store_every=0)
    out = {q: getattr(res, q).tolist() for q in QUANTITIES}
    out.update(t=res.t.tolist(), level=level, elements=int(dm.mesh.t.shape[1]))
    out["wall_s"] = round(time.perf_counter() - t0, 1)
    return out


def reference(scene) -> dict:
    """Richardson-extrapolated reference of ``scene`` from the two levels."""
    coarse, fine = (run_level(scene, lev) for lev in LEVELS)
    ref = {"t": fine["t"], "runs": [coarse, fine], "uncertainty": {}}
    for q in QUANTITIES:
        qf, qc = np.asarray(fine[q]), np.asarray(coarse[q])
        qx = qf + (qf - qc) / (RATIO**2 - 1)
        ref[q] = qx.tolist()
        scale = np.maximum(np.abs(qx), 0.1 if q == "load" else 0.0)
        ref["uncertainty"][q] = float(np.max(np.abs(qx - qf)[1:] / scale[1:]))
    return ref


def main() -> None:
    data = {
        "config": {"t_end": T_END, "dt": DT, "scheme": "bdf2", "levels": LEVELS, "ratio": RATIO},
        "machine": platform.processor() or platform.machine(),
    }
    for name, scene in scenes().items():
        data[name] = reference(scene)
        print(name, [r["elements"] for r in data[name]["runs"]], data[name]["uncertainty"], flush=True)
    OUT.write_text(json.dumps(data))


if __name__ == "__main__":
    main()
