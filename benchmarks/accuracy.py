"""What accuracy costs: error against wall time for the FE and FD solvers.

    femehl bench accuracy [--quick] [--out DIR] [--resume] [--analyze-only]
                          [--part study|timestep|all] [--fd-extra]

Runs the paper case (beta = 200, h0 = 0.1, t in [0, 5]) with

* FE over the mesh ladder (coarse .. xfine) x dt {0.02, 0.01, 0.005} x scheme
  {euler, bdf2}, trimmed of clearly dominated settings (see ``fe_cases``);
* FD (the paper-faithful polar reference) at the grids that survive the sliding
  start-up, plus the coarse grids that rupture (recorded as data points);

each in a fresh subprocess (BLAS pinned to one thread), measuring set-up and
stepping wall time, time per step, the time of one dense matvec with the
influence operator in use (the per-step floor), peak memory (ru_maxrss) and
the error of load, central film and minimum film at t = 1 and t = 5 and of the
centreline pressure (relative L2 over x in [-1.5, 1.5], y = 0) against a
Richardson-extrapolated reference (FE bdf2 on the two finest meshes, in h and
dt).  Writes ``accuracy_results.csv``, ``accuracy_results.md`` and
``accuracy_pareto.png`` to ``--out`` (default: this folder) and prints the
cheapest setting reaching 1 % and 0.1 % for every quantity.

``--part timestep`` is the time-step study (``timestep.csv`` / ``timestep.md``):
error against dt for euler and bdf2 on the medium mesh (observed orders) and the
largest stable dt for beta = 200 and 2000.

Every finished run is appended to ``runs.jsonl`` in ``--out``; ``--resume``
skips runs already there and ``--analyze-only`` only rewrites the tables.
``--quick`` is a smoke test (coarse and medium meshes, ~2 min): its reference
is crude and its numbers are not the study's.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import pathlib
import platform
import resource
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
T_END = 5.0
MESHES = ("coarse", "medium", "fine", "xfine")
RATIO = 1.45  # femehl.discretize.mesh.LADDER_RATIO (checked in the worker)
XPROF = (-1.5, 1.5, 301)
QUANTS = (
    "load@1",
    "film_center@1",
    "film_min@1",
    "load@5",
    "film_center@5",
    "film_min@5",
    "profile@1",
    "profile@5",
)
SCALARS = QUANTS[:6]


# ---------------------------------------------------------------------------
# the cases
# ---------------------------------------------------------------------------
def fe_case(mesh, dt, scheme, **kw):
    return dict(solver="fe", mesh=mesh, dt=dt, scheme=scheme, **kw)


def fd_case(dr_div, th_div, dt, **kw):
    """FD grid dr = 2/dr_div, dtheta = pi/th_div (both must divide exactly)."""
    return dict(solver="fd", dr_div=dr_div, th_div=th_div, dt=dt, scheme="euler", **kw)


def fe_cases(quick):
    if quick:
        return [
            fe_case(m, dt, s) for m in ("coarse", "medium") for dt in (0.02, 0.01) for s in ("euler", "bdf2")
        ]
    cases = []
    for m in ("coarse", "medium"):  # cheap: the full grid
        cases += [
            fe_case(m, dt, s, **({"series": True} if m == "medium" else {}))
            for dt in (0.02, 0.01, 0.005)
            for s in ("euler", "bdf2")
        ]
    # fine: euler at dt = 0.02 is dominated (its ~6 % time error exceeds every spatial error
    # at a cost above the medium runs); the rest is kept.
    cases += [
        fe_case("fine", dt, s)
        for dt, s in ((0.01, "euler"), (0.005, "euler"), (0.02, "bdf2"), (0.01, "bdf2"), (0.005, "bdf2"))
    ]
    # xfine: only the two bdf2 runs the reference needs (euler there is dominated: same
    # cost per step as bdf2, first-order time error of ~1-3 %).
    cases += [fe_case("xfine", dt, "bdf2") for dt in (0.01, 0.005)]
    # the paper's direct solve (a new dense LU every step), for the speed comparison:
    # short runs (t <= 0.5) only, the per-step time does not depend on t.
    cases += [fe_case(m, 0.01, "euler", linear_solver="lu", t_end=0.5) for m in MESHES[:3]]
    # one 2-thread variant (BLAS threads), for the note
    cases += [fe_case("medium", 0.01, "bdf2", threads=2), fe_case("fine", 0.01, "bdf2", threads=2)]
    return cases


def fd_cases(quick, extra):
    if quick:
        return [fd_case(40, 24, 0.02)]
    cases = [
        fd_case(40, 24, 0.01),  # dr = 0.05,  pi/24: ruptures at t ~ 1.6
        fd_case(80, 24, 0.01),  # dr = 0.025, pi/24: ruptures at t ~ 2.6
        fd_case(60, 36, 0.01),  # dr = 0.0333, pi/36
        fd_case(80, 36, 0.02),
        fd_case(80, 36, 0.01),
    ]  # dr = 0.025, pi/36 (2765 unknowns)
    if extra:
        cases += [fd_case(80, 48, 0.01)]  # dr = 0.025, pi/48 (3713 unknowns)
    return cases


def ts_cases():
    """Time-step study on the medium mesh (plus the runs shared with the main study)."""
    cases = [
        fe_case("medium", dt, s, series=True)
        for dt in (0.04, 0.02, 0.01, 0.005, 0.0025)
        for s in ("euler", "bdf2")
    ]
    for beta in (200.0, 2000.0):
        for s in ("euler", "bdf2"):
            for dt in (0.05, 0.1, 0.2):
                cases.append(fe_case("medium", dt, s, beta=beta, series=True, stability=True))
        # beta = 2000 needs its own small-dt reference trajectory
        if beta != 200.0:
            cases += [
                fe_case("medium", dt, "bdf2", beta=beta, series=True, stability=True) for dt in (0.01, 0.02)
            ]
            cases += [fe_case("medium", 0.02, "euler", beta=beta, series=True, stability=True)]
    return cases


def key(spec):
    return json.dumps({k: spec[k] for k in sorted(spec)}, sort_keys=True)


def label(r):
    if r["solver"] == "fe":
        res = r["mesh"]
    else:
        res = f"dr=2/{r['dr_div']},dth=pi/{r['th_div']}"
    extra = ""
    if r.get("linear_solver"):
        extra += f" [{r['linear_solver']}]"
    if r.get("threads", 1) != 1:
        extra += f" [{r['threads']} threads]"
    if r.get("beta", 200.0) != 200.0:
        extra += f" [beta={r['beta']:g}]"
    return f"{r['solver'].upper()} {r['scheme']} {res} dt={r['dt']:g}{extra}"


# ---------------------------------------------------------------------------
# the worker: one run in a fresh process
# ---------------------------------------------------------------------------
def worker(spec):
    import numpy as np

    import femehl
    from femehl.api import make_stepper
    from femehl.errors import SolverError
    from femehl.output.result import Result
    from femehl.solver.stepping import march

    t_end = spec.get("t_end", T_END)
    dt = spec["dt"]
    load0 = os.getloadavg()[0]
    scene = femehl.presets.paper_sphere(beta=spec.get("beta", 200.0))
    if spec["solver"] == "fe":
        from femehl.discretize.mesh import LADDER_RATIO

        assert abs(LADDER_RATIO - RATIO) < 1e-12
        opts = dict(mesh=spec["mesh"], scheme=spec["scheme"])
        if spec.get("linear_solver"):
            opts["linear_solver"] = spec["linear_solver"]
    else:
        opts = dict(dr=2.0 / spec["dr_div"], dtheta=math.pi / spec["th_div"])
    t0 = time.perf_counter()
    st = make_stepper(scene, spec["solver"], **opts)
    setup = time.perf_counter() - t0
    out = dict(spec)
    # the dense influence operator in use: FE elements x free nodes, FD nodes x free nodes
    D = st.C
    mv = []  # matvec timings, interleaved with the stepping (same load)
    if isinstance(D, np.ndarray):
        x = np.random.default_rng(0).random(D.shape[1])
        for _ in range(3):
            D @ x
        reps = max(3, int(0.1 / max(1e-5, _time(lambda: D @ x))))
        mv.append(_time(lambda: D @ x, reps))
        out["dense_shape"] = list(D.shape)
        out["dense_contiguous"] = bool(D.flags.c_contiguous)
    res = Result(scene=scene, method=st.method, disc=st.disc)
    every = max(1, int(round(1.0 / dt)))
    series = []
    status, t_fail = "ok", None
    nsteps = 0
    every_mv = max(1, int(round(t_end / dt)) // 10)
    t_mv = 0.0
    t1 = time.perf_counter()
    try:
        for state in march(st, t_end, dt):
            if mv and state.step % every_mv == 0 and state.step > 0:
                t2 = time.perf_counter()
                mv.append(_time(lambda: D @ x, 3))
                t_mv += time.perf_counter() - t2
            keep = state.step % every == 0 or abs(state.t - t_end) < 1e-9
            res.record(state, store_fields=keep)
            nsteps = state.step
            if spec.get("series"):
                series.append((state.t, state.film_min))
    except SolverError as exc:
        status, t_fail = type(exc).__name__, float(getattr(exc, "t", float("nan")))
    stepping = time.perf_counter() - t1 - t_mv
    if mv:
        out["matvec_s"] = float(np.median(mv))
        out["matvec_samples"] = len(mv)
    out.update(
        status=status,
        t_fail=t_fail,
        setup_s=setup,
        stepping_s=stepping,
        nsteps=nsteps,
        wall_s=setup + stepping,
        step_s=stepping / max(nsteps, 1),
        peak_rss_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        loadavg=[load0, os.getloadavg()[0]],
    )
    if "matvec_s" in out:
        out["step_over_matvec"] = out["step_s"] / out["matvec_s"]
    info = getattr(st, "info", {})
    for k in (
        "elements",
        "unknowns",
        "operator_bytes",
        "factorizations",
        "krylov_iterations",
        "factor_s",
        "krylov_s",
    ):
        if k in info:
            out[k] = info[k]
    xs = np.linspace(*XPROF)
    pts = np.column_stack([xs, np.zeros_like(xs)])
    for T in (1.0, 5.0):
        if res.t[-1] >= T - 1e-9:
            out[f"load@{T:g}"] = res.value_at("load", T)
            out[f"film_center@{T:g}"] = res.value_at("film_center", T)
            out[f"film_min@{T:g}"] = res.value_at("film_min", T)
            out[f"profile@{T:g}"] = [float(v) for v in res.pressure_at(pts, T)]
    if spec.get("series"):
        out["series"] = series
    return out


def _time(f, reps=1):
    t = time.perf_counter()
    for _ in range(reps):
        f()
    return (time.perf_counter() - t) / reps


def run_in_subprocess(spec, log):
    env = dict(os.environ)
    n = str(spec.get("threads", 1))
    for v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        env[v] = n
    cmd = [sys.executable, str(pathlib.Path(__file__).resolve()), "--worker", json.dumps(spec)]
    t = time.perf_counter()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        log.write(p.stderr)
        return dict(
            spec, status="crashed", error=p.stderr.strip().splitlines()[-1:], wall_s=time.perf_counter() - t
        )
    return json.loads(p.stdout.strip().splitlines()[-1])


# ---------------------------------------------------------------------------
# reference and errors
# ---------------------------------------------------------------------------
def _val(r, q):
    import numpy as np

    v = r.get(q)
    return None if v is None else np.asarray(v, dtype=float)


def _norm(v):
    import numpy as np

    xs = np.linspace(*XPROF)
    return float(np.sqrt(np.trapezoid(np.asarray(v) ** 2, xs))) if np.ndim(v) else abs(float(v))


def reference(runs, meshes, dts, p_t=2.0):
    """Richardson reference from FE bdf2 runs: dt first (order p_t), then h.

    ``meshes`` are three rungs (coarsest first) and ``dts`` two steps (larger first).
    Returns {quantity: dict(value, order_h, uncertainty, ...)}.
    """
    import numpy as np

    def get(mesh, dt):
        for r in runs:
            if (
                r["solver"],
                r["scheme"],
                r.get("mesh"),
                r["dt"],
                r.get("beta", 200.0),
                r.get("linear_solver"),
                r.get("threads", 1),
            ) == ("fe", "bdf2", mesh, dt, 200.0, None, 1) and r["status"] == "ok":
                return r
        raise KeyError(f"missing FE bdf2 run {mesh} dt={dt}")

    f_t = 1.0 / (2.0**p_t - 1.0) if dts[0] / dts[1] == 2 else None
    ref = {}
    for q in QUANTS:
        # time-extrapolated value on each of the three meshes
        vt = []
        for m in meshes:
            a, b = _val(get(m, dts[0]), q), _val(get(m, dts[1]), q)
            vt.append(b + (b - a) * f_t)
        d1, d2 = vt[1] - vt[0], vt[2] - vt[1]
        n1, n2 = _norm(d1), _norm(d2)
        signs_ok = (np.ndim(d1) > 0) or (d1 * d2 > 0)
        order = math.log(n1 / n2) / math.log(RATIO) if n2 > 0 and n1 > 0 else float("nan")
        flag = ""
        usable = signs_ok and 0.5 <= order <= 4.0
        if not usable:
            flag = (
                f"observed order {order:.2f} not usable (non-monotone or out of [0.5, 4]): "
                "used 2; uncertainty includes the order-1 extrapolation"
            )
            order = 2.0
        fh = 1.0 / (RATIO**order - 1.0)
        best = vt[2] + d2 * fh  # (fine, xfine) pair
        other = vt[1] + d1 * fh  # (medium, fine) pair, same order
        t_corr = vt[2] - _val(get(meshes[2], dts[1]), q)
        scale = _norm(best)
        unc = _norm(best - other) / scale  # different rung pairs
        if not usable:  # not in the asymptotic range: order 1 too
            unc = max(unc, _norm(d2 * (1.0 / (RATIO - 1.0) - fh)) / scale)
        ref[q] = dict(
            value=best,
            order_h=order,
            flag=flag,
            unc_pairs=unc,
            unc_time=_norm(t_corr) / scale,  # size of the dt correction
            h_corr=_norm(d2 * fh) / scale,
        )
    return ref


def errors(r, ref):
    out = {}
    for q in QUANTS:
        v = _val(r, q)
        if v is None:
            continue
        out[q] = _norm(v - ref[q]["value"]) / _norm(ref[q]["value"])
    return out


# ---------------------------------------------------------------------------
# outputs
# ---------------------------------------------------------------------------
def machine():
    import numpy as np
    import scipy

    info = dict(
        python=platform.python_version(),
        numpy=np.__version__,
        scipy=scipy.__version__,
        platform=platform.platform(),
    )
    try:
        cpu = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        info["cpu"] = next(
            (ln.split(":", 1)[1].strip() for ln in cpu.splitlines() if ln.startswith("Model name")), "?"
        )
        info["cpus"] = next(
            (ln.split(":", 1)[1].strip() for ln in cpu.splitlines() if ln.startswith("CPU(s)")), "?"
        )
    except OSError:
        pass
    try:
        mem = subprocess.run(["free", "-g"], capture_output=True, text=True).stdout.splitlines()[1]
        info["mem_gib"] = mem.split()[1]
    except (OSError, IndexError):
        pass
    try:
        from threadpoolctl import threadpool_info

        info["blas"] = ", ".join(f"{d.get('internal_api')} {d.get('version')}" for d in threadpool_info())
    except ImportError:
        try:
            cfg = np.show_config(mode="dicts")
            b = cfg["Build Dependencies"]["blas"]
            info["blas"] = f"{b.get('name')} {b.get('version')} (numpy build; threadpoolctl absent)"
        except Exception:  # noqa: BLE001
            info["blas"] = "?"
        try:
            cfg = scipy.show_config(mode="dicts")
            b = cfg["Build Dependencies"]["blas"]
            info["scipy_blas"] = b.get("openblas configuration") or f"{b.get('name')} {b.get('version')}"
        except Exception:  # noqa: BLE001
            pass
    try:
        info["load_avg"] = " ".join(f"{x:.1f}" for x in os.getloadavg())
    except OSError:
        pass
    return info


CSV_COLS = (
    [
        "solver",
        "scheme",
        "resolution",
        "dt",
        "threads",
        "linear_solver",
        "status",
        "t_fail",
        "elements",
        "unknowns",
        "nsteps",
        "setup_s",
        "stepping_s",
        "wall_s",
        "step_ms",
        "matvec_ms",
        "step_over_matvec",
        "factorizations",
        "krylov_its_per_step",
        "peak_rss_mb",
        "operator_bytes",
        "bytes_per_element",
    ]
    + [f"err_{q}" for q in QUANTS]
    + list(SCALARS)
)


def row(r, err):
    res = r["mesh"] if r["solver"] == "fe" else f"dr=2/{r['dr_div']} dth=pi/{r['th_div']}"
    ne = r.get("elements")
    return dict(
        solver=r["solver"],
        scheme=r["scheme"],
        resolution=res,
        dt=r["dt"],
        threads=r.get("threads", 1),
        linear_solver=r.get("linear_solver") or ("krylov" if r["solver"] == "fe" else "lu"),
        status=r["status"],
        t_fail=r.get("t_fail"),
        elements=ne,
        unknowns=r.get("unknowns"),
        nsteps=r.get("nsteps"),
        setup_s=r.get("setup_s"),
        stepping_s=r.get("stepping_s"),
        wall_s=r.get("wall_s"),
        step_ms=1e3 * r["step_s"] if r.get("step_s") else None,
        matvec_ms=1e3 * r["matvec_s"] if r.get("matvec_s") else None,
        step_over_matvec=r.get("step_over_matvec"),
        factorizations=r.get("factorizations"),
        krylov_its_per_step=(r["krylov_iterations"] / r["nsteps"])
        if r.get("krylov_iterations") is not None and r.get("nsteps")
        else None,
        peak_rss_mb=r.get("peak_rss_mb"),
        operator_bytes=r.get("operator_bytes"),
        bytes_per_element=(r["operator_bytes"] / ne) if ne and r.get("operator_bytes") else None,
        **{f"err_{q}": err.get(q) for q in QUANTS},
        **{q: r.get(q) for q in SCALARS},
    )


def _fmt(v, nd=3):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return ""
    if isinstance(v, float):
        if v == 0:
            return "0"
        if abs(v) >= 1000 or abs(v) < 1e-3:
            return f"{v:.{nd - 1}e}"
        return f"{v:.{nd}g}"
    return str(v)


def write_csv(path, rows):
    import csv

    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=CSV_COLS)
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in CSV_COLS})


def is_study(r):
    return (
        r.get("beta", 200.0) == 200.0
        and r.get("t_end", T_END) == T_END
        and not r.get("stability")
        and r.get("threads", 1) == 1
        and not r.get("linear_solver")
    )


def pareto_plot(path, runs, errs, ref):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    fig, axes = plt.subplots(2, 4, figsize=(17, 8), sharex=True)
    styles = {
        ("fe", "euler"): ("C0", "o", "FE euler (paper scheme)"),
        ("fe", "bdf2"): ("C1", "s", "FE bdf2"),
        ("fd", "euler"): ("C3", "^", "FD euler (paper)"),
    }
    for ax, q in zip(axes.ravel(), QUANTS, strict=True):
        for (solver, scheme), (col, mk, lab) in styles.items():
            pts = sorted(
                (r["wall_s"], errs[i][q])
                for i, r in enumerate(runs)
                if r["solver"] == solver
                and r["scheme"] == scheme
                and q in errs[i]
                and is_study(r)
                and r["status"] == "ok"
            )
            if not pts:
                continue
            x, y = np.array(pts).T
            y = np.maximum(y, 1e-7)
            ax.loglog(x, y, mk, color=col, alpha=0.45, ms=5)
            fx, fy, best = [], [], np.inf  # Pareto front: cheapest first, error falling
            for xi, yi in zip(x, y, strict=True):
                if yi < best:
                    best = yi
                    fx.append(xi)
                    fy.append(yi)
            ax.loglog(fx, fy, "-" + mk, color=col, label=lab, ms=6)
        if q.endswith("@1"):  # FD ruptures during sliding: its cost to t = 1
            pts = [
                (r["setup_s"] + r["step_s"] * round(1.0 / r["dt"]), errs[i][q])
                for i, r in enumerate(runs)
                if r["solver"] == "fd" and q in errs[i] and r.get("step_s")
            ]
            if pts:
                x, y = np.array(sorted(pts)).T
                ax.loglog(
                    x,
                    np.maximum(y, 1e-7),
                    "^",
                    color="C3",
                    mfc="none",
                    ms=7,
                    label="FD (paper), cost to t = 1; ruptures at t = 1.6-2.6",
                )
        unc = max(ref[q]["unc_pairs"], ref[q]["unc_time"])
        lo = ax.get_ylim()[0]
        ax.axhspan(lo, max(unc, lo), color="0.85", zorder=0, label="reference uncertainty")
        ax.set_ylim(bottom=lo)
        for lvl in (1e-2, 1e-3):
            ax.axhline(lvl, color="0.4", lw=0.8, ls="--")
        ax.set_title(q.replace("@", " at t = ").replace("profile", "centreline p (L2)"))
        ax.grid(True, which="both", alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("wall time of the whole run (s), 1 BLAS thread")
    for ax in axes[:, 0]:
        ax.set_ylabel("relative error")
    axes[0, 0].legend(fontsize=7, loc="lower left")
    fig.suptitle("femehl: error against wall time, paper case (beta = 200, h0 = 0.1, t in [0, 5])")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def analyze(out, runs, quick):
    import numpy as np

    study = [r for r in runs if is_study(r)]
    if quick:
        ref = reference(runs, ("coarse", "medium", "medium"), (0.02, 0.01))
    else:
        ref = reference(runs, ("medium", "fine", "xfine"), (0.01, 0.005))
    errs = [errors(r, ref) if r["status"] == "ok" or r.get("load@1") is not None else {} for r in runs]
    rows = [row(r, e) for r, e in zip(runs, errs, strict=True)]
    write_csv(out / "accuracy_results.csv", rows)
    pareto_plot(out / "accuracy_pareto.png", runs, errs, ref)

    lines = []
    mi = machine()
    lines.append("# femehl accuracy vs cost (paper case, beta = 200, h0 = 0.1, t in [0, 5])\n")
    lines.append(
        "Generated by `femehl bench accuracy"
        + (" --quick" if quick else "")
        + "`. Machine: "
        + ", ".join(f"{k} {v}" for k, v in mi.items())
        + ".\n"
    )
    lines.append("## Reference\n")
    if quick:
        lines.append(
            "QUICK MODE: the reference is extrapolated from coarse/medium only; "
            "errors below are indicative.\n"
        )
    else:
        lines.append(
            "Richardson extrapolation of FE bdf2: in dt (order 2, dt = 0.01 and 0.005) on "
            "each of medium, fine, xfine, then in h (ratio 1.45, observed order from the "
            "three time-extrapolated rungs) from the (fine, xfine) pair. Uncertainty: "
            "difference to the (medium, fine) extrapolation (same order), and the size "
            "of the dt correction on xfine.\n"
        )
    lines.append(
        "| quantity | reference | observed order in h | uncertainty (rung pairs; order 1 too if flagged) | "
        "dt correction | h correction | note |"
    )
    lines.append("|---|---|---|---|---|---|---|")
    for q in QUANTS:
        v = ref[q]["value"]
        sv = _fmt(float(v), 6) if np.ndim(v) == 0 else f"L2 norm {_norm(v):.5g}"
        lines.append(
            f"| {q} | {sv} | {ref[q]['order_h']:.2f} | {100 * ref[q]['unc_pairs']:.3f} % | "
            f"{100 * ref[q]['unc_time']:.3f} % | {100 * ref[q]['h_corr']:.3f} % | "
            f"{ref[q]['flag']} |"
        )
    lines.append("\n## Runs (errors in %; wall = set-up + stepping, 1 BLAS thread unless noted)\n")
    head = [
        "run",
        "status",
        "el./unknowns",
        "set-up s",
        "stepping s",
        "wall s",
        "ms/step",
        "step/matvec",
        "LU",
        "its/step",
        "peak MB",
        "op. B/el.",
    ] + [q for q in QUANTS]
    lines.append("| " + " | ".join(head) + " |")
    lines.append("|" + "---|" * len(head))
    for r, w, e in zip(runs, rows, errs, strict=True):
        if r.get("stability") or (r.get("series") and not is_study(r)):
            continue
        size = f"{w['elements']}/{w['unknowns']}" if w["elements"] else f"-/{w['unknowns']}"
        st = w["status"] if w["status"] == "ok" else f"{w['status']} at t={_fmt(w['t_fail'])}"
        cells = [
            label(r),
            st,
            size,
            _fmt(w["setup_s"]),
            _fmt(w["stepping_s"]),
            _fmt(w["wall_s"]),
            _fmt(w["step_ms"]),
            _fmt(w["step_over_matvec"]),
            _fmt(w["factorizations"]),
            _fmt(w["krylov_its_per_step"]),
            _fmt(w["peak_rss_mb"], 4),
            _fmt(w["bytes_per_element"], 4),
        ]
        cells += [_fmt(100 * e[q]) if q in e else "" for q in QUANTS]
        lines.append("| " + " | ".join(cells) + " |")

    lines.append("\n## Cheapest setting reaching 1 % and 0.1 % (study runs, 1 thread)\n")
    lines.append("| quantity | solver | <= 1 % | <= 0.1 % |")
    lines.append("|---|---|---|---|")
    summary = []
    for q in QUANTS:
        unc = max(ref[q]["unc_pairs"], ref[q]["unc_time"])
        for solver in ("fe", "fd"):
            cells = []
            for lvl in (1e-2, 1e-3):
                ok = [
                    (r["wall_s"], label(r), e[q])
                    for r, e in zip(study, [errs[runs.index(s)] for s in study], strict=True)
                    if r["solver"] == solver and r["status"] == "ok" and q in e and e[q] <= lvl
                ]
                if not ok:
                    c = "none"
                else:
                    w_, lab, ev = min(ok)
                    c = f"{lab}: {w_:.1f} s (err {100 * ev:.3g} %)"
                if lvl < unc:
                    c += f" [threshold below the reference uncertainty {100 * unc:.2g} %: not verifiable]"
                cells.append(c)
            lines.append(f"| {q} | {solver.upper()} | {cells[0]} | {cells[1]} |")
            summary.append(f"{q:15s} {solver.upper()}  1%: {cells[0]}\n{'':19s} 0.1%: {cells[1]}")

    # all quantities at once
    lines.append("\n## Cheapest setting with ALL eight quantities within the error (FE, whole run)\n")
    lines.append("| error level | run | wall s | worst quantity |")
    lines.append("|---|---|---|---|")
    for lvl in (1e-2, 3e-3, 1e-3):
        ok = [
            (r["wall_s"], label(r), max(errs[runs.index(r)].items(), key=lambda kv: kv[1]))
            for r in study
            if r["status"] == "ok"
            and len(errs[runs.index(r)]) == len(QUANTS)
            and max(errs[runs.index(r)].values()) <= lvl
        ]
        if ok:
            w_, lab, (wq, wv) = min(ok)
            lines.append(f"| {100 * lvl:g} % | {lab} | {w_:.1f} | {wq} ({100 * wv:.3g} %) |")
        else:
            lines.append(f"| {100 * lvl:g} % | none | | |")

    # FE vs FD at equal error.  The FD runs rupture during sliding (t ~ 1.6 - 2.6), so they
    # are compared at t = 1 (end of indentation): FD cost = set-up + 100 steps (dt = 0.01) or
    # 50 (dt = 0.02); FE cost = its WHOLE run to t = 5 (conservative for FE) and, in brackets,
    # set-up + steps to t = 1 at its mean step time.
    q1 = [q for q in QUANTS if q.endswith("@1")]
    lines.append("\n## FE vs FD at equal error, at t = 1 (the FD runs rupture during sliding)\n")
    lines.append(
        "FD cost: set-up + steps to t = 1. FE: the cheapest run whose errors in ALL of "
        + ", ".join(q1)
        + " are at most the FD run's worst; its cost is its whole run to "
        "t = 5 (conservative) and, in brackets, its cost to t = 1 (set-up + steps at the "
        "mean step time).\n"
    )
    lines.append(
        "| FD run | ruptured at t | FD cost to t = 1 (s) | FD worst error at t = 1 | "
        "cheapest FE run as accurate | FE whole run s (to t = 1) | speed-up (to t = 1) |"
    )
    lines.append("|---|---|---|---|---|---|---|")
    for r in runs:
        if r["solver"] != "fd" or not r.get("step_s") or r.get("load@1") is None:
            continue
        e = errs[runs.index(r)]
        emax = max(e[q] for q in q1)
        fd_cost = r["setup_s"] + r["step_s"] * round(1.0 / r["dt"])
        cands = [
            (f["wall_s"], f["setup_s"] + f["step_s"] * round(1.0 / f["dt"]), label(f))
            for f in study
            if f["solver"] == "fe" and f["status"] == "ok" and all(errs[runs.index(f)][q] <= emax for q in q1)
        ]
        if cands:
            w_, w1, lab = min(cands)
            lines.append(
                f"| {label(r)} | {_fmt(r.get('t_fail'))} | {fd_cost:.1f} | {100 * emax:.3g} % | "
                f"{lab} | {w_:.1f} ({w1:.1f}) | {fd_cost / w_:.0f}x ({fd_cost / w1:.0f}x) |"
            )
    (out / "accuracy_results.md").write_text("\n".join(lines) + "\n")
    print("\n".join(summary))
    return ref, errs


# ---------------------------------------------------------------------------
# time-step study
# ---------------------------------------------------------------------------
def analyze_timestep(out, runs):
    import numpy as np

    def find(scheme, dt, beta=200.0):
        for r in runs:
            if (
                (r["solver"], r.get("mesh"), r["scheme"], r["dt"], r.get("beta", 200.0))
                == ("fe", "medium", scheme, dt, beta)
                and r.get("series")
                and not r.get("linear_solver")
                and r.get("threads", 1) == 1
            ):
                return r
        return None

    qs = ("load@1", "film_center@1", "film_min@1", "load@5", "film_center@5", "film_min@5")
    a, b = find("bdf2", 0.005), find("bdf2", 0.0025)
    if a is None or b is None:
        print("timestep: reference runs missing")
        return
    ref = {q: b[q] + (b[q] - a[q]) / 3.0 for q in qs}
    lines = [
        "# femehl time-step study (paper case, medium mesh)\n",
        "Error of each quantity against the dt -> 0 limit ON THE SAME MESH (Richardson of "
        "bdf2 at dt = 0.005 and 0.0025, order 2), so only the time error is measured. "
        "Observed order between successive dt (ratio 2, except 0.04/0.02).\n",
    ]
    rows = []
    lines.append(
        "| scheme | dt | wall s | "
        + " | ".join(f"err {q} %" for q in qs)
        + " | "
        + " | ".join(f"order {q}" for q in qs)
        + " |"
    )
    lines.append("|" + "---|" * (3 + 2 * len(qs)))
    for s in ("euler", "bdf2"):
        prev = None
        for dt in (0.04, 0.02, 0.01, 0.005, 0.0025):
            r = find(s, dt)
            if r is None or r["status"] != "ok":
                continue
            e = {q: abs(r[q] - ref[q]) / abs(ref[q]) for q in qs}
            o = {}
            if prev is not None:
                for q in qs:
                    o[q] = (
                        math.log(prev[1][q] / e[q]) / math.log(prev[0] / dt)
                        if e[q] > 0 and prev[1][q] > 0
                        else float("nan")
                    )
            prev = (dt, e)
            rows.append(
                dict(
                    kind="error",
                    scheme=s,
                    dt=dt,
                    beta=200.0,
                    wall_s=r["wall_s"],
                    **{f"err_{q}": e[q] for q in qs},
                    **{f"order_{q}": o.get(q) for q in qs},
                )
            )
            lines.append(
                f"| {s} | {dt:g} | {r['wall_s']:.1f} | "
                + " | ".join(_fmt(100 * e[q]) for q in qs)
                + " | "
                + " | ".join(_fmt(o.get(q)) for q in qs)
                + " |"
            )

    lines.append("\n## Stability: largest dt that completes to t = 5 without spurious oscillation\n")
    lines.append(
        "Oscillation test: count the direction reversals of film_min(t_k) step to step and "
        "compare with the same count of a small-dt reference (bdf2) sampled at the same "
        "times; more than 2 extra reversals, or an error in film_min at t = 5 above 20 %, "
        "is called spurious.\n"
    )
    lines.append(
        "| beta | scheme | dt | status | reversals (run / reference) | film_min at t=5 | "
        "error film_min@5 % (max over the run) | verdict |"
    )
    lines.append("|---|---|---|---|---|---|---|---|")
    for beta in (200.0, 2000.0):
        refr = find("bdf2", 0.005 if beta == 200.0 else 0.01, beta)
        if refr is None:
            continue
        rt, rv = np.array(refr["series"]).T
        for s in ("euler", "bdf2"):
            largest = None
            for dt in (0.01, 0.02, 0.04, 0.05, 0.1, 0.2):
                r = find(s, dt, beta)
                if r is None:
                    continue
                if r["status"] != "ok":
                    verdict, rev, fm, efm = "unstable (discrete film ruptured)", "", "", ""
                else:
                    t, v = np.array(r["series"]).T
                    refv = np.interp(t, rt, rv)
                    rev_run = int(np.sum(np.diff(np.sign(np.diff(v))) != 0))
                    rev_ref = int(np.sum(np.diff(np.sign(np.diff(refv))) != 0))
                    rev = f"{rev_run} / {rev_ref}"
                    fm = v[-1]
                    efm = abs(fm - refv[-1]) / abs(refv[-1])
                    dev = float(np.max(np.abs(v - refv) / np.abs(refv)))
                    ok = np.all(np.isfinite(v)) and rev_run <= rev_ref + 2 and efm < 0.2
                    verdict = "stable" if ok else "spurious oscillation/error"
                    if ok:
                        largest = dt
                    fm, efm = _fmt(float(fm), 5), _fmt(100 * efm) + f" (max over t: {100 * dev:.3g})"
                st = r["status"] if r["status"] == "ok" else f"{r['status']} at t={_fmt(r.get('t_fail'))}"
                lines.append(f"| {beta:g} | {s} | {dt:g} | {st} | {rev} | {fm} | {efm} | {verdict} |")
                rows.append(
                    dict(
                        kind="stability",
                        scheme=s,
                        dt=dt,
                        beta=beta,
                        wall_s=r.get("wall_s"),
                        status=r["status"],
                        verdict=verdict,
                    )
                )
            lines.append(f"| {beta:g} | {s} | **largest stable tried: {largest}** | | | | | |")
    (out / "timestep.md").write_text("\n".join(lines) + "\n")
    import csv

    cols = sorted({k for r in rows for k in r}, key=lambda k: (k not in ("kind", "scheme", "beta", "dt"), k))
    with open(out / "timestep.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=cols)
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r.get(k) is None else r[k]) for k in cols})
    print("\n".join(lines[-40:]))


# ---------------------------------------------------------------------------
def main(argv=None):
    ap = argparse.ArgumentParser(prog="femehl bench accuracy", description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="smoke test: coarse/medium only (~2 min)")
    ap.add_argument(
        "--out", default=None, help="output folder (default: benchmarks/, quick: benchmarks/quick/)"
    )
    ap.add_argument("--part", choices=["study", "timestep", "all"], default="all")
    ap.add_argument("--resume", action="store_true", help="skip runs already in runs.jsonl")
    ap.add_argument("--analyze-only", action="store_true", help="only rewrite tables and plot")
    ap.add_argument("--fd-extra", action="store_true", help="also FD dr = 0.025, dtheta = pi/48")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.worker:
        print(json.dumps(worker(json.loads(a.worker))))
        return 0
    out = pathlib.Path(a.out) if a.out else (HERE / "quick" if a.quick else HERE)
    out.mkdir(parents=True, exist_ok=True)
    store = out / "runs.jsonl"
    done = {}
    if store.exists() and (a.resume or a.analyze_only):
        for ln in store.read_text().splitlines():
            if ln.strip():
                r = json.loads(ln)
                done[key(r["spec"])] = r["result"]
    elif store.exists():
        store.unlink()
    cases = []
    if a.part in ("study", "all"):
        cases += fe_cases(a.quick) + fd_cases(a.quick, a.fd_extra)
    if a.part in ("timestep", "all") and not a.quick:
        cases += [c for c in ts_cases() if key(c) not in {key(x) for x in cases}]
    if not a.analyze_only:
        t_all = time.perf_counter()
        with open(out / "runs.log", "a") as log:
            for i, spec in enumerate(cases):
                k = key(spec)
                if k in done:
                    continue
                r = run_in_subprocess(spec, log)
                done[k] = r
                with open(store, "a") as fh:
                    fh.write(json.dumps({"spec": spec, "result": r}) + "\n")
                print(
                    f"[{i + 1}/{len(cases)}] {label(spec)}: {r['status']}, wall {r.get('wall_s', 0):.1f} s"
                    + (
                        f", {1e3 * r['step_s']:.1f} ms/step, "
                        f"{r.get('step_over_matvec', float('nan')):.1f} matvecs/step"
                        if r.get("step_s")
                        else ""
                    )
                    + f"  [total {time.perf_counter() - t_all:.0f} s]",
                    flush=True,
                )
    runs = [done[key(c)] for c in cases if key(c) in done]
    if a.part in ("study", "all"):
        analyze(out, runs, a.quick)
    if a.part in ("timestep", "all") and not a.quick:
        analyze_timestep(out, runs)
    return 0


if __name__ == "__main__":
    sys.exit(main())
