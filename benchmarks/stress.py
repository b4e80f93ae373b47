"""Stress matrix: does the lagged non-iterative scheme stay stable where relaxation fails?

Run from a source checkout::

    femehl bench stress [--quick] [--out DIR] [--only fe,fd,relax]

(or ``python benchmarks/stress.py ...``).  Writes ``DIR/stress_results.csv``
(one row per case, rewritten after every case so a partial run is readable)
and ``DIR/stress_results.md`` (summary lines, tables, notes).  Default DIR
is this folder.

The matrix (the paper's sphere, Eq. 12, with the sliding ramp time T free)::

    beta in {2, 20, 200, 2000, 20000}      h0 in {0.01, 0.1, 1}
    V = tanh((t - 1)/T), T in {0.1, 1}      dt in {0.002, 0.01, 0.05}

* femehl FE: every (beta, h0, T, dt) on the "coarse" mesh (90 cases); on the
  "medium" (default) mesh every (beta, h0, T) with dt in {0.01, 0.05} (60
  cases; dt = 0.002 on the medium mesh would add ~35 min to the 60-min budget
  of the run: it is left out).
* FD reference (dr = 0.025, dtheta = pi/36, 0.4-1.4 s per step on the
  shared machine, ~100x the FE coarse step): the corners beta in {2, 20000}
  x h0 in {0.01, 1} and the paper case beta = 200, h0 = 0.1, all at T = 0.1,
  dt = 0.05 (5 cases, 60 steps each).
* relaxation baseline (:mod:`femehl.reference.baseline`, coarse mesh): omega picked by
  a scan on the paper case (beta = 200, h0 = 0.1, T = 1, dt in {0.01, 0.05}),
  then every (beta, h0, T) with dt in {0.01, 0.05}, each case capped at
  ``--max-case-seconds`` of wall time.

Horizon: t_end = 3 for T = 0.1 (indentation to t = 1, sliding settled by
t = 1.3) and t_end = 5 for T = 1 (the paper's horizon), so that every case has
at least one time unit after the ramp has settled (t > 1 + 3T) to look for
spurious oscillation.

Recorded per case (see ``COLUMNS``): completed or stopped (exception, time,
place), minimum film over the run, non-finite values, the mass-balance
residual of every step (the discrete weak form; the load residual does not
apply to these imposed-gap runs), and oscillation measures over t > 1 + 3T:

* ``osc_min_per_t``: sign changes of the step-to-step change of the minimum
  film, per unit time.  Reported, but NOT a stability test: the minimum of
  an element-wise film hops between neighbouring elements while the exit
  constriction moves, so it reverses direction whenever the minimum changes
  element, at a rate set by the mesh, not by any instability.
* ``osc_elem_per_t``: the largest number, over elements (FD: nodes), of sign
  changes of the step-to-step change of the local film d, per unit time
  (changes smaller than 1e-6 d are ignored: round-off).
* ``sawtooth``: the longest run, over elements, of consecutive steps at
  which the local film change reverses sign.  A run of 3 is a period-2dt
  oscillation sustained over 4 steps: no signal the time step resolves can
  do that, so it is spurious by definition.

A case is *stable* when it completed, every value stayed finite and
``sawtooth < 3``.
"""

from __future__ import annotations

import argparse
import csv
import math
import pathlib
import sys
import time
import traceback

import numpy as np

import femehl
from femehl.errors import FemehlError, SolverError
from femehl.problem.scene import Domain, Fluid, HalfSpace, Motion, RampHold, Scene, Sphere, TanhStart
from femehl.solver.stepping import march

HERE = pathlib.Path(__file__).resolve().parent

BETAS = (2.0, 20.0, 200.0, 2000.0, 20000.0)
H0S = (0.01, 0.1, 1.0)
TS = (0.1, 1.0)
DTS = (0.002, 0.01, 0.05)
FD_OPTIONS = {"dr": 0.025, "dtheta": math.pi / 36}
OMEGAS = (0.02, 0.05, 0.1, 0.2, 0.5, 1.0)
SAWTOOTH_LIMIT = 3
NOISE = 1e-6

COLUMNS = (
    "solver",
    "mesh",
    "beta",
    "h0",
    "T",
    "dt",
    "t_end",
    "status",
    "error",
    "t_reached",
    "where_x",
    "where_y",
    "steps",
    "film_min",
    "film_min_end",
    "nonfinite",
    "mass_residual_max",
    "load_residual",
    "osc_min_per_t",
    "osc_elem_per_t",
    "sawtooth",
    "iters_mean",
    "iters_max",
    "wall_s",
    "stable",
)


def paper_scene(beta: float, h0: float, T: float) -> Scene:
    """The paper's sphere (Eq. 12) with sliding ramp time ``T``."""
    return Scene(
        indenter=Sphere(1.0),
        substrate=HalfSpace(0.5),
        fluid=Fluid(beta),
        motion=Motion(gap=RampHold(h0=h0, h_end=-1.0, t1=1.0), velocity=TanhStart(t1=1.0, T=T)),
        domain=Domain(2.0),
    )


def horizon(T: float) -> float:
    """t_end: 3, or long enough for one time unit after the ramp settles (t > 1 + 3T)."""
    return max(3.0, 1.0 + 3.0 * T + 1.0)


class OscillationTracker:
    """Sign changes of step-to-step changes, of film_min and of every local film value."""

    def __init__(self, t_start: float):
        self.t_start = t_start
        self.prev_min = None
        self.prev_dmin_sign = 0
        self.min_changes = 0
        self.prev_d = None
        self.last_sign = None
        self.run = None
        self.changes = None
        self.max_run = 0
        self.t_first = None
        self.t_last = None

    def update(self, t: float, film_min: float, d: np.ndarray):
        d = np.asarray(d, dtype=float)
        if self.prev_d is None:
            self.prev_d, self.prev_min = d.copy(), film_min
            self.last_sign = np.zeros(d.size, dtype=np.int8)
            self.run = np.zeros(d.size, dtype=np.int64)
            self.changes = np.zeros(d.size, dtype=np.int64)
            return
        delta = d - self.prev_d
        dmin = film_min - self.prev_min
        self.prev_d, self.prev_min = d.copy(), film_min
        if t <= self.t_start + 1e-12:
            return
        if self.t_first is None:
            self.t_first = t
        self.t_last = t
        # film_min (the oscillation measure)
        s = int(np.sign(dmin)) if abs(dmin) > NOISE * abs(film_min) else 0
        if s and self.prev_dmin_sign and s != self.prev_dmin_sign:
            self.min_changes += 1
        if s:
            self.prev_dmin_sign = s
        # local films
        sig = np.where(np.abs(delta) > NOISE * np.abs(d), np.sign(delta), 0).astype(np.int8)
        flip = (sig != 0) & (self.last_sign != 0) & (sig != self.last_sign)
        self.changes += flip
        self.run = np.where(flip, self.run + 1, 0)
        self.max_run = max(self.max_run, int(self.run.max(initial=0)))
        self.last_sign = np.where(sig != 0, sig, self.last_sign)
        # an insignificant change breaks a sawtooth run
        self.run[sig == 0] = 0

    def figures(self):
        if self.t_first is None or self.changes is None:
            return math.nan, math.nan, 0
        span = max(self.t_last - self.t_start, 1e-12)
        return self.min_changes / span, float(self.changes.max(initial=0)) / span, self.max_run


def make_case_stepper(solver: str, scene: Scene, mesh: str | None, omega: float | None):
    if solver == "fe":
        return femehl.make_stepper(scene, "fe", mesh=mesh)
    if solver == "fd":
        return femehl.make_stepper(scene, "fd", **FD_OPTIONS)
    if solver == "relax":
        from femehl.reference.baseline import RelaxationStepper

        return RelaxationStepper(scene, mesh=mesh, omega=omega)
    raise ValueError(solver)


def run_case(
    solver: str,
    beta: float,
    h0: float,
    T: float,
    dt: float,
    mesh: str | None = "coarse",
    t_end: float | None = None,
    omega: float | None = None,
    max_seconds: float | None = None,
) -> dict:
    """Run one case and return its row (a dict with the keys of COLUMNS)."""
    from femehl.reference.baseline import mass_balance_residual

    t_end = horizon(T) if t_end is None else t_end
    row = dict(
        solver=solver if solver != "relax" else f"relax(omega={omega:g})",
        mesh=mesh if solver != "fd" else "dr=0.025,dth=pi/36",
        beta=beta,
        h0=h0,
        T=T,
        dt=dt,
        t_end=t_end,
        status="completed",
        error="",
        t_reached=0.0,
        where_x="",
        where_y="",
        steps=0,
        film_min=math.inf,
        film_min_end=math.nan,
        nonfinite=False,
        mass_residual_max=0.0,
        load_residual="n/a (imposed gap)",
        osc_min_per_t=math.nan,
        osc_elem_per_t=math.nan,
        sawtooth=0,
        iters_mean="",
        iters_max="",
        wall_s=0.0,
        stable=False,
    )
    t0 = time.perf_counter()
    osc = OscillationTracker(1.0 + 3.0 * T)
    iters = []
    prev = None
    try:
        stepper = make_case_stepper(solver, paper_scene(beta, h0, T), mesh, omega)
        for state in march(stepper, t_end, dt):
            finite = (
                np.all(np.isfinite(state.p)) and np.all(np.isfinite(state.d)) and math.isfinite(state.load)
            )
            if not finite:
                row["nonfinite"] = True
            row["film_min"] = min(row["film_min"], state.film_min)
            row["film_min_end"] = state.film_min
            row["t_reached"] = state.t
            row["steps"] = state.step
            osc.update(state.t, state.film_min, state.d)
            if prev is not None:
                res = mass_balance_residual(
                    stepper, prev, state, "implicit" if solver == "relax" else "lagged"
                )
                row["mass_residual_max"] = max(row["mass_residual_max"], res)
                if solver == "relax":
                    iters.append(state.info.get("iterations", 0))
            prev = state
            if max_seconds is not None and time.perf_counter() - t0 > max_seconds and state.t < t_end:
                row["status"] = "timeout"
                row["error"] = f"wall-time cap {max_seconds:g} s reached at t = {state.t:.4g}"
                break
    except SolverError as exc:
        row["status"] = "stopped"
        row["error"] = f"{type(exc).__name__} at t = {exc.t:.4g}: {exc}".replace("\n", " ")
        where = getattr(exc, "where", None)
        if where is not None:
            row["where_x"], row["where_y"] = round(where[0], 4), round(where[1], 4)
        if getattr(exc, "iterations", None) is not None:
            iters.append(exc.iterations)
    except FemehlError as exc:
        row["status"] = "rejected"
        row["error"] = f"{type(exc).__name__}: {exc}"
    except Exception as exc:  # noqa: BLE001 - a crash is a finding, record it
        row["status"] = "crashed"
        row["error"] = f"{type(exc).__name__}: {exc} | " + traceback.format_exc(limit=3).replace("\n", " ")
    row["osc_min_per_t"], row["osc_elem_per_t"], row["sawtooth"] = osc.figures()
    if iters:
        row["iters_mean"] = round(float(np.mean(iters)), 1)
        row["iters_max"] = int(max(iters))
    row["wall_s"] = round(time.perf_counter() - t0, 2)
    row["stable"] = bool(
        row["status"] == "completed" and not row["nonfinite"] and row["sawtooth"] < SAWTOOTH_LIMIT
    )
    return row


# ---- the matrix ---------------------------------------------------------------------------
def fe_cases(quick: bool, meshes=("coarse", "medium"), medium_dts=(0.01, 0.05)):
    if quick:
        return [
            dict(solver="fe", beta=b, h0=h, T=0.1, dt=0.05, mesh="coarse")
            for b in (2.0, 20000.0)
            for h in (0.01, 1.0)
        ]
    out = []
    for mesh, dts in (("coarse", DTS), ("medium", medium_dts)):
        if mesh not in meshes:
            continue
        for b in BETAS:
            for h in H0S:
                for T in TS:
                    for dt in dts:
                        out.append(dict(solver="fe", beta=b, h0=h, T=T, dt=dt, mesh=mesh))
    return out


def fd_cases(quick: bool):
    if quick:
        return [dict(solver="fd", beta=200.0, h0=0.1, T=0.1, dt=0.05, mesh=None, t_end=1.5)]
    out = [
        dict(solver="fd", beta=b, h0=h, T=0.1, dt=0.05, mesh=None)
        for b in (2.0, 20000.0)
        for h in (0.01, 1.0)
    ]
    out.append(dict(solver="fd", beta=200.0, h0=0.1, T=0.1, dt=0.05, mesh=None))
    return out


def relax_cases(quick: bool, omega: float):
    if quick:
        return [
            dict(solver="relax", beta=b, h0=1.0, T=0.1, dt=0.05, mesh="coarse", omega=omega)
            for b in (2.0, 20000.0)
        ]
    return [
        dict(solver="relax", beta=b, h0=h, T=T, dt=dt, mesh="coarse", omega=omega)
        for b in BETAS
        for h in H0S
        for T in TS
        for dt in (0.01, 0.05)
    ]


def omega_scan(quick: bool, log=print):
    """Run the paper case (beta 200, h0 0.1, T 1) with each omega; best = furthest time reached."""
    rows = []
    dts = (0.05,) if quick else (0.01, 0.05)
    omegas = (0.1, 0.5) if quick else OMEGAS
    for om in omegas:
        reach, its = 0.0, []
        for dt in dts:
            r = run_case("relax", 200.0, 0.1, 1.0, dt, mesh="coarse", omega=om, max_seconds=120)
            reach += r["t_reached"]
            if r["iters_mean"] != "":
                its.append(r["iters_mean"])
            rows.append(r)
            log(
                f"  omega scan: omega = {om:g}, dt = {dt:g}: {r['status']} at t = {r['t_reached']:.3g}, "
                f"iterations/step {r['iters_mean']} (max {r['iters_max']})"
            )
    best = max(
        omegas,
        key=lambda om: (
            sum(r["t_reached"] for r in rows if r["solver"] == f"relax(omega={om:g})"),
            -np.mean([r["iters_mean"] or 1e9 for r in rows if r["solver"] == f"relax(omega={om:g})"]),
        ),
    )
    return best, rows


# ---- writing --------------------------------------------------------------------------------
def _fmt(v):
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf"
        return f"{v:.6g}"
    return str(v)


def write_csv(rows, path):
    tmp = path.with_suffix(".csv.tmp")
    with open(tmp, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(COLUMNS)
        for r in rows:
            w.writerow([_fmt(r[c]) for c in COLUMNS])
    tmp.replace(path)


def read_csv(path):
    """Rows of a written stress_results.csv, numbers and flags converted back."""
    rows = []
    with open(path, newline="") as fh:
        for r in csv.DictReader(fh):
            for k, v in r.items():
                if v in ("True", "False"):
                    r[k] = v == "True"
                elif k not in ("solver", "mesh", "status", "error", "load_residual"):
                    try:
                        r[k] = float(v) if v != "" else ""
                    except ValueError:
                        pass
            rows.append(r)
    return rows


def summary_lines(rows, omega=None):
    out = []
    for label, pred in (
        ("femehl FE", lambda r: r["solver"] == "fe"),
        ("femehl FD (paper-faithful reference)", lambda r: r["solver"] == "fd"),
        (
            f"relaxation baseline (omega = {omega:g})" if omega else "relaxation baseline",
            lambda r: r["solver"].startswith("relax"),
        ),
    ):
        sel = [r for r in rows if pred(r)]
        if sel:
            n = sum(1 for r in sel if r["stable"])
            out.append(f"{label}: {n} stable / {len(sel)} cases")
    return out


MD_COLUMNS = (
    "mesh",
    "beta",
    "h0",
    "T",
    "dt",
    "status",
    "t_reached",
    "film_min",
    "mass_residual_max",
    "osc_min_per_t",
    "osc_elem_per_t",
    "sawtooth",
    "iters_mean",
    "iters_max",
    "wall_s",
    "stable",
)


def _md_table(rows, cols=MD_COLUMNS):
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        lines.append("| " + " | ".join(_fmt(r[c]) for c in cols) + " |")
    return lines


def write_md(rows, path, omega, scan_rows, wall, notes=""):
    lines = [
        "# Stress matrix: femehl FE, FD reference and the relaxation baseline",
        "",
        "Generated by `femehl bench stress` (benchmarks/stress.py); the method, matrix and",
        "definitions are in that file's docstring.  Stable = completed, all values finite, and",
        f"no element whose film change reverses sign at {SAWTOOTH_LIMIT} consecutive steps (sawtooth).",
        "",
        "## Summary",
        "",
    ]
    lines += [f"- {s}" for s in summary_lines(rows, omega)]
    lines += [
        "",
        f"Wall time: {wall / 60:.1f} min, the sum of the cases' wall times (OMP_NUM_THREADS=1, "
        "on a shared 2-core machine under load).",
        "",
    ]
    if notes:
        lines += ["## What fails and why", "", notes.strip(), ""]
    if scan_rows:
        lines += [
            "## Relaxation: omega scan on the paper case (beta 200, h0 0.1, T 1, coarse mesh)",
            "",
            f"Best fixed omega (furthest time reached, then fewest iterations): {omega:g}.",
            "",
        ]
        lines += _md_table(
            scan_rows, ("solver", "dt", "status", "t_reached", "iters_mean", "iters_max", "wall_s")
        )
        lines.append("")
    for label, pred in (
        ("femehl FE", lambda r: r["solver"] == "fe"),
        ("FD reference", lambda r: r["solver"] == "fd"),
        ("Relaxation baseline", lambda r: r["solver"].startswith("relax")),
    ):
        sel = [r for r in rows if pred(r)]
        if not sel:
            continue
        lines += [f"## {label}", ""] + _md_table(sel) + [""]
        stopped = [r for r in sel if r["status"] != "completed"]
        if stopped:
            lines += [f"### {label}: why the stopped cases stopped", ""]
            for r in stopped:
                lines.append(
                    f"- {r['mesh']}, beta {r['beta']:g}, h0 {r['h0']:g}, T {r['T']:g}, dt {r['dt']:g}: "
                    f"{r['error'][:300]}"
                )
            lines.append("")
    path.write_text("\n".join(lines))


#: Interpretation of the committed run (benchmarks/stress_results.md), written after reading it.
NOTES = """
**femehl FE: 116 stable / 150.**  No case produced a non-finite value, no case showed a
sawtooth (the longest run of consecutive reversals of any element's film is 2, below the
limit 3), and every step solved its weak form (mass-balance residual <= 4e-7, most
1e-10..1e-8: the linear-solver tolerance).  All 34 unstable cases stopped with the
documented FilmRuptureError naming time and place; none crashed.  They fall in two groups:

1. beta = 20000, every h0, T, dt and both meshes (30 cases) -- numerics: resolution.
   The films are of order 1e-3 (beta = 2000 gives minimum films of 0.002-0.004;
   soft-EHL films fall roughly like beta^-0.65).  At dt = 0.05 the run stops during
   the indentation ramp (t <= 0.55) at the tip: one step closes the rigid gap by
   (1 + h0) dt >= 0.05, more than the film,
   while the film's mobility d^3 is lagged from the previous, thicker step -- the lag
   error is larger than the film.  At dt <= 0.01 the indentation survives and the run
   stops at t = 1.1-1.9 in the side lobes of the horseshoe constriction (r ~ 1,
   |y| = 0.6-0.94) during the sliding start, where neither the coarse nor the medium
   mesh resolves the constriction.  Outside the matrix, beta = 20000, h0 = 0.1, T = 0.1,
   dt = 0.01 on the *fine* mesh runs through the start-up (t = 2, minimum film 0.00098 in
   the side lobes): what the error message suggests (finer mesh, smaller dt) is the fix.
2. beta = 2, h0 = 0.01 (coarse dt = 0.002 and medium dt = 0.01, both T; 4 cases) --
   physics that the mesh does not resolve.  The fast indentation of a very thin initial
   gap traps a large fluid pocket (central film 0.3-0.47 against a rim of 0.01); the
   sliding carries it out through the exit, and behind it the centreline film at
   x = -1.2 ... -1.65 thins sharply (on the medium mesh at dt = 0.002, outside the matrix:
   down to 0.0025 at t = 2.52, then it recovers).  Whether the discrete film touches zero
   in this transient depends on mesh and step (coarse dt = 0.01/0.05 and medium dt = 0.05
   come through): a genuine thin-film event whose depth is not converged at these
   resolutions, stopped with the documented error rather than continued with a negative
   film.

The oscillation measure (sign changes of the change of the minimum film,
osc_min_per_t) reaches 20-33 per unit time in the beta = 2-20, h0 = 0.01 cases: the
minimum hops between neighbouring elements while the trapped pocket's rim travels
through the exit (each element's film stays smooth: sawtooth <= 2), so it is reported
but not used as the stability test.

**FD reference (dr = 0.025, dtheta = pi/36, dt = 0.05): 2 stable / 5.**  beta = 20000
stops like FE at dt = 0.05 (tip, indentation ramp: numerics, dt).  beta = 2, h0 = 0.01
blows up one step after the sliding starts (t = 1.05, film -1e6 at the centre): the
paper's forward differences are downwind on the exit side -- a numerical instability,
where the FE scheme completes this case at dt = 0.05 on both meshes.  The paper case
(beta = 200, h0 = 0.1) and beta = 2, h0 = 1 complete.

**Relaxation baseline (omega = 0.1, tol 1e-6, 200 iterations, coarse mesh, dt 0.01 and
0.05): 0 stable / 60.**  No case reaches the sliding phase: the furthest last good state
is t = 0.7 (beta = 20, h0 = 1, dt = 0.05); 28 cases fail in their first step.  Every case
stops with RelaxationDivergedError, either because the iterate's film goes negative
(divergence) or because 200 iterations do not bring the pressure change below 1e-6; in
the 32 cases with at least one converged step the mean is 56-200 iterations per step
(each iteration one sparse Reynolds solve and one dense elastic product, ~7 ms on the
coarse mesh: 0.4-1.4 s per step against femehl's ~10 ms).  The fixed-point map's
sensitivity (beta K)^-1 (M/dt) C has
eigenvalues up to -9000 at beta = 2, dt = 0.002 already at t = 0 (film 0.1) and grows like
1/(beta dt d^3) as the contact forms, so a fixed omega small enough to converge in the
thin-film phase (< 2/(1 + |lambda|)) needs thousands of iterations per step everywhere.
That is the failure of relaxation the paper describes (section 1); femehl's scheme
solves one linear system per step instead.
"""


def main(argv=None):
    ap = argparse.ArgumentParser(prog="femehl bench stress", description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="a handful of corner cases (about a minute)")
    ap.add_argument("--out", default=str(HERE), help="output folder (default: benchmarks/)")
    ap.add_argument("--only", default="fe,fd,relax", help="comma list of solvers to run")
    ap.add_argument("--fe-meshes", default="coarse,medium", help="FE meshes of the matrix")
    ap.add_argument("--medium-dt", default="0.01,0.05", help="time steps run on the medium mesh")
    ap.add_argument(
        "--from-csv",
        action="store_true",
        help="only rewrite the Markdown from an existing stress_results.csv in --out",
    )
    ap.add_argument(
        "--max-case-seconds", type=float, default=60.0, help="wall-time cap per relaxation case (default 60)"
    )
    args = ap.parse_args(argv)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    which = set(args.only.split(","))
    t0 = time.perf_counter()
    rows, scan_rows, omega = [], [], None
    csv_path, md_path = out / "stress_results.csv", out / "stress_results.md"

    def done(r):
        rows.append(r)
        write_csv(scan_rows + rows, csv_path)
        print(
            f"{r['solver']:>18} {str(r['mesh']):>18} beta={r['beta']:<7g} h0={r['h0']:<5g} T={r['T']:<4g} "
            f"dt={r['dt']:<6g} {r['status']:>9} t={r['t_reached']:.4g} dmin={r['film_min']:.3g} "
            f"res={r['mass_residual_max']:.2g} saw={r['sawtooth']} osc={r['osc_min_per_t']:.3g} "
            f"its={r['iters_mean']} {r['wall_s']:.1f}s stable={r['stable']}",
            flush=True,
        )

    if args.from_csv:
        rows = read_csv(csv_path)
        scan_rows = [r for r in rows if r["solver"].startswith("scan")]
        rows = [r for r in rows if not r["solver"].startswith("scan")]
        omega = float(scan_rows[0]["error"].split("best omega = ")[1].split(";")[0]) if scan_rows else None
        wall = sum(float(r["wall_s"]) for r in rows + scan_rows)
        write_md(rows, md_path, omega, scan_rows, wall, "" if args.quick else NOTES)
        print("\n".join(summary_lines(rows, omega)))
        return 0
    if "relax" in which:
        print("relaxation baseline: omega scan", flush=True)
        omega, scan_rows = omega_scan(args.quick)
        for r in scan_rows:
            r["solver"] = "scan " + r["solver"]
            r["error"] = f"best omega = {omega:g}; " + r["error"]
        print(f"relaxation baseline: best omega = {omega:g}", flush=True)
    cases = []
    if "fe" in which:
        cases += fe_cases(
            args.quick, args.fe_meshes.split(","), tuple(float(x) for x in args.medium_dt.split(","))
        )
    if "fd" in which:
        cases += fd_cases(args.quick)
    if "relax" in which:
        cases += relax_cases(args.quick, omega)
    for c in cases:
        kw = dict(c)
        if kw["solver"] == "relax":
            kw["max_seconds"] = args.max_case_seconds
        done(run_case(**kw))
    wall = time.perf_counter() - t0
    notes = "" if args.quick else NOTES
    write_md(rows, md_path, omega, scan_rows, wall, notes)
    print("\n".join(summary_lines(rows, omega)))
    print(f"wall time {wall / 60:.1f} min; wrote {csv_path} and {md_path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
