"""Time steps balanced against space (issue 42, item 3): what the adaptive controller's
tolerance buys on the paper case, where its steps go, and a PI controller beside it.

The automatic mode (``femehl.solve(scene, tol=...)``, :mod:`femehl.accuracy.auto`) runs
each level of its ladder with adaptive BDF2 steps at ``tol_t = TAU1 * level**2``
(:func:`femehl.accuracy.auto.time_tolerance`).  This study measures, on the scene-fitted
meshes of the last two levels the paper case (``femehl.presets.paper_sphere()``,
``t_end = 5``) runs at ``tol = 1e-2``:

* adaptive BDF2 (:class:`femehl.solver.adaptive.AdaptiveSteps`, femehl's I controller) at
  ``step_tol = m * TAU1 * level**2``, ``m`` in :data:`MULTS` and a check near the balance
  (:data:`CHECK_MULTS`): accepted steps, rejected trials, the wall time of the run (the
  operators' set-up, once per mesh, apart), Krylov iterations and LU refreshes of the
  preconditioner, and the true error of load, central and minimum film;
* fixed-step BDF2 at the steps of :data:`FIXED_DT` on the same mesh: the same figures.
  The two finest give the mesh's time-converged solution (Richardson in dt, order 2), so
  each run's error splits into its space part (time-converged against the reference, the
  reference's own dt = 0.005 time error removed) and its time part (run against the
  time-converged solution);
* where the steps go (initial layer, indentation ramp to its breakpoint t = 1, sliding
  start t in (1, 3], near-steady sliding t in (3, 5]) and whether the controller chatters
  (rejections of a step just accepted at that size, hard cuts, reversals of the step's
  direction of change);
* the controller's per-step ``error_estimate`` accumulated as the automatic mode does
  (:func:`femehl.accuracy.auto.time_error`) against the time error actually made;
* other controllers, defined here without touching femehl (swapped into a subclass of
  ``AdaptiveSteps``): femehl's own with its largest growth at the hold, 1.5, instead of 2
  ("I-max1.5"), and two with memory (:class:`FilterController`): Gustafsson's PI
  ("PI3040", ``kI = 0.3/k``, ``kP = 0.4/k``; K. Gustafsson, ACM TOMS 17 (1991) 533-554
  and 20 (1994) 496-517; Hairer, Norsett and Wanner, Solving ODEs I, section II.4) and
  Soderlind's low-pass filter H211b with b = 4 (G. Soderlind, ACM TOMS 29 (2003) 1-26).

The true error is computed as ``benchmarks/auto.py`` does for this scene (its ``_ref`` and
``_compared``): against ``auto_reference_scenes.json`` (levels 0.35 / 0.25, BDF2 dt = 0.005,
Richardson in h), max over the reference's times from t = 8 reference steps (0.04) on, the
load relative to max(|ref|, 0.1), the films relative; an adaptive run is interpolated to
the reference's times (PCHIP between the motion's breakpoints), a fixed-step run compared
at its own times.

Each mesh runs in one subprocess with one BLAS thread; its operators are built once and
every run on it gets a fresh linear solver (the same as a fresh stepper).  Raw rows go to
``time_balance.jsonl`` as they come (``--resume`` skips those present), the tables to
``time_balance.md`` and the plot to ``time_balance.png``.

Run (about 17 minutes here, one core)::

    python benchmarks/time_balance.py                  # the automatic run, both meshes, tables
    python benchmarks/time_balance.py --resume         # what is missing only
    python benchmarks/time_balance.py --analyze-only   # tables and plot from time_balance.jsonl
"""

from __future__ import annotations

import argparse
import json
import math
import os
import pathlib
import subprocess
import sys
import time

from _machine import load_average, machine, provenance

HERE = pathlib.Path(__file__).resolve().parent
#: the automatic mode's time tolerance at level 1 when this study was made (femehl.auto's
#: TAU1 until 2026-12-05; now 5 times it): kept so that the study reruns as it was made
STUDY_TAU1 = 1.25e-3
RUNS = HERE / "time_balance.jsonl"
TABLE = HERE / "time_balance.md"
PLOT = HERE / "time_balance.png"
REFERENCE = HERE / "auto_reference_scenes.json"
SCENE = "paper"
T_END = 5.0
TOL = 1e-2
QUANTITIES = ("load", "film_center", "film_min")
#: the last two levels of ``femehl.solve(paper, tol=1e-2)`` (auto_runs.jsonl: 4, 2, 1, 0.5);
#: the automatic run of this script replaces them with the levels it ran
DEFAULT_LEVELS = (1.0, 0.5)
#: step_tol = m * TAU1 * level**2
MULTS = (1, 2, 4, 8, 16, 32)
#: ... and a check near the balance the first pass found (m* = 3.8 to 7 on both meshes)
CHECK_MULTS = (5,)
#: the multipliers each controller is run at (femehl's "I" and the two with memory)
CONTROLLER_MULTS = {
    "I": tuple(sorted(MULTS + CHECK_MULTS)),
    "I-max1.5": tuple(sorted(MULTS + CHECK_MULTS)),
    "PI3040": tuple(sorted(MULTS + CHECK_MULTS)),
    "H211b": tuple(sorted((1, 4, 16) + CHECK_MULTS)),
}
#: fixed BDF2 steps; the last two give the time-converged solution (Richardson in dt)
FIXED_DT = (0.04, 0.02, 0.01, 0.005, 0.0025)
#: the phases of the paper's motion (ramp to hc = -1 at t = 1, then V = tanh(t - 1))
PHASES = (
    ("initial layer", 0.0, 0.04),
    ("indentation ramp", 0.04, 1.0),
    ("sliding start", 1.0, 3.0),
    ("near-steady sliding", 3.0, 5.0),
)
#: the time error aimed at, as a fraction of the mesh's space error
BALANCE = 1.0 / 3.0
#: the BDF2 order (Richardson in dt) and the series' rounding in the jsonl
ORDER = 2
DIGITS = 12


# ---- controllers with memory (femehl is not changed) ------------------------------------
class FilterController:
    """A drop-in for :class:`femehl.solver.adaptive.StepController` with memory.

    ``kind`` "PI3040": ``f = safety (tol/e_n)^(0.7/k) (e_{n-1}/tol)^(0.4/k)``, i.e.
    ``(tol/e_n)^kI (e_{n-1}/e_n)^kP`` with ``kI = 0.3/k``, ``kP = 0.4/k`` (Gustafsson);
    "H211b": ``f = safety (tol/e_n)^(1/(b k)) (tol/e_{n-1})^(1/(b k)) (h_n/h_{n-1})^(-1/b)``,
    b = 4 (Soderlind).  ``k`` is femehl's exponent: the order p for steps >= UNIT_STEP (an
    error per unit time, ~ h^p), p + 1 below.  The memory ``(e_{n-1}, h_{n-1})`` is of the
    last accepted BDF2 step; a rejected trial, the start pair of a (re)start and the first
    step after it use femehl's elementary rule ``safety (tol/e)^(1/k)``, and a start pair
    clears the memory.  Limits (fac_min, fac_max, the hold below 1.5, no growth right after
    a rejection) are femehl's, applied by ``AdaptiveSteps`` as for its own controller.  The
    hold keeps ``dt`` when the factor is in [1, 1.5): the filter then goes on from its own
    step ``h_n`` (the step it asked for, within fac_min..fac_max of the step taken), not
    the held one, so that its integral part accumulates (with a constant error
    PI3040's factor is ``(tol/e)^(0.3/k)``: restarted from the held step each time it would
    grow only once the error is 30 times below tol).
    """

    def __init__(self, tol: float, safety: float, kind: str, b: float = 4.0):
        from femehl.solver.adaptive import StepController

        base = StepController(tol, safety)
        self.tol, self.safety, self.kind, self.b = tol, safety, kind, b
        self.fac_min, self.fac_max, self.hold = base.fac_min, base.fac_max, base.hold
        self._ok = False
        self._prev = None  # (e_{n-1}, h_{n-1}) of the last accepted BDF2 step
        self._virtual = None  # the filter's own next step (before the hold)

    def accepts(self, err: float) -> bool:
        self._ok = err <= self.tol
        return self._ok

    def factor(self, err: float, order: int, grow: bool = True, dt: float = math.inf) -> float:
        from femehl.solver.adaptive import UNIT_STEP

        top = self.fac_max if grow else 1.0
        k = order if dt >= UNIT_STEP else order + 1
        accepted = self._ok
        self._ok = False
        if not (accepted and order > 1):  # a rejection, or a start pair (a new history)
            if accepted:
                self._prev = None
            self._virtual = None
            f = top if not err > 0.0 else self.safety * (self.tol / err) ** (1.0 / k)
            return min(top, max(self.fac_min, f))
        # an accepted BDF2 step: the filter acts on its own (virtual) step, which the hold
        # may leave unapplied, so that its integral part accumulates through the hold
        h = dt if self._virtual is None else self._virtual
        if not err > 0.0:
            f, self._prev = top * dt / h, None
        elif self._prev is None:
            f = self.safety * (self.tol / err) ** (1.0 / k)
        else:
            e1, h1 = self._prev
            if self.kind == "PI3040":
                f = self.safety * (self.tol / err) ** (0.7 / k) * (e1 / self.tol) ** (0.4 / k)
            elif self.kind == "H211b":
                bk = self.b * k
                f = (
                    self.safety
                    * (self.tol / err) ** (1.0 / bk)
                    * (self.tol / e1) ** (1.0 / bk)
                    * (h / h1) ** (-1.0 / self.b)
                )
            else:
                raise ValueError(f"unknown controller {self.kind!r}")
        ratio = min(top, max(self.fac_min, h * f / dt))  # anti-windup: within femehl's limits
        if err > 0.0:
            self._prev = (err, h)
        self._virtual = ratio * dt
        return ratio


def filtered_steps(tol: float, kind: str):
    """``AdaptiveSteps(tol)`` with another controller: :class:`FilterController` ("PI3040",
    "H211b"), or femehl's own with its largest growth at the hold, 1.5 ("I-max1.5")."""
    from femehl.solver.adaptive import AdaptiveSteps, StepController

    class FilteredSteps(AdaptiveSteps):
        def begin(self, stepper, t_end, start):
            state = super().begin(stepper, t_end, start)
            if kind == "I-max1.5":
                self._ctl = StepController(self.tol, self.safety, fac_max=1.5)
            else:
                self._ctl = FilterController(self.tol, self.safety, kind)
            return state

    return FilteredSteps(tol)


class _Trials:
    """The stepper, logging every trial step ``(t_base, t_new)`` (accepted or not)."""

    def __init__(self, stepper):
        self._stepper = stepper
        self.log = []

    def __getattr__(self, name):
        return getattr(self._stepper, name)

    def step(self, state, t_new, dt):
        self.log.append((float(state.t), float(t_new)))
        return self._stepper.step(state, t_new, dt)


# ---- workers (subprocesses) -----------------------------------------------------------
def _round(xs) -> list:
    return [float(f"{x:.{DIGITS}g}") if math.isfinite(x) else None for x in xs]


def auto_worker() -> dict:
    """Today's automatic run at tol = 1e-2: its levels, cells, steps and wall times."""
    import femehl

    scene = femehl.presets.paper_sphere()
    t0 = time.perf_counter()
    res = femehl.solve(scene, t_end=T_END, tol=TOL, store_every=0)
    a = res.info["auto"]
    keys = ("levels", "elements", "steps", "rejected_steps", "tol_t", "wall", "reached", "total")
    return {"kind": "auto", "tol": TOL, "wall_s": time.perf_counter() - t0, **{k: a.get(k) for k in keys}}


def level_worker(level: float, specs: list) -> None:
    """Every run of ``specs`` on the fitted mesh of ``level`` (operators built once),
    each record appended to :data:`RUNS` as it finishes."""
    import femehl
    from femehl.accuracy.auto import LADDERS
    from femehl.solver.adaptive import AdaptiveSteps
    from femehl.solver.linsolve import make_linear_solver
    from femehl.solver.loop import make_stepper
    from femehl.solver.stepping import FixedSteps, march

    scene = femehl.presets.paper_sphere()
    t0 = time.perf_counter()
    options = {"scheme": "bdf2", **LADDERS["fe"].options(scene, T_END, level)}  # as auto._run
    stepper = make_stepper(scene, "fe", **options)
    setup = time.perf_counter() - t0
    base_tol = STUDY_TAU1 * level**2
    for spec in specs:
        stepper.solver = make_linear_solver(stepper.info["linear_solver"])  # a fresh solver
        if spec["kind"] == "fixed":
            policy = FixedSteps(spec["dt"])
        else:
            step_tol = spec["mult"] * base_tol
            spec = dict(spec, step_tol=step_tol)
            ctl = spec["controller"]
            policy = AdaptiveSteps(step_tol) if ctl == "I" else filtered_steps(step_tol, ctl)
        proxy = _Trials(stepper)
        rows = []
        rec = dict(spec, scene=SCENE, level=level, status="ok")
        t1 = time.perf_counter()
        try:
            for s in march(proxy, T_END, policy):
                info = s.info or {}
                rows.append(
                    (
                        s.t,
                        s.load,
                        s.film_center,
                        s.film_min,
                        info.get("dt", math.nan),
                        info.get("error_estimate", math.nan),
                        info.get("rejected", 0),
                    )
                )
        except femehl.FemehlError as exc:
            rec["status"] = f"{type(exc).__name__}: {exc}"
        wall = time.perf_counter() - t1
        cols = list(zip(*rows, strict=True)) if rows else [[]] * 7
        accepted = {float(t) for t in cols[0]}
        rec.update(
            wall_s=wall,
            setup_s=setup,
            elements=int(stepper.info["elements"]),
            steps=max(0, len(rows) - 1),
            rejected=int(sum(cols[6])),
            factorizations=int(stepper.solver.info.get("factorizations", 0)),
            krylov_iterations=int(stepper.solver.info.get("krylov_iterations", 0)),
            t=_round(cols[0]),
            **{q: _round(cols[i + 1]) for i, q in enumerate(QUANTITIES)},
            dts=_round(cols[4]),
            error_estimate=_round(cols[5]),
            rejected_at=[int(r) for r in cols[6]],
            trial_t=_round([b for _, b in proxy.log]),
            trial_h=_round([b - a for a, b in proxy.log]),
            trial_ok=[b in accepted for _, b in proxy.log],
            loadavg=load_average(),
            **provenance(),
        )
        with RUNS.open("a") as fh:
            fh.write(json.dumps(rec) + "\n")
        print(
            f"level {level:g} {_label(rec)}: {rec['steps']} steps, {rec['rejected']} rejected, "
            f"{wall:.1f} s ({rec['status'][:60]})",
            flush=True,
        )


def _env() -> dict:
    env = dict(os.environ)
    for v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        env[v] = "1"
    env.setdefault("MPLBACKEND", "Agg")
    return env


def _label(r: dict) -> str:
    if r["kind"] == "fixed":
        return f"fixed dt = {r['dt']:g}"
    return f"{r['controller']} x{r['mult']:g}"


def _key(r: dict) -> tuple:
    return (r.get("kind"), r.get("level"), r.get("dt"), r.get("controller"), r.get("mult"))


def read_runs() -> list:
    if not RUNS.exists():
        return []
    return [json.loads(line) for line in RUNS.read_text().splitlines() if line.strip()]


def specs_for() -> list:
    specs = [{"kind": "fixed", "dt": dt} for dt in FIXED_DT]
    for ctl, mults in CONTROLLER_MULTS.items():
        specs += [{"kind": "adaptive", "controller": ctl, "mult": m} for m in mults]
    return specs


# ---- analysis ---------------------------------------------------------------------------
def _scale(q: str, values):
    import numpy as np

    return np.maximum(np.abs(values), 0.1 if q == "load" else 0.0)


def _view(rec: dict, every: int = 1) -> dict:
    """``rec`` as ``benchmarks/auto.py``'s ``_compared`` reads a record ("hand": fixed steps)."""
    out = {"kind": "hand" if rec["kind"] == "fixed" else "auto", "t": rec["t"][::every]}
    out.update({q: rec[q][::every] for q in QUANTITIES})
    return out


def _max_err(rec: dict, target: dict, q: str, every: int = 1, series: bool = False):
    """Max over the compared times of ``|rec - target| / scale`` (``target`` on a grid), or
    the times and errors when ``series``."""
    import numpy as np
    from auto import _compared

    tc, qv, qr, _ = _compared(_view(rec, every), target, q, _breakpoints())
    e = np.abs(qv - qr) / _scale(q, qr)
    if series:
        return tc, e
    return float(np.max(e)) if e.size else math.nan


def _breakpoints() -> tuple:
    import femehl

    return tuple(femehl.presets.paper_sphere().motion.breakpoints)


def _fixed(runs: list, level: float, dt: float):
    for r in runs:
        if r["kind"] == "fixed" and r["level"] == level and abs(r["dt"] - dt) < 1e-12 and r["status"] == "ok":
            return r
    return None


def _on_grid(rec: dict, grid, q: str):
    """``rec``'s ``q`` at the times ``grid`` (each must be one of its own times)."""
    import numpy as np

    t = np.asarray(rec["t"])
    idx = np.searchsorted(t, np.asarray(grid) - 1e-9)
    if np.max(np.abs(t[idx] - grid)) > 1e-9:
        raise RuntimeError(f"{_label(rec)}: the grid is not in its times")
    return np.asarray(rec[q], dtype=float)[idx]


def converged(runs: list, level: float, ref: dict) -> dict | None:
    """The mesh's time-converged solution and its space error.

    ``tc = q(dt2) + (q(dt2) - q(dt1)) / 3`` on the dt1 grid (the two finest fixed steps);
    its uncertainty: its difference to the same extrapolation one step coarser.  The space
    error: ``tc`` against the reference with the reference's own time error removed
    (``ref + (q_a - q_a(2 DT)) / 3`` from its level-0.35 runs at DT and 2 DT, on the 2 DT
    grid), and against the reference as stored (on its grid).
    """
    import numpy as np

    dt0, dt1, dt2 = FIXED_DT[-3:]
    r0, r1, r2 = (_fixed(runs, level, dt) for dt in (dt0, dt1, dt2))
    if r1 is None or r2 is None:
        return None
    t1 = np.asarray(r1["t"])
    out = {"t": t1.tolist(), "reference": {}, "t_from": ref["t_from"]}
    unc, space, space_raw = {}, {}, {}
    refs = json.loads(REFERENCE.read_text())["scenes"][SCENE]["runs"]
    ra, ra2 = refs["a"], refs["a_dt2"]
    t2g = np.asarray(ra2["t"])
    for q in QUANTITIES:
        q1, q2 = np.asarray(r1[q], dtype=float), _on_grid(r2, t1, q)
        tc = q2 + (q2 - q1) / (2**ORDER - 1)
        out["reference"][q] = tc.tolist()
        keep = t1 >= ref["t_from"] - 1e-9
        scale = _scale(q, np.interp(t1, ref["t"], ref["reference"][q]))
        if r0 is not None:  # the coarser extrapolation, on the dt0 grid
            t0g = np.asarray(r0["t"])
            c0 = _on_grid(r1, t0g, q) + (_on_grid(r1, t0g, q) - np.asarray(r0[q])) / (2**ORDER - 1)
            k0 = t0g >= ref["t_from"] - 1e-9
            unc[q] = float(
                np.max((np.abs(np.interp(t0g, t1, tc) - c0) / _scale(q, np.interp(t0g, t1, tc)))[k0])
            )
        qa = _on_grid(ra, t2g, q)
        ref_tc = np.interp(t2g, ref["t"], ref["reference"][q]) + (qa - np.asarray(ra2[q])) / (2**ORDER - 1)
        k2 = t2g >= ref["t_from"] - 1e-9
        tc2 = np.interp(t2g, t1, tc)
        err = np.abs(tc2 - ref_tc) / _scale(q, ref_tc)
        space[q] = float(np.max(err[k2]))
        space_raw[q] = float(
            np.max((np.abs(tc - np.interp(t1, ref["t"], ref["reference"][q])) / scale)[keep])
        )
        out.setdefault("space_series", {})[q] = (t2g[k2].tolist(), err[k2].tolist())
    out.update(uncertainty=unc, space=space, space_raw=space_raw)
    return out


def chatter(rec: dict) -> dict:
    """Rejected trials right after an accepted step of the same or a smaller size (the
    estimate jumped at a step that had just passed), hard cuts (a second rejection of the
    same step: dt x fac_min), accepted-step changes of dt and reversals of their direction."""
    import numpy as np

    ok = rec["trial_ok"]
    h = rec["trial_h"]
    after_ok = sum(1 for i in range(1, len(ok)) if not ok[i] and ok[i - 1] and h[i] >= h[i - 1] * (1 - 1e-9))
    cuts = sum(1 for i in range(1, len(ok)) if not ok[i] and not ok[i - 1])
    dt = np.asarray([x for x in rec["dts"][1:] if x is not None], dtype=float)
    steps = np.diff(np.log(dt)) if dt.size > 1 else np.zeros(0)
    moves = np.sign(steps[np.abs(steps) > 0.01])
    reversals = int(np.sum(moves[1:] != moves[:-1])) if moves.size > 1 else 0
    return {"after_ok": after_ok, "cuts": cuts, "dt_changes": int(moves.size), "reversals": reversals}


def cost_model(rows: list) -> dict | None:
    """Least squares ``wall = a trials + b Krylov iterations + c LU refreshes`` over the runs."""
    import numpy as np

    if len(rows) < 4:
        return None
    X = np.array(
        [[len(r["trial_h"]), r["krylov_iterations"], r["factorizations"]] for r in rows], dtype=float
    )
    y = np.array([r["wall_s"] for r in rows])
    c = np.linalg.lstsq(X, y, rcond=None)[0]
    dev = np.abs(X @ c - y) / y
    return {"trial_ms": 1e3 * c[0], "iteration_ms": 1e3 * c[1], "lu_ms": 1e3 * c[2], "dev": float(dev.max())}


def phases(rec: dict, tc_errors: dict | None = None) -> list:
    """Per phase: accepted steps, median and largest dt, rejected trials, the controller's
    accumulated estimate over the phase and the largest time error there."""
    import numpy as np

    t = np.asarray(rec["t"], dtype=float)
    dt = np.asarray([math.nan if x is None else x for x in rec["dts"]], dtype=float)
    est = _accumulated(rec)
    rej = np.asarray(rec["rejected_at"])
    out = []
    for name, a, b in PHASES:
        m = (t > a + 1e-12) & (t <= b + 1e-9)
        before = est[t <= a + 1e-12][-1] if np.any(t <= a + 1e-12) else 0.0
        row = {
            "phase": name,
            "steps": int(m.sum()),
            "dt_median": float(np.median(dt[m])) if m.any() else math.nan,
            "dt_max": float(np.max(dt[m])) if m.any() else math.nan,
            "rejected": int(rej[m].sum()),
            "estimate": float(est[m][-1] - before) if m.any() else math.nan,
        }
        if tc_errors is not None:
            worst = 0.0
            for tt, e in tc_errors.values():
                mm = (tt > a + 1e-12) & (tt <= b + 1e-9)
                if mm.any():
                    worst = max(worst, float(np.max(e[mm])))
            row["time_error"] = worst if a >= 0.04 - 1e-12 else math.nan
        out.append(row)
    return out


def _accumulated(rec: dict):
    """The controller's accumulated estimate at each state (:func:`femehl.accuracy.auto.time_error`)."""
    from types import SimpleNamespace

    import numpy as np

    from femehl.accuracy.auto import time_error

    e = np.asarray([math.nan if x is None else x for x in rec["error_estimate"]], dtype=float)
    dt = np.asarray([0.0 if x is None else x for x in rec["dts"]], dtype=float)
    if rec["kind"] == "fixed":
        return np.zeros(len(rec["t"]))
    return time_error(SimpleNamespace(error_estimate=e, dt=dt))


def evaluate(runs: list, ref: dict, level: float) -> dict:
    """Every run of ``level`` with its true, space and time errors (dicts per quantity)."""
    import numpy as np

    conv = converged(runs, level, ref)
    rows = []
    for r in runs:
        if r["kind"] == "auto" or r["level"] != level or r["status"] != "ok":
            continue
        every = 2 if r["kind"] == "fixed" and r["dt"] < 0.005 - 1e-12 else 1
        row = {"rec": r, "true": {q: _max_err(r, ref, q, every) for q in QUANTITIES}}
        if conv is not None:
            series = {q: _max_err(r, conv, q, every, series=True) for q in QUANTITIES}
            row["time"] = {q: float(np.max(e)) if e.size else math.nan for q, (_, e) in series.items()}
            row["time_series"] = series
        if r["kind"] == "adaptive":
            row["estimate"] = float(_accumulated(r)[-1])
            row["chatter"] = chatter(r)
            row["tol_t"] = r["step_tol"]
            row["base_tol"] = STUDY_TAU1 * level**2
        rows.append(row)
    return {"level": level, "converged": conv, "rows": rows}


def _interp_log(x, xs, ys):
    """log-log interpolation (and linear extrapolation in logs beyond the ends)."""
    import numpy as np

    lx, ly = np.log(np.asarray(xs, float)), np.log(np.asarray(ys, float))
    i = int(np.clip(np.searchsorted(lx, math.log(x)), 1, len(lx) - 1))
    w = (math.log(x) - lx[i - 1]) / (lx[i] - lx[i - 1])
    return float(np.exp(ly[i - 1] + w * (ly[i] - ly[i - 1])))


def balance(ev: dict, controller: str) -> dict | None:
    """Where the worst time error is BALANCE x the worst space error: the multiplier ``m*``
    of the tolerance (``controller`` "I", "PI3040", "H211b") or the fixed step ``dt*``
    ("fixed"), by log-log interpolation of the worst time error between the runs around the
    first crossing (the time error need not be monotone at the percent level: the first
    crossing is the safe side); steps and run wall time interpolated the same way."""
    conv = ev["converged"]
    if controller == "fixed":
        rows = [r for r in ev["rows"] if r["rec"]["kind"] == "fixed"]
        rows.sort(key=lambda r: r["rec"]["dt"])
        xs = [r["rec"]["dt"] for r in rows]
    else:
        rows = [
            r for r in ev["rows"] if r["rec"]["kind"] == "adaptive" and r["rec"]["controller"] == controller
        ]
        rows.sort(key=lambda r: r["rec"]["mult"])
        xs = [r["rec"]["mult"] for r in rows]
    if conv is None or len(rows) < 2:
        return None
    space = max(conv["space"].values())
    target = BALANCE * space
    worst = [max(r["time"].values()) for r in rows]
    x_star, beyond = xs[-1], True
    if worst[0] >= target:
        x_star, beyond = xs[0], False
    else:
        for i in range(1, len(xs)):
            if worst[i] >= target:
                x_star, beyond = _interp_log(target, [worst[i - 1], worst[i]], [xs[i - 1], xs[i]]), False
                break
    steps = [r["rec"]["steps"] for r in rows]
    walls = [r["rec"]["wall_s"] for r in rows]
    first = rows[0]["rec"] if controller != "fixed" else None
    return {
        "space": space,
        "target": target,
        "x_star": x_star,
        "beyond": beyond,
        "steps": _interp_log(x_star, xs, steps),
        "wall": _interp_log(x_star, xs, walls),
        "steps_1": None if first is None else first["steps"],
        "wall_1": None if first is None else first["wall_s"],
    }


def _f(x, digits=3) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return f"{x:.{digits}g}"


def _pct(x) -> str:
    return "-" if x is None or not math.isfinite(x) else f"{100 * x:.3g}"


def _order(r: dict) -> tuple:
    rec = r["rec"]
    if rec["kind"] == "fixed":
        return (0, "", -rec["dt"])
    return (
        1,
        {"I": "0", "I-max1.5": "1", "PI3040": "2", "H211b": "3"}.get(rec["controller"], rec["controller"]),
        rec["mult"],
    )


def _worst(d: dict) -> float:
    return max(d.values())


def analyze(runs: list) -> str:
    from auto import _ref

    refs = json.loads(REFERENCE.read_text())
    ref = _ref(refs, SCENE)
    auto_rec = next((r for r in reversed(runs) if r["kind"] == "auto"), None)
    levels = sorted({r["level"] for r in runs if r["kind"] != "auto"}, reverse=True)
    evs = {lv: evaluate(runs, ref, lv) for lv in levels}
    dates = sorted({r.get("date", "?") for r in runs})
    commits = sorted({r.get("commit", "?") for r in runs})
    loads = [r["loadavg"] for r in runs if isinstance(r.get("loadavg"), float)]
    out = [
        "# Time steps balanced against space (paper case, the meshes of tol = 1e-2)",
        "",
        f"Generated by `python benchmarks/time_balance.py`. Machine: {machine()}. "
        f"Runs of {', '.join(dates)} at commit {', '.join(commits)}, one at a time; load "
        f"average {min(loads, default=math.nan):.2f} to {max(loads, default=math.nan):.2f} "
        "at the end of the runs (a shared 2-core machine; per run in `time_balance.jsonl`).",
        "",
        "The paper case (`femehl.presets.paper_sphere()`, t_end = 5) on the scene-fitted meshes "
        "of the last two levels `femehl.solve(paper, tol=1e-2)` runs (the `Ladder`'s "
        "`_fe_options(scene, 5, level)`, BDF2, as `femehl.accuracy.auto._run` builds them).  "
        "Errors in % against `auto_reference_scenes.json`, max over the reference's times "
        "from t = 0.04 on, as `benchmarks/auto.py` compares (load relative to max(|ref|, 0.1), "
        "films relative; an adaptive run PCHIP-interpolated to the reference's times, a "
        "fixed-step run at its own).  *space*: the mesh's time-converged solution (Richardson "
        "in dt of its fixed dt = 0.005 and 0.0025 runs) against the reference with the "
        "reference's own dt = 0.005 time error removed; *time*: the run against the mesh's "
        "time-converged solution, compared the same way; *true*: the run against the "
        "reference as stored.  *wall*: the run alone (the operators are built once per mesh, "
        "the set-up apart; every run has a fresh linear solver); *its*: Krylov iterations; "
        "*LU*: preconditioner factorizations.  *est*: the controller's accumulated local "
        "errors at t = 5 (`femehl.accuracy.auto.time_error`, the automatic mode's time part); "
        "*est / time*: over the worst time error; *time / tol_t*: the worst time error over "
        "the run's tolerance.  m: step_tol = m TAU1 level^2 (TAU1 = 1.25e-3, m = 1 today).",
        "",
    ]
    if auto_rec is not None:
        out += [
            "## Today's automatic run at tol = 1e-2 (this session)",
            "",
            "| level | cells | tol_t | steps | rejected | wall s (set-up included) |",
            "|---|---|---|---|---|---|",
        ]
        for i, lv in enumerate(auto_rec["levels"]):
            out.append(
                f"| {lv:.3g} | {auto_rec['elements'][i]} | {auto_rec['tol_t'][i]:.3g} | "
                f"{auto_rec['steps'][i]} | {auto_rec['rejected_steps'][i]} | {auto_rec['wall'][i]:.1f} |"
            )
        out += [
            "",
            f"The whole automatic run {auto_rec['wall_s']:.1f} s; reached: {auto_rec['reached']}, "
            f"estimated error {_pct(auto_rec['total'])} %.",
            "",
        ]
    found = {}
    for lv in levels:
        ev = evs[lv]
        conv, rows = ev["converged"], ev["rows"]
        if not rows:
            continue
        r0 = rows[0]["rec"]
        base = next((r["base_tol"] for r in rows if "base_tol" in r), math.nan)
        out += [
            f"## Level {lv:g}: {r0['elements']} cells, operators set up in {r0['setup_s']:.1f} s, "
            f"TAU1 level^2 = {base:.3g}",
            "",
        ]
        space = _worst(conv["space"]) if conv is not None else math.nan
        if conv is not None:
            out += [
                "| | load | film_center | film_min |",
                "|---|---|---|---|",
                "| space error % (time-converged vs time-corrected reference) | "
                + " | ".join(_pct(conv["space"][q]) for q in QUANTITIES)
                + " |",
                "| ... against the reference as stored % | "
                + " | ".join(_pct(conv["space_raw"][q]) for q in QUANTITIES)
                + " |",
                "| time-converged solution's uncertainty % (against the extrapolation of dt 0.01 / 0.005) | "
                + " | ".join(_pct(conv["uncertainty"].get(q, math.nan)) for q in QUANTITIES)
                + " |",
                "",
            ]
        out += [
            "| run | step_tol | steps | rejected | its | LU | wall s | ms/step | true load / fc / fmin % "
            "| time load / fc / fmin % | time / space | est % | est / time | time / tol_t |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for r in sorted(rows, key=_order):
            rec = r["rec"]
            tw = _worst(r["time"]) if "time" in r else math.nan
            adaptive = rec["kind"] == "adaptive"
            tail = (
                f"{_pct(r['estimate'])} | {_f(r['estimate'] / tw, 2)} | {_f(tw / rec['step_tol'], 2)} |"
                if adaptive
                else "- | - | - |"
            )
            out.append(
                f"| {_label(rec)} | {_f(rec['step_tol']) if adaptive else '-'} | {rec['steps']} | "
                f"{rec['rejected'] if adaptive else '-'} | {rec['krylov_iterations']} | "
                f"{rec['factorizations']} | {rec['wall_s']:.1f} | "
                f"{1e3 * rec['wall_s'] / max(1, rec['steps']):.0f} | "
                + " / ".join(_pct(r["true"][q]) for q in QUANTITIES)
                + " | "
                + (" / ".join(_pct(r["time"][q]) for q in QUANTITIES) if "time" in r else "-")
                + f" | {_f(tw / space, 2)} | {tail}"
            )
        out.append("")
        cm = cost_model([r["rec"] for r in rows])
        if cm is not None:
            out += [
                f"Cost of a run on this mesh (least squares over its {len(rows)} runs, within "
                f"{100 * cm['dev']:.0f} %): {cm['trial_ms']:.1f} ms per trial step + "
                f"{cm['iteration_ms']:.1f} ms per Krylov iteration + {cm['lu_ms']:.0f} ms per LU.",
                "",
            ]
        shown = [
            r
            for r in sorted(rows, key=_order)
            if r["rec"]["kind"] == "adaptive"
            and (r["rec"]["controller"], r["rec"]["mult"])
            in {("I", 1), ("I", 4), ("I", 5), ("I-max1.5", 5), ("PI3040", 5)}
        ]
        if shown:
            out += [
                "Where the steps go: accepted steps, median / largest dt, rejected trials; "
                "*est*: the controller's accumulated estimate over the phase, *err*: the worst "
                "time error at a time in the phase (carried over from before it too), % (the "
                "initial layer is outside the compared window).  The dt over t: "
                "`time_balance.png`.",
                "",
                "| run | " + " | ".join(f"{name} ({a:g}, {b:g}]" for name, a, b in PHASES) + " |",
                "|---|" + "---|" * len(PHASES),
            ]
            for r in shown:
                cells = [
                    f"{p['steps']} steps, dt {_f(p['dt_median'], 2)} / {_f(p['dt_max'], 2)}, "
                    f"{p['rejected']} rej, est {_pct(p['estimate'])}, "
                    f"err {_pct(p.get('time_error', math.nan))}"
                    for p in phases(r["rec"], r.get("time_series"))
                ]
                out.append(f"| {_label(r['rec'])} | " + " | ".join(cells) + " |")
            out.append("")
        adapt = [r for r in rows if r["rec"]["kind"] == "adaptive"]
        if adapt:
            out += [
                "Chatter: rejected trials; of them right after an accepted step at the same or a "
                "smaller size (the estimate jumped over tol at a step that had just passed), and "
                "hard cuts (a second rejection of the same step: dt x 0.2); accepted-step changes "
                "of dt (by more than 1 %) and reversals of their direction:",
                "",
                "| run | steps | rejected | after an accepted step | hard cuts | dt changes | reversals |",
                "|---|---|---|---|---|---|---|",
            ]
            for r in sorted(adapt, key=_order):
                c = r["chatter"]
                out.append(
                    f"| {_label(r['rec'])} | {r['rec']['steps']} | {r['rec']['rejected']} | "
                    f"{c['after_ok']} | {c['cuts']} | {c['dt_changes']} | {c['reversals']} |"
                )
            out.append("")
        for ctl in ("I", "I-max1.5", "PI3040", "H211b", "fixed"):
            b = balance(ev, ctl)
            if b is not None:
                found[(lv, ctl)] = (b, r0["setup_s"], base)
    if found:
        out += [
            "## Balance: the time error at 1/3 of the mesh's space error",
            "",
            "m* (dt* for fixed steps): where the worst time error (of the three quantities, max "
            "over the run) reaches 1/3 of the worst space error, log-log interpolated between "
            "the runs around the first crossing; steps and run wall time interpolated the same "
            "way (the wall times carry the machine's +-15 % and the runs' own chatter); the "
            "last run's cost = set-up + run.",
            "",
            "| level | controller | worst space % | target % | m* (dt*) | step_tol | steps at m* (m = 1) "
            "| run s at m* (m = 1) | set-up + run s at m* (m = 1) |",
            "|---|---|---|---|---|---|---|---|---|",
        ]
        for (lv, ctl), (b, setup, base) in found.items():
            fixed = ctl == "fixed"
            star = f"dt* = {b['x_star']:.3g}" if fixed else f"{b['x_star']:.3g}"
            star += " (beyond the runs)" if b["beyond"] else ""
            out.append(
                f"| {lv:g} | {ctl} | {_pct(b['space'])} | {_pct(b['target'])} | {star} | "
                f"{'-' if fixed else _f(b['x_star'] * base)} | {b['steps']:.0f}"
                + ("" if fixed else f" ({b['steps_1']})")
                + f" | {b['wall']:.1f}"
                + ("" if fixed else f" ({b['wall_1']:.1f})")
                + f" | {b['wall'] + setup:.1f}"
                + ("" if fixed else f" ({b['wall_1'] + setup:.1f})")
                + " |"
            )
        out.append("")
        if auto_rec is not None and len(levels) >= 2:
            out += [
                "The automatic run with the balanced tolerance on its last two levels (the "
                "pilots at levels 4 and 2 as measured today; set-up + interpolated run):",
                "",
                "| controller | last two levels s | whole automatic run s (today "
                f"{auto_rec['wall_s']:.1f}) |",
                "|---|---|---|",
            ]
            pilots = sum(auto_rec["wall"][:-2])
            for ctl in ("I", "I-max1.5", "PI3040", "H211b"):
                if all((lv, ctl) in found for lv in levels[-2:]):
                    last = sum(found[(lv, ctl)][0]["wall"] + found[(lv, ctl)][1] for lv in levels[-2:])
                    out.append(f"| {ctl} | {last:.1f} | {pilots + last:.1f} |")
            out.append("")
    out += findings(evs, found, auto_rec)
    _plot(evs)
    return "\n".join(out) + "\n"


def _run(ev: dict, controller: str, mult: float):
    for r in ev["rows"]:
        rec = r["rec"]
        if rec["kind"] == "adaptive" and rec["controller"] == controller and rec["mult"] == mult:
            return r
    return None


def findings(evs: dict, found: dict, auto_rec) -> list:
    """The study's conclusions, in numbers (from the tables above)."""
    levels = sorted(evs)  # finest first
    if len(levels) < 2 or not found:
        return []
    last, before = levels[0], levels[1]
    out = ["## Findings", ""]
    ratios = []
    for lv in (last, before):
        r = _run(evs[lv], "I", 1)
        if r is not None and evs[lv]["converged"] is not None:
            ratios.append(f"{_worst(r['time']) / _worst(evs[lv]['converged']['space']):.2f} (level {lv:g})")
    if ratios:
        out.append(
            "- Today (m = 1) the worst time error is " + " and ".join(ratios) + " times the worst "
            "space error (film_min's both): the steps buy a time error about 10 times below the mesh's."
        )
    stars = {
        ctl: [found[(lv, ctl)][0]["x_star"] for lv in (last, before) if (lv, ctl) in found]
        for ctl in ("I", "I-max1.5", "PI3040", "H211b")
    }
    out.append(
        "- The time error reaches 1/3 of the space error at m* = "
        + "; ".join(f"{ctl} {', '.join(f'{m:.2g}' for m in ms)}" for ctl, ms in stars.items() if ms)
        + f" (levels {last:g}, {before:g}): TAU1 about 5 x 1.25e-3 = 6.3e-3 balances both meshes "
        "(their space errors scale like level^2, as tol_t does)."
    )
    b = found.get((last, "I"))
    setup = b[1] if b else math.nan
    today = _run(evs[last], "I", 1)
    lines = []
    for ctl in ("I", "I-max1.5", "PI3040", "H211b"):
        r5 = _run(evs[last], ctl, CHECK_MULTS[0])
        if r5 is None or today is None:
            continue
        rec = r5["rec"]
        lines.append(
            f"{ctl} {rec['steps']} steps ({rec['rejected']} rejected), run {rec['wall_s']:.1f} s, "
            f"last run {rec['wall_s'] + setup:.1f} s, time / space "
            f"{_worst(r5['time']) / _worst(evs[last]['converged']['space']):.2f}, true worst "
            f"{_pct(_worst(r5['true']))} %"
        )
    if today is not None and lines:
        rec = today["rec"]
        out.append(
            f"- On the last mesh ({rec['elements']} cells, set-up {setup:.1f} s) today's tolerance takes "
            f"{rec['steps']} steps ({rec['rejected']} rejected), run {rec['wall_s']:.1f} s, last run "
            f"{rec['wall_s'] + setup:.1f} s, true worst {_pct(_worst(today['true']))} %; at m = "
            f"{CHECK_MULTS[0]:g} (measured): " + "; ".join(lines) + "."
        )
    r5 = _run(evs[last], "I", CHECK_MULTS[0])
    if r5 is not None:
        space_q = evs[last]["converged"]["space"]
        out.append(
            "- The balance is of the worst quantities (the automatic mode accepts on the worst "
            f"estimate); per quantity, I x{CHECK_MULTS[0]:g} on the last mesh has time / space "
            + ", ".join(f"{q} {r5['time'][q] / space_q[q]:.2g}" for q in QUANTITIES)
            + f": the load's space error is small ({_pct(space_q['load'])} %), so its time error "
            "passes it, far below the films' errors."
        )
    cm = cost_model([r["rec"] for r in evs[last]["rows"]])
    r5 = _run(evs[last], "PI3040", CHECK_MULTS[0]) or today
    if cm is not None and r5 is not None:
        rec = r5["rec"]
        share = rec["krylov_iterations"] * cm["iteration_ms"] / 1e3 / rec["wall_s"]
        lu = rec["factorizations"] * cm["lu_ms"] / 1e3 / rec["wall_s"]
        out.append(
            f"- Halving the steps does not halve the run: on the last mesh a run costs "
            f"{cm['trial_ms']:.1f} ms per trial + {cm['iteration_ms']:.1f} ms per Krylov iteration + "
            f"{cm['lu_ms']:.0f} ms per LU, and the iterations per step grow with dt (fixed steps: "
            + ", ".join(
                f"{r['rec']['krylov_iterations'] / r['rec']['steps']:.1f} at dt {r['rec']['dt']:g}"
                for r in sorted(evs[last]["rows"], key=_order)
                if r["rec"]["kind"] == "fixed"
            )
            + f"), so a run makes about 1,000 to 1,500 iterations whatever its steps.  In "
            f"{_label(rec)}: iterations {100 * share:.0f} %, LU {100 * lu:.0f} % of its "
            f"{rec['wall_s']:.1f} s."
        )
    ch = []
    for lv in (last, before):
        worst_i = max(
            (r for r in evs[lv]["rows"] if r["rec"]["kind"] == "adaptive" and r["rec"]["controller"] == "I"),
            key=lambda r: r["rec"]["rejected"],
        )
        m = worst_i["rec"]["mult"]
        other = {ctl: _run(evs[lv], ctl, m) for ctl in ("I-max1.5", "PI3040", "H211b")}
        ch.append(
            f"level {lv:g}: I x{m:g} {worst_i['rec']['rejected']} rejected ({worst_i['chatter']['cuts']} "
            "hard cuts), "
            + ", ".join(
                f"{ctl} {r['rec']['rejected']} ({r['chatter']['cuts']})" for ctl, r in other.items() if r
            )
        )
    out.append(
        "- femehl's controller chatters at some tolerances: a step grown x2 passes (its estimate "
        "0.3 to 0.6 tol), the next step of the same size fails (3 to 4 times that estimate), the "
        "retry at 0.6 to 0.8 of it fails too (the estimate falls far less than the step's "
        "square), the hard cut takes dt x 0.2 and the doublings start again: a sawtooth "
        "through the indentation ramp (time_balance.png) and after growths in the near-steady "
        "phase; " + "; ".join(ch) + ".  Growth capped at the hold (x1.5, I-max1.5) "
        "removes most of it; PI3040 too, but with the hold in place its many small decreases "
        "reverse dt often (reversals column; they cost few LU refreshes)."
    )
    ests, bys = [], []
    for lv in (last, before):
        for r in evs[lv]["rows"]:
            if r["rec"]["kind"] == "adaptive" and "time" in r:
                ests.append(r["estimate"] / _worst(r["time"]))
                if r["rec"]["controller"] == "I":
                    bys.append(_worst(r["time"]) / r["rec"]["step_tol"])
    if ests:
        out.append(
            f"- What tol_t buys: femehl's controller ends with a worst time error of {min(bys):.2g} to "
            f"{max(bys):.2g} x tol_t (design.md section 3.1 says 0.3 to 1); the accumulated "
            f"estimate (the automatic mode's time part) is {min(ests):.2g} to {max(ests):.2g} x the "
            f"worst time error over all {len(ests)} adaptive runs: it bounds the time error in "
            f"{sum(e >= 1 for e in ests)} of {len(ests)}."
        )
    if auto_rec is not None:
        pilots = sum(auto_rec["wall"][:-2])
        best = min(
            (
                sum(found[(lv, ctl)][0]["wall"] + found[(lv, ctl)][1] for lv in (last, before)),
                ctl,
            )
            for ctl in ("I", "I-max1.5", "PI3040", "H211b")
            if (last, ctl) in found and (before, ctl) in found
        )
        out.append(
            f"- The tol = 1e-2 paper case: today {auto_rec['wall_s']:.1f} s (last run "
            f"{auto_rec['wall'][-1]:.1f} s); balanced, its last run would take about "
            f"{found[(last, best[1])][0]['wall'] + setup:.0f} s ({best[1]}) and the whole run about "
            f"{pilots + best[0]:.0f} s.  The 15 s target is out of reach by the steps alone: the last "
            f"mesh's set-up is {setup:.1f} s and its Krylov iterations about as much again."
        )
    out.append("")
    return out


def _plot(evs: dict) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import numpy as np
    except ImportError:
        return
    lv = min(evs) if evs else None
    if lv is None:
        return
    ev = evs[lv]
    pick = [("I", 1, "C0", "-"), ("I", 4, "C3", "-"), ("I-max1.5", 5, "C1", "--"), ("PI3040", 5, "C2", ":")]
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    for ctl, m, color, ls in pick:
        row = next(
            (
                r
                for r in ev["rows"]
                if r["rec"]["kind"] == "adaptive" and r["rec"]["controller"] == ctl and r["rec"]["mult"] == m
            ),
            None,
        )
        if row is None:
            continue
        rec = row["rec"]
        t = np.asarray(rec["t"][1:], float)
        dt = np.asarray([math.nan if x is None else x for x in rec["dts"][1:]], float)
        lab = f"{ctl} x{m} ({rec['steps']} steps, {rec['rejected']} rejected)"
        a1.step(t, dt, where="pre", color=color, ls=ls, label=lab)
        if "time_series" in row:
            tt, e = row["time_series"]["film_min"]
            a2.semilogy(tt, np.maximum(e, 1e-9), color=color, ls=ls, label=f"{ctl} x{m}: time error")
    conv = ev["converged"]
    if conv is not None:
        tt, e = conv["space_series"]["film_min"]
        a2.semilogy(tt, np.maximum(e, 1e-9), color="k", lw=1.5, label="space error of the mesh")
    for ax in (a1, a2):
        for _, a, _b in PHASES[1:]:
            ax.axvline(a, color="0.7", lw=0.8)
    a1.set_yscale("log")
    a1.set_ylabel("accepted dt")
    a1.legend(fontsize=8)
    a1.set_title(
        f"paper case, level {lv:g} ({ev['rows'][0]['rec']['elements']} cells): steps and film_min errors"
    )
    a2.set_ylabel("relative error of film_min")
    a2.set_xlabel("t")
    a2.set_ylim(1e-6, 1e-1)
    a2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(PLOT, dpi=110)
    plt.close(fig)


# ---- main -------------------------------------------------------------------------------
def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--resume", action="store_true", help="skip runs already in time_balance.jsonl")
    ap.add_argument("--analyze-only", action="store_true", help="tables and plot from time_balance.jsonl")
    ap.add_argument(
        "--no-auto", action="store_true", help="skip today's automatic run (levels: DEFAULT_LEVELS)"
    )
    ap.add_argument("--levels", help="comma-separated levels (default: the last two of the automatic run)")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        spec = json.loads(args.worker)
        if spec["what"] == "auto":
            rec = auto_worker()
            rec.update(loadavg=load_average(), **provenance())
            with RUNS.open("a") as fh:
                fh.write(json.dumps(rec) + "\n")
        else:
            level_worker(spec["level"], spec["specs"])
        return
    if not args.analyze_only:
        if not args.resume and RUNS.exists():
            RUNS.unlink()
        done = {_key(r) for r in read_runs()}
        cmd = [sys.executable, str(pathlib.Path(__file__).resolve()), "--worker"]
        if not args.no_auto and not any(k[0] == "auto" for k in done):
            print("today's automatic run at tol = 1e-2 ...", flush=True)
            subprocess.run([*cmd, json.dumps({"what": "auto"})], env=_env(), check=True)
        auto_rec = next((r for r in reversed(read_runs()) if r["kind"] == "auto"), None)
        if args.levels:
            levels = [float(x) for x in args.levels.split(",")]
        else:
            levels = list(auto_rec["levels"][-2:]) if auto_rec else list(DEFAULT_LEVELS)
        for level in sorted(levels):  # the last (finest) level first
            todo = [s for s in specs_for() if _key({**s, "level": level}) not in done]
            if todo:
                print(f"level {level:g}: {len(todo)} runs ...", flush=True)
                spec = {"what": "level", "level": level, "specs": todo}
                subprocess.run([*cmd, json.dumps(spec)], env=_env(), check=True)
    TABLE.write_text(analyze(read_runs()))
    print(f"wrote {TABLE.name}, {PLOT.name}")


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    main()
