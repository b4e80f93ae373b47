"""``femehl.solve``: run a scene with a registered solver and collect a Result.

Solvers are registered in :data:`SOLVERS` (name -> stepper class); tests
parametrize over this registry.  The stepping itself is the generator
:func:`femehl.stepping.march`; :func:`steps` exposes it directly.
"""

from __future__ import annotations

import inspect
from typing import Callable, Iterator

from .errors import SceneError
from .result import Result
from .scene import Scene
from .stepping import State, march

__all__ = ["SOLVERS", "register_solver", "make_stepper", "steps", "solve", "run_loop"]

SOLVERS: dict[str, type] = {}


def register_solver(name: str):
    """Class decorator adding a stepper class to :data:`SOLVERS` under ``name``."""
    def deco(cls):
        SOLVERS[name] = cls
        return cls
    return deco


def _load_solvers():
    from .fd.solver import FDStepper
    SOLVERS.setdefault("fd", FDStepper)
    try:
        from .fe.solver import FEStepper
    except ImportError:  # pragma: no cover - FE module absent
        return
    SOLVERS.setdefault("fe", FEStepper)


DEFAULT_METHOD = "fe"


def make_stepper(scene: Scene, method: str | None = None, **options):
    """Build the stepper of ``method`` for ``scene`` (operators are built here, once)."""
    _load_solvers()
    if not isinstance(scene, Scene):
        raise SceneError(f"scene must be a femehl.Scene, got {type(scene).__name__}.")
    method = DEFAULT_METHOD if method is None else method
    if method not in SOLVERS:
        raise SceneError(f"unknown method {method!r}: choose one of {sorted(SOLVERS)}.")
    cls = SOLVERS[method]
    allowed = set(inspect.signature(cls).parameters) - {"scene"}
    unknown = set(options) - allowed
    if unknown:
        raise SceneError(f"method {method!r} does not take {sorted(unknown)}; it takes {sorted(allowed)}.")
    return cls(scene, **options)


def steps(scene: Scene, t_end: float, dt: float, method: str | None = None,
          **options) -> Iterator[State]:
    """Generator of States, the initial one first (see :func:`femehl.stepping.march`)."""
    stepper = make_stepper(scene, method, **options)
    yield from march(stepper, t_end, dt)


def solve(scene: Scene, method: str | None = None, *, t_end: float = 5.0, dt: float = 0.01,
          store_every: int = 1, callback: Callable[[State], None] | None = None,
          **options) -> Result:
    """Run ``scene`` from t = 0 to ``t_end`` and return a :class:`~femehl.result.Result`.

    Parameters
    ----------
    scene : femehl.Scene
        The problem (see :mod:`femehl.scene`, :mod:`femehl.presets`).
    method : str, default: "fe"
        A key of :data:`SOLVERS`: "fe" (finite elements, default) or "fd"
        (the paper's polar finite differences).
    t_end : float, default: 5.0
        End time (normalized).
    dt : float, default: 0.01
        Time step (the paper's value).
    store_every : int, default: 1
        Keep the fields of every ``store_every``-th step (and the last); 0 keeps none.
    callback : callable, optional
        Called with each State as it is produced (progress bars, writers).
    **options
        Discretization options of the method: FD ``dr``, ``dtheta``; FE ``mesh``, ...
    """
    from .stepping import check_run

    check_run(t_end, dt)
    stepper = make_stepper(scene, method, **options)
    return run_loop(stepper, t_end, dt, store_every=store_every, on_state=callback)


def run_loop(stepper, t_end: float, dt: float, *, start: State | None = None,
             store_every: int = 1, on_state: Callable[[State], None] | None = None) -> Result:
    """The one driver loop: march ``stepper`` and feed every State to a Result and ``on_state``.

    Every way of running femehl (``solve``, ``run_to_folder``, the CLI) goes through
    here.  ``start`` resumes from a State (its own record is kept, ``on_state`` is not
    called for it).  If the run stops on a :class:`~femehl.errors.SolverError` or is
    interrupted, the partial Result is attached to the exception as ``.result`` and
    the exception propagates; everything fed to ``on_state`` before stays valid.
    """
    from .errors import SolverError

    if isinstance(store_every, bool) or not isinstance(store_every, int) or store_every < 0:
        raise SceneError(f"store_every must be an integer >= 0, got {store_every!r}.")
    result = Result(scene=stepper.scene, method=stepper.method, disc=stepper.disc)
    last = None
    try:
        for state in march(stepper, t_end, dt, start=start):
            keep = store_every > 0 and state.step % store_every == 0
            result.record(state, store_fields=keep)
            if on_state is not None and state is not start:
                on_state(state)
            last = (state, keep)
    except (SolverError, KeyboardInterrupt) as exc:
        exc.result = result
        raise
    finally:
        if last is not None and store_every > 0 and not last[1]:
            result._stored.append(last[0])
        result.info.update(getattr(stepper, "info", {}))      # counters as at the end of the run
    return result
