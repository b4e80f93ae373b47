"""The one time loop (:func:`march`), the :class:`State` it yields and the time schemes.

A *stepper* (:class:`femehl.solver.stepper.LaggedStepper`, the same for every method)
builds its operators once and advances one step (ONE linear solve, docs/design.md
section 3); a step policy (:class:`FixedSteps`, :class:`GivenSteps`, or
:class:`femehl.solver.adaptive.AdaptiveSteps`) chooses the steps; ``march`` yields the
initial state and then every accepted state, so a caller can stop, store or plot whenever
it likes.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from femehl.errors import FilmRuptureError, SceneError, SingularSystemError

__all__ = [
    "State",
    "Stepper",
    "march",
    "FixedSteps",
    "GivenSteps",
    "breakpoints_of",
    "without_history",
    "check_run",
    "Scheme",
    "SCHEMES",
    "get_scheme",
    "film_floor",
    "film_positive",
]


@dataclass(frozen=True)
class State:
    """Everything known at one time level.

    ``p`` lives on the solver's pressure unknowns (FD: grid nodes; FE: mesh
    nodes), ``w`` and ``d`` on its film locations (FD: grid nodes; FE: element
    centroids).  Scalars are whole-plane figures in normalized units.
    """

    step: int
    t: float
    hc: float
    V: float
    p: np.ndarray
    w: np.ndarray
    d: np.ndarray
    load: float
    film_center: float
    film_min: float
    film_min_at: tuple
    p_max: float
    p_max_at: tuple
    info: dict = field(default_factory=dict)
    d_prev: np.ndarray | None = None  # d one step earlier (two-step schemes)
    dt_prev: float | None = None  # the step that led to this state
    #: the step parts' own variables by name (:mod:`femehl.solver.parts`: a free indenter's
    #: ``hc_dot``, a viscoelastic memory's ``creep``, a cavitation condition's ``p_aux`` and
    #: ``gas``), numbers or arrays; checkpoints write them as they are
    own: dict = field(default_factory=dict)

    def with_own(self, **values) -> State:
        """This state with ``values`` added to (or replacing some of) its own variables."""
        return dataclasses.replace(self, own={**self.own, **values})


class Stepper(Protocol):
    """What :func:`march` needs from a discretization."""

    def initial_state(self) -> State: ...

    def step(self, state: State, t_new: float, dt: float) -> State: ...


def check_run(t_end, dt):
    """Validate a run's horizon and step; return them as floats and the step count."""
    from femehl.validation import check_positive

    t_end = check_positive("t_end", t_end, "Give the end time of the run in normalized units.")
    dt = check_positive("dt", dt, "Give a positive time step (the paper uses 0.01).")
    if dt > t_end:
        raise SceneError(f"dt = {dt:g} is larger than t_end = {t_end:g}: use dt <= t_end.")
    ratio = t_end / dt
    if not math.isfinite(ratio) or ratio > 10_000_000:
        raise SceneError(f"t_end/dt = {ratio:.3g} steps is too many: increase dt or decrease t_end.")
    n = int(math.ceil(ratio - 1e-9))
    if n > 10_000_000:
        raise SceneError(f"{n} steps is too many: increase dt or decrease t_end.")
    return t_end, dt, n


@dataclass(frozen=True)
class Scheme:
    """A time discretization that keeps ONE linear system per step.

    The film's time derivative is ``(a0 d^{k+1} - a1 d^k + a2 d^{k-1}) / dt`` and the
    lagged coefficients use ``d* = l0 d^k - l1 d^{k-1}``, with coefficients depending on
    the step ratio ``omega = dt / dt_prev`` (variable-step formulas).
    """

    name: str
    order: int

    def coefficients(self, omega: float | None):
        """``(a0, a1, a2, l0, l1)`` for step ratio ``omega`` (None: first step)."""
        if self.order == 1 or omega is None:
            return 1.0, 1.0, 0.0, 1.0, 0.0
        w = omega
        return (1 + 2 * w) / (1 + w), 1 + w, w * w / (1 + w), 1 + w, w


#: "euler": the paper's scheme (backward Euler in d_t, coefficients lagged one step);
#: "bdf2": BDF2 in d_t with coefficients extrapolated linearly from two steps.
SCHEMES = {"euler": Scheme("euler", 1), "bdf2": Scheme("bdf2", 2)}


def get_scheme(name: str) -> Scheme:
    if not isinstance(name, str) or name not in SCHEMES:
        raise SceneError(f"unknown time scheme {name!r}: choose one of {sorted(SCHEMES)}.")
    return SCHEMES[name]


class _Planned:
    """A step policy whose steps are known in advance: a step that fails raises (nothing is
    retried), an accepted one is yielded and ``_accepted`` moves the plan on."""

    def judge(self, trial: State | None, failure: Exception | None):
        if failure is None:
            try:
                _check_film(trial)
            except FilmRuptureError as exc:
                failure = exc
        if failure is not None:
            if self._retry(failure):
                return
            raise failure
        self._accepted(trial)
        yield trial

    def _retry(self, failure: Exception) -> bool:
        """Plan the failed step again (True) or let ``failure`` stand (False: the default)."""
        return False


class FixedSteps(_Planned):
    """The step policy of fixed steps ``dt``: steps land on ``k dt``, the last is shortened to
    land on ``t_end``; a step that fails raises (nothing is retried)."""

    def __init__(self, dt: float):
        self.dt = dt

    def begin(self, stepper: Stepper, t_end: float, start: State | None) -> State:
        self._t_end, self._dt, self._n = check_run(t_end, self.dt)
        if start is None:
            self._k = 0
            state = stepper.initial_state()
        else:
            self._k = int(round(start.t / self._dt))
            if abs(self._k * self._dt - start.t) > 1e-9 * max(1.0, start.t):
                raise SceneError(
                    f"cannot resume at t = {start.t:g} with dt = {self._dt:g}: "
                    "resume with the dt of the original run."
                )
            state = start
        self._last = state
        return state

    def propose(self):
        if self._k >= self._n:
            return None
        t_new = min((self._k + 1) * self._dt, self._t_end)
        h = t_new - self._last.t
        if h <= 1e-14:
            return None
        return self._last, t_new, h

    def _accepted(self, trial: State) -> None:
        self._k += 1
        self._last = trial


class GivenSteps(_Planned):
    """The step policy that lands on given ``times`` (e.g. another run's, so that two
    discretizations are compared at the same steps), then on ``t_end``.  As adaptive steps
    do, the history is dropped at the motion's breakpoints and at ``start`` (a backward-Euler
    step follows).  A step that fails raises, or with ``halvings = k`` is cut in two, up to
    ``k`` times (:attr:`cut`: how many were)."""

    def __init__(self, times, halvings: int = 0):
        ts = np.asarray(times, dtype=float).ravel()
        if ts.size == 0 or not np.all(np.isfinite(ts)) or np.any(np.diff(ts) <= 0.0):
            raise SceneError("times must be a non-empty increasing sequence of finite times.")
        if isinstance(halvings, bool) or not isinstance(halvings, int) or halvings < 0:
            raise SceneError(f"halvings must be an integer >= 0, got {halvings!r}.")
        self.times = ts
        self.halvings = halvings
        self.cut = 0

    def begin(self, stepper: Stepper, t_end: float, start: State | None) -> State:
        from femehl.validation import check_positive

        t_end = check_positive("t_end", t_end, "Give the end time of the run in normalized units.")
        state = stepper.initial_state() if start is None else without_history(start)
        if t_end <= state.t:
            raise SceneError(f"t_end = {t_end:g} is not after the start t = {state.t:g}.")
        eps = 1e-12 * max(1.0, abs(t_end))
        self._stops = [float(t) for t in self.times if state.t + eps < t < t_end - eps] + [t_end]
        self._depth = [0] * len(self._stops)
        scene = getattr(stepper, "scene", None)
        self._breaks = [b for b in breakpoints_of(scene) if state.t + eps < b < t_end - eps]
        self._eps, self._last = eps, state
        self.cut = 0
        return state

    def propose(self):
        if not self._stops:
            return None
        base, t_new = self._last, self._stops[0]
        if any(abs(base.t - b) <= self._eps for b in self._breaks):
            base = without_history(base)
        return base, t_new, t_new - base.t

    def _retry(self, failure: Exception) -> bool:
        """The failed step cut in two, while it has been cut fewer than ``halvings`` times."""
        depth = self._depth[0]
        if depth >= self.halvings:
            return False
        self._stops.insert(0, 0.5 * (self._last.t + self._stops[0]))
        self._depth[:1] = [depth + 1, depth + 1]
        self.cut += 1
        return True

    def _accepted(self, trial: State) -> None:
        self._stops.pop(0)
        self._depth.pop(0)
        self._last = trial


def breakpoints_of(scene) -> tuple:
    """The motion's breakpoints (:attr:`femehl.problem.scene.Motion.breakpoints`), () if it has none."""
    motion = getattr(scene, "motion", None)
    return tuple(getattr(motion, "breakpoints", ()) or ())


def without_history(state: State) -> State:
    """``state`` without its history: the next step is a backward-Euler (start) step."""
    return dataclasses.replace(state, d_prev=None, dt_prev=None)


def march(stepper: Stepper, t_end: float, steps, start: State | None = None) -> Iterator[State]:
    """The one time loop: yield the initial state, then every accepted state up to ``t_end``.

    ``steps`` is the step policy: a number (fixed steps of that size, :class:`FixedSteps`) or
    a policy object with ``begin(stepper, t_end, start) -> State`` (the first state),
    ``propose() -> (base, t_new, dt) | None`` (the next trial step, None when done) and
    ``judge(trial, failure)``, a generator of the states the trial's outcome accepts
    (:class:`femehl.solver.adaptive.AdaptiveSteps` retries and rejects; fixed steps raise).
    Each trial is ONE call of ``stepper.step``: one linear solve.  With ``start`` (a State
    of an earlier run, e.g. from a checkpoint) the run continues from it.  A film
    thickness reaching zero raises :class:`~femehl.errors.FilmRuptureError` (everything
    yielded before stays valid).
    """
    policy = FixedSteps(steps) if not hasattr(steps, "propose") else steps
    yield policy.begin(stepper, t_end, start)
    while (trial := policy.propose()) is not None:
        base, t_new, h = trial
        try:
            new = stepper.step(base, t_new, h)
        except (FilmRuptureError, SingularSystemError) as exc:
            yield from policy.judge(None, exc)
        else:
            yield from policy.judge(new, None)


def film_floor(state: State) -> tuple:
    """``(d, (x, y), where)``: the thinnest (or a non-finite) film ``state`` knows of.

    Candidates: the origin (the central film), the probed nodes and the film points; on a
    tie the first named wins (``state.film_min`` is already the smallest of them all).
    """
    cands = [(state.film_center, (0.0, 0.0), "the origin")]
    if "node_film_min" in state.info:
        cands.append((state.info["node_film_min"], tuple(state.info["node_film_min_at"]), "a node"))
    cands.append((state.film_min, tuple(state.film_min_at), "the film points"))
    bad = [c for c in cands if not math.isfinite(c[0])]
    return bad[0] if bad else min(cands, key=lambda c: c[0])


def film_positive(state: State) -> bool:
    """True when every film ``state`` knows of is finite and > 0 (the test of
    :func:`_check_film`, without raising); where a part carries the load through contact,
    above its limit instead (``state.info["film_limit"]``: a rough surface's -10 sigma)."""
    d = film_floor(state)[0]
    return math.isfinite(d) and d > state.info.get("film_limit", 0.0)


def _check_film(state: State):
    if film_positive(state):
        return
    d, (x, y), where = film_floor(state)
    if "film_limit" in state.info:  # through contact: only a runaway step gets there
        raise FilmRuptureError(
            f"the film reached {d:.3g} at t = {state.t:.6g}, at {where} (x, y) = ({x:.3g}, {y:.3g}), "
            f"below the rough surfaces' limit {state.info['film_limit']:.3g} (their asperities would "
            "press harder than any contact carries): the step overshot. Try a smaller dt or adaptive "
            "steps (step_tol).",
            t=state.t,
            where=(x, y),
            d_min=d,
        )
    raise FilmRuptureError(
        f"film thickness reached {d:.3g} <= 0 at t = {state.t:.6g}, at {where} "
        f"(x, y) = ({x:.3g}, {y:.3g}): the fluid film ruptured (solid contact) or the "
        "step was too coarse to follow it. Try a smaller dt or a finer mesh; if the "
        "load truly squeezes the film out, the lubricated model no longer applies.",
        t=state.t,
        where=(x, y),
        d_min=d,
    )
