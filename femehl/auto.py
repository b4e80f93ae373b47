"""Any scene to a requested accuracy, with an error estimate: :func:`solve_to_tolerance`.

A first version, FE only.  The run is repeated on fitted meshes
(:func:`femehl.fe.fitted.fitted_disk`) of decreasing size level ``1, 1/1.45, 1/1.45^2,
...`` (each about twice the elements of the previous one), every run with adaptive BDF2
time steps (:mod:`femehl.core.adaptive`) at ``tol_t = tol / 3``, until the estimated
space error of the headline quantities is below ``tol / 2``.  The finest run is returned
with ``result.estimate`` and :meth:`femehl.result.Result.uncertainty`.

Estimators (relative errors, one array per quantity on the returned run's ``t``)
--------------------------------------------------------------------------------
Relative to ``max(|q(t)|, floor)`` with the floor 0.1 for the load (as the adaptive
controller's ``LOAD_FLOOR``: a load growing from 0 has no relative error) and 0 for the
films.

* **space** (Richardson, order 2 in h, ratio 1.45): with ``q_f`` the finer run and
  ``q_c`` the coarser run interpolated onto the finer run's times (``value_at``),
  ``err_space = |q_f - q_c| / (1.45^2 - 1)``.  The difference also holds the two runs'
  different time errors (their step sequences differ); at ``tol_t = tol/3`` that part was
  measured below the space difference (paper sphere, t = 1.5: film_min 0.03438 / 0.03451
  at levels 1 / 1/1.45 with tol_t = tol/3; 0.03435 / 0.03444 at tol/9), so it makes the
  estimate larger, not smaller.
* **time** (accumulated local errors): the controller's per-step estimate
  ``error_estimate`` is a local error per unit time (per 0.01 below steps of 0.01) in
  the relative max norm over the film points and the load, so
  ``err_time(t_n) = sum_{k <= n} error_estimate_k * max(dt_k, 0.01)`` bounds the
  accumulated local errors with no damping and no cancellation: one bound for every
  quantity, free (no extra run).  Measured in tests/test_adaptive.py: the global error is
  0.3-1 times ``tol * t``; this sum is about ``0.5 tol_t * t``.
* **total** = space + time.

Why adaptive steps at tol/3 (not a fixed small dt): on the paper sphere to t = 1.5 the
adaptive runs take 160-200 accepted steps (4-38 rejected trials) where the reference's
fixed dt = 0.0025 takes 600, and their time estimate (<= 0.26 % at tol = 1e-2) is below
the space part.  Why the accumulated estimate (not a second run at 3 tol_t): it costs
nothing, and it does not rely on two adaptive step sequences differing smoothly.

Measured against benchmarks/auto_reference.json (tests/test_auto.py, paper sphere,
t_end = 1.5, max over the steps): from level 1.45 at tol = 3e-2 the estimated / true
errors are load 0.95 % / 0.19 %, film_center 1.02 % / 0.40 %, film_min 1.56 % / 1.58 %
(estimate >= true/2 at 90-100 % of the steps); the ellipsoid of the tests 0.72 / 0.09,
0.84 / 0.34, 0.90 / 0.51 % (benchmarks/auto_results.md).  The largest space estimate is the minimum
film early in the run (t ~ 0.04, the film minimum near the tip sampled at element
centroids), so tol = 1e-2 takes the sphere to level 1/1.45^2 (12642 elements).

Budget: a level whose mesh would exceed ``max_elements`` (default 25,000, about 3 GB of
dense influence matrix) is not run; the tolerance is then reported as not reached
(``result.info["auto"]["reached"] = False`` and a logging warning).
"""

from __future__ import annotations

import logging
import time

import numpy as np

from .api import solve
from .core.adaptive import LOAD_FLOOR, UNIT_STEP
from .errors import SceneError
from .fe.fitted import fitted_disk, fitted_sizes
from .result import Result

__all__ = ["solve_to_tolerance", "QUANTITIES", "RATIO", "MAX_ELEMENTS"]

logger = logging.getLogger("femehl")

#: the headline quantities whose errors are estimated
QUANTITIES = ("load", "film_center", "film_min")
#: mesh size ratio between two levels (one ladder rung: about twice the elements)
RATIO = 1.45
#: observed/expected order of the FE space error in h
ORDER = 2
#: levels whose fitted mesh would have more elements than this are not run
MAX_ELEMENTS = 25_000
#: the time tolerance given to the adaptive controller, as a fraction of tol
TIME_SHARE = 1.0 / 3.0
#: the space estimate must stay below this fraction of tol
SPACE_SHARE = 0.5


def _scale(name: str, q: np.ndarray) -> np.ndarray:
    """The denominator of relative errors: |q|, floored at LOAD_FLOOR for the load."""
    floor = LOAD_FLOOR if name == "load" else 0.0
    return np.maximum(np.abs(q), floor)


def space_error(fine: Result, coarse: Result, name: str) -> np.ndarray:
    """Relative Richardson estimate of ``fine``'s space error of ``name`` on ``fine.t``."""
    qf = getattr(fine, name)
    qc = np.array([coarse.value_at(name, t) for t in fine.t])
    return np.abs(qf - qc) / (RATIO**ORDER - 1.0) / _scale(name, qf)


def time_error(steps: list) -> np.ndarray:
    """Accumulated local time errors ``sum error_estimate * max(dt, UNIT_STEP)`` per step.

    ``steps`` holds ``(t, dt, error_estimate)`` of every state of the run (the initial
    state has dt = 0 and a nan estimate: no error).
    """
    local = np.array([0.0 if not np.isfinite(e) or dt <= 0 else e * max(dt, UNIT_STEP) for _, dt, e in steps])
    return np.cumsum(local)


def estimate(fine: Result, coarse: Result, steps: list) -> dict:
    """``{"t": fine.t, name: {"space", "time", "total"}}`` for every quantity."""
    et = time_error(steps)
    if et.size != fine.t.size:
        raise SceneError(f"internal: {et.size} step records for {fine.t.size} steps")
    out = {"t": fine.t}
    for name in QUANTITIES:
        es = space_error(fine, coarse, name)
        out[name] = {"space": es, "time": et.copy(), "total": es + et}
    return out


def _elements(scene, t_end: float, level: float) -> float:
    half = bool(getattr(scene.indenter, "symmetric_y", False))
    return fitted_sizes(scene, t_end, level).estimate_elements(half)


def _run(scene, t_end, level, tol_t, store_every, options) -> tuple[Result, list]:
    """One adaptive run on the fitted mesh at ``level``; also every step's (t, dt, err)."""
    mesh = fitted_disk(scene, t_end, level=level)
    steps = []
    user = options.get("callback")
    options = {k: v for k, v in options.items() if k != "callback"}

    def record(state):
        steps.append((state.t, state.info.get("dt", 0.0), state.info.get("error_estimate", np.nan)))
        if user is not None:
            user(state)

    t0 = time.perf_counter()
    res = solve(
        scene, "fe", t_end=t_end, tol=tol_t, store_every=store_every, callback=record, mesh=mesh, **options
    )
    n = int(mesh.mesh.t.shape[1])
    res.info.update(level=level, elements=n, wall=time.perf_counter() - t0)
    logger.info("auto: level %.4g, %d elements, %d steps, %.1f s", level, n, res.nsteps, res.info["wall"])
    return res, steps


def _worst(est: dict, part: str) -> float:
    return max(float(np.max(est[q][part])) for q in QUANTITIES)


def solve_to_tolerance(
    scene,
    *,
    t_end: float,
    tol: float = 1e-2,
    method: str = "fe",
    store_every: int = 1,
    max_elements: int = MAX_ELEMENTS,
    level: float = 1.0,
    **options,
) -> Result:
    """Run ``scene`` to ``t_end`` with the load and films to about ``tol`` relative.

    Returns the finest run (a :class:`~femehl.result.Result`) with ``result.estimate``
    (see the module docstring for the estimators) and ``result.info["auto"]``: ``tol``,
    ``reached``, ``levels``, ``elements``, ``steps`` and ``wall`` of every run, and the
    largest estimated ``space``, ``time`` and ``total`` errors.  ``level`` is the first
    (coarsest) level; ``options`` go to :func:`femehl.solve` (not ``mesh``, ``tol``);
    a ``callback`` is called with the states of every run.
    """
    if method != "fe":
        raise SceneError(f"solve_to_tolerance: method {method!r} is not supported yet; use method='fe'.")
    if not (isinstance(tol, float | int) and 0 < tol < 1):
        raise SceneError(f"solve_to_tolerance: tol must be in (0, 1), got {tol!r}.")
    for key in ("mesh", "tol", "dt_max"):
        if key in options:
            raise SceneError(f"solve_to_tolerance chooses {key!r} itself; do not pass it.")
    tol_t = TIME_SHARE * tol
    coarse, _ = _run(scene, t_end, level, tol_t, store_every, options)
    runs = [coarse]
    fine, est, reached = coarse, None, False
    while True:
        level /= RATIO
        ne = _elements(scene, t_end, level)
        if ne > max_elements:
            logger.info("auto: level %.4g would have ~%.0f elements > %d: stop", level, ne, max_elements)
            break
        fine, steps = _run(scene, t_end, level, tol_t, store_every, options)
        runs.append(fine)
        est = estimate(fine, coarse, steps)
        if _worst(est, "space") <= SPACE_SHARE * tol:
            reached = True
            break
        coarse = fine
    return _finish(fine, est, runs, tol, reached)


def _finish(res: Result, est, runs, tol, reached) -> Result:
    """Attach the estimate and the summary of the runs; warn when tol was not reached."""
    res.estimate = est
    info = {
        "tol": tol,
        "reached": reached,
        "levels": [r.info["level"] for r in runs],
        "elements": [r.info["elements"] for r in runs],
        "steps": [r.nsteps for r in runs],
        "rejected_steps": [r.info.get("rejected_steps") for r in runs],
        "wall": [r.info["wall"] for r in runs],
    }
    if est is not None:
        info.update({part: _worst(est, part) for part in ("space", "time", "total")})
    res.info["auto"] = info
    if not reached:
        worst = "unknown (one level only)" if est is None else f"{info['space']:.3g}"
        logger.warning(
            "solve_to_tolerance: tolerance %g not reached within %d elements: estimated space error %s",
            tol,
            max(info["elements"]),
            worst,
        )
    return res
