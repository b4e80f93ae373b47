"""A user-defined indenter: a sphere with an oblique ripple
========================================================

A user-defined indenter from a Python function: a sphere with an oblique ripple.

Any vectorized function s(x, y) >= 0 with s(0, 0) = 0 can be the indenter's gap.
Here a sphere carries a sinusoidal ripple whose crests run at 30 degrees to the sliding
direction, so the shape is NOT symmetric in y and the solver runs on the full disk
(``Shape(..., symmetric_y=False)``, the default).  The motion is the paper's: indent
to hc = -1 over 0 <= t <= 1, then slide with V = tanh(t - 1).

Run::

    python examples/custom_shape.py

(No TOML twin: a scene file cannot hold a Python function; sample the shape into a
height map, ``kind = "heightmap"``, to use it from a scene file.)
"""

from __future__ import annotations

import math
import time

import numpy as np

from femehl.api import run_to_folder
from femehl.problem.indenters import Shape
from femehl.problem.scene import Domain, Fluid, HalfSpace, Motion, RampHold, Scene, TanhStart

AMPLITUDE = 0.05  # ripple height, in units of h_inf
WAVENUMBER = 6.0  # 2 pi / wavelength, in units of 1/sqrt(R h_inf)
ANGLE = math.radians(30.0)  # crest direction vs the sliding direction x


def rippled_sphere(x, y):
    """s(x, y) = r^2/2 + A (1 - cos(k (x cos a + y sin a))): >= 0 and 0 at the tip."""
    xi = x * math.cos(ANGLE) + y * math.sin(ANGLE)
    return 0.5 * (x * x + y * y) + AMPLITUDE * (1.0 - np.cos(WAVENUMBER * xi))


def scene(beta: float = 200.0) -> Scene:
    return Scene(
        indenter=Shape(rippled_sphere, name="rippled sphere"),
        substrate=HalfSpace(0.5),
        fluid=Fluid(beta),
        motion=Motion(gap=RampHold(0.1, -1.0, 1.0), velocity=TanhStart(1.0, 1.0)),
        domain=Domain(2.0),
    )


def main(out="femehl-out/custom_shape", t_end: float = 5.0, mesh: str = "coarse", dt: float = 0.01) -> dict:
    """Run the scene on the full disk; print and return the final load and films.

    Returns
    -------
    dict
        ``load``, ``film_center``, ``film_min``, ``half`` (False: the full disk),
        ``wall_s``, ``result``.
    """
    t0 = time.perf_counter()
    res = run_to_folder(
        scene(), out, method="fe", mesh=mesh, t_end=t_end, dt=dt, store_every=10, overwrite=True
    )
    o = {
        "load": float(res.load[-1]),
        "film_center": float(res.film_center[-1]),
        "film_min": float(res.film_min[-1]),
        "half": bool(res.info["half"]),
        "wall_s": time.perf_counter() - t0,
        "result": res,
    }
    print(
        f"t = {res.t[-1]:g}: load {o['load']:.5g}, central film {o['film_center']:.5g}, "
        f"minimum film {o['film_min']:.5g}  ({'half' if o['half'] else 'full'} disk, "
        f"{res.info['elements']} elements)  [{o['wall_s']:.1f} s]"
    )
    return o


if __name__ == "__main__":
    main()
