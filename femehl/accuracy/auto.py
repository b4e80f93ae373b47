"""Any scene to a requested accuracy, with an error estimate: :func:`solve_to_tolerance`.

``femehl.solve(scene, t_end=..., tol=1e-2)`` (and ``femehl run``) come here when the caller
gives neither ``dt`` nor a discretization option.  The load, the central film and the
minimum film of the returned run are within ``tol`` relative at every step: its
:class:`~femehl.accuracy.estimate.Estimate` is at most :data:`ACCEPT` * ``tol``.  How:
one number, the level, refines mesh and time steps together (:class:`Ladder`, time
tolerance ``TAU1 * level**2``); pilots at levels 4 and 2, then each level aimed at
``SAFETY * tol`` from the last pair's Richardson estimate, within the cell and time
budgets.  The sequence, the estimators, the budgets and the measurements behind every
constant: docs/design.md section 9.
"""

from __future__ import annotations

import itertools
import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from femehl.accuracy.estimate import Estimate
from femehl.errors import SceneError, SolverError, TimeBudgetError
from femehl.output.result import Result
from femehl.registry import Registry
from femehl.solver.adaptive import LOAD_FLOOR, UNIT_STEP, breakpoints_of

__all__ = [
    "solve_to_tolerance",
    "Ladder",
    "LADDERS",
    "register_ladder",
    "QUANTITIES",
    "ACCEPT",
    "MAX_ELEMENTS",
    "LOCAL_MAX_ELEMENTS",
    "FAST_MAX_ELEMENTS",
    "cell_budget",
    "budget_level",
    "predicted_wall",
    "time_tolerance",
]

logger = logging.getLogger("femehl")

#: the headline quantities whose errors are estimated
QUANTITIES = ("load", "film_center", "film_min")
#: observed/expected order of the space error in h and of the BDF2 global time error in tol_t
ORDER = 2
#: levels whose discretization would have more cells than this are not run, on a
#: substrate whose elastic operator is dense only (``operators = ("dense",)``: a layer)
MAX_ELEMENTS = 25_000
#: ... on a substrate with the fast hierarchical operator (the half space, compressible
#: or not; a viscoelastic one relaxing it), used by the FE method from 8,000 elements
#: on: its memory grows like the cells (20 kB each) and a step costs about 1 s at
#: 89,000 cells (``benchmarks/fast_operator.md``), so this is a cost budget, not a
#: memory limit
FAST_MAX_ELEMENTS = 100_000
#: ... on a substrate whose operators are all sparse (``substrate.local``: Winkler,
#: rigid): a step there costs a sparse LU, not dense products, so the same cost buys
#: more cells.  Measured on the Winkler scene of ``benchmarks/auto.py`` (adaptive BDF2,
#: another run beside it): 29 ms per step at 11,458 cells, 183 ms at 45,182; a dense
#: step at 27,640 cells costs about 900 ms (``benchmarks/fast_operator.md``).
LOCAL_MAX_ELEMENTS = 100_000
#: time tolerance of the run at level 1: ``tol_t = TAU1 * level**2``
TAU1 = 1.25e-3
#: bounds of the time tolerance
TAU_RANGE = (1e-6, 5e-2)
#: first (coarsest) level, and the least number of runs before one is accepted
LEVEL0 = 4.0
MIN_RUNS = 3
#: the next level aims at an estimated error of SAFETY * tol ...
SAFETY = 0.6
#: a run is accepted (``reached``) when its worst estimate is <= ACCEPT * tol.  The
#: estimate assumes order 2; on the fitted meshes the films converge somewhat slower
#: between the levels that decide (observed orders 1.4-2), so it runs low.  Over the pairs
#: of the eleven tol = 1e-2 scenes of ``benchmarks/auto_margin.py`` at levels <= 1 whose
#: worst true error is at least twice its reference's uncertainty, worst true / worst
#: estimate was at most 1.23 (22 pairs, above 1 in 11), 1.29 where the reference is as
#: uncertain as the error; accepted at <= tol, the sphere sliding at beta = 2000 and the
#: ellipsoid along the sliding ended 14 % and 5 % over tol.  1 / 0.75 = 1.33 covers both ratios.
ACCEPT = 0.75
#: ... with a ratio to the previous level in this range
RATIO_RANGE = (math.sqrt(2.0), 2.0)
#: the level the estimate asks for would exceed the cell budget: the finest level within
#: it is still run if it is at least this ratio finer than the last run (its pair estimate
#: divides the difference by ratio**2 - 1 >= 0.44), found to about 1 % in cells
BUDGET_RATIO = 1.2
BUDGET_BISECTIONS = 8


def time_tolerance(level: float) -> float:
    """The adaptive controller's tolerance on ``level``: ``TAU1 * level**2`` (clipped)."""
    lo, hi = TAU_RANGE
    return float(min(hi, max(lo, TAU1 * level**2)))


# ---- how each method is refined ---------------------------------------------------------
@dataclass(frozen=True)
class Ladder:
    """How a method is refined by one number, ``level`` (sizes proportional to it).

    ``options(scene, t_end, level)`` gives the discretization options of
    :func:`femehl.solve` (e.g. ``mesh=``); ``cells(scene, t_end, level)`` estimates the
    number of cells (elements) without building anything, for the budget.
    """

    options: Callable[..., dict]
    cells: Callable[..., float]
    #: the option names ``options`` sets (refused from the caller)
    keys: tuple[str, ...] = ()
    #: ``companion(scene, options) -> (options, ratio) | None``: a coarser discretization
    #: (sizes ``ratio`` times) of an expert's options, for the space estimate of an expert run
    companion: Callable[..., tuple | None] | None = None
    #: ``sizer(scene, t_end) -> cells(level)``: :attr:`cells` with what does not depend on
    #: the level computed once (the budgets ask for many levels); default: :attr:`cells`
    sizer: Callable[..., Callable[[float], float]] | None = None
    #: ``adapt(result, scene, t_end) -> Ladder``: a ladder of discretizations adapted to a
    #: finished run (its meshes where that run's error is), or None: the method has none
    adapt: Callable[..., Ladder] | None = None
    #: how to rebuild this ladder when a run folder resumes a run made on it (JSON-able:
    #: the plan records it), None for a registered ladder
    record: dict | None = None

    def cells_of(self, scene, t_end: float) -> Callable[[float], float]:
        """``cells(level)`` of ``scene`` over a run to ``t_end``."""
        if self.sizer is not None:
            return self.sizer(scene, t_end)
        return lambda level: self.cells(scene, t_end, level)


#: method name -> its :class:`Ladder`
LADDERS = Registry("ladder")


def register_ladder(method: str, ladder: Ladder) -> Ladder:
    """Make ``method`` automatic: :func:`solve_to_tolerance` refines it along ``ladder``."""
    if not isinstance(ladder, Ladder):
        raise SceneError(f"register_ladder: give a femehl.auto.Ladder, got {type(ladder).__name__}.")
    return LADDERS.register(method)(ladder)


def _fe_options(scene, t_end, level):
    from femehl.discretize.fitted import fitted_disk

    return {"mesh": fitted_disk(scene, t_end, level=level)}


def _fe_cells(scene, t_end, level):
    return _fe_sizer(scene, t_end)(level)


def _fe_sizer(scene, t_end):
    from femehl.discretize.fitted import fitted_sizes

    half = bool(getattr(scene.indenter, "symmetric_y", False))
    base = fitted_sizes(scene, t_end, 1.0)  # the contact extent: the costly part (~0.4 s)
    return lambda level: base.at_level(level).estimate_elements(half)


#: line contact: 400 elements (the LineDisc default) at level 1
LINE_ELEMENTS = 400


#: the automatic sequence adapts its meshes to the run at this level (the second pilot)
ADAPT_LEVEL = 2.0


def _fe_adapt(result, scene, t_end) -> Ladder:
    """The ladder of meshes adapted to ``result``, its level 1 as many cells as the fitted one's."""
    from femehl.discretize.adapted import adapted_sizes

    return adapted_ladder(adapted_sizes(result, _fe_sizer(scene, t_end)(1.0)))


def adapted_ladder(sizes) -> Ladder:
    """The FE ladder of :class:`femehl.discretize.adapted.AdaptedSizes` ``sizes`` (each
    level's mesh built once)."""
    meshes = {}

    def options(scene, t_end, level):
        key = float(level)
        if key not in meshes:
            meshes[key] = sizes.mesh(key)
        return {"mesh": meshes[key]}

    return Ladder(
        options,
        lambda scene, t_end, level: sizes.cells(level),
        ("mesh", "half"),
        sizer=lambda scene, t_end: sizes.cells,
        record={"adapted": sizes.record()},
    )


def _ladder_of(method: str, plan: dict) -> Ladder:
    """The ladder a resumed candidate was made on: adapted (its plan holds the sizes) or
    the method's registered one, fitted to the first run's end ``t_fit``."""
    if "adapted" in plan:
        from femehl.discretize.adapted import AdaptedSizes

        return adapted_ladder(AdaptedSizes.from_record(plan["adapted"]))
    t_fit = float(plan.get("t_fit", plan["companion"]["t"][-1]))
    return _fitted_to(LADDERS[method], t_fit)


def _line_elements(level) -> int:
    return max(20, round(LINE_ELEMENTS / level))


def _fe_companion(scene, options):
    from femehl.discretize.fe_disk import FITTED, _horizon
    from femehl.discretize.fitted import fitted_disk
    from femehl.discretize.mesh import LADDER, LADDER_RATIO

    mesh = options.get("mesh", "medium")
    if not isinstance(mesh, str):
        return None
    if mesh == FITTED:
        coarse = fitted_disk(scene, _horizon(scene), level=2.0, half=options.get("half"))
        return {**options, "mesh": coarse}, 2.0
    names = list(LADDER)
    if mesh not in names or names.index(mesh) == 0:
        return None
    k = names.index(mesh)
    down = min(k, 2)
    return {**options, "mesh": names[k - down]}, LADDER_RATIO**down


def _line_companion(scene, options):
    n = int(options.get("n_elements", LINE_ELEMENTS))
    return ({**options, "n_elements": n // 2}, n / (n // 2)) if n >= 40 else None


register_ladder("fe", Ladder(_fe_options, _fe_cells, ("mesh", "half"), _fe_companion, _fe_sizer, _fe_adapt))
register_ladder(
    "line",
    Ladder(
        lambda scene, t_end, level: {"n_elements": _line_elements(level)},
        lambda scene, t_end, level: float(_line_elements(level)),
        ("n_elements",),
        _line_companion,
    ),
)


# ---- estimators --------------------------------------------------------------------------
def _scale(name: str, q: np.ndarray) -> np.ndarray:
    """The denominator of relative errors: |q|, floored at LOAD_FLOOR for the load."""
    floor = LOAD_FLOOR if name == "load" else 0.0
    return np.maximum(np.abs(q), floor)


def pair_error(fine: Result, coarse: Result, name: str, ratio: float) -> np.ndarray:
    """Relative Richardson estimate of ``fine``'s error of ``name`` on ``fine.t``.

    ``coarse`` ran at ``ratio`` times the level of ``fine`` (sizes and, through
    :func:`time_tolerance`, ``ratio**2`` times its time tolerance), so both errors scale
    like ``ratio**2`` and ``err_fine = |q_f - q_c| / (ratio**2 - 1)``.
    """
    qf = getattr(fine, name)
    qc = np.array([coarse.value_at(name, t) for t in fine.t])
    scene = getattr(fine, "scene", None)
    if getattr(getattr(scene, "substrate", None), "instant", False):
        qc = _across_jumps(coarse, name, fine.t, qc, breakpoints_of(scene))
    return np.abs(qf - qc) / (ratio**ORDER - 1.0) / _scale(name, qf)


def _across_jumps(coarse, name, ts, qc, breaks) -> np.ndarray:
    """``coarse``'s ``name`` at ``ts`` where it jumps at its start and at the motion's
    ``breaks`` (a substrate whose pressure follows hc' at once): within each stretch
    ``(a, b]`` from the coarse levels after ``a`` only, extrapolated linearly back to ``a``."""
    tc = np.asarray(coarse.t, dtype=float)
    q = np.array([coarse.value_at(name, t) for t in tc])
    out = qc.copy()
    edges = [tc[0], *sorted(b for b in breaks if tc[0] < b < tc[-1]), math.inf]
    for a, b in itertools.pairwise(edges):
        inside = (tc > a) & (tc <= b)
        if inside.sum() < 2:
            continue
        t1, t2 = tc[inside][:2]
        q1, q2 = q[inside][:2]
        early = (ts > a) & (ts < t1)
        out[early] = q1 + (ts[early] - t1) * (q2 - q1) / (t2 - t1)
    return out


def time_error(res: Result) -> np.ndarray:
    """Accumulated local time errors ``sum error_estimate * max(dt, UNIT_STEP)`` per step.

    From the adaptive controller's per-step ``error_estimate`` (:mod:`femehl.solver.adaptive`,
    a local error per unit time, per UNIT_STEP below steps of UNIT_STEP) and ``dt`` of
    every state of ``res`` (the initial state: dt = 0, no error).
    """
    e, dt = res.error_estimate, res.dt
    local = np.where(np.isfinite(e) & (dt > 0), np.nan_to_num(e) * np.maximum(dt, UNIT_STEP), 0.0)
    return np.cumsum(local)


def companion_run(scene, method, options, run: Result, dt, step_tol) -> tuple:
    """``(Result, ratio)`` of the coarser companion of an expert ``run``, or ``(None, None)``.

    The method's :attr:`Ladder.companion` discretization on the run's own time steps: its
    fixed ``dt``, or the times its adaptive steps (to ``step_tol``) took, replayed
    (:class:`femehl.solver.stepping.GivenSteps`), so the two differ in space only.  A
    companion that stops (its coarser mesh may not resolve the film) is logged and gives no
    space estimate.
    """
    from femehl.solver.loop import make_stepper, run_loop
    from femehl.solver.stepping import GivenSteps

    ladder = LADDERS.get(method)
    plan = ladder.companion(scene, options) if ladder is not None and ladder.companion else None
    if plan is None:
        return None, None
    coarse_options, ratio = plan
    steps = {"dt": dt} if step_tol is None else {"steps": GivenSteps(run.t[1:])}
    try:
        coarse = make_stepper(scene, method, **coarse_options)
        return run_loop(coarse, float(run.t[-1]), store_every=0, **steps), ratio
    except SolverError as exc:
        logger.warning("femehl: no space estimate: the coarser companion run stopped (%s)", exc)
        return None, None


def expert_estimate(res: Result, companion: Result | None, ratio: float | None, adaptive: bool):
    """The :class:`~femehl.accuracy.estimate.Estimate` of an expert run (its own mesh and steps).

    ``space``: the running maximum of ``|q - q_c| / (ratio**2 - 1)`` against a
    ``companion`` run ``ratio`` times coarser in space on the same time steps (fixed
    ``dt``, or the adaptive run's own times replayed), so the difference is the space
    error; None without a companion.  ``time``: the controller's accumulated local errors (:func:`time_error`)
    for adaptive steps, None for fixed steps.  ``total = space + time`` when both are
    known, else None.  None when neither is.
    """
    if companion is None and not adaptive:
        return None
    et = time_error(res) if adaptive else None
    errors = {}
    for name in QUANTITIES:
        space = None
        if companion is not None:
            space = np.maximum.accumulate(pair_error(res, companion, name, ratio))
        tpart = None if et is None else et.copy()
        total = space + tpart if space is not None and tpart is not None else None
        errors[name] = {"total": total, "space": space, "time": tpart}
    how = "controller" if companion is None else "companion"
    return Estimate(res.t, errors, how, ratio)


def estimate(fine: Result, coarse: Result, ratio: float) -> Estimate:
    """The pair :class:`~femehl.accuracy.estimate.Estimate` of ``fine`` against ``coarse``.

    ``total`` is the running maximum over the steps so far of the pair estimate
    (:func:`pair_error`, space and time together): the pair difference changes sign in
    time, and where it crosses zero the error does not vanish, so the estimate at t is
    that of the run up to t.  ``time`` is the accumulated local errors of ``fine``
    (:func:`time_error`) but at most ``total``; ``space = total - time``.
    """
    et = time_error(fine)
    errors = {}
    for name in QUANTITIES:
        total = np.maximum.accumulate(pair_error(fine, coarse, name, ratio))
        tpart = np.minimum(et, total)
        errors[name] = {"total": total, "space": total - tpart, "time": tpart}
    levels = tuple(float(r.info["level"]) for r in (fine, coarse) if "level" in r.info)
    return Estimate(fine.t, errors, "pair", ratio, levels)


class CompanionSeries:
    """The headline series of a run, as saved in a run folder (``auto.json``): ``value_at``."""

    def __init__(self, record: dict):
        self.t = np.asarray(record["t"], dtype=float)
        self._q = {q: np.asarray(record[q], dtype=float) for q in QUANTITIES}
        self.info = {"level": float(record["level"])}

    def value_at(self, name: str, t: float) -> float:
        return float(np.interp(t, self.t, self._q[name]))


def companion_record(res) -> dict:
    """What the estimate needs of the companion run (JSON-able): level and headline series."""
    return {
        "level": float(res.info["level"]),
        "t": res.t.tolist(),
        **{q: getattr(res, q).tolist() for q in QUANTITIES},
    }


# ---- the driver --------------------------------------------------------------------------
def _run(
    scene,
    method,
    ladder,
    t_end,
    level,
    store_every,
    options,
    folder=None,
    previous=None,
    deadline=None,
    progress=None,
    tol=None,
    plan=None,
) -> Result:
    """One adaptive run at ``level`` (its discretization from ``ladder``) through the one
    loop (:func:`femehl.solver.loop.run_scene`).

    A run that may be the answer (``previous``, the run before it, given; or its ``plan``,
    a resumed one) is written into ``folder`` (a :class:`~femehl.output.run.RunFolder`,
    if any) as it goes, and always finishes; the others run in memory, and one still going at ``deadline``
    (``time.perf_counter()``) raises :class:`_OutOfTime`.  ``progress(desc, t_end,
    t_start)``, when given, makes a State handler with a ``close()`` (a progress bar).
    """
    from femehl.solver.adaptive import CONTROLS
    from femehl.solver.loop import run_scene

    t0 = time.perf_counter()
    tol_t = time_tolerance(level)
    disc = {"scheme": "bdf2", **ladder.options(scene, t_end, level), **options}
    on_state = disc.pop("callback", None)
    controls = {k: disc.pop(k) for k in CONTROLS if k in disc}
    if plan is None and previous is not None:
        plan = _plan(tol, level, tol_t, t_end, previous, ladder)
    sink = None if plan is None else folder
    if sink is None and deadline is not None:
        on_state = _deadline_guard(deadline, on_state)
    res = run_scene(
        scene,
        method,
        disc,
        t_end,
        None,
        step_tol=tol_t,
        store_every=store_every,
        on_state=on_state,
        sink=sink,
        plan=plan,
        progress=progress,
        label=f"level {level:.3g}",
        **controls,
    )
    n = int(res.info["elements"]) if "elements" in res.info else int(ladder.cells(scene, t_end, level))
    res.info.update(level=level, elements=n, tol_t=tol_t, wall=time.perf_counter() - t0)
    logger.info(
        "auto: level %.3g (%d cells, time tolerance %.2g): %d steps, %.1f s",
        level,
        n,
        tol_t,
        res.nsteps,
        res.info["wall"],
    )
    return res


def _plan(tol, level, tol_t, t_fit, previous, ladder) -> dict:
    """What a run folder records of a candidate run, to resume it (its checkpoint's ``auto``)."""
    return {
        "tol": tol,
        "level": level,
        "tol_t": tol_t,
        "t_fit": t_fit,
        "companion": companion_record(previous),
        **(ladder.record or {}),
    }


def resume_to_tolerance(scene, folder, saved: dict, *, t_end, method, store_every, progress=None, **options):
    """A resumed automatic run: the saved candidate (``saved``, its plan in the checkpoint)
    goes on in ``folder`` on the mesh it was fitted with (to the run's first ``t_end``);
    the budgets of the sequence no longer apply.  Extended past its companion's end, the
    companion runs again; the estimate goes on from the earlier part's
    (:meth:`~femehl.accuracy.estimate.Estimate.continued`)."""
    kept = {k: v for k, v in options.items() if k not in ("max_wall", "max_elements")}
    ladder = _ladder_of(method, saved)
    res = _run(
        scene,
        method,
        ladder,
        t_end,
        saved["level"],
        store_every,
        kept,
        folder,
        progress=progress,
        plan=saved,
    )
    if res.info.get("nothing_to_do"):
        return res
    res.info["tol_t"] = saved["tol_t"]
    level_c = float(saved["companion"]["level"])
    companion = CompanionSeries(saved["companion"])
    if t_end > companion.t[-1] * (1.0 + 1e-9):  # extended: its companion goes on too
        folder.say(
            f"femehl: the coarser companion (level {level_c:.3g}) again to t = {t_end:g} (the estimate)"
        )
        companion = _run(scene, method, ladder, t_end, level_c, 0, dict(kept))
    est = estimate(res, companion, level_c / saved["level"])
    before = folder.earlier_estimate()
    res.estimate = est.continued(before) if before else est
    res.info["auto"] = {"tol": saved["tol"], "resumed": True}
    return res


def _fitted_to(ladder: Ladder, t_fit: float) -> Ladder:
    """``ladder`` with its discretizations fitted to a run to ``t_fit`` whatever the run's end."""
    return Ladder(lambda sc, _t, lv: ladder.options(sc, t_fit, lv), ladder.cells, ladder.keys)


def _next_level(level: float, err: float, tol: float) -> float:
    """The level predicted to bring the error to SAFETY * tol, within RATIO_RANGE of ``level``."""
    lo, hi = RATIO_RANGE
    ratio = hi if not np.isfinite(err) or err <= 0 else math.sqrt(err / (SAFETY * tol))
    return level / min(hi, max(lo, ratio))


def budget_level(cells, previous: float, wanted: float, max_elements: int, fits=None):
    """The finest level whose cells fit ``max_elements``, between ``wanted`` (the level the
    estimate asks for, over the budget) and ``previous`` (the last run's level), if it is
    at least :data:`BUDGET_RATIO` finer than ``previous``; else None.

    By bisection in ``log(level)`` on ``cells(level)`` (:meth:`Ladder.cells_of`, nothing
    is built): the budget
    still buys one more run, whose pair estimate (ratio >= BUDGET_RATIO to the last run)
    is the one returned.  ``fits(level) -> bool``, when given, must hold as well (the
    time budget: :func:`predicted_wall`); it must be true on coarser levels if on a finer one.
    """
    within = fits if fits is not None else (lambda lv: True)
    fits = lambda lv: cells(lv) <= max_elements and within(lv)  # noqa: E731
    lo, hi = math.log(previous / BUDGET_RATIO), math.log(wanted)
    if hi >= lo or not fits(math.exp(lo)):
        return None
    for _ in range(BUDGET_BISECTIONS):  # lo fits, hi does not
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if fits(math.exp(mid)) else (lo, mid)
    return math.exp(lo)


#: exponent of the cost per step in the cells when the last two runs do not give it (one
#: run: between the dense path's 2 and the rest's 1.1), and the range the fitted one is
#: kept in: a fast or sparse step costs about cells^1.1, a dense one cells^2
#: (``benchmarks/fast_operator.md``), while small runs, whose cost is mostly overhead, fit
#: below 1 and the switch to the fast operator (set-up, compilation) costs more than
#: either.  Replayed on the 147 recorded level changes of the auto and stress_auto
#: benchmarks (``benchmarks/time_budget.md``), predicted / actual wall time: median 2.03,
#: 0.45 to 18.7 (the pilots after the first run, which compiles); over the 76 runs
#: longer than 20 s median 1.70, 0.45 to 6.6 (the thin films at beta = 20000, whose steps
#: grow less than the level ratio), under 1 in 13 (most near the switch to the fast
#: operator).  With the range (1, 2), on the auto runs alone: median 1.35 over 20 s, but
#: under 1 in 11 of 32 (5 of 32 with this range).
COST_EXPONENT = 1.5
COST_EXPONENT_RANGE = (1.3, 2.0)


def predicted_wall(runs, cells: float, level: float) -> float:
    """The wall time (s) of a run at ``level`` with ``cells`` cells, from the finished ``runs``.

    Steps: the last run's times ``r = last level / level`` (adaptive BDF2 at ``tol_t``
    proportional to ``level**2`` takes steps proportional to ``1 / level``; measured
    ratios 1.6 to 1.85 per halving on the paper case).  Cost per step (set-up included):
    the last run's times ``(cells / its cells)**e``, ``e`` fitted on the last two runs'
    costs per step and kept in :data:`COST_EXPONENT_RANGE`, :data:`COST_EXPONENT` with
    one run.  ``runs`` carry ``info["elements"]``, ``info["wall"]``, ``info["level"]``
    and ``nsteps``.
    """
    last = runs[-1]
    n1, w1, s1 = float(last.info["elements"]), float(last.info["wall"]), max(1, last.nsteps)
    e = COST_EXPONENT
    if len(runs) >= 2:
        prev = runs[-2]
        n0, w0, s0 = float(prev.info["elements"]), float(prev.info["wall"]), max(1, prev.nsteps)
        if n1 > 1.05 * n0 and w0 > 0.0 and w1 > 0.0:
            e = math.log((w1 / s1) / (w0 / s0)) / math.log(n1 / n0)
            e = min(COST_EXPONENT_RANGE[1], max(COST_EXPONENT_RANGE[0], e))
    ratio = float(last.info["level"]) / level
    return w1 * (max(cells, 1.0) / n1) ** e * ratio


def check_max_wall(max_wall) -> float | None:
    """The automatic mode's time budget: None or a positive number of seconds."""
    if max_wall is None:
        return None
    if isinstance(max_wall, bool) or not isinstance(max_wall, int | float) or not (0 < max_wall < math.inf):
        raise SceneError(
            f"max_wall must be a positive number of seconds (or None: no limit), got {max_wall!r}."
        )
    return float(max_wall)


class _OutOfTime(Exception):
    """A run held in memory was still going at the deadline of ``max_wall``."""

    def __init__(self, t: float):
        super().__init__(t)
        self.t = t


def _deadline_guard(deadline: float, callback):
    """A state callback that calls ``callback`` and stops the run past ``deadline``."""

    def guard(state):
        if callback is not None:
            callback(state)
        if time.perf_counter() > deadline:
            raise _OutOfTime(float(state.t))

    return guard


def cell_budget(scene, max_elements: int | None = None) -> int:
    """The automatic mode's cell budget: ``max_elements``, or by default
    :data:`LOCAL_MAX_ELEMENTS` when the scene's substrate has sparse operators only
    (``substrate.local``), :data:`FAST_MAX_ELEMENTS` when it has the fast hierarchical
    operator (``"fast"`` in ``substrate.operators``, the default) and
    :data:`MAX_ELEMENTS` when its operator is dense only (a layer)."""
    if max_elements is None:
        from femehl.elastic.base import substrate_operators

        sub = getattr(scene, "substrate", None)  # None: a line contact's own foundation
        if getattr(sub, "local", False):
            return LOCAL_MAX_ELEMENTS
        if sub is not None and "fast" in substrate_operators(sub):
            return FAST_MAX_ELEMENTS
        return MAX_ELEMENTS
    if isinstance(max_elements, bool) or not isinstance(max_elements, int) or max_elements < 1:
        raise SceneError(f"max_elements must be a positive integer (cells), got {max_elements!r}.")
    return max_elements


def solve_to_tolerance(
    scene,
    *,
    t_end: float,
    tol: float = 1e-2,
    method: str | None = None,
    store_every: int = 1,
    max_elements: int | None = None,
    max_wall: float | None = None,
    level: float = LEVEL0,
    folder=None,
    on_run: Callable[[Result], None] | None = None,
    progress=None,
    **options,
) -> Result:
    """Run ``scene`` to ``t_end`` with the load and films to about ``tol`` relative.

    Returns the finest run (a :class:`~femehl.output.result.Result`) with ``result.estimate``
    (docs/design.md section 9 for the estimators) and ``result.info["auto"]``: ``tol``,
    ``reached`` (the estimate is <= :data:`ACCEPT` * ``tol``), ``accept``, ``stopped``
    (None, ``"cell budget"`` or ``"time budget"``: what ended a sequence that did not
    reach ``tol``), ``levels``, ``elements``, ``steps``,
    ``rejected_steps``, ``tol_t`` and ``wall`` of every run, and the largest estimated
    ``total``, ``space`` and ``time`` errors.  ``level`` is the first (coarsest) level;
    ``max_elements`` the cell budget (default: :func:`cell_budget` of the scene's
    substrate); ``max_wall`` a time budget in seconds for the whole sequence (default:
    none; see docs/design.md section 9); ``options`` go to
    :func:`femehl.solve` (not the discretization's,
    nor ``tol``, ``dt_max``); a ``callback`` is called with the states of every run;
    ``on_run(result)`` with every finished run, pilots included (its scalars stay; its
    fields are dropped once a finer run supersedes it); ``progress(desc, t_end, t_start)``
    makes a progress handler (a State callable with ``close()``) for each run;
    ``folder`` (a :class:`~femehl.output.run.RunFolder`) is fed each run that may be the
    answer (the pilots stay in memory; a finer candidate replaces the coarser one's files).
    """
    method = _check_request(scene, method, tol, on_run, options)
    ladder = LADDERS[method]
    max_elements = cell_budget(scene, max_elements)
    max_wall = check_max_wall(max_wall)
    deadline = None if max_wall is None else time.perf_counter() + max_wall
    cells = ladder.cells_of(scene, t_end)
    if folder is not None:
        folder.say(f"femehl: automatic run to tol = {tol:g} (pilot runs in memory, then the run itself)")

    def in_time(lv: float) -> bool:
        """A run at ``lv`` is predicted to finish before the deadline (always without one)."""
        if deadline is None:
            return True
        left = deadline - time.perf_counter()
        return left > 0.0 and (not runs or predicted_wall(runs, cells(lv), lv) <= left)

    runs, est, reached, err = [], None, False, math.nan
    fine, failed, last, stopped = None, None, False, None
    family = 0  # runs[family:] are on the current ladder (a pair is made within it only)
    seeded, adapted_at = False, None  # one run may seed adapted meshes; the level of that run
    while True:
        if (runs or failed) and (cells(level) > max_elements or not in_time(level)):
            fit, why = _within_budget(cells, runs, level, max_elements, in_time, deadline, last)
            if fit is None:
                stopped = why
                if failed is not None and not runs:
                    if why == "time budget":
                        raise TimeBudgetError(
                            f"no run finished within max_wall = {max_wall:g} s: the film closed on the "
                            f"coarser meshes ({failed}). Give a larger max_wall.",
                            t=failed.t,
                        ) from failed
                    raise failed  # no level within the budget got through
                break
            # the cell budget's fit is the finest level there is; the time budget's is
            # asked again after the run (a run cheaper than predicted leaves time for more)
            level, last, stopped = fit, why == "cell budget", why
        candidate = len(runs) >= MIN_RUNS - 1 and len(runs) > family
        previous = runs[-1] if candidate else None
        seed = ladder.adapt is not None and not seeded and level <= ADAPT_LEVEL
        try:
            res = _run(
                scene,
                method,
                ladder,
                t_end,
                level,
                1 if seed else store_every,  # the run meshes are adapted to: all its states
                options,
                folder,
                previous,
                deadline,
                progress,
                tol,
            )
        except _OutOfTime as exc:
            stopped = "time budget"
            if not runs:
                raise TimeBudgetError(
                    f"no run finished within max_wall = {max_wall:g} s: the first, at level {level:.3g} "
                    f"(~{cells(level):.0f} cells), had reached t = {exc.t:.4g} of {t_end:g}. Give a larger "
                    "max_wall, or a coarser first level (level=).",
                    t=exc.t,
                ) from None
            logger.warning(
                "auto: max_wall = %g s reached at t = %.4g of the run at level %.3g: it is abandoned, "
                "the answer is the last finished run",
                max_wall,
                exc.t,
                level,
            )
            break
        except SolverError as exc:
            if getattr(exc, "where", None) is None:
                raise  # not a film that closes or a step floor: nothing a finer mesh changes
            failed = _closing_confirmed(failed, exc, level, t_end)
            level /= 2.0  # the film closed on this mesh: a finer one decides whether it really closes
            continue
        if len(runs) > family:
            ratio = runs[-1].info["level"] / level
            est = estimate(res, runs[-1], ratio)
            err = est.worst()
            logger.info("auto: estimated error %.3g (%s), level ratio %.3g", err, est.where(), ratio)
        else:
            est, err = None, math.nan
        if fine is not None:
            fine._stored.clear()  # superseded: its scalars stay (the companion), its fields go
        fine = res
        runs.append(res)
        if on_run is not None:
            on_run(res)
        if len(runs) >= MIN_RUNS and err <= ACCEPT * tol:
            reached = True
            break
        if last:
            break
        seeded = seeded or seed  # adapted to it or not, the meshes are decided once
        if seed and not err <= ACCEPT * tol:  # from here on, meshes adapted to this run, from its level again
            adapted = _adapted(ladder, res, scene, t_end)
            if adapted is not None:
                ladder, family, adapted_at = adapted, len(runs), level
                cells = ladder.cells_of(scene, t_end)
                continue
        level = _next_level(level, err, tol) if len(runs) - family >= 2 else level / 2.0
    adapted_at = adapted_at if len(runs) > family else None  # no run was made on adapted meshes
    return _finish(fine, est, runs, tol, reached, None if reached else stopped, max_wall, adapted_at)


def _check_request(scene, method, tol, on_run, options) -> str:
    """The method of an automatic run (SceneError naming the fix for a bad request)."""
    from femehl.solver.loop import _registry

    method = scene.default_method if method is None else method
    if method not in LADDERS:
        known = sorted(_registry())
        raise SceneError(
            f"method {method!r} has no refinement ladder, so it cannot choose its own "
            f"discretization; automatic methods: {sorted(LADDERS)} (all: {known}). "
            "Give its discretization options and dt (or tol for the time steps) instead."
        )
    if isinstance(tol, bool) or not (isinstance(tol, float | int) and 0 < tol < 1):
        raise SceneError(f"tol must be a number in (0, 1), e.g. 1e-2 for 1 %; got {tol!r}.")
    if on_run is not None and not callable(on_run):
        raise SceneError(f"on_run must be a function of a finished run (a Result), got {on_run!r}.")
    for key in ("dt_max", "dt", *LADDERS[method].keys):
        if key in options:
            raise SceneError(f"solve_to_tolerance chooses {key!r} itself; do not pass it.")
    return method


def _within_budget(cells, runs, level, max_elements, in_time, deadline, last) -> tuple:
    """``(fit, why)`` when ``level`` is over a budget: the finest level within it to run
    instead (None: stop), and which budget binds (``"cell budget"`` or ``"time budget"``)."""
    ne = cells(level)
    over_cells = ne > max_elements
    fit = cell_fit = None
    if runs and not last:
        before = runs[-1].info["level"]
        fit = budget_level(cells, before, level, max_elements, fits=in_time)
        cell_fit = fit if deadline is None else budget_level(cells, before, level, max_elements)
    # the budget that binds: time, when the cells alone are not exceeded or allow a
    # finer level than the time does (beyond the bisection's 1 %)
    time_binds = not over_cells or (cell_fit is not None and (fit is None or cell_fit < fit / 1.02))
    why = "time budget" if time_binds else "cell budget"
    if fit is None:
        logger.info("auto: level %.3g (~%.0f cells) is over the %s: stop", level, ne, why)
    else:
        logger.info(
            "auto: level %.3g (~%.0f cells) is over the %s: a run at level %.3g, the finest within it",
            level,
            ne,
            why,
            fit,
        )
    return fit, why


def _adapted(ladder: Ladder, res: Result, scene, t_end: float) -> Ladder | None:
    """The ladder adapted to ``res`` (None, logged, when the run gives nothing to adapt to)."""
    from femehl.errors import FemehlError

    try:
        adapted = ladder.adapt(res, scene, t_end)
    except FemehlError as exc:
        logger.warning("auto: meshes not adapted (%s): the fitted meshes go on", exc)
        return None
    logger.info(
        "auto: meshes adapted to the run at level %.3g (%d cells) from here on",
        res.info["level"],
        res.info["elements"],
    )
    return adapted


#: two runs whose films close within this fraction of t_end of each other, and within
#: CLOSE_DISTANCE of each other in space, confirm that the film really closes
CLOSE_TIME, CLOSE_DISTANCE = 0.05, 0.2
#: ... if the finer one's film fell steadily to zero, or below this fraction of the initial film
CLOSED_FILM = 1e-3


def _closing_confirmed(earlier, exc, level, t_end):
    """Raise ``exc`` if a coarser run closed its film at about the same time and place.

    A film that closes on one mesh may only be unresolved there (a coarse pilot at a
    thin exit); the next level, twice as fine, decides.  The closing is confirmed when
    this run's film really closes (``reason == "closes"``: it fell steadily to zero; or
    the step floor was reached with the film below CLOSED_FILM times the initial film),
    at a level <= 1 (not a pilot), within CLOSE_TIME * t_end and CLOSE_DISTANCE of the
    previous failure.  Returns ``exc`` (with the level recorded)
    to remember for that comparison.
    """
    exc.level = level
    logger.info(
        "auto: the film closed at level %.3g (t = %.4g at %s): trying a finer mesh", level, exc.t, exc.where
    )
    d_min, film0 = getattr(exc, "d_min", math.nan), getattr(exc, "film0", math.nan)
    closed = getattr(exc, "reason", "closes") == "closes" or d_min <= CLOSED_FILM * film0
    if earlier is not None and closed and level <= 1.0:
        dt = abs(float(exc.t) - float(earlier.t))
        dx = float(np.hypot(*(np.asarray(exc.where, float) - np.asarray(earlier.where, float))))
        if dt <= CLOSE_TIME * t_end and dx <= CLOSE_DISTANCE:
            exc.args = (
                f"{exc.args[0]} The film closed at about the same time and place on two meshes "
                f"(levels {earlier.level:.3g} and {level:.3g}), the finer one to {d_min:.3g} "
                f"({d_min / film0:.2g} of the initial film): it really closes.",
                *exc.args[1:],
            )
            raise exc
    return exc


def _finish(res: Result, est, runs, tol, reached, stopped=None, max_wall=None, adapted_at=None) -> Result:
    """Attach the estimate and the summary of the runs; warn when tol was not reached."""
    res.estimate = est
    info = {
        "tol": tol,
        "reached": reached,
        "accept": ACCEPT,
        "stopped": stopped,
        "max_wall": max_wall,
        "levels": [r.info["level"] for r in runs],
        "elements": [r.info["elements"] for r in runs],
        "steps": [r.nsteps for r in runs],
        "rejected_steps": [r.info.get("rejected_steps") for r in runs],
        "tol_t": [r.info["tol_t"] for r in runs],
        "wall": [r.info["wall"] for r in runs],
        "adapted_at": adapted_at,
    }
    if est is not None:
        info.update({part: est.worst(part) for part in ("total", "space", "time")})
    res.info["auto"] = info
    if not reached:
        worst = "unknown (one level only)" if est is None else f"{info['total']:.3g}"
        cells = max(info["elements"])
        within = f"max_wall = {max_wall:g} s" if stopped == "time budget" else f"{cells} cells"
        logger.warning(
            "solve_to_tolerance: tolerance %g not reached within %s: estimated error %s (accepted at "
            "<= %g tol)",
            tol,
            within,
            worst,
            ACCEPT,
        )
    return res
