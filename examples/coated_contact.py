"""A glass ball on a soft coating bonded to a stiff base
=====================================================

The paper's sphere pressed by a constant load (the Hertz load of the half space at unit
indentation, ramped over t = 1) and slid, on a soft coating -- a PDMS or hydrogel layer
bonded to glass -- instead of a thick block.  The coating's thickness ``h`` is given in
units of the contact's length scale ``sqrt(R h_inf)`` (the Hertz contact radius of the
half space); a coating as thin as the contact is stiffer than the half space, so the same
load makes a smaller, higher-pressure contact and squeezes a thinner film.
femehl's :class:`femehl.Layer` is the exact layered-solid kernel (bonded to a rigid base,
any Poisson ratio); ``h -> infinity`` is the half space and ``h -> 0`` a Winkler
foundation (compressible) or the thin incompressible layer (``benchmarks/layer.md``).

Run::

    python examples/coated_contact.py          # or: femehl run examples/coated_contact.toml

Output: one run folder per coating (summary.csv, fields.pvd) in ``femehl-out/coated_contact``.
"""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path

import femehl
from femehl.api import run_to_folder
from femehl.problem.presets import paper_sphere
from femehl.problem.scene import Constant, Motion, Table, TanhStart

THICKNESSES = (0.3, 1.0, 3.0)  # coating thickness / sqrt(R h_inf)


def scene(thickness: float | None = 1.0, nu: float = 0.5) -> femehl.Scene:
    """The paper's sphere under the Hertz load on a coating of ``thickness`` (None: the half
    space)."""
    sub = femehl.HalfSpace(nu) if thickness is None else femehl.Layer(thickness, nu=nu)
    load = Table((0.0, 1.0), (0.0, 4.0 / (3.0 * math.pi)))  # ramped to the Hertz load over t = 1
    motion = Motion(gap=Constant(0.1), velocity=TanhStart(1.0, 1.0, 1.0), load=load)
    return dataclasses.replace(paper_sphere(), substrate=sub, motion=motion)


def main(out="femehl-out/coated_contact", thicknesses=THICKNESSES, t_end=5.0, mesh="coarse", dt=0.02):
    """Run the half space and every coating; print and return their figures at ``t_end``."""
    rows = []
    for h in (None, *thicknesses):
        t0 = time.perf_counter()
        name = "halfspace" if h is None else f"h_{h:g}"
        res = run_to_folder(
            scene(h), Path(out) / name, method="fe", mesh=mesh, t_end=t_end, dt=dt, scheme="bdf2",
            store_every=50, overwrite=True, log=lambda *a: None,
        )  # fmt: skip
        row = {
            "thickness": h,
            "hc": float(res.hc[-1]),
            "film_center": float(res.film_center[-1]),
            "film_min": float(res.film_min[-1]),
            "wall_s": time.perf_counter() - t0,
        }
        rows.append(row)
        label = "half space" if h is None else f"coating h = {h:g}"
        print(
            f"{label}: indentation hc {row['hc']:.4g}, central film {row['film_center']:.4g}, "
            f"minimum film {row['film_min']:.4g}  [{row['wall_s']:.1f} s]"
        )
    return rows


if __name__ == "__main__":
    main()
