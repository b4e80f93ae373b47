"""A textured sphere: 200,000 elements on the fast operator
========================================================

A textured sphere sliding on the full disk: a square array of shallow dimples, 200k elements.

Surface texturing (laser-made dimples) is the application the paper names for its scheme.
Here the sphere carries a square array of smooth dimples of depth ``DEPTH`` (in units of
``h_inf``), radius ``DIMPLE_R`` and pitch ``PITCH`` (units of ``sqrt(R h_inf)``), the
array tilted by ``ANGLE`` to the sliding direction, so the shape is not symmetric in y
and the run is on the full disk.  The contact (radius about 1) holds some 35 dimples;
each needs about 20 elements across, so the mesh is uniformly fine over the contact
(``r <= R_FINE``) and grows to the rim: about 200,000 elements, where the dense elastic
operator (320 GB) cannot be held and femehl's ``operator="auto"`` picks the fast one
(:mod:`femehl.elastic.hmatrix`).  The motion is the paper's: indent to hc = -1 over
0 <= t <= 1, then slide with V = tanh(t - 1).

Run::

    python examples/textured_sphere.py                  # 200k elements to t = 5
    python examples/textured_sphere.py --elements 20000 --t-end 2

and open ``femehl-out/textured_sphere/fields.pvd`` in ParaView (the film ``d`` shows the
dimples inside the contact and the horseshoe constriction around it).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from femehl.api import run_to_folder
from femehl.discretize.mesh import estimate_elements, sized_disk
from femehl.problem.indenters import Shape
from femehl.problem.scene import Domain, Fluid, HalfSpace, Motion, RampHold, Scene, TanhStart

DEPTH = 0.05  # dimple depth, units of h_inf
DIMPLE_R = 0.12  # dimple radius, units of sqrt(R h_inf)
PITCH = 0.35  # centre-to-centre distance of the square array
ANGLE = math.radians(20.0)  # array axes vs the sliding direction x
L = 2.0  # domain radius
R_FINE = 1.35  # the mesh is uniformly fine for r <= R_FINE (contact radius about 1.1)


def dimpled_sphere(x, y):
    """s = r^2/2 + DEPTH * (1 - (rho/DIMPLE_R)^2)^2 inside every dimple (rho: distance to its
    centre); dimple centres at ((i + 1/2) PITCH, (j + 1/2) PITCH) in the tilted frame, so
    the tip (0, 0) lies between four dimples and s(0, 0) = 0."""
    c, s = math.cos(ANGLE), math.sin(ANGLE)
    u = x * c + y * s
    v = -x * s + y * c
    du = u - PITCH * (np.floor(u / PITCH) + 0.5)
    dv = v - PITCH * (np.floor(v / PITCH) + 0.5)
    q = np.clip(1.0 - (du * du + dv * dv) / DIMPLE_R**2, 0.0, None)
    return 0.5 * (x * x + y * y) + DEPTH * q * q


def scene(beta: float = 200.0) -> Scene:
    return Scene(
        indenter=Shape(dimpled_sphere, name="dimpled sphere"),
        substrate=HalfSpace(0.5),
        fluid=Fluid(beta),
        motion=Motion(gap=RampHold(0.1, -1.0, 1.0), velocity=TanhStart(1.0, 1.0)),
        domain=Domain(L),
    )


def size_field(h_fine: float):
    """h(r): ``h_fine`` for r <= R_FINE, then growing linearly to 12 h_fine (<= 0.25) at L."""
    h_far = min(0.25, 12.0 * h_fine)

    def h(r):
        return h_fine if r <= R_FINE else h_fine + (h_far - h_fine) * (r - R_FINE) / (L - R_FINE)

    return h


def textured_mesh(elements: int = 200_000):
    """A full-disk gmsh mesh of about ``elements`` triangles, uniformly fine over the contact."""
    h_fine = 0.05
    for _ in range(4):  # the count goes as h^-2 over the fine zone: a few fixed-point steps
        h_fine *= math.sqrt(estimate_elements(L, False, size_field(h_fine)) / elements)
    h = size_field(h_fine)
    return sized_disk(L, False, lambda x, y: h(math.hypot(x, y)), f"textured-{elements}")


def main(
    out="femehl-out/textured_sphere",
    t_end: float = 5.0,
    elements: int = 200_000,
    dt: float = 0.01,
    operator: str = "auto",
    store_every: int = 10,
) -> dict:
    """Mesh, run and report; returns the final load and films, the operator and timings."""
    t0 = time.perf_counter()
    dm = textured_mesh(elements)
    t_mesh = time.perf_counter() - t0
    res = run_to_folder(
        scene(),
        out,
        method="fe",
        mesh=dm,
        operator=operator,
        scheme="bdf2",
        t_end=t_end,
        dt=dt,
        store_every=store_every,
        overwrite=True,
    )
    o = {
        "load": float(res.load[-1]),
        "film_center": float(res.film_center[-1]),
        "film_min": float(res.film_min[-1]),
        "elements": int(res.info["elements"]),
        "operator": res.info["operator"],
        "half": bool(res.info["half"]),
        "mesh_s": t_mesh,
        "wall_s": time.perf_counter() - t0,
        "result": res,
    }
    print(
        f"t = {res.t[-1]:g}: load {o['load']:.5g}, central film {o['film_center']:.5g}, "
        f"minimum film {o['film_min']:.5g}  (full disk, {o['elements']} elements, {o['operator']} "
        f"operator; mesh {t_mesh:.0f} s, total {o['wall_s']:.0f} s)"
    )
    return o


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=200_000)
    ap.add_argument("--t-end", type=float, default=5.0)
    ap.add_argument("--dt", type=float, default=0.01)
    ap.add_argument("--out", default="femehl-out/textured_sphere")
    a = ap.parse_args()
    main(out=a.out, t_end=a.t_end, elements=a.elements, dt=a.dt)
