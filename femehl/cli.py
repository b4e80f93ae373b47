"""Command line: ``femehl run [SCENE.toml]`` (and ``femehl bench ...``).

``femehl run`` without a file runs the built-in default: the paper's sphere
(beta = 200, h0 = 0.1) to t = 5 with the FE solver, automatically to 1 %
(``--tol 0.01``: femehl chooses the mesh and the time steps and reports its error
estimate; see :mod:`femehl.accuracy.auto`).  ``--mesh``, ``--n-elements``, ``--dt`` (or
``--method fd``) choose the discretization by hand instead (expert mode).  Options override the file's [run].
Exit status: 0 done, 2 bad input (nothing written), 3 the run stopped (film
rupture, singular system) after writing what it had, 130 interrupted (Ctrl-C:
what was written stays readable and the command to resume is printed).

An output folder that already holds a run is refused unless ``--overwrite``
(replaces femehl's files of that run; other files stay) or ``--resume``.
Options that do not apply to the chosen method are refused.  The run's
reports go to stderr (logger "femehl"), the figures reached to stdout.

A scene file with ``[indenter] kind = "cylinder"`` is line contact (a
:class:`femehl.problem.line.LineScene`, method "line"): the same run folder (summary.csv with
y = 0, the field series on the 1-D mesh, checkpoints) and line.png.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import math
import shlex
import sys

from femehl.errors import FemehlError, SolverError

DEFAULT_OUT = "femehl-out"
EXIT_DONE, EXIT_BAD_INPUT, EXIT_STOPPED, EXIT_INTERRUPTED = 0, 2, 3, 130

logger = logging.getLogger("femehl")


def _parser():
    p = argparse.ArgumentParser(prog="femehl", description="Transient soft-EHL solver (Wu, Hui et al. 2022).")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run a scene (default: the paper's sphere) into an output folder")
    r.add_argument("scene", nargs="?", help="TOML scene file (default: built-in paper case)")
    r.add_argument(
        "--method", choices=["fe", "fd", "line"], help="solver (default fe; line contact scenes: line)"
    )
    r.add_argument(
        "--mesh",
        help="FE mesh: coarse|medium|fine|xfine|fitted or a mesh file (default: chosen from --tol)",
    )
    r.add_argument(
        "--operator",
        choices=["auto", "dense", "fast"],
        help="FE elastic operator: dense, fast (hierarchical, for large meshes) or auto (default: by size)",
    )
    r.add_argument("--dr", type=float, help="FD radial step (default 0.0125)")
    r.add_argument("--dtheta-divisions", type=int, help="FD: dtheta = pi/N (default 36)")
    r.add_argument(
        "--n-elements", type=int, help="line contact: number of elements (default: chosen from --tol)"
    )
    r.add_argument("--dt", type=float, help="fixed time step (expert mode; default 0.01 with --mesh)")
    r.add_argument(
        "--tol",
        type=float,
        help="relative accuracy of load and films (default 0.01: femehl chooses mesh and steps)",
    )
    r.add_argument(
        "--step-tol",
        type=float,
        help="with --mesh / --n-elements (expert mode): adaptive time steps to this local error "
        "per unit time (--dt is then the first step)",
    )
    r.add_argument(
        "--max-wall",
        type=float,
        help="automatic mode: a time budget in seconds (a finer run predicted to overrun it is not "
        "started; the answer says 'tol NOT reached' with its estimate)",
    )
    r.add_argument(
        "--scheme",
        choices=["euler", "bdf2"],
        help="FE time scheme: euler (the paper's, default) or bdf2 (second order)",
    )
    r.add_argument("--t-end", type=float, help="end time (default 5)")
    r.add_argument("--store-every", type=int, help="write fields every N steps (default 10)")
    r.add_argument("--out", help=f"output folder (default {DEFAULT_OUT}/<scene name>)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.add_argument(
        "--resume", action="store_true", help="continue the run in the output folder from its checkpoint.npz"
    )
    r.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the run already in the output folder (its femehl files only)",
    )
    r.add_argument(
        "--animate",
        action="store_true",
        help="also write animation.gif (maps and centreline, one frame per stored step; "
        "0.16 s a frame on the coarse mesh)",
    )
    pl = sub.add_parser("plot", help="draw a run folder's pictures again (any stored time)")
    pl.add_argument(
        "what",
        choices=["history", "maps", "centreline", "animation"],
        help="history: load, hc, V, films against t; maps: film and pressure maps; "
        "centreline: p and d along y = 0, the cavitated interval(s) shaded; "
        "animation: GIF of the maps",
    )
    pl.add_argument("folder", help="the run's output folder (femehl run --out)")
    pl.add_argument(
        "--t",
        type=float,
        help="maps, centreline: draw the stored time nearest T, and say which (default: the last); "
        "a T outside the stored times is refused",
    )
    pl.add_argument(
        "--out",
        help="where to write: an existing folder, or a name ending in / (a folder, created), gets the "
        "usual file name inside it; anything else is the file (no suffix: .png, animation .gif) "
        "(default: in the run folder: history.png, maps[_tT].png, centreline_tT.png, animation.gif)",
    )
    pl.add_argument("--fps", type=int, default=8, help="animation: frames per second (default 8)")
    sw = sub.add_parser(
        "sweep",
        help="a parameter study on a Dask cluster: femehl sweep SWEEP.toml, femehl sweep plot OUT",
    )
    sw.add_argument(
        "args", nargs="+", metavar="SWEEP.toml | plot OUT", help="a sweep file, or plot and its output folder"
    )
    sw.add_argument("--scheduler", help="address of an existing Dask scheduler (default: a local cluster)")
    sw.add_argument(
        "--workers", type=int, help="local cluster: worker processes, a positive integer (default: the cores)"
    )
    sw.add_argument(
        "--memory-limit", help="local cluster: memory per worker, e.g. 4GiB (default: a share of RAM)"
    )
    sw.add_argument(
        "--overwrite", action="store_true", help="replace another sweep's table in the output folder"
    )
    sw.add_argument("--retry-failed", action="store_true", help="run the cases recorded as failed again")
    sw.add_argument("--quiet", action="store_true", help="no progress bar")
    sw.add_argument("--x", help="plot: the parameter on the x axis (default: the first swept number)")
    st = sub.add_parser(
        "stribeck",
        help="the Stribeck curve: a scene's steady state at many speeds, on a Dask cluster",
    )
    st.add_argument("scene", help="TOML scene file reaching a steady sliding state by its [run] t_end")
    st.add_argument(
        "--speeds",
        nargs=2,
        type=float,
        required=True,
        metavar=("LO", "HI"),
        help="the lowest and highest speed: V_ss in m/s for an SI scene, else factors on the scene's speed",
    )
    st.add_argument("--num", type=int, default=26, help="number of speeds, evenly spaced in log (default 26)")
    st.add_argument("--out", help="output folder (default <scene name>-stribeck)")
    st.add_argument("--scheduler", help="address of an existing Dask scheduler (default: a local cluster)")
    st.add_argument("--workers", type=int, help="local cluster: worker processes (default: the cores)")
    st.add_argument("--overwrite", action="store_true", help="replace another study's table in the folder")
    st.add_argument("--retry-failed", action="store_true", help="run the speeds recorded as failed again")
    st.add_argument("--quiet", action="store_true", help="no progress bar")
    b = sub.add_parser("bench", help="benchmarks (see benchmarks/)")
    b.add_argument(
        "what",
        choices=["accuracy", "stress", "stress_auto", "fitted_mesh", "auto", "fast_operator"],
        help="which study",
    )
    b.add_argument("rest", nargs=argparse.REMAINDER)
    return p


FD_KEYS = ("dr", "dtheta")
RUN_KEYS = ("dt", "t_end", "store_every", "checkpoint_every", "tol", "step_tol")


def _method_options(run: dict, method: str, from_cli: bool) -> dict:
    """The [run] options that belong to ``method``; the other method's are refused.

    When ``--method`` overrode the file's method, the file's options of the other
    method are dropped (with a note) instead.
    """
    out = dict(run)
    if method == "fd":
        other = [k for k in out if k not in FD_KEYS + RUN_KEYS and not (k == "scheme" and out[k] == "euler")]
    else:
        other = [k for k in out if k in FD_KEYS]
    if other and not from_cli:
        fix = "give --mesh instead" if method == "fe" else "drop it or use --method fe"
        raise FemehlError(f"[run] {', '.join(other)} do(es) not apply to method {method!r}: {fix}.")
    if other:
        logger.info("femehl: --method %s: ignoring the scene file's [run] %s", method, ", ".join(other))
    for k in other + (["scheme"] if method == "fd" else []):
        out.pop(k, None)
    return out


def _run(args, argv=()):
    from femehl.api import run_to_folder
    from femehl.output._validation import (
        METHOD_FLAGS,
        check_divisions,
        check_method_flags,
        check_resume_overwrite,
        check_step,
    )
    from femehl.problem import presets
    from femehl.problem.scenefile import load_scene_file, run_options

    dim = None
    if args.scene:
        scene, run = load_scene_file(args.scene)
        dim = run.pop("_dimensional", None)  # the scene was stated in SI units
        name = args.scene.rsplit("/", 1)[-1].rsplit(".", 1)[0]
    else:
        scene, run = presets.paper_sphere(), {}
        name = "paper_sphere"
    is_line = scene.default_method == "line"
    resume, overwrite = check_resume_overwrite(args.resume, args.overwrite)
    run = run_options(run)
    method = args.method or run.pop("method", "line" if is_line else "fe")
    run.pop("method", None)
    if is_line and method != "line":
        raise FemehlError(
            f"--method {method} does not apply to line contact; its method is 'line' (leave --method out)."
        )
    if method == "line" and not is_line:
        raise FemehlError(
            '--method line is for line contact scenes ([indenter] kind = "cylinder"); '
            "use fe or fd for this scene."
        )
    check_method_flags(method, {k: getattr(args, k) for k in METHOD_FLAGS})
    run = _method_options(run, method, from_cli=args.method is not None)
    for key in (
        "scheme",
        "mesh",
        "operator",
        "n_elements",
        "dt",
        "tol",
        "step_tol",
        "max_wall",
        "t_end",
        "store_every",
    ):
        v = getattr(args, key)
        if v is not None and not (key == "scheme" and method == "fd"):  # fd: euler, its own scheme
            run[key] = v
    if args.dr is not None:
        run["dr"] = check_step("--dr", args.dr)
    if args.dtheta_divisions is not None:
        run["dtheta"] = math.pi / check_divisions(args.dtheta_divisions)
    if method == "fd":
        # the coarsest FD grid found to survive the paper case's sliding start-up
        # (coarser ones rupture at the exit: see docs/design.md section 5)
        run.setdefault("dr", 0.0125)
        run.setdefault("dtheta", math.pi / 36)
    out = args.out or f"{DEFAULT_OUT}/{name}"
    if args.animate and run.get("store_every", 10) == 0:
        raise FemehlError("--animate draws the stored fields: drop --store-every 0 (or store_every = 0).")
    try:
        res = run_to_folder(
            scene,
            out,
            method=method,
            t_end=run.pop("t_end", 5.0),
            dt=run.pop("dt", None),
            store_every=run.pop("store_every", 10),
            progress=not args.quiet,
            resume=resume,
            overwrite=overwrite,
            **run,
        )
    except KeyboardInterrupt:
        return _interrupted(out, argv)
    if res.info.get("nothing_to_do"):
        print(
            f"femehl: {out} already holds the run to t = {res.t[-1]:g}: nothing to do (give a larger --t-end)"
        )
        return EXIT_DONE
    from femehl.output.plots import FIGURES, plot_animation

    names = [name for name, _ in FIGURES[res.disc.dimension]]
    if args.animate and res.disc.dimension == 2:
        plot_animation(out)
        names.append("animation.gif")
    files = ", ".join(["fields.pvd"] + names)
    print(
        f"femehl: done in {res.info['wall_s']:.1f} s ({res.info['unknowns']} unknowns, "
        f"{res.nsteps} steps); wrote {out}/summary.csv, {files}"
    )
    if dim is not None:
        print(f"femehl: wrote {_write_si_summary(dim, _SummaryFile(out), out)} (SI units)")
    _print_choice(res)
    for t in sorted({1.0, float(res.t[-1])}):
        if res.t[0] - 1e-9 <= t <= res.t[-1] + 1e-9:  # a resumed run starts at its checkpoint
            cav = "".join(f", {c} {res.value_at(c, t):.5g}" for c in res.cavitation_columns)
            if "friction" in res.extra_columns:
                cav += f", friction {res.value_at('friction', t):.5g}"
            print(
                f"  t = {t:g}: load {_with_error(res, 'load', t)}, central film "
                f"{_with_error(res, 'film_center', t)}, minimum film {_with_error(res, 'film_min', t)}" + cav
            )
    return 0


def _plot(args) -> int:
    """``femehl plot history|maps|centreline|animation FOLDER``: the picture, from the folder's files."""
    import time

    from femehl.output.plots import FOLDER_PLOTS, TIMED_PLOTS

    t0 = time.perf_counter()
    if args.what not in TIMED_PLOTS and args.t is not None:
        raise FemehlError(
            "--t applies to femehl plot maps and centreline only (history and animation cover every time)."
        )
    own = {"animation": {"fps": args.fps}}.get(args.what, {"t": args.t} if args.what in TIMED_PLOTS else {})
    try:
        path = FOLDER_PLOTS[args.what](args.folder, out=args.out, **own)
    except KeyboardInterrupt:  # pictures are written atomically: nothing half-written
        print(
            "femehl: interrupted; the picture was not written (a file of that name, if any, is unchanged).",
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    print(f"femehl: wrote {path} in {time.perf_counter() - t0:.1f} s")
    return EXIT_DONE


def _sweep(args) -> int:
    """``femehl sweep SWEEP.toml`` (run) or ``femehl sweep plot OUT`` (master curves).

    Exit status: 0 every case done, 2 a bad sweep (nothing started), 3 some cases failed
    (the others are written; their keys and errors are printed), 130 interrupted (the
    finished cases stay; the command that goes on is printed).
    """
    from femehl.studies import sweeps as sw

    if args.args[0] == "plot":
        if len(args.args) != 2:
            raise FemehlError("femehl sweep plot takes one output folder: femehl sweep plot OUT.")
        from femehl.studies.sweep_plot import plot_master_curves

        png, fits = plot_master_curves(args.args[1], x=args.x)
        for line in fits:
            print(line)
        print(f"femehl: wrote {png}")
        return EXIT_DONE
    if len(args.args) != 1:
        raise FemehlError("femehl sweep takes one sweep file (or: femehl sweep plot OUT).")
    plan = None
    try:
        plan = sw.load_sweep_file(args.args[0])
        cluster = plan.spec.get("cluster", {})

        def given(flag, key):  # the command line's value, else the file's (0 is a value, refused)
            return flag if flag is not None else cluster.get(key)

        table = sw.sweep(
            plan=plan,
            scheduler=given(args.scheduler, "scheduler"),
            workers=given(args.workers, "workers"),
            memory_limit=given(args.memory_limit, "memory_limit"),
            overwrite=args.overwrite,
            retry_failed=args.retry_failed,
            progress=not args.quiet,
        )
    except KeyboardInterrupt:
        return _sweep_interrupted(args, plan)
    info = table.attrs["sweep"]
    cases = table.drop_duplicates("case")
    status = cases["status"].value_counts().to_dict()
    eff = info["cases_s"] / info["wall_s"] if info["wall_s"] > 0 and info["ran"] else float("nan")
    print(
        f"femehl: sweep of {len(plan.cases)} cases ({info['ran']} run, {info['skipped']} finished before): "
        + ", ".join(f"{v} {k}" for k, v in sorted(status.items()))
        + f"; {info['wall_s']:.1f} s wall for {info['cases_s']:.1f} s of cases "
        f"({eff:.2f} cases running on average); wrote {plan.out}/results.parquet"
    )
    bad = cases[cases["status"] != "done"]
    if bad.empty:
        return EXIT_DONE
    params = {c.key: c.params for c in plan.cases}
    print(f"femehl: {len(bad)} of {len(cases)} cases did not finish:", file=sys.stderr)
    for _, row in bad.head(20).iterrows():
        shown = ", ".join(f"{k} = {v!r}" for k, v in params.get(row["case"], {}).items())
        error = str(row["error"] or row["status"]).splitlines()[0]
        print(f"  {row['case']} ({shown}): {row['status']}: {error}", file=sys.stderr)
    if len(bad) > 20:
        print(f"  ... and {len(bad) - 20} more (the status column of results.parquet)", file=sys.stderr)
    print(
        f"  their logs: {plan.out}/cases/<key>/run.log; the finished cases are written. To run the "
        f"failed ones again:\n  {_sweep_command(args, '--retry-failed')}",
        file=sys.stderr,
    )
    return EXIT_STOPPED


def _stribeck(args, argv) -> int:
    """``femehl stribeck SCENE.toml --speeds LO HI``: the curve's table and picture.

    Exit status: 0 every speed done, 2 bad input (nothing started), 3 some speeds failed
    (the curve is written with them marked), 130 interrupted (the finished speeds stay;
    running the same command goes on).
    """
    from femehl.studies.stribeck import stribeck

    try:
        curve = stribeck(
            args.scene,
            args.speeds,
            args.num,
            out=args.out,
            scheduler=args.scheduler,
            workers=args.workers,
            overwrite=args.overwrite,
            retry_failed=args.retry_failed,
            progress=not args.quiet,
        )
    except KeyboardInterrupt:
        print(
            "femehl: interrupted; the finished speeds stay in the output folder. Running the same "
            f"command goes on where it stopped:\n  {shlex.join(['femehl', *argv])}",
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    for _, row in curve.iterrows():
        mu = row["friction_coefficient"]
        print(
            f"  speed {row['speed']:<10.4g} {row['status']:<7} mu {mu:<10.4g} film/sigma "
            f"{row['film_over_sigma']:<10.4g} asperities {row['asperity_share']:<7.3f} {row['regime']}"
            + ("" if row["steady"] or row["status"] != "done" else " (not steady at t_end)")
        )
    bad = curve[curve["status"] != "done"]
    print(f"femehl: wrote {curve.attrs['csv']} and {curve.attrs['png']}")
    if bad.empty:
        return EXIT_DONE
    print(
        f"femehl: {len(bad)} of {len(curve)} speeds did not finish (their logs: "
        f"{curve.attrs['csv'].parent}/cases/<key>/run.log); to run them again add --retry-failed.",
        file=sys.stderr,
    )
    return EXIT_STOPPED


def _sweep_command(args, *extra) -> str:
    """The ``femehl sweep`` command line of ``args``, plus ``extra``."""
    words = ["femehl", "sweep", args.args[0]]
    words += ["--overwrite"] if args.overwrite else []  # harmless again: finished cases are reused
    for flag, value in (
        ("--scheduler", args.scheduler),
        ("--workers", args.workers),
        ("--memory-limit", args.memory_limit),
    ):
        if value is not None:
            words += [flag, str(value)]
    words += [w for w, on in (("--retry-failed", args.retry_failed), ("--quiet", args.quiet)) if on]
    words += [w for w in extra if w not in words]
    return shlex.join(words)


def _sweep_interrupted(args, plan) -> int:
    """Ctrl-C during a sweep: how many cases finished (they stay) and the command that goes on."""
    from femehl.studies import sweeps as sw

    if plan is None:
        print("femehl: interrupted while reading the sweep; nothing was started.", file=sys.stderr)
        return EXIT_INTERRUPTED
    done = 0
    for c in plan.cases:
        rec = sw.read_case(plan.out / "cases" / c.key)
        done += rec is not None and rec.get("key") == c.key and rec.get("status") in sw.FINISHED
    print(
        f"femehl: interrupted; {done} of {len(plan.cases)} cases finished and stay in {plan.out}/cases "
        f"(the cases that were running start again). Rerunning goes on where it stopped (finished cases "
        f"are skipped):\n  {_sweep_command(args)}",
        file=sys.stderr,
    )
    return EXIT_INTERRUPTED


def _print_choice(res) -> None:
    """What an automatic run chose, and its estimated error."""
    a = res.info.get("auto")
    if not a or "levels" not in a:
        return
    spent = a.get("estimate_wall") or [None] * len(a["wall"])
    runs = ", ".join(
        f"{n} cells / {k} steps / {w:.1f} s" + ("" if e is None else f" (+{e:.1f} s its estimate)")
        for n, k, w, e in zip(a["elements"], a["steps"], a["wall"], spent, strict=True)
    )
    status = "reached" if a["reached"] else f"NOT reached ({a.get('stopped') or 'budget'})"
    total = a.get("total", float("nan"))
    err = (
        "no estimate: its companion runs stopped"
        if not math.isfinite(total)
        else f"estimated error up to {100 * total:.2g} %"
    )
    accepted = 100 * a["accept"] * a["tol"]
    print(
        f"femehl: automatic to tol = {a['tol']:g} ({status}): runs {runs}; the answer is the last "
        f"({err}, accepted at <= {accepted:.2g} %)"
    )


def _with_error(res, name: str, t: float) -> str:
    """``0.04112 (+-0.35 %)``: the value and its estimated relative error, where estimated."""
    v = f"{res.value_at(name, t):.5g}"
    if res.estimate is None:
        return v
    u = res.uncertainty(name, t)
    if u["total"] is not None:
        return f"{v} (+-{100 * u['total']:.2g} %)"
    part = "space" if u["space"] is not None else "time"
    return f"{v} ({part} part +-{100 * u[part]:.2g} %)"


class _SummaryFile:
    """The whole summary.csv of a run folder, as ``summary()`` columns (a resumed run included)."""

    def __init__(self, folder):
        import pathlib

        self.path = pathlib.Path(folder) / "summary.csv"

    def summary(self) -> dict:
        from femehl.output.table import read_summary

        return read_summary(self.path)


def _write_si_summary(dim, result, out):
    """``out/summary_si.csv``: the per-step table in SI units (scene stated with [si])."""
    import csv
    import os
    import pathlib

    table = dim.result_table(result)
    path = pathlib.Path(out) / "summary_si.csv"
    tmp = path.with_name(path.name + ".tmp")
    cols = list(table)
    with open(tmp, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([f"{c}_{dim.unit(c)}" for c in cols])
        for i in range(len(table["t"])):
            w.writerow([f"{table[c][i]:.10g}" for c in cols])
    os.replace(tmp, path)
    return path


def _bench(args):
    import pathlib
    import runpy

    root = pathlib.Path(__file__).resolve().parents[1] / "benchmarks"
    script = root / f"{args.what}.py"
    if not script.exists():
        raise FemehlError(
            f"benchmark script {script} not found: benchmarks ship with the source "
            "checkout (git clone), not with an installed wheel."
        )
    sys.argv = [str(script)] + list(args.rest)
    sys.path.insert(0, str(root))  # as `python benchmarks/x.py` would: its helpers import
    try:
        runpy.run_path(str(script), run_name="__main__")
    finally:
        sys.path.remove(str(root))
    return 0


@contextlib.contextmanager
def _log_to_stderr():
    """femehl's log lines (INFO and up) as plain lines on stderr, for the time of one command."""
    logger = logging.getLogger("femehl")
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(message)s"))
    saved = logger.level, logger.propagate
    logger.setLevel(logging.INFO)
    logger.propagate = False
    logger.addHandler(handler)
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.setLevel(saved[0])
        logger.propagate = saved[1]


def resume_command(argv, out) -> str:
    """The ``femehl ...`` command line that resumes the run of ``argv`` in ``out``."""
    words, skip = [], False
    for a in argv:
        if skip:
            skip = False
            continue
        if a == "--out":
            skip = True
            continue
        if a in ("--resume", "--overwrite") or a.startswith("--out="):
            continue
        words.append(a)
    return shlex.join(["femehl", *words, "--resume", "--out", str(out)])


def _interrupted(out, argv) -> int:
    """Ctrl-C during a run: say what is in the output folder and how to go on; exit status 130."""
    import pathlib

    if out is not None and (pathlib.Path(out) / "checkpoint.npz").is_file():
        print(
            f"femehl: interrupted; what was written is in {out}. To go on:\n  {resume_command(argv, out)}",
            file=sys.stderr,
        )
    else:
        print("femehl: interrupted before the run wrote a checkpoint; nothing to resume.", file=sys.stderr)
    return EXIT_INTERRUPTED


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    args = _parser().parse_args(argv)
    with _log_to_stderr():
        try:
            if args.command == "run":
                return _run(args, argv)
            if args.command == "plot":
                return _plot(args)
            if args.command == "sweep":
                return _sweep(args)
            if args.command == "stribeck":
                return _stribeck(args, argv)
            return _bench(args)
        except SolverError as exc:
            print(f"femehl: error: {exc}", file=sys.stderr)
            return EXIT_STOPPED
        except FemehlError as exc:
            print(f"femehl: error: {exc}", file=sys.stderr)
            return EXIT_BAD_INPUT
        except KeyboardInterrupt:
            return _interrupted(None, argv)


if __name__ == "__main__":
    sys.exit(main())
