"""Load-controlled approach of the paper's sphere
==============================================

Load-controlled approach: the paper's sphere pressed by a constant load instead of a gap ramp.

The load F = 4/(3 pi) (the normalized Hertz load of an indentation hc = -1) is applied
at t = 0 to the paper's sphere (beta = 200, hc(0) = 0.1, incompressible half space).
The tip clearance hc(t) is then an unknown: every step solves ONE linear system with
one extra row, int p dA = F (docs/design.md, section 6).  The sphere sinks fast, then slowly,
toward the Hertz depth hc = -1 while the trapped film drains.

Run::

    python examples/load_controlled.py                 # or: femehl run examples/load_controlled.toml

Output (summary.csv, fields.pvd, PNGs) goes to ``femehl-out/load_controlled``.
"""

from __future__ import annotations

import math
import time

from femehl.api import run_to_folder
from femehl.problem.scene import Domain, Fluid, HalfSpace, Motion, Scene, Sphere

HERTZ_LOAD = 4.0 / (3.0 * math.pi)  # normalized load of the Hertz contact at hc = -1


def scene(F: float = HERTZ_LOAD, beta: float = 200.0, h0: float = 0.1) -> Scene:
    """The paper's sphere under a constant imposed load ``F`` (no sliding)."""
    return Scene(
        indenter=Sphere(1.0),
        substrate=HalfSpace(0.5),
        fluid=Fluid(beta),
        motion=Motion(gap=h0, velocity=0.0, load=F),
        domain=Domain(2.0),
    )


def main(
    out="femehl-out/load_controlled",
    t_end: float = 5.0,
    mesh: str = "coarse",
    dt: float = 0.01,
    F: float = HERTZ_LOAD,
) -> dict:
    """Run the load-controlled approach; print and return the final figures.

    Returns
    -------
    dict
        ``load`` (equals F), ``F``, ``hc``, ``hc_hertz`` (Hertz depth for F),
        ``film_center``, ``film_min``, ``wall_s``, ``result``.
    """
    t0 = time.perf_counter()
    sc = scene(F)
    res = run_to_folder(sc, out, method="fe", mesh=mesh, t_end=t_end, dt=dt, store_every=10, overwrite=True)
    hc_hertz = -((F / HERTZ_LOAD) ** (2.0 / 3.0))
    o = {
        "load": float(res.load[-1]),
        "F": F,
        "hc": float(res.hc[-1]),
        "hc_hertz": hc_hertz,
        "film_center": float(res.film_center[-1]),
        "film_min": float(res.film_min[-1]),
        "wall_s": time.perf_counter() - t0,
        "result": res,
    }
    print(
        f"t = {res.t[-1]:g}: load {o['load']:.6g} (imposed {F:.6g}), tip clearance hc "
        f"{o['hc']:.5g} (Hertz {hc_hertz:.4g}), central film {o['film_center']:.5g}, "
        f"minimum film {o['film_min']:.5g}  [{o['wall_s']:.1f} s]"
    )
    return o


if __name__ == "__main__":
    main()
