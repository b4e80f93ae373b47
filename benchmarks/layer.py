"""Benchmark: ``femehl.Layer``, an elastic layer on a rigid base, against its two limits.

``python benchmarks/layer.py`` (or ``femehl bench layer``) writes ``layer.md`` next to
this file:

* **limits**: a sphere pressed into a bonded layer (nu = 0.3) by a load ramped from 0 to
  0.42 over t in [0, 1] (beta = 200, L = 2, no sliding, dt = 0.02, the medium ladder mesh),
  for layer thicknesses h = 0.01 .. 100, against the half space ``HalfSpace(0.3)`` and the
  thin-layer Winkler foundation ``Winkler(k)``, ``k = (1 - nu) / (2 pi (1 - 2 nu) h)``
  (:func:`femehl.elastic.layer_kernel.winkler_limit`): clearance hc, central and minimum film at
  t = 1;
* **set-up**: the time to build the layer's operator against the half space's dense
  build, on the medium and fine ladder meshes, and which form it took (sparse for thin
  layers; dense for the others, the smooth part low-rank for thick ones, on an FFT grid or
  direct between);
* **accuracy**: 24 rows of each operator against a refined-quadrature reference (7-point
  rule on triangles of diameter <= h/20, polar edge integrals with 12 points on pieces of
  h/2, the direct smooth part), relative to the operator's largest entry.

Threads pinned to one.  The raw results go to ``layer.json``; ``--table-only`` rebuilds
the table from it, ``--builds-only`` measures the set-up again and keeps its limits.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")

from _machine import header  # noqa: E402

HERE = Path(__file__).resolve().parent
NU = 0.3
THICKNESS = [0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 100.0]
BUILD = {"medium": [100.0, 1.0, 0.3, 0.1, 0.03, 0.01], "fine": [100.0, 1.0, 0.3, 0.1, 0.01]}


def scene(substrate):
    import femehl

    return femehl.Scene(
        substrate=substrate,
        fluid=femehl.Fluid(200.0),
        motion=femehl.Motion(gap=0.1, load=femehl.Table((0.0, 1.0), (0.0, 0.42)), velocity=0.0),
        domain=femehl.Domain(2.0),
    )


def run(substrate):
    import femehl

    t0 = time.perf_counter()
    try:
        sc = scene(substrate)
    except femehl.SceneError:  # a soft Winkler foundation's contact does not fit in L = 2
        return None
    r = femehl.solve(sc, t_end=1.0, dt=0.02, mesh="medium", estimate=False)
    return {
        "hc": float(r.hc[-1]),
        "center": float(r.film_center[-1]),
        "min": float(r.film_min[-1]),
        "wall": time.perf_counter() - t0,
    }


def limits():
    import femehl
    from femehl.elastic.layer_kernel import winkler_limit

    half = run(femehl.HalfSpace(NU))
    rows = []
    for h in THICKNESS:
        lay = run(femehl.Layer(h, nu=NU))
        wink = run(femehl.Winkler(winkler_limit(h, NU)))
        rows.append((h, lay, wink))
        print("limits", h, lay, wink, flush=True)
    return half, rows


def build_and_accuracy():
    import numpy as np

    import femehl
    from femehl.discretize.fe_disk import FEDisc
    from femehl.elastic import kernels

    out = []
    for mesh, hs in BUILD.items():
        d = FEDisc(femehl.presets.paper_sphere(), mesh=mesh)
        t0 = time.perf_counter()
        d.boussinesq()
        t_half = time.perf_counter() - t0
        rows = np.random.default_rng(0).choice(d.nelements, 24, replace=False)
        for h in hs:
            sub = femehl.Layer(h, nu=NU)
            t0 = time.perf_counter()
            C = sub.compliance_operator(d)
            t_layer = time.perf_counter() - t0
            form = d.info["radial_kernel"]
            if hasattr(C, "nnz"):
                form += f", {C.nnz / C.shape[0]:.0f} per row"
            got = C[rows].toarray() if hasattr(C, "nnz") else C[rows]
            names = ("SMALL_TRIANGLE", "EDGE_PIECE", "EDGE_GAUSS", "_GL_X", "_GL_W")
            saved = {k: getattr(kernels, k) for k in names}
            x, w = np.polynomial.legendre.leggauss(12)
            try:
                for k, v in zip(names, (0.05, 0.5, 12, x, w), strict=True):
                    setattr(kernels, k, v)
                pts = d.centroids[rows]
                X = kernels.influence_matrix(pts, d.tri, mirror_y=d.half)
                X -= kernels.smooth_matrix(pts, d.tri, sub.kernel, mirror_y=d.half)
                ref = sub.compliance * np.asarray(d.P[:, d.free].T @ X.T).T
            finally:
                for k, v in saved.items():
                    setattr(kernels, k, v)
            err = float(np.abs(got - ref).max() / np.abs(ref).max())
            out.append((mesh, d.nelements, d.n, h, t_half, t_layer, form, err))
            print("build", out[-1], flush=True)
    return out


def main(table_only=False, builds_only=False):
    """Run (or, with ``table_only``, reuse ``layer.json``; ``builds_only``: reuse its
    limits, measure the set-up again) and write ``layer.md``."""
    import json

    raw = HERE / "layer.json"
    if table_only:
        data = json.loads(raw.read_text())
    elif builds_only:
        data = json.loads(raw.read_text())
        data["builds"] = build_and_accuracy()
        raw.write_text(json.dumps(data, indent=1) + "\n")
    else:
        half, rows = limits()
        data = {"half": half, "rows": rows, "builds": build_and_accuracy()}
        raw.write_text(json.dumps(data, indent=1) + "\n")
    half, rows, builds = data["half"], data["rows"], data["builds"]
    a = (-half["hc"]) ** 0.5
    lines = [
        "# Elastic layer on a rigid base (`femehl.Layer`) against its limits",
        "",
        header("layer.py"),
        "",
        f"## Limits (bonded, nu = {NU})",
        "",
        "Sphere, load ramped 0 -> 0.42 over t in [0, 1], beta = 200, L = 2, no sliding, backward "
        "Euler at dt = 0.02, medium ladder mesh; values at t = 1.  Half space "
        f"`HalfSpace({NU})`: hc = {half['hc']:.5g}, central film {half['center']:.5g}, minimum film "
        f"{half['min']:.5g} (contact radius a = sqrt(-hc) = {a:.3g}).  Winkler: `Winkler(k)` with "
        "k = (1 - nu)/(2 pi (1 - 2 nu) h).  Ratios: layer over half space (hc, minimum film) and "
        "layer over Winkler.",
        "",
        "| h | h/a | layer hc | layer central film | layer minimum film | Winkler hc | Winkler "
        "minimum film | hc: layer/half | film_min: layer/half | hc: layer/Winkler | film_min: "
        "layer/Winkler | wall s (layer) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for h, lay, wink in rows:
        if wink is None:  # a soft foundation: its dry contact does not fit in L = 2
            w = ["refused (contact > L)", "", "", ""]
        else:
            w = [
                f"{wink['hc']:.5g}",
                f"{wink['min']:.5g}",
                f"{lay['hc'] / wink['hc']:.4f}",
                f"{lay['min'] / wink['min']:.4f}",
            ]
        lines.append(
            f"| {h:g} | {h / a:.3g} | {lay['hc']:.5g} | {lay['center']:.5g} | {lay['min']:.5g} | "
            f"{w[0]} | {w[1]} | {lay['hc'] / half['hc']:.4f} | {lay['min'] / half['min']:.4f} | "
            f"{w[2]} | {w[3]} | {lay['wall']:.1f} |"
        )

    def within(key, ref_of, tol):
        """The h/a of the rows whose ``key`` is within ``tol`` of the reference."""
        return [
            f"{h / a:.3g}"
            for h, lay, wink in rows
            if ref_of(wink) is not None and abs(lay[key] / ref_of(wink)[key] - 1.0) <= tol
        ]

    def winkler(w):
        return w

    def halfspace(w):
        return half

    lines += [""]
    for what, ref_of in (("Winkler", winkler), ("half space", halfspace)):
        for key, name in (("hc", "hc"), ("min", "minimum film")):
            one = ", ".join(within(key, ref_of, 0.01)) or "-"
            five = ", ".join(within(key, ref_of, 0.05)) or "-"
            lines.append(f"- {name} within 1 % of the {what}'s at h/a = {one}; within 5 % at h/a = {five}.")
    lines += [
        "",
        "hc is one number per run: near h/a = 1 the layer's and the foundation's hc cross "
        "(the films there differ by 20 % and more), which is not the limit.  The central film "
        "is read at the origin node: the layer integrates its kernel over the "
        "element-average pressure around the node, the Winkler foundation takes the nodal "
        "pressure, so in the thin limit the two central films differ by the mesh's O(size^2) "
        "(the film there is a small difference of large terms); hc and the minimum film, which "
        "come from the film points, agree.",
        "",
        "## Operator set-up and accuracy (paper-sphere half disks)",
        "",
        "Build: the layer's `compliance_operator` against the half space's dense `boussinesq()`. "
        "Accuracy: 24 rows against the refined-quadrature reference, max |difference| / max |entry|.",
        "",
        "| mesh (elements, unknowns) | h | half space s | layer s | ratio | form | accuracy |",
        "|---|---|---|---|---|---|---|",
    ]
    for mesh, ne, n, h, t_half, t_layer, form, err in builds:
        lines.append(
            f"| {mesh} ({ne}, {n}) | {h:g} | {t_half:.2f} | {t_layer:.2f} | {t_layer / t_half:.1f} | "
            f"{form} | {err:.1e} |"
        )
    (HERE / "layer.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    import sys

    main(table_only="--table-only" in sys.argv[1:], builds_only="--builds-only" in sys.argv[1:])
