"""Command line: ``femehl run [SCENE.toml]`` (and ``femehl bench ...``).

``femehl run`` without a file runs the built-in default: the paper's sphere
(beta = 200, h0 = 0.1) to t = 5 with the FE solver on the "medium" mesh,
which takes well under a minute here.  Options override the file's [run].
Exit status: 0 done, 2 bad input, 3 the run stopped (film rupture,
singular system) after writing what it had.

A scene file with ``[indenter] kind = "cylinder"`` is line contact (a
:class:`femehl.line.LineScene`): it is run by :func:`femehl.line.solve_line`
and writes summary.csv (same columns, y = 0) and line.png.
"""

from __future__ import annotations

import argparse
import math
import sys

from .errors import FemehlError, SolverError

DEFAULT_OUT = "femehl-out"


def _parser():
    p = argparse.ArgumentParser(prog="femehl", description="Transient soft-EHL solver (Wu, Hui et al. 2022).")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run a scene (default: the paper's sphere) into an output folder")
    r.add_argument("scene", nargs="?", help="TOML scene file (default: built-in paper case)")
    r.add_argument("--method", choices=["fe", "fd", "line"],
                   help="solver (default fe; line contact scenes: line)")
    r.add_argument("--mesh", help="FE mesh: coarse|medium|fine|xfine or a mesh file (default medium)")
    r.add_argument("--dr", type=float, help="FD radial step (default 0.0125)")
    r.add_argument("--dtheta-divisions", type=int, help="FD: dtheta = pi/N (default 36)")
    r.add_argument("--n-elements", type=int, help="line contact: number of elements (default 400)")
    r.add_argument("--dt", type=float, help="time step (default 0.01)")
    r.add_argument("--scheme", choices=["euler", "bdf2"],
                   help="FE time scheme: euler (the paper's, default) or bdf2 (second order)")
    r.add_argument("--t-end", type=float, help="end time (default 5)")
    r.add_argument("--store-every", type=int, help="write fields every N steps (default 10)")
    r.add_argument("--out", help=f"output folder (default {DEFAULT_OUT}/<scene name>)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.add_argument("--resume", action="store_true",
                   help="continue the run in the output folder from its checkpoint.npz")
    b = sub.add_parser("bench", help="benchmarks (see benchmarks/)")
    b.add_argument("what", choices=["accuracy", "stress"], help="which study")
    b.add_argument("rest", nargs=argparse.REMAINDER)
    return p


def _run(args):
    from . import presets
    from .run import run_to_folder
    from .scenefile import load_scene_file, run_options

    dim = None
    if args.scene:
        scene, run = load_scene_file(args.scene)
        dim = run.pop("_dimensional", None)      # the scene was stated in SI units
        name = args.scene.rsplit("/", 1)[-1].rsplit(".", 1)[0]
    else:
        scene, run = presets.paper_sphere(), {}
        name = "paper_sphere"
    from .line import LineScene
    if isinstance(scene, LineScene):
        return _run_line(scene, run, args, name)
    if args.method == "line":
        raise FemehlError("--method line is for line contact scenes ([indenter] kind = \"cylinder\"); "
                          "use fe or fd for this scene.")
    if args.n_elements is not None:
        raise FemehlError("--n-elements is a line contact option ([indenter] kind = \"cylinder\"); "
                          "with a 2-D scene give --mesh (fe) or --dr (fd) instead.")
    run = run_options(run)
    for key in ("method", "scheme", "mesh", "dr", "dt", "t_end", "store_every"):
        v = getattr(args, key)
        if v is not None:
            run[key] = v
    if args.dtheta_divisions is not None:
        run["dtheta"] = math.pi / args.dtheta_divisions
    method = run.pop("method", "fe")
    if method == "fd":
        # the coarsest FD grid found to survive the paper case's sliding start-up
        # (coarser ones rupture at the exit: see the FD module docstring)
        run.setdefault("dr", 0.0125)
        run.setdefault("dtheta", math.pi / 36)
        for k in ("mesh", "linear_solver", "scheme"):
            if k in run and not (k == "scheme" and run[k] == "euler"):
                if k != "mesh":
                    raise FemehlError(f"{k} is an FE option; the FD reference uses the paper's "
                                      "scheme (drop it or use --method fe).")
            run.pop(k, None)
    else:
        run.setdefault("mesh", "medium")
        for k in ("dr", "dtheta"):
            if k in run:
                raise FemehlError(f"{k} is an FD option; with method 'fe' give --mesh instead.")
    out = args.out or f"{DEFAULT_OUT}/{name}"
    res = run_to_folder(scene, out, method=method, t_end=run.pop("t_end", 5.0), dt=run.pop("dt", 0.01),
                        store_every=run.pop("store_every", 10), progress=not args.quiet,
                        resume=args.resume, **run)
    print(f"femehl: done in {res.info['wall_s']:.1f} s; wrote {out}/summary.csv, fields.pvd, centreline.png, fields.png")
    if dim is not None:
        print(f"femehl: wrote {_write_si_summary(dim, res, out)} (SI units)")
    for t in sorted({1.0, float(res.t[-1])}):
        if t <= res.t[-1] + 1e-9:
            print(f"  t = {t:g}: load {res.value_at('load', t):.5g}, central film "
                  f"{res.value_at('film_center', t):.5g}, minimum film {res.value_at('film_min', t):.5g}")
    return 0


def _run_line(scene, run, args, name):
    """Line contact: :func:`femehl.line.solve_line`, summary.csv and line.png in the output folder."""
    import pathlib
    import time

    import numpy as np

    from .line import solve_line
    from .output.table import SummaryWriter

    bad = [opt for opt, key in (("--mesh", "mesh"), ("--dr", "dr"),
                                ("--dtheta-divisions", "dtheta_divisions"), ("--resume", "resume"))
           if getattr(args, key) not in (None, False)]
    if bad:
        raise FemehlError(f"{', '.join(bad)} do(es) not apply to line contact (1-D mesh of "
                          "[-L, L]); give --n-elements (and [run] grading) instead.")
    if args.method not in (None, "line"):
        raise FemehlError(f"--method {args.method} does not apply to line contact; "
                          "its solver is 'line' (leave --method out).")
    run = dict(run)
    for key in ("scheme", "dt", "t_end", "store_every", "n_elements"):
        v = getattr(args, key)
        if v is not None:
            run[key] = v
    t_end, dt = run.pop("t_end", 5.0), run.pop("dt", 0.01)
    store_every = run.pop("store_every", 10)
    out = pathlib.Path(args.out or f"{DEFAULT_OUT}/{name}")
    out.mkdir(parents=True, exist_ok=True)
    ts = np.linspace(0.0, t_end, 2001) if t_end > 0 else np.zeros(1)
    sq = scene.imposed_load or any(scene.motion.hc(t) != scene.motion.hc(0.0) for t in ts)
    sl = any(scene.motion.V(t) != 0.0 for t in ts)
    n_steps = max(1, math.ceil(t_end / dt - 1e-9)) if dt > 0 and t_end > 0 else 0
    every = max(1, n_steps // 20) if n_steps else 1
    t0 = time.perf_counter()

    def progress(s):
        if not args.quiet and s.step and (s.step % every == 0):
            print(f"  step {s.step}: t = {s.t:.4g}, load {s.load:.5g}, minimum film {s.film_min:.5g}",
                  flush=True)

    with SummaryWriter(out / "summary.csv") as writer:
        def callback(s):
            writer.write(s)
            progress(s)
        print(f"femehl: method line, terms: squeeze={sq}, sliding={sl}, elasticity=winkler, "
              f"imposed_load={scene.imposed_load}; k={scene.k:g}, beta={scene.beta:g}, L={scene.L:g}")
        res = solve_line(scene, t_end, dt, store_every=store_every, callback=callback, **run)
    png = _line_png(res, out / "line.png")
    print(f"femehl: done in {time.perf_counter() - t0:.1f} s ({res.info['elements']} elements, "
          f"{res.info['steps']} steps); wrote {out}/summary.csv, {png.name}")
    for t in sorted({1.0, float(res.t[-1])}):
        if t <= res.t[-1] + 1e-9:
            val = {c: float(np.interp(t, res.t, getattr(res, c)))
                   for c in ("load", "film_center", "film_min")}
            print(f"  t = {t:g}: load {val['load']:.5g}, central film {val['film_center']:.5g}, "
                  f"minimum film {val['film_min']:.5g}")
    return 0


def _line_png(res, path):
    """p(x) and d(x) at a few stored times of a line-contact run."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    states = list(res.states[:: max(1, len(res.states) // 6)])
    if states[-1] is not res.final:
        states.append(res.final)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 7), sharex=True)
    for i, s in enumerate(states):
        last = s is res.final
        kw = dict(lw=2 if last else 0.8, alpha=1.0 if last else 0.6, label=f"t = {s.t:.3g}")
        ax1.plot(res.disc.x, s.p, **kw)
        ax2.plot(res.disc.xc, s.d, **kw)
    ax1.set_ylabel("p")
    ax2.set_ylabel("d")
    ax2.set_xlabel("x  (cylinder slides toward +x)")
    ax1.legend(fontsize=7, ncol=2)
    sc = res.scene
    fig.suptitle(f"cylinder on Winkler foundation: k = {sc.k:g}, beta = {sc.beta:g}")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _write_si_summary(dim, result, out):
    """``out/summary_si.csv``: the per-step table in SI units (scene stated with [si])."""
    import csv
    import pathlib

    table = dim.result_table(result)
    path = pathlib.Path(out) / "summary_si.csv"
    cols = list(table)
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([f"{c}_{dim.RESULT_COLUMNS[c][2]}" for c in cols])
        for i in range(len(table["t"])):
            w.writerow([f"{table[c][i]:.10g}" for c in cols])
    return path


def _bench(args):
    import runpy
    import pathlib

    root = pathlib.Path(__file__).resolve().parents[1] / "benchmarks"
    script = root / f"{args.what}.py"
    if not script.exists():
        raise FemehlError(f"benchmark script {script} not found: benchmarks ship with the source "
                          "checkout (git clone), not with an installed wheel.")
    sys.argv = [str(script)] + list(args.rest)
    runpy.run_path(str(script), run_name="__main__")
    return 0


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    try:
        return {"run": _run, "bench": _bench}[args.command](args)
    except SolverError as exc:
        print(f"femehl: error: {exc}", file=sys.stderr)
        return 3
    except FemehlError as exc:
        print(f"femehl: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
