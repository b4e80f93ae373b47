"""An elliptic contact sliding across its long axis
================================================

An elliptic contact sliding along x, its long axis across the sliding direction.

The indenter is an elliptic paraboloid s = x^2/(2 Rx) + y^2/(2 Ry) with Rx = 0.5 < Ry = 2:
the dry contact is an ellipse elongated along y, across the sliding direction +x (like a
ball in a groove or a crowned roller).  It is pressed to hc = -0.5 over 0 <= t <= 1, then
slides with V = tanh(t - 1), as in the paper's sphere case.  The shape is symmetric in y,
so the solver uses the half disk automatically.  The minimum film sits at the exit
(x < 0), where the horseshoe constriction of the sphere becomes a long band across the
contact.

Run::

    python examples/ellipsoid_sliding.py             # or: femehl run examples/ellipsoid_sliding.toml
"""

from __future__ import annotations

import time

from femehl.api import run_to_folder
from femehl.problem.indenters import Ellipsoid
from femehl.problem.scene import Domain, Fluid, HalfSpace, Motion, RampHold, Scene, TanhStart


def scene(Rx: float = 0.5, Ry: float = 2.0, h_end: float = -0.5, beta: float = 200.0) -> Scene:
    """Indent to ``h_end`` over t in [0, 1], then slide along +x with V = tanh(t - 1)."""
    return Scene(
        indenter=Ellipsoid(Rx, Ry),
        substrate=HalfSpace(0.5),
        fluid=Fluid(beta),
        motion=Motion(gap=RampHold(0.1, h_end, 1.0), velocity=TanhStart(1.0, 1.0)),
        domain=Domain(2.0),
    )


def main(
    out="femehl-out/ellipsoid_sliding", t_end: float = 5.0, mesh: str = "coarse", dt: float = 0.01
) -> dict:
    """Run the scene; print and return the final load and films.

    Returns
    -------
    dict
        ``load``, ``film_center``, ``film_min``, ``film_min_at`` (x, y), ``wall_s``, ``result``.
    """
    t0 = time.perf_counter()
    res = run_to_folder(
        scene(), out, method="fe", mesh=mesh, t_end=t_end, dt=dt, store_every=10, overwrite=True
    )
    s = res.summary()
    o = {
        "load": float(res.load[-1]),
        "film_center": float(res.film_center[-1]),
        "film_min": float(res.film_min[-1]),
        "film_min_at": (float(s["film_min_x"][-1]), float(s["film_min_y"][-1])),
        "wall_s": time.perf_counter() - t0,
        "result": res,
    }
    x, y = o["film_min_at"]
    print(
        f"t = {res.t[-1]:g}: load {o['load']:.5g}, central film {o['film_center']:.5g}, "
        f"minimum film {o['film_min']:.5g} at (x, y) = ({x:.3g}, {y:.3g})  [{o['wall_s']:.1f} s]"
    )
    return o


if __name__ == "__main__":
    main()
