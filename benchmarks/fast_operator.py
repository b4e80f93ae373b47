"""Benchmark: the fast (hierarchical) elastic operator against the dense one.

``python benchmarks/fast_operator.py`` (or ``femehl bench fast_operator``) runs, each case in
its own process (so the peak memory is the case's own), the paper sphere on fitted
half-disk meshes from about 3,000 to 500,000 elements:

* ``case``: the first ``--steps`` steps of the paper case (BDF2, dt = 0.01) with one
  operator; prints one JSON line: elements, set-up s, ms per step (steps 5 onwards, the
  contact forming), Krylov iterations per step, peak RSS, operator bytes;
* ``agree``: the whole paper case to t = 5 with both operators on one mesh: the largest
  relative difference of load, central and minimum film over every step;
* the driver (no sub-command) runs the ladder and writes ``fast_operator.jsonl``,
  ``fast_operator.md`` and ``fast_operator.png`` next to this file.

Threads are pinned to one (``OMP_NUM_THREADS=1`` ...), as in every femehl benchmark.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

from _machine import machine

HERE = Path(__file__).resolve().parent
ENV = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1", MPLBACKEND="Agg")

#: fitted-mesh levels of the ladder (about 3k .. 500k half-disk elements; 0.244: 47,296
#: elements, the largest dense mesh femehl accepts on this 24 GiB machine (dense_bytes
#: 20.21 of 20.22 GB), where the paths were paired on 2026-12-04 at 3e0e5c7; earlier
#: rows used 0.251 (44,792 elements) and 0.25 (45,156))
LEVELS = [1.0, 0.5, 0.32, 0.244, 0.177, 0.125, 0.0735]
#: the dense path is run where it fits (femehl.discretize.mesh.dense_bytes <= 80 % of the memory)
DENSE_LEVELS = [1.0, 0.5, 0.32, 0.244]
#: the tighter fast operator of the agreement runs (p = 13 against the default's 11, double
#: factors; p = 11 against 10 until 4cb7e0f; 3e-7 before that: p = 10 against 9)
TIGHT_OPERATOR_TOL = 1e-7


def _scene():
    from femehl.problem.presets import paper_sphere

    return paper_sphere()


def case(
    level: float,
    operator: str,
    steps: int,
    save: str | None = None,
    refactor_after: int | None = None,
    operator_tol: float | None = None,
) -> dict:
    """The first ``steps`` steps of the paper case on the fitted mesh of ``level``.

    ``save``: also write the histories (t, load, central and minimum film) to this
    ``.npz``, to compare the two operators over a whole run.  ``refactor_after``: refresh
    the preconditioner whenever a solve takes more Krylov iterations than this (default:
    femehl's cost balance); such rows are tagged ``experiment`` and not fitted.
    ``operator_tol``: the fast operator's (default: femehl's); its rows are tagged
    ``operator_tol`` and not fitted either.
    """

    import femehl
    from femehl.discretize.fitted import fitted_disk

    scene = _scene()
    t0 = time.perf_counter()
    dm = fitted_disk(scene, 5.0, level)
    t_mesh = time.perf_counter() - t0
    stamps = []
    t1 = time.perf_counter()
    res = femehl.solve(
        scene,
        t_end=steps * 0.01,
        dt=0.01,
        mesh=dm,
        scheme="bdf2",
        operator=operator,
        estimate=False,
        store_every=0,
        refactor_after=refactor_after,
        **({} if operator_tol is None else {"operator_tol": operator_tol}),
        callback=lambda s: stamps.append((time.perf_counter(), s.info.get("krylov_iterations", 0))),
    )
    wall = time.perf_counter() - t1
    if save:
        import numpy as np

        np.savez(save, t=res.t, load=res.load, film_center=res.film_center, film_min=res.film_min)
    extra = {} if refactor_after is None else {"experiment": f"refactor_after={refactor_after}"}
    if operator_tol is not None:
        extra["experiment"] = f"operator_tol={operator_tol:g}"
    return {
        **extra,
        "level": level,
        **_figures(res, [t1 + res.info["setup_s"]] + [t for t, _ in stamps], stamps, t_mesh),
        "operator": operator,
        "factorizations": res.info["factorizations"],
        "wall_s": wall,
        "steps": steps,
        "fast": res.info.get("fast_operator"),
    }


def _figures(res, times, stamps, t_mesh) -> dict:
    """Per-step figures from steps 5 on (the first steps build the preconditioner)."""
    import numpy as np

    info = res.info
    its = [k for _, k in stamps]
    return {
        "elements": info["elements"],
        "unknowns": info["unknowns"],
        "operator": info["operator"],
        "mesh_s": t_mesh,
        "setup_s": info["setup_s"],
        "ms_per_step": 1e3 * float(np.mean(np.diff(times)[5:])),
        "krylov_per_step": float(np.mean(its[5:])),
        "krylov_max": int(max(its[5:])),
        "operator_bytes": info["operator_bytes"],
        "peak_rss": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
    }


#: the fast path's difference split by source (``agree --sources``): the operator alone
#: (the Krylov solve to rtol 1e-11), the Krylov solve alone (operator_tol 1e-8, p = 13),
#: and both tightened (operator_tol TIGHT_OPERATOR_TOL, rtol 1e-10)
SOURCES = (
    ("fast_operator_part", {"operator": "fast", "rtol": 1e-11}),
    ("fast_krylov_part", {"operator": "fast", "operator_tol": 1e-8}),
    ("fast_both", {"operator": "fast", "operator_tol": TIGHT_OPERATOR_TOL, "rtol": 1e-10}),
)


def _variant(spec: str) -> tuple[str, dict]:
    """``"p:eta:svd_ratio"`` -> (name, the run options that build the fast operator so:
    ``operator_tol = FastOptions(p=p, eta=eta, svd_ratio=svd_ratio)``), an experiment."""
    from femehl.elastic.hmatrix import FastOptions

    p, eta, ratio = spec.split(":")
    p, eta, ratio = int(p), float(eta), float(ratio)
    options = FastOptions(p=p, eta=eta, svd_ratio=ratio)
    return f"fast_p{p}_eta{eta:g}_svd{ratio:g}", {"operator": "fast", "operator_tol": options}


def agree(
    level: float,
    t_end: float,
    sources: bool = False,
    variants: tuple = (),
    fast_rtols: tuple = (),
    fast_only: bool = False,
) -> dict:
    """Whole paper case: the fast and the dense path (defaults), and the fast path at
    ``operator_tol = TIGHT_OPERATOR_TOL``, against the dense operator solved to
    rtol = 1e-10 (about the exact solution of the same discretization); with
    ``sources``, also the runs of :data:`SOURCES`; each of ``variants``
    (``"p:eta:svd_ratio"``, :func:`_variant`) a fast run at the default rtol with the
    operator built so; each of ``fast_rtols`` a fast run (default operator) at that Krylov
    rtol.  ``fast_only``: the reference and the default fast run alone (no dense run at its
    default rtol, no tighter fast run: on the largest dense mesh each dense run takes most of
    an hour)."""
    import numpy as np

    import femehl
    from femehl.discretize.fitted import fitted_disk

    scene = _scene()
    dm = fitted_disk(scene, 5.0, level)
    out = {"level": level, "t_end": t_end, "tight_operator_tol": TIGHT_OPERATOR_TOL}
    runs = {}
    left_out = {"dense", "fast_tight"} if fast_only else set()
    for name, opts in (
        ("reference", {"operator": "dense", "rtol": 1e-10}),
        ("dense", {"operator": "dense"}),
        ("fast", {"operator": "fast"}),
        ("fast_tight", {"operator": "fast", "operator_tol": TIGHT_OPERATOR_TOL}),
        *(SOURCES if sources else ()),
        *map(_variant, variants),
        *((f"fast_rtol{r:g}", {"operator": "fast", "rtol": r}) for r in fast_rtols),
    ):
        if name in left_out:
            continue
        t0 = time.perf_counter()
        runs[name] = femehl.solve(
            scene, t_end=t_end, dt=0.01, mesh=dm, scheme="bdf2", estimate=False, store_every=0, **opts
        )
        out[f"{name}_s"] = time.perf_counter() - t0
    out["elements"] = runs["fast"].info["elements"]
    for name, res in runs.items():  # the Chebyshev order each fast run's tolerance gave
        if isinstance(res.info.get("fast_operator"), dict):
            out[f"{name}_p"] = res.info["fast_operator"].get("p")
    for name in runs:
        if name == "reference":
            continue
        for q in ("load", "film_center", "film_min"):
            a = np.asarray(getattr(runs["reference"], q))
            b = np.asarray(getattr(runs[name], q))
            scale = np.maximum(np.abs(a), 1e-3 * np.max(np.abs(a)))
            out[f"{name}_{q}"] = float(np.max(np.abs(a - b) / scale))
    return out


#: the couplings' truncation (femehl.elastic.hmatrix.SVD_RATIO) of the error rows recorded before
#: rows carried it: 0.1 until 566eb3b, then 1
_SVD_BEFORE = {"36c856f": 0.1, "6759f61": 0.1, "566eb3b": 1.0}

#: rows of the exact operator sampled by ``error`` (uniformly over the elements) and the
#: random vectors it applies at once (64 estimate the Frobenius ratio to about 10 %; rows
#: before 2026-12-04's last session used one)
ERROR_ROWS, ERROR_VECTORS = 384, 64


def operator_error(
    level: float,
    tols: list[float],
    rows: int = ERROR_ROWS,
    n_vectors: int = ERROR_VECTORS,
    p: int | None = None,
    svd_ratio: float | None = None,
    eta: float | None = None,
) -> list[dict]:
    """Relative error of the fast operator at each ``operator_tol`` on the fitted mesh of
    ``level``, against exact rows at ``rows`` elements drawn uniformly
    (:func:`femehl.elastic.hmatrix.sampled_error`): so it is measured where the dense operator
    does not fit.

    For ``n_vectors`` random vectors at once (standard normal nodal values; the Frobenius
    ratio over them: one vector's error scatters by a factor of 5) and a smooth one
    (``1 - r**2`` inside the unit circle, the shape of a Hertz pressure).  ``p``,
    ``svd_ratio`` and ``eta`` override the order, truncation and admissibility of the
    default (:class:`femehl.elastic.hmatrix.FastOptions`; experiment rows, tagged and not the
    default's).  One record per tolerance,
    with the Chebyshev order, the far factors' precision, the build seconds and bytes of
    the operator (the preconditioner's coarse space is not built).
    """
    import numpy as np

    from femehl.discretize.fe_disk import FEDisc
    from femehl.discretize.fitted import fitted_disk
    from femehl.elastic.hmatrix import FastCompliance, FastOptions, sampled_error

    scene = _scene()
    disc = FEDisc(scene, mesh=fitted_disk(scene, 5.0, level), operator="fast")
    vectors = {
        "random": np.random.default_rng(7).standard_normal((disc.n, n_vectors) if n_vectors > 1 else disc.n),
        "smooth": np.maximum(0.0, 1.0 - np.hypot(*disc.nodes[disc.free].T) ** 2),
    }
    out = []
    for tol in tols:
        t0 = time.perf_counter()
        overrides = {k: v for k, v in (("p", p), ("svd_ratio", svd_ratio), ("eta", eta)) if v is not None}
        C = FastCompliance(disc, FastOptions(tol=tol, **overrides), coarse=False)
        build = time.perf_counter() - t0
        extra = {}
        if overrides:
            extra["experiment"] = ", ".join(f"{k}={v:g}" for k, v in overrides.items())
        out.append(
            {
                **extra,
                "kind": "operator_error",
                "vectors": n_vectors,
                "svd_ratio": C.options.svd_ratio,
                "level": level,
                "elements": disc.nelements,
                "rows": min(rows, disc.nelements),
                "tol": tol,
                "p": C.H.p,
                "factors": C.H.factor_dtype.name,
                "build_s": build,
                "bytes": int(C.H.nbytes),
                **sampled_error(disc, C, vectors, rows),
            }
        )
        del C
    return out


def textured(elements: int, t_end: float, out: str) -> dict:
    """The textured example (examples/textured_sphere.py) to ``t_end``, instrumented."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "textured_sphere", HERE.parent / "examples" / "textured_sphere.py"
    )
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    import femehl

    t0 = time.perf_counter()
    dm = mod.textured_mesh(elements)
    t_mesh = time.perf_counter() - t0
    stamps = []
    t1 = time.perf_counter()
    res = femehl.solve(
        mod.scene(),
        t_end=t_end,
        dt=0.01,
        mesh=dm,
        scheme="bdf2",
        store_every=50,
        estimate=False,
        callback=lambda s: stamps.append((time.perf_counter(), s.info.get("krylov_iterations", 0))),
    )
    wall = time.perf_counter() - t1
    figures = {
        "kind": "textured",
        **_figures(res, [t for t, _ in stamps], stamps, t_mesh),
        "wall_s": wall + t_mesh,
        "steps": res.nsteps,
        "t_end": float(res.t[-1]),
        "film_min": float(res.film_min[-1]),
        "load": float(res.load[-1]),
        "commit": _head(),
    }
    (HERE / "fast_operator_textured.json").write_text(json.dumps(figures, indent=1) + "\n")  # first
    res.save(out, overwrite=True)  # the ParaView series of the stored steps (every 50th)
    return figures


#: fitted-mesh levels around the crossover of operator="auto" (5,766 / 7,998 / 11,450 elements)
CROSSOVER_LEVELS = [0.71, 0.6, 0.5]


def crossover(levels: list[float], rounds: int, timeout: float) -> list[dict]:
    """The whole paper case (``case --steps 500``, set-up included) with the dense and the
    fast operator in turn, ``rounds`` times each, in their own processes: one record per
    level with every process's wall seconds (start-up and imports included), the medians
    and the median of the pairs' fast / dense ratios (pairs in turn, so the ratio holds
    while the machine's speed drifts)."""
    import statistics

    out = []
    for level in levels:
        walls, elements = {"dense": [], "fast": []}, None
        for _ in range(rounds):
            for op in ("dense", "fast"):
                t0 = time.perf_counter()
                r = _run(["case", "--level", str(level), "--operator", op, "--steps", "500"], timeout)
                if "error" in r:
                    raise SystemExit(f"crossover: {op} at level {level} failed: {r['error']}")
                walls[op].append(time.perf_counter() - t0)
                elements = r["elements"]
        ratios = [f / d for d, f in zip(walls["dense"], walls["fast"], strict=True)]
        out.append(
            {
                "kind": "crossover",
                "level": level,
                "elements": elements,
                "dense_s": walls["dense"],
                "fast_s": walls["fast"],
                "dense_median_s": statistics.median(walls["dense"]),
                "fast_median_s": statistics.median(walls["fast"]),
                "fast_over_dense": statistics.median(ratios),
                "commit": _head(),
            }
        )
        print(json.dumps(out[-1]), flush=True)
    return out


def _run(args: list[str], timeout: float) -> dict | None:
    try:
        p = subprocess.run(
            [sys.executable, __file__, *args], env=ENV, capture_output=True, text=True, timeout=timeout
        )
    except subprocess.TimeoutExpired:
        return {"args": args, "error": f"timeout {timeout:.0f} s"}
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith("{")]
    if p.returncode or not lines:
        return {"args": args, "error": (p.stderr or p.stdout)[-600:]}
    return {**json.loads(lines[-1]), "commit": _head()}


def _head() -> str | None:
    """The short commit of the checkout this benchmark runs from (None outside git)."""
    try:
        out = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], cwd=HERE, capture_output=True, text=True, timeout=10
        )
    except (OSError, subprocess.TimeoutExpired):
        return None
    return out.stdout.strip() or None if out.returncode == 0 else None


def fit_exponent(n, y):
    import numpy as np

    ln, ly = np.log(np.asarray(n, float)), np.log(np.asarray(y, float))
    return float(np.polyfit(ln, ly, 1)[0])


def _commits(rows: list[dict]) -> str:
    """The sentence " Commits: a, b." of the rows that record theirs (empty if none does)."""
    done = sorted({r["commit"] for r in rows if r.get("commit")})
    return f" Commits: {', '.join(done)}." if done else ""


def _one_session(rows: list[dict]) -> list[dict]:
    """The ladder to fit and plot: the rows of the newest commit that ran at least three
    sizes (wall times drift between sessions, so exponents come from one), else all rows;
    sorted by elements."""
    commits = [r.get("commit") for r in rows]
    for c in reversed(commits):
        if c is not None and commits.count(c) >= 3:
            rows = [r for r in rows if r.get("commit") == c]
            break
    return sorted(rows, key=lambda r: r["elements"])


def _experiment(r: dict) -> str:
    """``", refactor_after=5 (6 preconditioner LUs)"`` for a row of another refresh policy,
    in the commit cell (a cell past the header's would not be shown)."""
    return f", {r['experiment']} ({r['factorizations']} preconditioner LUs)" if r.get("experiment") else ""


def _orders(a: dict) -> str:
    """``" (p = 10 / 11)"``: the Chebyshev orders of the default and the tight fast run of an
    agreement row, where recorded (since they depend on the commit's error model)."""
    if "fast_tight_load" not in a:
        return f" (p = {a['fast_p']}, reference and fast runs only)" if a.get("fast_p") else ""
    tight = f"tight operator_tol {a.get('tight_operator_tol', 3e-7):g}"
    if a.get("fast_p") is None:
        return f" ({tight})"
    return f" (p = {a['fast_p']} / {a.get('fast_tight_p', '?')}, {tight})"


def write(
    rows: list[dict],
    agreements: list[dict],
    path_md: Path,
    path_png: Path,
    tex: dict | None = None,
    errors: list[dict] = (),
    crossings: list[dict] = (),
) -> None:
    import numpy as np

    ok = [r for r in rows if "error" not in r]
    # the ladder: the rows of the first steps (whole-run rows, more steps, are paired only)
    first = min((r["steps"] for r in ok), default=0)
    ladder = [r for r in ok if r["steps"] == first]
    # rows run beside a dense run (the pairs) share the memory bandwidth: not fitted
    # ... nor the experiments (another refresh policy)
    fast = _one_session(
        [r for r in ladder if r["operator"] == "fast" and not r.get("beside") and not r.get("experiment")]
    )
    dense = sorted([r for r in ladder if r["operator"] == "dense"], key=lambda r: r["elements"])
    pairs = [
        (d, f)
        for d in ok
        for f in ok
        if (d["operator"], f["operator"]) == ("dense", "fast")
        and (f["elements"], f["steps"]) == (d["elements"], d["steps"])
        # one session: rows tagged with the dense run's session (fast runs of several
        # commits beside it), else the rows of one commit
        and (
            f.get("session") == d["session"]
            if d.get("session")
            else (not f.get("session") and f.get("commit") == d.get("commit"))
        )
    ]
    lines = [
        "# Fast (hierarchical) elastic operator against the dense one",
        "",
        f"Generated by `python benchmarks/fast_operator.py`. Machine: {machine()}. Load average at the "
        f"end: {os.getloadavg()[0]:.2f}.",
        "",
        "Paper sphere (beta = 200), fitted half-disk meshes, BDF2 at dt = 0.01; ms per step is the "
        "mean over steps 5 to the last of the first `steps` steps (the contact forming), Krylov "
        "iterations per step likewise; peak RSS is the whole process (mesh, operators, solver). "
        "Each case ran in its own process, one after another (the 45,156-element rows of b39ccda, "
        "the 44,792-element rows of 93f7c14 and the 47,296-element rows of 3e0e5c7: "
        "dense on one core, fast and other runs on the other, at the same time)." + _commits(rows),
        "",
    ]
    header = [
        "| operator | elements | set-up s | ms / step | Krylov / step (max) | operator bytes / element "
        "| peak RSS GiB | steps | commit |",
        "|---|---|---|---|---|---|---|---|---|",
    ]

    def row(r):
        return (
            f"| {r['operator']} | {r['elements']} | {r['setup_s']:.1f} | {r['ms_per_step']:.0f} | "
            f"{r['krylov_per_step']:.1f} ({r['krylov_max']}) | {r['operator_bytes'] / r['elements']:.0f} | "
            f"{r['peak_rss'] / 2**30:.2f} | {r['steps']} | {r.get('commit', '')}{_experiment(r)} |"
        )

    if len(fast) >= 3:
        n = [r["elements"] for r in fast]
        lines += [
            f"## The fast ladder (commit {fast[-1].get('commit')}, one session, fitted below)",
            "",
            *header,
            *map(row, fast),
            "",
            f"Fitted exponents over the fast ladder ({n[0]} to {n[-1]} elements, commit "
            f"{fast[-1].get('commit')}): time per step "
            f"N^{fit_exponent(n, [r['ms_per_step'] for r in fast]):.2f}, set-up "
            f"N^{fit_exponent(n, [r['setup_s'] for r in fast]):.2f}, operator bytes "
            f"N^{fit_exponent(n, [r['operator_bytes'] for r in fast]):.2f}, peak RSS "
            f"N^{fit_exponent(n, [r['peak_rss'] for r in fast]):.2f} (N log N fitted the same way: "
            f"N^{fit_exponent(n, [k * math.log(k) for k in n]):.2f}).",
        ]
        big = [r for r in fast if r["elements"] >= 20_000]
        if len(big) >= 3:
            nb = [r["elements"] for r in big]
            per_it = [r["ms_per_step"] / r["krylov_per_step"] for r in big]
            per_step = fit_exponent(nb, [r["ms_per_step"] for r in big])
            lines.append("")
            lines.append(
                f"From {nb[0]} elements on: time per step N^{per_step:.2f} (N log N: "
                f"N^{fit_exponent(nb, [k * math.log(k) for k in nb]):.2f}), "
                f"per Krylov iteration N^{fit_exponent(nb, per_it):.2f}, Krylov iterations per step "
                f"{big[0]['krylov_per_step']:.1f} -> {big[-1]['krylov_per_step']:.1f}."
            )
        lines += ["", "## Every recorded run (earlier operators and sessions included)", ""]
    lines += header
    for r in sorted(ok, key=lambda r: (r["steps"], r["elements"], r["operator"])):
        lines.append(row(r))
    for r in ok:
        if r.get("note"):
            lines.append(f"| ({r['elements']}: {r['note']}) |  |  |  |  |  |  |  |  |")
    for r in rows:
        if "error" in r:
            lines.append(f"| failed | {' '.join(r['args'])} | {r['error'][-200:]!r} |  |  |  |  |  |")
    lines.append("")
    if pairs:
        lines.append(
            "Fast against dense on the same mesh (rows of one commit, or of one session: fast runs "
            "beside that dense run, named by their commit):"
        )
        lines.append("")
        lines.append(
            "| elements | steps | time per step dense / fast | peak RSS dense / fast "
            "| operator bytes dense / fast |"
        )
        lines.append("|---|---|---|---|---|")
        for d, f in pairs:
            lines.append(
                f"| {d['elements']}{' (' + f['experiment'] + ')' if f.get('experiment') else ''}"
                f"{' (' + f['commit'] + ', ' + f['session'] + ')' if f.get('session') else ''} | "
                f"{d['steps']} | {d['ms_per_step'] / f['ms_per_step']:.2f} | "
                f"{d['peak_rss'] / f['peak_rss']:.2f} | {d['operator_bytes'] / f['operator_bytes']:.2f} |"
            )
        lines.append("")
    if errors:
        lines.append(
            "Operator error (`error`): the fast operator against exact rows (the triangle "
            f"integrals, O(N) a row) at {ERROR_ROWS} elements drawn uniformly, so measured where the "
            "dense operator does not fit: ||(C_fast - C) z|| / ||C z|| over those rows for a random "
            "z (standard normal nodal values) and a smooth one (1 - r^2 in the unit circle, the "
            "shape of a Hertz pressure); p the Chebyshev order the tolerance gave, the far "
            "factors' storage precision, the operator's build s and bytes per element (without the "
            "preconditioner); 'vectors' how many random vectors (the Frobenius ratio over them): "
            "the error of one scatters by a factor of 5 between vectors (the rows of largest "
            "error dominate it), so the single-vector rows (before 2026-12-04's last session) "
            "are samples, not estimates; svd the couplings' truncation relative to "
            "operator_tol." + _commits(errors)
        )
        lines.append("")
        lines.append(
            "| elements | operator_tol | p | svd | far factors | random z (vectors) | smooth z "
            "| build s | bytes / element | commit |"
        )
        lines.append("|---|---|---|---|---|---|---|---|---|---|")
        order = lambda e: (e.get("commit") or "", e.get("elements", 0), -e.get("tol", 0))  # noqa: E731
        for e in sorted(errors, key=order):
            if "args" in e:
                failed = f"| failed | {' '.join(e['args'])} | {e['error'][-200:]!r} |"
                lines.append(failed + "  |" * 7)
                continue
            svd = e.get("svd_ratio", _SVD_BEFORE.get(e.get("commit"), 0.1))
            lines.append(
                f"| {e['elements']} | {e['tol']:g} | {e['p']} | {svd:g} | {e['factors']} | "
                f"{e['random']:.1e} ({e.get('vectors', 1)}) | "
                f"{e['smooth']:.1e} | {e['build_s']:.0f} | {e['bytes'] / e['elements']:.0f} | "
                f"{e.get('commit', '')}{', ' + e['experiment'] if e.get('experiment') else ''} |"
            )
        lines.append("")
    if agreements:
        lines.append(
            "Agreement over the whole paper case (largest relative difference over every step) "
            "against the dense operator solved to rtol = 1e-10; the dense path's own default "
            "(rtol = 1e-8) for comparison; wall times of the whole run, set-up included, the "
            "runs one after another in one process (the fast one at the tighter operator_tol "
            f"since 3e0e5c7, named in the last cell).{_commits(agreements)}"
        )
        lines.append("")
        lines.append(
            "| elements | t_end | fast: load | central film | minimum film | dense: load | central film "
            "| minimum film | reference s | dense s | fast s | fast at the tighter operator_tol: "
            "load, central, minimum film, s | commit (p: default / tight) |"
        )
        lines.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for a in agreements:
            if "error" in a:
                lines.append(f"| failed | {a['error'][-200:]!r} |  |  |  |  |  |  |  |  |  |  |  |")
                continue
            tight = (
                f"{a['fast_tight_load']:.1e}, {a['fast_tight_film_center']:.1e}, "
                f"{a['fast_tight_film_min']:.1e}, {a['fast_tight_s']:.0f}"
                if "fast_tight_load" in a
                else ""
            )
            e = lambda key, fmt=".1e", a=a: format(a[key], fmt) if key in a else "-"  # noqa: E731 - left out: -
            lines.append(
                f"| {a['elements']} | {a['t_end']:g} | {e('fast_load')} | {e('fast_film_center')} | "
                f"{e('fast_film_min')} | {e('dense_load')} | {e('dense_film_center')} | "
                f"{e('dense_film_min')} | {e('reference_s', '.0f')} | {e('dense_s', '.0f')} | "
                f"{e('fast_s', '.0f')} | {tight} | {a.get('commit', '')}{_orders(a)} |"
            )
        lines.append("")
        split = [a for a in agreements if "fast_operator_part_load" in a]
        if split:
            lines.append(
                "Where the fast path's difference comes from (`agree --sources`; minimum film, "
                "central film and load against the same reference, whole paper case): the "
                "operator alone (Krylov solve to rtol = 1e-11), the Krylov solve alone "
                "(operator_tol = 1e-8), the defaults (operator_tol = 1e-6, rtol = 1e-9), and both "
                "tightened (the row's tighter operator_tol, named in the table above, and rtol = 1e-10); "
                "wall s of the whole run."
            )
            lines.append("")
            lines.append(
                "| elements | operator alone: min film, central, load, s | Krylov alone | defaults "
                "| both tightened | commit |"
            )
            lines.append("|---|---|---|---|---|---|")

            def cell(a, name):
                return (
                    f"{a[name + '_film_min']:.1e}, {a[name + '_film_center']:.1e}, "
                    f"{a[name + '_load']:.1e}, {a[name + '_s']:.0f}"
                )

            for a in split:
                lines.append(
                    f"| {a['elements']} | {cell(a, 'fast_operator_part')} | {cell(a, 'fast_krylov_part')} "
                    f"| {cell(a, 'fast')} | {cell(a, 'fast_both')} | {a.get('commit', '')} |"
                )
            lines.append("")
        variants = [
            (a, k[: -len("_film_min")])
            for a in agreements
            for k in a
            if k.startswith(("fast_p", "fast_rtol")) and k.endswith("_film_min")
        ]
        if variants:
            lines.append(
                "Operator variants (`agree --variant P:ETA:SVD`, experiments): the fast path at "
                "its default rtol with the operator built at Chebyshev order P, admissibility "
                "ETA and couplings truncated at SVD x operator_tol (1e-6) at their exact ranks, "
                "or (`--fast-rtol R`, rows rtolR) the default operator solved to Krylov rtol R, "
                "against the same reference; the row's default for comparison (p10_eta2_svd1 is "
                "the default of 566eb3b to 82c2143 but for its ranks, rounded up to 4 there: 3 % "
                "more far-field bytes)."
            )
            lines.append("")
            lines.append(
                "| elements | variant | minimum film | central film | load | s "
                "| default's minimum film | commit |"
            )
            lines.append("|---|---|---|---|---|---|---|---|")
            for a, name in variants:
                lines.append(
                    f"| {a['elements']} | {name[len('fast_') :]} | {a[name + '_film_min']:.1e} | "
                    f"{a[name + '_film_center']:.1e} | {a[name + '_load']:.1e} | {a[name + '_s']:.0f} | "
                    f"{a['fast_film_min']:.1e} | {a.get('commit', '')} |"
                )
            lines.append("")
    if crossings:
        lines += [
            'Crossover of `operator="auto"` (`crossover`): the whole paper case (500 steps, set-up '
            "included) with each operator in its own process, dense and fast in turn; wall seconds of "
            "the processes (start-up and imports included), medians, and the median of the pairs' "
            "fast / dense ratios (below 1: the fast path is cheaper).",
            "",
            "| elements | dense s (median) | fast s (median) | fast / dense | runs each | commit |",
            "|---|---|---|---|---|---|",
        ]
        for c in sorted(crossings, key=lambda c: (c.get("commit") or "", c["elements"])):
            lines.append(
                f"| {c['elements']} | {c['dense_median_s']:.1f} | {c['fast_median_s']:.1f} | "
                f"{c['fast_over_dense']:.2f} | {len(c['dense_s'])} | {c.get('commit', '')} |"
            )
        lines.append("")
    if tex is not None:
        lines.append(
            "The textured example (`examples/textured_sphere.py`: dimpled sphere, full disk, "
            "BDF2 at dt = 0.01, to t = 5; `python benchmarks/fast_operator.py textured`):"
        )
        lines.append("")
        lines.append(
            "| elements | operator | mesh s | set-up s | ms / step | Krylov / step (max) | operator bytes "
            "/ element | peak RSS GiB | steps | wall to t_end |"
        )
        lines.append("|---|---|---|---|---|---|---|---|---|---|")
        lines.append(
            f"| {tex['elements']} | {tex['operator']} | {tex['mesh_s']:.0f} | {tex['setup_s']:.0f} | "
            f"{tex['ms_per_step']:.0f} | {tex['krylov_per_step']:.1f} ({tex['krylov_max']}) | "
            f"{tex['operator_bytes'] / tex['elements']:.0f} | {tex['peak_rss'] / 2**30:.2f} | "
            f"{tex['steps']} | "
            f"{tex['wall_s'] / 60:.1f} min to t = {tex['t_end']:g} |"
        )
        if tex.get("commit"):
            lines += ["", f"Commit: {tex['commit']}."]
        if tex.get("note"):
            lines += ["", tex["note"]]
        lines.append("")
    path_md.write_text("\n".join(lines) + "\n")
    try:
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for rs, lab, m in ((dense, "dense", "s-"), (fast, "fast", "o-")):
        if rs:
            n = [r["elements"] for r in rs]
            ax[0].loglog(n, [r["ms_per_step"] for r in rs], m, label=lab)
            ax[1].loglog(n, [r["peak_rss"] / 2**30 for r in rs], m, label=f"{lab}: peak RSS")
            ax[1].loglog(
                n, [r["operator_bytes"] / 2**30 for r in rs], m.replace("-", "--"), label=f"{lab}: operator"
            )
    if fast:
        n = np.array([r["elements"] for r in fast], float)
        ref = fast[0]["ms_per_step"] * (n * np.log(n)) / (n[0] * math.log(n[0]))
        ax[0].loglog(n, ref, "k:", label="N log N")
    ax[0].set(xlabel="elements", ylabel="ms per step", title="time per step")
    ax[1].set(xlabel="elements", ylabel="GiB", title="memory")
    for a in ax:
        a.grid(True, which="both", alpha=0.3)
        a.legend()
    fig.tight_layout()
    fig.savefig(path_png, dpi=110)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd")
    c = sub.add_parser("case")
    c.add_argument("--level", type=float, required=True)
    c.add_argument("--operator", default="fast")
    c.add_argument("--steps", type=int, default=30)
    c.add_argument("--save", help="also write the histories to this .npz")
    c.add_argument("--refactor-after", type=int, help="refresh the preconditioner above this many iterations")
    c.add_argument("--operator-tol", type=float, help="the fast operator's tolerance (default: femehl's)")
    sub.add_parser("report", help="rewrite the .md and .png from the .jsonl (and the textured .json)")
    x = sub.add_parser("textured")
    x.add_argument("--elements", type=int, default=200_000)
    x.add_argument("--t-end", type=float, default=5.0)
    x.add_argument("--out", default="femehl-out/textured_sphere")
    x2 = sub.add_parser("crossover", help="whole paper case, dense and fast in turn, around the crossover")
    x2.add_argument("--at", type=float, nargs="*", default=CROSSOVER_LEVELS, help="levels")
    x2.add_argument("--rounds", type=int, default=3)
    g = sub.add_parser("agree")
    g.add_argument("--level", type=float, required=True)
    g.add_argument("--t-end", type=float, default=5.0)
    g.add_argument("--sources", action="store_true", help="also split the fast path's difference by source")
    g.add_argument("--fast-rtol", type=float, action="append", default=[], help="also a fast run at it")
    g.add_argument("--fast-only", action="store_true", help="the reference and the default fast run only")
    g.add_argument(
        "--variant",
        action="append",
        default=[],
        metavar="P:ETA:SVD",
        help="experiment: also a fast run with this order, admissibility and truncation ratio",
    )
    e = sub.add_parser("error", help="relative operator error against sampled exact rows")
    e.add_argument("--level", type=float, required=True)
    e.add_argument("--tols", type=float, nargs="*", default=[1e-6])
    e.add_argument("--rows", type=int, default=ERROR_ROWS)
    e.add_argument("--vectors", type=int, default=ERROR_VECTORS, help="random vectors at once")
    e.add_argument("--p", type=int, help="experiment: this Chebyshev order instead of the tolerance's")
    e.add_argument("--svd-ratio", type=float, help="experiment: couplings truncated at this times tol")
    e.add_argument("--eta", type=float, help="experiment: this admissibility instead of the default's")
    ap.add_argument("--levels", type=float, nargs="*", default=LEVELS)
    ap.add_argument("--dense-levels", type=float, nargs="*", default=DENSE_LEVELS)
    ap.add_argument("--agree-levels", type=float, nargs="*", default=[1.0, 0.5])
    ap.add_argument("--error-levels", type=float, nargs="*", default=LEVELS[:2] + LEVELS[3:])
    ap.add_argument("--steps", type=int, default=30)
    ap.add_argument("--timeout", type=float, default=5400.0)
    ap.add_argument("--out", type=Path, default=HERE / "fast_operator")
    a = ap.parse_args(argv)
    if a.cmd == "case":
        print(json.dumps(case(a.level, a.operator, a.steps, a.save, a.refactor_after, a.operator_tol)))
        return 0
    if a.cmd == "textured":
        print(json.dumps(textured(a.elements, a.t_end, a.out)))
        return 0
    if a.cmd == "report":
        return _report(a.out)
    if a.cmd == "crossover":
        with a.out.with_suffix(".jsonl").open("a") as fh:
            for rec in crossover(a.at, a.rounds, a.timeout):
                fh.write(json.dumps(rec) + "\n")
        return _report(a.out)
    if a.cmd == "agree":
        rec = agree(a.level, a.t_end, a.sources, tuple(a.variant), tuple(a.fast_rtol), a.fast_only)
        print(json.dumps(rec))
        return 0
    if a.cmd == "error":
        for rec in operator_error(a.level, a.tols, a.rows, a.vectors, a.p, a.svd_ratio, a.eta):
            print(json.dumps(rec))
        return 0
    jsonl = a.out.with_suffix(".jsonl")
    rows, agreements, errors = [], [], []
    with jsonl.open("w") as fh:
        for level in a.levels:
            for op in ("dense", "fast") if level in a.dense_levels else ("fast",):
                r = _run(
                    ["case", "--level", str(level), "--operator", op, "--steps", str(a.steps)], a.timeout
                )
                rows.append(r)
                fh.write(json.dumps(r) + "\n")
                fh.flush()
                print(json.dumps(r), flush=True)
        for kind, levels, into in (
            ("error", a.error_levels, errors),
            ("agree", a.agree_levels, agreements),
        ):
            for level in levels:
                r = _run([kind, "--level", str(level)], a.timeout)
                r["kind"] = "operator_error" if kind == "error" else kind
                into.append(r)
                fh.write(json.dumps(r) + "\n")
                print(json.dumps(r), flush=True)
    return _report(a.out)


def _report(out: Path) -> int:
    rows, agreements, errors, crossings = [], [], [], []
    for line in out.with_suffix(".jsonl").read_text().splitlines():
        r = json.loads(line)
        kind = r.get("kind")
        into = {"agree": agreements, "operator_error": errors, "crossover": crossings}.get(kind, rows)
        into.append(r)
    tex_path = HERE / "fast_operator_textured.json"
    tex = json.loads(tex_path.read_text()) if tex_path.is_file() else None
    write(rows, agreements, out.with_suffix(".md"), out.with_suffix(".png"), tex, errors, crossings)
    return 0


if __name__ == "__main__":
    sys.exit(main())
