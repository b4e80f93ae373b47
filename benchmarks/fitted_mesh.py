"""Scene-fitted meshes against the mesh ladder: minimum film at t = 3.

Scenes (FE, BDF2, dt = 0.01, to t = 3, half disk: all are symmetric in y):

* ``ellipsoid``: the shipped example (``examples/ellipsoid_sliding.py``),
  Ellipsoid(Rx = 0.5, Ry = 2), hc -> -0.5, beta = 200;
* ``ellipsoid_x``: the same turned by 90 degrees, Rx = 2, Ry = 0.5;
* ``sphere``: the paper sphere (``femehl.problem.presets.paper_sphere()``);
* ``sphere_b2000``: the same at beta = 2000 (films 5x thinner: the edge band narrows).

Each is run on the ladder meshes and on ``fitted_disk(scene, 3, level)`` for
levels ``1.45^2, 1.45, 1, 1/1.45`` (each level has about twice the elements of
the one before).  The converged value is estimated by Richardson extrapolation
from the two finest fitted levels, ``f_inf = f_1 + (f_1 - f_2) / (1.45^2 - 1)``
(order 2 in the mesh size assumed; the order observed from the three finest is
printed as a check); errors are relative to it.

Part two measures the exit zone of the paper sphere against beta (fine ladder
mesh, BDF2, dt = 0.02, t = 3, centreline y = 0): the distance ``e`` from the
Hertz edge x = -1 to where the film, past its exit minimum, has doubled.  It
justifies the edge-band half-width ``W(beta) = 1.17 beta^(-1/3)`` of
:mod:`femehl.discretize.fitted`.

Run (about 8 minutes on 2 cores)::

    python benchmarks/fitted_mesh.py            # writes benchmarks/fitted_mesh.md
    python benchmarks/fitted_mesh.py --quick    # ladder coarse/medium, levels 2.1, 1.45
    python benchmarks/fitted_mesh.py --xfine    # also the xfine rung (about 5 minutes more)
    python benchmarks/fitted_mesh.py --analyze-only   # rebuild the .md from the .json
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import pathlib  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from _machine import machine  # noqa: E402

import femehl  # noqa: E402
from femehl.discretize.fitted import contact_extent, fitted_disk  # noqa: E402
from femehl.discretize.mesh import LADDER_RATIO, load_mesh  # noqa: E402

HERE = pathlib.Path(__file__).resolve().parent
T_END, DT = 3.0, 0.01


def _example_scene():
    """``scene(Rx, Ry, h_end, beta)`` of the shipped example examples/ellipsoid_sliding.py."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "femehl_example_ellipsoid", HERE.parent / "examples" / "ellipsoid_sliding.py"
    )
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.scene


ellipsoid = _example_scene()


SCENES = {
    "ellipsoid (Rx=0.5, Ry=2)": ellipsoid(0.5, 2.0),
    "ellipsoid_x (Rx=2, Ry=0.5)": ellipsoid(2.0, 0.5),
    "sphere (paper)": femehl.presets.paper_sphere(),
    "sphere (paper, beta=2000)": femehl.presets.paper_sphere(beta=2000.0),
}
#: --scenes keys -> SCENES labels
KEYS = dict(zip(("ellipsoid", "ellipsoid_x", "sphere", "sphere_b2000"), SCENES, strict=True))


def run(scene, mesh, dt=DT, t_end=T_END):
    """Minimum film (value, x, y) at t_end and the stepping wall time."""
    t0 = time.perf_counter()
    res = femehl.solve(scene, t_end=t_end, dt=dt, mesh=mesh, scheme="bdf2", store_every=0)
    wall = time.perf_counter() - t0
    s = res.summary()
    return float(res.film_min[-1]), float(s["film_min_x"][-1]), float(s["film_min_y"][-1]), wall


def richardson(values, p=2.0):
    """Converged value from the two finest levels (size ratio LADDER_RATIO), assumed order p.

    Returns ``(f_inf, p_obs)``: ``f_inf = f_1 + (f_1 - f_2) / (1.45^p - 1)`` with ``p = 2``
    (P1 pressure, centroid films: second order in the mesh size), and the order
    observed from the three finest levels as a check (nan if they do not converge
    monotonically).
    """
    r = LADDER_RATIO
    f2, f1 = values[-2:]
    f_inf = f1 + (f1 - f2) / (r**p - 1.0)
    p_obs = float("nan")
    if len(values) >= 3:
        f3 = values[-3]
        q = (f3 - f2) / (f2 - f1) if f2 != f1 else 0.0
        if q > 0:
            p_obs = math.log(q) / math.log(r)
    return f_inf, p_obs


def mesh_study(ladder, levels, keys):
    rows = []
    for label in (KEYS[k] for k in keys):
        scene = SCENES[label]
        ax, ay = contact_extent(scene, T_END)
        print(f"\n{label}: contact semi-axes ax = {ax:.4f}, ay = {ay:.4f}", flush=True)
        recs = []
        for name in ladder:
            dm = load_mesh(name, half=True)
            f, x, y, wall = run(scene, name)
            recs.append(("ladder", name, dm.mesh.t.shape[1], 0.0, f, x, y, wall))
            print(
                f"  ladder {name:7s} ne {recs[-1][2]:6d}  film_min {f:.5f} at ({x:.3f}, {y:.3f})"
                f"  {wall:.1f} s",
                flush=True,
            )
        fitted_vals = []
        for lev in levels:
            t0 = time.perf_counter()
            dm = fitted_disk(scene, T_END, level=lev, cache=False)
            tmesh = time.perf_counter() - t0
            f, x, y, wall = run(scene, dm)
            fitted_vals.append(f)
            recs.append(("fitted", f"level {lev:.3g}", dm.mesh.t.shape[1], tmesh, f, x, y, wall))
            print(
                f"  fitted {lev:7.3g} ne {recs[-1][2]:6d}  film_min {f:.5f} at ({x:.3f}, {y:.3f})"
                f"  {wall:.1f} s (+{tmesh:.2f} s gmsh)",
                flush=True,
            )
        rows.append((label, ax, ay, recs))
    return rows


def exit_zone(betas):
    """Exit-zone extent e(beta) of the paper sphere on the centreline (see the module docstring)."""
    out = []
    x = np.linspace(-1.8, 0.0, 1801)
    pts = np.column_stack([x, 0.0 * x])
    for beta in betas:
        sc = femehl.presets.paper_sphere(beta=beta)
        t0 = time.perf_counter()
        res = femehl.solve(sc, t_end=T_END, dt=0.02, mesh="fine", scheme="bdf2", store_every=10**6)
        d = np.asarray(res.film_at(pts, t=T_END)).ravel()
        m = (x < -0.6) & np.isfinite(d)
        k = np.flatnonzero(m)[np.argmin(d[m])]
        j = k
        while j > 0 and d[j] < 2.0 * d[k]:
            j -= 1
        e = -1.0 - x[j]
        out.append(
            (
                beta,
                float(res.film_min[-1]),
                float(x[k]),
                float(d[k]),
                float(-x[j] - 1.0),
                e,
                time.perf_counter() - t0,
            )
        )
        print(
            f"  beta {beta:g}: exit min {d[k]:.5f} at x = {x[k]:.3f}; film doubled at x = {x[j]:.3f}; "
            f"e = {-x[j] - 1.0:.4f}",
            flush=True,
        )
    return out


def machine_and_gmsh():
    import gmsh

    return f"{machine()}, gmsh {gmsh.__version__}"


def _summary(rows):
    """At the medium rung's element count: the closest fitted level's error vs the medium rung's."""
    out = [
        "## At the medium rung's element count",
        "",
        "| scene | ladder medium: elements, error | closest fitted level: elements, error |",
        "|---|---|---|",
    ]
    for label, _ax, _ay, recs in rows:
        ref, _p = richardson([f for kind, _n, _ne, _t, f, *_ in recs if kind == "fitted"])
        med = [r for r in recs if r[0] == "ladder" and r[1] == "medium"]
        if not med:
            continue
        ne_med = med[0][2]
        fit = min((r for r in recs if r[0] == "fitted"), key=lambda r: abs(math.log(r[2] / ne_med)))
        out.append(
            f"| {label} | {ne_med}, {100 * (med[0][4] / ref - 1):+.2f} % | {fit[1]}: {fit[2]}, "
            f"{100 * (fit[4] / ref - 1):+.2f} % |"
        )
    return out + [""]


def report(rows, zone, quick):
    L = ["# Scene-fitted meshes vs the mesh ladder", ""]
    L.append(
        f"Machine: {machine_and_gmsh()}. Generated by `python benchmarks/fitted_mesh.py"
        f"{' --quick' if quick else ''}` on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}."
    )
    L += [
        "",
        "Minimum film at t = 3, FE, BDF2, dt = 0.01, half disk. The reference is the Richardson "
        "extrapolation from the two finest fitted levels (size ratio 1.45, order 2 assumed: "
        "f_inf = f_1 + (f_1 - f_2) / (1.45^2 - 1)); `error` is relative to it. The observed order "
        "from the three finest levels is a check (negative: the differences do not shrink, i.e. "
        "they are at the mesh-noise level of a minimum over element centroids). Wall: stepping "
        "time of the run (gmsh: mesh generation, uncached).",
        "",
    ]
    for label, ax, ay, recs in rows:
        ref, p = richardson([f for kind, _n, _ne, _t, f, *_ in recs if kind == "fitted"])
        L.append(f"## {label}")
        L.append("")
        L.append(
            f"Contact semi-axes (contact_extent): ax = {ax:.4f}, ay = {ay:.4f}. "
            f"Reference film_min = {ref:.5f}; observed order from the three finest levels "
            f"{p:.2f}; the extrapolation step from the finest level is "
            f"{100 * abs(ref / recs[-1][4] - 1):.2f} %."
        )
        L.append("")
        L.append("| mesh | elements | film_min | at (x, y) | error | wall [s] | gmsh [s] |")
        L.append("|---|---|---|---|---|---|---|")
        for kind, name, ne, tm, f, x, y, wall in recs:
            L.append(
                f"| {kind} {name} | {ne} | {f:.5f} | ({x:.3f}, {y:.3f}) | {100 * (f / ref - 1):+.2f} % "
                f"| {wall:.1f} | {tm:.2f} |"
                if kind == "fitted"
                else f"| {kind} {name} | {ne} | {f:.5f} | ({x:.3f}, {y:.3f}) | {100 * (f / ref - 1):+.2f} % "
                f"| {wall:.1f} | - |"
            )
        L.append("")
    L += _summary(rows)
    if zone:
        L += [
            "## Exit zone against beta (edge-band width)",
            "",
            "Paper sphere, fine ladder mesh, BDF2, dt = 0.02, t = 3, centreline y = 0. `e`: "
            "distance from the Hertz edge x = -1 to where the film, past its exit minimum, "
            "has doubled; the band half-width of `fitted_disk` is `W = 1.17 beta^(-1/3)` "
            "(times the contact size, 1 here).",
            "",
            "| beta | film_min | exit min at x | exit min film | e | W(beta) | W / e |",
            "|---|---|---|---|---|---|---|",
        ]
        for beta, fm, xk, dk, e, _e, _w in zone:
            W = max(0.05, 1.17 * beta ** (-1 / 3))
            L.append(f"| {beta:g} | {fm:.5f} | {xk:.3f} | {dk:.5f} | {e:.4f} | {W:.4f} | {W / e:.2f} |")
        if len(zone) >= 2:
            b = np.log([z[0] for z in zone])
            e = np.log([z[4] for z in zone])
            slope = np.polyfit(b, e, 1)[0]
            L += ["", f"Fitted exponent: e ~ beta^{slope:.3f}."]
        L.append("")
    return "\n".join(L)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--xfine", action="store_true", help="also the xfine rung (about 100 s a run)")
    ap.add_argument("--no-zone", action="store_true", help="skip the exit-zone study")
    ap.add_argument("--out", default=str(HERE / "fitted_mesh.md"))
    ap.add_argument("--analyze-only", action="store_true", help="rebuild the table from the .json")
    ap.add_argument("--scenes", default=",".join(KEYS), help=f"comma-separated, of {', '.join(KEYS)}")
    ap.add_argument("--merge", nargs="*", default=[], help="with --analyze-only: more .json to add")
    a = ap.parse_args()
    raw = pathlib.Path(a.out).with_suffix(".json")
    if a.analyze_only:
        data = json.loads(raw.read_text())
        for extra in a.merge:
            data["rows"] += json.loads(pathlib.Path(extra).read_text())["rows"]
        rows = [(r[0], r[1], r[2], r[-1]) for r in data["rows"]]  # (label, ax, ay, runs)
        text = report(rows, data.get("zone", []), data.get("quick", False))
        print(text)
        pathlib.Path(a.out).write_text(text + "\n")
        return
    r = LADDER_RATIO
    ladder = ["coarse", "medium"] if a.quick else ["coarse", "medium", "fine"] + ["xfine"] * a.xfine
    levels = [r * r, r] if a.quick else [r * r, r, 1.0, 1.0 / r]
    rows = mesh_study(ladder, levels, [k for k in a.scenes.split(",") if k])
    raw.write_text(json.dumps({"rows": rows, "quick": a.quick}, indent=1))
    zone = [] if (a.quick or a.no_zone) else exit_zone([20.0, 200.0, 2000.0])
    raw.write_text(json.dumps({"rows": rows, "zone": zone, "quick": a.quick}, indent=1))
    text = report(rows, zone, a.quick)
    print("\n" + text)
    pathlib.Path(a.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
