"""Adaptive time steps, still ONE linear system per trial step: :class:`AdaptiveSteps`, the
step policy the one time loop (:func:`femehl.solver.stepping.march`) walks with when a step
tolerance is given.

The estimator (Milne's device on the film and the load), its norm, the controller, the
start pair, breakpoints and restarts, and the failures are in docs/design.md section 3.1.
Every yielded State's ``info`` gets ``dt``, ``error_estimate`` (nan where none was made) and
``rejected`` (trial steps discarded since the previous yielded state).
"""

from __future__ import annotations

import dataclasses
import itertools
import logging
import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from femehl.errors import FilmRuptureError, SceneError, SolverError
from femehl.solver.stepping import State, breakpoints_of, film_floor, film_positive, without_history
from femehl.validation import check_positive

__all__ = ["AdaptiveSteps", "StepController", "breakpoints_of", "CONTROLS"]

logger = logging.getLogger("femehl")

#: a rejected (failed) trial is retried with this fraction of its step
RETRY_FACTOR = 0.25
#: "a few steps": a film closes when its last decrease extrapolates to zero within this many steps
CLOSE_STEPS = 3.0
#: ... or when, decreasing steadily, it is thinner than THIN_FILM times the initial thinnest film
THIN_FILM = 1e-4
#: the load component is relative to max(largest |load| so far, LOAD_FLOOR): loads are O(0.1 .. 1)
#: in the paper's normalization, and a load growing from 0 has no relative error at t = 0
LOAD_FLOOR = 0.1
#: the local error is per unit time for steps longer than UNIT_STEP, per UNIT_STEP below
UNIT_STEP = 0.01
#: the lag's period-two mode (:func:`_lag_mode`): three film increments in a row, each with a
#: cosine below -LAG_COSINE to the one before, the last at least LAG_RATIO of the one before
#: and its largest relative change above LAG_FLOOR times tol (an oscillation that small is
#: harmless; a diverging one crosses it within steps); the step is then retried, and every
#: later one kept, below LAG_SHARE of it (a quarter: the time companion's steps, twice the
#: run's, stay below half of it)
LAG_COSINE = 0.5
LAG_RATIO = 0.9
LAG_FLOOR = 3e-3
LAG_SHARE = 0.25
#: keyword arguments of :class:`AdaptiveSteps` that tune the controller
CONTROLS = ("dt0", "dt_min", "dt_max", "safety")


@dataclass(frozen=True)
class StepController:
    """The step-size rule: ``dt * min(fac_max, max(fac_min, safety * (tol/err)^(1/p)))``.

    ``err`` is an error per unit time of a method of order ``p`` (``err ~ dt^p``).
    """

    tol: float
    safety: float = 0.9
    fac_min: float = 0.2
    fac_max: float = 2.0
    hold: float = 1.5

    def accepts(self, err: float) -> bool:
        return err <= self.tol

    def factor(self, err: float, order: int, grow: bool = True, dt: float = math.inf) -> float:
        """The factor of the next step after an error ``err`` of a method of order ``order``."""
        top = self.fac_max if grow else 1.0
        if not err > 0.0:
            return top
        p = order if dt >= UNIT_STEP else order + 1
        f = self.safety * (self.tol / err) ** (1.0 / p)
        return min(top, max(self.fac_min, f))

    def kink_factor(self, err: float, dt: float) -> float:
        """The factor after a second rejection of one step, whose error did not fall as
        ``dt^p``: a kink's (the contact edge crossing a node), whose local error falls only as
        ``dt``, so per unit time it is flat above ``UNIT_STEP`` and ``~ dt`` below."""
        f = self.safety * (self.tol / err) * min(dt, UNIT_STEP) / dt
        return min(1.0, max(self.fac_min, f))


@dataclass
class _Run:
    """The explicit state of an adaptive run between trial steps."""

    dt: float  # the next trial step
    levels: list  # accepted states since the last (re)start, <= 3
    pending: State | None = None  # the Euler start step, yielded once its pair passes
    pending_rejected: int = 0
    rejected: int = 0  # trials discarded since the last yielded state
    grow: bool = True  # False right after a rejection
    streak: int = 0  # consecutive error rejections of this step
    load_scale: float = 0.0  # largest |load| so far
    recent: deque = field(default_factory=lambda: deque(maxlen=6))  # last yielded states
    film0: float = math.nan  # the initial thinnest film
    accepted_total: int = 0
    rejected_total: int = 0
    dt_low: float = math.inf
    dt_high: float = 0.0
    #: the substrate's pressure follows the motion at once (``substrate.instant``: rigid):
    #: the load jumps at the (re)start ``origin`` where hc' does, which is no time error
    instant: bool = False
    origin: float = -math.inf
    #: the first state does not carry the imposed load (an impulsive start, F(t0) != its
    #: load): the first step is a jump, accepted alone, and the run restarts after it
    jump: bool = False
    stops: list = field(default_factory=list)  # the breakpoints ahead, then t_end
    trial: tuple = (math.nan, math.nan)  # the trial step proposed: (t_new, h)
    #: ``settled(states)``: the film points the estimate reads (None: all), from the fluid's
    #: cavitation model (JFO: not the cells whose nodes switched set)
    settled: object = None
    #: ``switched(states)``: whether the cavitated set switched a node over them (None: no set)
    switched: object = None
    #: where the last catch of the lag's mode retried its step: the check reads the steps after it
    lag_from: float = -math.inf


@dataclass(frozen=True)
class _Failure:
    """Why a trial step failed: the message, and the film and its place when known."""

    reason: str
    where: tuple | None = None
    d: float | None = None
    label: str = "the film points"


# ---- helpers ------------------------------------------------------------------------------
def _order(stepper) -> int:
    return int(getattr(getattr(stepper, "scheme", None), "order", 2))


def _tag(state: State, dt: float, err: float, rejected: int) -> State:
    info = dict(state.info)
    info.update(dt=float(dt), error_estimate=float(err), rejected=int(rejected))
    return dataclasses.replace(state, info=info)


def _lagrange(ts, t) -> np.ndarray:
    """Weights of the polynomial through the times ``ts`` evaluated at ``t``."""
    w = np.ones(len(ts))
    for i, ti in enumerate(ts):
        for j, tj in enumerate(ts):
            if j != i:
                w[i] *= (t - tj) / (ti - tj)
    return w


def _norm(run: _Run, trial: State, d_pred: np.ndarray, load_pred: float | None) -> float:
    """``max( max_i |d_i - d_pred_i| / d_i, |F - F_pred| / max|F| )`` (docs/design.md section 3.1);
    the film alone when ``load_pred`` is None.  Where a part lets the film close
    (``info["film_error_floor"]``: a rough surface's sigma), the film's scale is at least that."""
    d = np.asarray(trial.d, dtype=float)
    rel = np.abs(d - d_pred) / np.maximum(d, (trial.info or {}).get("film_error_floor", 0.0))
    keep = None if run.settled is None else run.settled([*run.levels, trial])
    if keep is not None and keep.any():
        rel = rel[keep]
    err = float(np.max(rel)) if rel.size else 0.0
    if load_pred is None:
        return err
    load = _load(trial)
    scale = max(run.load_scale, abs(load), LOAD_FLOOR)
    return max(err, abs(load - load_pred) / scale)


def _impulsive(scene, state: State) -> bool:
    """True when an imposed load is applied at once: ``F(t0)`` is not the first state's load
    (a constant load from rest).  The pressure and hc jump at ``t0+``, and the film near
    the rim with them (by an amount that depends on the first step, not on its error)."""
    mo = getattr(scene, "motion", None)
    if mo is None or not getattr(mo, "load_controlled", False) or getattr(mo, "free", False):
        return False
    F = float(mo.F(state.t))
    return abs(F - _load(state)) > 1e-9 * max(abs(F), LOAD_FLOOR)


def _load(state: State) -> float:
    """The load of the step's own solution (half-Sommerfeld: before its clipping, so the
    steps are those of the full-Sommerfeld run)."""
    return float((state.info or {}).get("load_full", state.load))


def _predict(run: _Run, levels, t):
    """The film and load extrapolated to ``t``; the load of an instant substrate from the
    levels after its (re)start only, and never from a step a part marks ``load_unsettled``
    (a cavitation set not formed yet), linear from two levels, None from fewer."""
    w = _lagrange([s.t for s in levels], t)
    d_pred = sum(wi * np.asarray(s.d, dtype=float) for wi, s in zip(w, levels, strict=True))
    kept = [s for s in levels if not (s.info or {}).get("load_unsettled")]
    if run.instant:
        kept = [s for s in kept if s.t > run.origin]
    if len(kept) < len(levels):
        if len(kept) < 2:
            return d_pred, None
        levels = kept
        w = _lagrange([s.t for s in levels], t)
    load_pred = float(sum(wi * _load(s) for wi, s in zip(w, levels, strict=True)))
    return d_pred, load_pred


def _milne(run: _Run, trial: State, order: int) -> float:
    """The local error of a step of a method of ``order`` from its last ``order + 1`` levels."""
    levels = run.levels[-(order + 1) :]
    h = trial.t - levels[-1].t
    h1 = levels[-1].t - levels[-2].t
    if order == 1:
        c = h / (2.0 * h + h1)
    else:
        h2 = levels[-2].t - levels[-3].t
        om = h / h1
        hb = h * (1.0 + om) / (1.0 + 2.0 * om)
        c = hb / (hb + h + h1 + h2)
    return c * _norm(run, trial, *_predict(run, levels, trial.t)) / max(h, UNIT_STEP)


def _start_error(run: _Run, trial: State) -> float:
    """The error of the Euler start step from the second difference of ``d0, d1, d2``."""
    s0, s1 = run.levels[0], run.levels[1]
    h1, h2 = s1.t - s0.t, trial.t - s1.t
    err = _norm(run, trial, *_predict(run, [s0, s1], trial.t))
    return h1 * h1 / (h2 * (h1 + h2)) * err / max(h1, UNIT_STEP)


def _next_h(dt: float, remaining: float) -> float:
    """The step toward a stop ``remaining`` ahead: land on it, never leave a sliver."""
    if remaining <= dt * (1.0 + 1e-9):
        return remaining
    if remaining < 2.0 * dt:
        return 0.5 * remaining
    return dt


def _film_track(stepper, states, where):
    """Times and films at the film point nearest ``where`` (the film floor if it cannot tell)."""
    pts = getattr(getattr(stepper, "disc", None), "film_points", None)
    ts = [s.t for s in states]
    if where is not None and pts is not None and all(np.size(s.d) == len(pts) for s in states):
        i = int(np.argmin(np.sum((np.asarray(pts) - np.asarray(where)) ** 2, axis=1)))
        return ts, [float(s.d[i]) for s in states]
    return ts, [film_floor(s)[0] for s in states]


def _closing(ts, ds, film0: float) -> float | None:
    """The time the film reaches 0 if it closes steadily, else None.

    Steadily: it decreased over each of the last (at least 3) accepted levels, and its last
    rate of decrease reaches zero within CLOSE_STEPS steps, or it is already thinner than
    THIN_FILM times the initial thinnest film ``film0``.
    """
    ts, ds = ts[-4:], ds[-4:]
    if len(ds) < 3 or not all(b < a for a, b in zip(ds, ds[1:], strict=False)):
        return None
    h = ts[-1] - ts[-2]
    rate = (ds[-2] - ds[-1]) / h
    if rate <= 0.0:
        return None
    if ds[-1] / rate > CLOSE_STEPS * h and not ds[-1] < THIN_FILM * film0:
        return None
    return ts[-1] + ds[-1] / rate


def _floor_error(
    stepper, run: _Run, t_new: float, h: float, dt_min: float, fail: _Failure | None, err: float | None = None
):
    """The error to raise when a retry would go below ``dt_min``."""
    last = run.levels[-1]
    if fail is not None and fail.where is not None:
        where, d, label = fail.where, fail.d, fail.label
    else:
        d, where, label = film_floor(last)
    x, y = (tuple(where) + (0.0, 0.0))[:2]
    states = list(run.recent)
    ts, ds = _film_track(stepper, states, where)
    # where a part carries the load through contact (rough asperities) a film <= 0 is no end
    t_zero = None if "film_limit" in (last.info or {}) else _closing(ts, ds, run.film0)
    what = f"a trial step of dt = {h:.3g} to t = {t_new:.6g} " + (
        f"failed ({fail.reason})" if fail is not None else f"has an error estimate {err:.3g} > tol"
    )
    history = ", ".join(f"{v:.3g}" for v in ds[-4:])
    ts = ts[-4:]
    if t_zero is not None:
        exc = FilmRuptureError(
            f"the film closes (solid contact) near t = {t_new:.6g}, at {label} (x, y) = ({x:.3g}, "
            f"{y:.3g}): over the last accepted steps (t = {ts[0]:.6g} .. {ts[-1]:.6g}) it fell "
            f"steadily ({history}), which extrapolates to zero by t = {t_zero:.6g}, and {what} "
            f"at the step floor dt_min = {dt_min:.3g}. The load squeezes the film out: the "
            "lubricated model no longer applies.",
            t=t_new,
            where=(x, y),
            d_min=float(d),
        )
        exc.reason = "closes"
        exc.film0 = float(run.film0)
        return exc
    msg = (
        f"adaptive step floor reached at t = {last.t:.6g}: {what}, and the next retry would "
        f"be below dt_min = {dt_min:.3g}; the film at {label} (x, y) = ({x:.3g}, {y:.3g}) is "
        f"{float(d):.3g} and was not closing steadily over the last accepted steps "
        f"({history}). Try a finer discretization or a smaller dt_min."
    )
    if fail is None:
        exc = SolverError(msg, t=last.t)
    else:
        exc = FilmRuptureError(msg, t=last.t, where=(x, y), d_min=float(d))
    exc.reason = "step floor"
    exc.where, exc.d_min, exc.film0 = (x, y), float(d), float(run.film0)  # for femehl.auto
    return exc


def _limits(t_span, tol, dt0, dt_min, dt_max, limit=math.inf, squeeze=math.inf):
    dt_max = t_span / 10.0 if dt_max is None else check_positive("dt_max", dt_max)
    dt_max = min(dt_max, limit)  # the substrate's model resolves no longer step (its memory)
    # the floor stays 100 times below the first step (a long run at a small tol starts
    # with steps ~0.05 tol, below 1e-6 of its span); the first step is no longer than the
    # film's squeeze time, the floor 100 times below it
    if dt_min is None:
        dt_min = min(1e-6 * t_span, 5e-4 * tol, dt_max, 0.01 * squeeze)
    else:
        dt_min = check_positive("dt_min", dt_min)
    if dt0 is None:
        dt0 = max(dt_min, min(dt_max, 0.05 * tol, squeeze))
    dt0 = check_positive("dt0", dt0)
    if dt0 > dt_max == limit:  # a first step given beyond what the substrate resolves
        dt0 = max(dt_min, dt_max)
    if not dt_min <= dt0 <= dt_max:
        raise SceneError(f"need dt_min <= dt0 <= dt_max, got {dt_min:g}, {dt0:g}, {dt_max:g}.")
    return dt0, dt_min, dt_max


def _squeeze_time(scene, state: State) -> float:
    """``1 / (beta d0^2)``: the time in which a unit pressure squeezes the initial thinnest
    film ``d0`` by its own size (``beta div(d^3 grad p) = dd/dt`` over a unit length).  A
    slow scene (``beta`` large: a soft rough ball at 1e-7 m/s, beta = 3e8, 2.8e-7) falls
    to the asperities that fast when its load comes on: a first step of the usual
    ``0.05 tol`` takes the film, its coefficient lagged at ``d0``, through the asperities
    in one step (measured at 1.8e-6 m/s: from 40 sigma to -9 sigma in a step of 5e-4, and
    no later step recovers).  For the paper's beta = 200 it is 0.5: the usual steps."""
    beta = getattr(getattr(scene, "fluid", None), "beta", None)
    d0 = film_floor(state)[0]
    if not beta or not np.isfinite(d0) or d0 <= 0.0:
        return math.inf
    return 1.0 / (float(beta) * d0 * d0)


# ---- the step policy ----------------------------------------------------------------------
class AdaptiveSteps:
    """The step policy of adaptive steps to a local error ``tol`` (for
    :func:`femehl.solver.stepping.march`, the one time loop).

    Parameters
    ----------
    tol : float
        Relative local error per unit time, in the norm of docs/design.md section 3.1 (0 < tol < 1);
        the global error of load and films is then about 0.3 to 2 times tol (docs/design.md
        section 3.1).
    dt0 : float, optional
        First step and the step after each breakpoint; default ``0.05 tol``, at most the
        film's squeeze time ``1 / (beta d0^2)``.
    dt_min, dt_max : float, optional
        Step floor and ceiling; default ``min(1e-6 span, 5e-4 tol)`` (100 times below
        the default first step) and ``0.1`` times the run's span.  The ceiling is at most
        the substrate's ``step_limit`` (:func:`femehl.elastic.base.step_limit`: the
        largest step a viscoelastic memory resolves).
    safety : float, default: 0.9
        The controller's safety factor.

    The stepper is a LaggedStepper or any object with ``initial_state()``, ``step(state, t,
    dt)`` (and optionally ``scheme`` and ``scene`` for the order and the breakpoints).  A
    run from ``start`` drops its history: the run restarts there.
    """

    def __init__(
        self,
        tol: float,
        *,
        dt0: float | None = None,
        dt_min: float | None = None,
        dt_max: float | None = None,
        safety: float = 0.9,
    ):
        tol = check_positive("tol", tol, "Give a relative error per unit time, e.g. 1e-3.")
        if tol >= 1.0:
            raise SceneError(f"tol = {tol:g} is a relative error per unit time: use tol < 1 (e.g. 1e-3).")
        safety = check_positive("safety", safety)
        if safety > 1.0:
            raise SceneError(f"safety = {safety:g} must be in (0, 1] (0.9 is usual).")
        self.tol, self.safety = tol, safety
        self.dt0, self.dt_min, self.dt_max = dt0, dt_min, dt_max

    def begin(self, stepper, t_end: float, start: State | None) -> State:
        from femehl.elastic.base import step_limit

        t_end = check_positive("t_end", t_end, "Give the end time of the run in normalized units.")
        state = stepper.initial_state() if start is None else start
        if t_end <= state.t:
            raise SceneError(f"t_end = {t_end:g} is not after the start t = {state.t:g}.")
        scene = getattr(stepper, "scene", None)
        limit = step_limit(getattr(scene, "substrate", None), scene, getattr(stepper, "disc", None), t_end)
        dt0, dt_min, dt_max = _limits(
            t_end - state.t, self.tol, self.dt0, self.dt_min, self.dt_max, limit, _squeeze_time(scene, state)
        )
        eps = 1e-12 * max(1.0, abs(t_end))
        stops = sorted({b for b in breakpoints_of(scene) if state.t + eps < b < t_end - eps} | {t_end})
        state = _tag(state, 0.0, math.nan if start is None else state.info.get("error_estimate", math.nan), 0)
        self._stepper, self._order = stepper, _order(stepper)
        self._ctl = StepController(self.tol, self.safety)
        self._dt0, self._dt_min, self._dt_max, self._eps, self._t_end = dt0, dt_min, dt_max, eps, t_end
        cavitation = getattr(stepper, "cavitation", None)
        cells = getattr(cavitation, "settled_cells", None)
        disc = getattr(stepper, "disc", None)
        self._run = _Run(
            settled=None if cells is None else (lambda states: cells(disc, states)),
            switched=getattr(cavitation, "set_switched", None),
            dt=dt0,
            levels=[without_history(state)],
            load_scale=abs(_load(state)),
            film0=film_floor(state)[0],
            instant=bool(getattr(getattr(scene, "substrate", None), "instant", False)),
            origin=state.t,
            stops=stops,
            jump=_impulsive(scene, state),
        )
        self._run.recent.append(state)
        return state

    def propose(self):
        """The next trial ``(base, t_new, h)`` toward the next stop, None when the run is done."""
        run = self._run
        if not run.stops:
            logger.info(
                "femehl: adaptive run to t = %.6g: %d accepted steps, %d rejected trials, dt in [%.3g, %.3g]",
                self._t_end,
                run.accepted_total,
                run.rejected_total,
                run.dt_low,
                run.dt_high,
            )
            return None
        base, stop, dt_min = run.levels[-1], run.stops[0], self._dt_min
        remaining = stop - base.t
        if len(run.levels) == 1:  # the Euler start step leaves room for the second step of its pair
            if remaining <= 2.0 * dt_min:
                h = min(run.dt, remaining)
            else:
                h = min(run.dt, self._dt_max, 0.5 * remaining)
        else:
            h = _next_h(min(run.dt, self._dt_max), remaining)
        t_new = stop if h == remaining else base.t + h
        run.trial = (t_new, h)
        return base, t_new, h

    def judge(self, trial: State | None, failure: Exception | None):
        """The states the trial's outcome accepts (none, one or two), after the controller."""
        run, ctl, dt_min = self._run, self._ctl, self._dt_min
        t_new, h = run.trial
        fail = _failure(trial, failure)
        if fail is not None:
            if h <= dt_min * (1.0 + 1e-9):
                raise _floor_error(self._stepper, run, t_new, h, dt_min, fail)
            _reject(run, 1, max(RETRY_FACTOR * h, dt_min), fail.reason, t_new, h)
            return
        run.load_scale = max(run.load_scale, abs(_load(trial)))
        if run.jump:  # an impulsive start: no error estimate spans the jump; restart after it
            run.jump = False
            yield from _emit(run, trial, run.rejected, math.nan)
            run.rejected = 0
            run.levels = [without_history(trial)]
            run.origin = trial.t
            logger.debug("adaptive: impulsive start, restart at t = %.6g", trial.t)
            yield from self._arrived()
            return
        if len(run.levels) == 1:  # the Euler start step: judged with the next step
            run.levels.append(trial)
            run.pending, run.pending_rejected, run.rejected = trial, run.rejected, 0
            run.dt = h
            yield from self._arrived()
            return
        if run.pending is not None:  # the second step judges the Euler start step
            err, p = _start_error(run, trial), 1
        else:
            err, p = _milne(run, trial, self._order), self._order
        if not ctl.accepts(err):
            self._refuse(err, p, t_new, h)
            return
        if run.pending is None and h > dt_min * (1.0 + 1e-9) and _lag_mode(run, trial, ctl.tol):
            self._dt_max = max(dt_min, LAG_SHARE * h)
            run.lag_from = run.levels[-1].t
            logger.info(
                "femehl: at t = %.4g the film oscillates from step to step at steps of %.3g (the "
                "lagged coefficients' fixed point diverges): steps are kept below %.3g from here on",
                t_new,
                h,
                self._dt_max,
            )
            _reject(run, 1, self._dt_max, "the lag's period-two mode", t_new, h)
            return
        if run.pending is not None:
            yield from _emit(run, run.pending, run.pending_rejected, err)
        yield from _emit(run, trial, run.rejected, err)
        run.rejected = 0
        run.levels = (run.levels + [trial])[-3:]
        f = ctl.factor(err, p, grow=run.grow, dt=h)
        if 1.0 <= f < ctl.hold:  # small growth is not worth a new operator
            f = 1.0
        run.dt = min(self._dt_max, max(dt_min, h * f))
        run.grow = True
        run.streak = 0
        yield from self._arrived()

    def _refuse(self, err: float, p: int, t_new: float, h: float):
        """Reject a trial whose error is above tol (the start pair with it, if pending)."""
        run, ctl, dt_min = self._run, self._ctl, self._dt_min
        if h <= dt_min * (1.0 + 1e-9):
            raise _floor_error(self._stepper, run, t_new, h, dt_min, None, err)
        if run.pending is not None:  # reject the pair: back to the level before it
            h1 = run.pending.t - run.levels[0].t
            if h1 <= dt_min * (1.0 + 1e-9):
                raise _floor_error(self._stepper, run, t_new, h1, dt_min, None, err)
            run.levels = run.levels[:1]
            run.rejected += run.pending_rejected + 1
            run.pending = None
            new = max(h1 * ctl.factor(err, 1, grow=False, dt=h1), dt_min)
            _reject(run, 1, new, f"start pair error {err:.3g} > tol", t_new, h1)
            run.rejected_total += 1
        else:
            run.streak += 1
            f = ctl.factor(err, p, grow=False, dt=h)
            if run.streak > 1:  # the estimate is not asymptotic here: a kink's, first order per step
                f = ctl.kink_factor(err, h)
            _reject(run, 1, max(h * f, dt_min), f"error {err:.3g} > tol", t_new, h)

    def _arrived(self):
        """At a stop: emit a pending Euler start step that reached it alone; past a breakpoint
        the derivatives jump, so the run restarts there."""
        run = self._run
        if run.stops[0] - run.levels[-1].t > self._eps:
            return
        stop = run.stops.pop(0)
        if run.pending is not None:
            yield from _emit(run, run.pending, run.pending_rejected, math.nan)
        if run.stops:
            run.levels = [without_history(run.levels[-1])]
            run.origin = run.levels[0].t
            run.dt = min(run.dt, self._dt0)
            logger.debug("adaptive: breakpoint t = %.6g, restart with dt = %.3g", stop, run.dt)


def _lag_mode(run: _Run, trial: State, tol: float) -> bool:
    """True when the film's last three increments (two levels and the trial) are the lag's
    period-two mode: each opposite to the one before (cosines below ``-LAG_COSINE``), the
    last at least ``LAG_RATIO`` of the one before and large enough to matter (its largest
    relative change above ``LAG_FLOOR * tol``: a diverging mode crosses it within a few
    steps), on steps over which the cavitated set held still, all after the last catch
    (the first steps after it, shorter, still undo the oscillation the longer ones left).

    With its coefficients lagged a step is one iteration of the steady problem's fixed
    point, which diverges in sign-alternating increments on steps too long for the time
    derivative to damp it; Milne's estimate, per unit time, passes those steps.  A physical
    turning point reverses the increments once; a pattern that reverses every step is no
    evolution the steps resolve.  Where the lagged set switches, it flips nodes back and
    forth on steps of any length (in deep contact, where the film's pressure is round-off),
    and through the elasticity the whole film follows: that is no divergence of the fixed
    point, and shorter steps do not end it."""
    if len(run.levels) < 3 or run.levels[-3].t < run.lag_from:
        return False
    if run.switched is not None and run.switched([*run.levels, trial]):
        return False
    d = np.asarray(trial.d, dtype=float)
    scale = np.maximum(d, (trial.info or {}).get("film_error_floor", 0.0))
    films = [np.asarray(s.d, dtype=float) for s in run.levels[-3:]] + [d]
    steps = [(b - a) / scale for a, b in itertools.pairwise(films)]
    norms = [float(np.linalg.norm(x)) for x in steps]
    if not min(norms) > 0.0 or norms[2] < LAG_RATIO * norms[1]:
        return False
    if np.max(np.abs(steps[2])) <= LAG_FLOOR * tol:
        return False
    return all(
        float(a @ b) < -LAG_COSINE * na * nb
        for a, b, na, nb in zip(steps, steps[1:], norms, norms[1:], strict=False)
    )


def _failure(trial: State | None, exc: Exception | None) -> _Failure | None:
    """Why a trial failed (it raised, or its film is <= 0 somewhere), None if it did not."""
    if isinstance(exc, FilmRuptureError):
        return _Failure(str(exc), tuple(exc.where), exc.d_min)
    if exc is not None:
        return _Failure(f"singular step ({exc})")
    if not film_positive(trial):
        d, at, label = film_floor(trial)
        return _Failure(f"film {d:.3g} <= 0", at, d, label)
    return None


def _emit(run: _Run, state: State, rejected: int, err: float):
    state = _tag(state, state.t - run.recent[-1].t, err, rejected)
    run.recent.append(state)
    run.accepted_total += 1
    run.dt_low = min(run.dt_low, state.info["dt"])
    run.dt_high = max(run.dt_high, state.info["dt"])
    run.pending = None
    yield state


def _reject(run: _Run, n: int, new_dt: float, what: str, t: float, h: float):
    run.rejected += n
    run.rejected_total += n
    run.grow = False
    logger.debug("adaptive: t = %.6g, dt = %.3g rejected (%s); retry with dt = %.3g", t, h, what, new_dt)
    run.dt = new_dt
