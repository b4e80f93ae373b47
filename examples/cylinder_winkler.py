"""Line contact: a cylinder sliding on a Winkler foundation
========================================================

Transient sliding of a rigid cylinder on a lubricated Winkler foundation (paper section 4).

The cylinder (gap x^2/2) is pushed from hc = 0.1 to hc = h_end over 0 <= t <= 1
(pure squeeze), then slides with V = tanh(t - 1).  At long times the film
reaches steady sliding, which is compared with the exact steady solution
(quadrature and shooting, :mod:`femehl.reference.line_steady`).  A PNG of p(x) and d(x)
with the exact solution overlaid is written to the output folder.

Run::

    PYTHONPATH=. python examples/cylinder_winkler.py [outdir] [--t-end 15] [--n 400]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from femehl.api import solve_line
from femehl.problem.line import LineScene
from femehl.problem.scene import Motion, RampHold, TanhStart
from femehl.reference.line_steady import steady_line


def main(
    t_end: float = 15.0,
    dt: float = 0.05,
    n_elements: int = 400,
    k: float = 1.0,
    beta: float = 10.0,
    h_end: float = -0.5,
    L: float = 2.0,
    outdir="femehl-out/cylinder",
    verbose: bool = True,
) -> dict:
    """Run the transient, compare its final state with the steady solution, plot.

    Returns
    -------
    dict
        ``film_error`` (max |d - d_exact| / min d_exact), ``load_error``
        (relative), ``load``, ``load_exact``, ``film_center``,
        ``film_center_exact``, ``film_min``, ``film_min_exact``,
        ``film_min_x``, ``d_star``, ``run_s``, ``steady_s``, ``png``.
    """
    scene = LineScene(
        k=k, beta=beta, L=L, motion=Motion(gap=RampHold(0.1, h_end, 1.0), velocity=TanhStart(1.0, 1.0))
    )
    t0 = time.perf_counter()
    res = solve_line(scene, t_end, dt, n_elements=n_elements, store_every=max(1, int(round(0.5 / dt))))
    t1 = time.perf_counter()
    ex = steady_line(k, beta, h_end, L, full=True)
    t2 = time.perf_counter()

    f = res.final
    d_ex = ex.film(res.disc.xc)
    out = {
        "t_end": float(f.t),
        "film_error": float(np.abs(f.d - d_ex).max() / d_ex.min()),
        "load_error": float(abs(f.load - ex.load) / ex.load),
        "load": f.load,
        "load_exact": ex.load,
        "film_center": f.film_center,
        "film_center_exact": float(ex.film(0.0)),
        "film_min": f.film_min,
        "film_min_exact": float(d_ex.min()),
        "film_min_x": f.film_min_at[0],
        "d_star": ex.d_star,
        "run_s": t1 - t0,
        "steady_s": t2 - t1,
    }

    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    xs = np.linspace(-L, L, 1601)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 7), sharex=True)
    for s in res.states[:: max(1, len(res.states) // 6)]:
        ax1.plot(res.disc.x, s.p, lw=0.6, alpha=0.5, label=f"t = {s.t:.1f}")
        ax2.plot(res.disc.xc, s.d, lw=0.6, alpha=0.5)
    ax1.plot(res.disc.x, f.p, "C0", lw=2, label=f"FE, t = {f.t:g}")
    ax1.plot(xs, ex.pressure(xs), "k--", lw=1.2, label="exact steady")
    ax2.plot(res.disc.xc, f.d, "C0", lw=2)
    ax2.plot(xs, ex.film(xs), "k--", lw=1.2)
    ax2.plot(xs, h_end + xs**2 / 2, ":", color="gray", lw=1, label="rigid gap h")
    ax1.set_ylabel("p")
    ax2.set_ylabel("d")
    ax2.set_xlabel("x  (cylinder slides toward +x)")
    ax2.set_ylim(0.0, max(0.6, 4 * float(d_ex.min())))
    ax1.legend(fontsize=7, ncol=2)
    ax2.legend(fontsize=7)
    fig.suptitle(f"cylinder on Winkler foundation: k = {k:g}, beta = {beta:g}, hc = {h_end:g}")
    fig.tight_layout()
    png = outdir / "cylinder_winkler.png"
    fig.savefig(png, dpi=120)
    plt.close(fig)
    out["png"] = str(png)

    if verbose:
        print(
            f"transient: {res.info['elements']} elements, {res.info['steps']} steps of dt = {dt:g} "
            f"in {out['run_s']:.2f} s; steady solution in {out['steady_s']:.2f} s"
        )
        print(f"film  max|d - d_exact| / min d = {out['film_error']:.3e}")
        print(
            f"load  FE {out['load']:.8f}  exact {out['load_exact']:.8f}  rel. error {out['load_error']:.3e}"
        )
        print(f"film at x = 0: FE {out['film_center']:.6f}  exact {out['film_center_exact']:.6f}")
        print(
            f"min film: FE {out['film_min']:.6f} at x = {out['film_min_x']:.3f}  "
            f"exact {out['film_min_exact']:.6f};  d_* = {out['d_star']:.6f}"
        )
        print(f"figure: {png}")
    return out


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir", nargs="?", default="femehl-out/cylinder")
    ap.add_argument("--t-end", type=float, default=15.0)
    ap.add_argument("--dt", type=float, default=0.05)
    ap.add_argument("--n", type=int, default=400, help="number of elements")
    ap.add_argument("--k", type=float, default=1.0)
    ap.add_argument("--beta", type=float, default=10.0)
    ap.add_argument("--h-end", type=float, default=-0.5)
    ap.add_argument("--L", type=float, default=2.0)
    a = ap.parse_args()
    main(t_end=a.t_end, dt=a.dt, n_elements=a.n, k=a.k, beta=a.beta, h_end=a.h_end, L=a.L, outdir=a.outdir)
