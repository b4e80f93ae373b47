"""A run's companions replaying its steps in processes of their own while it runs.

:class:`Companions` is a State handler attached to a run of the automatic mode: every
accepted time goes down a pipe to two forked processes, one replaying every step on the
companions' coarser mesh, one every other step, so the estimate is ready when the run
ends.  Where processes cannot be forked (:func:`concurrent`) or one fails, the caller
replays after the run (:func:`femehl.accuracy.auto.replays`), with the same result to the
linear solver's tolerance.
"""

from __future__ import annotations

import contextlib
import logging
import math
import multiprocessing
import os
import pickle
import select
import signal
import struct
import sys
import threading
import time
import warnings
from dataclasses import dataclass

from femehl.errors import MeshError, SceneError, SolverError
from femehl.solver.stepping import GivenSteps

__all__ = ["ENV", "Companions", "Replayed", "concurrent"]

logger = logging.getLogger("femehl")

#: environment variable: ``"serial"`` replays after the run in the same process; ``"auto"``
#: (or unset) in two processes beside it where :func:`concurrent` allows
ENV = "FEMEHL_COMPANIONS"

_END = math.inf  # after the run's last time: the run finished, send the replay back
_RECORD = struct.Struct("d")
_OPEN: set[int] = set()  # write ends of live companions' pipes (closed in every child)


def concurrent() -> bool:
    """Whether the companions may run in processes of their own: ``FEMEHL_COMPANIONS`` is not
    ``serial``; Linux (fork); at least two CPUs for this process; the main thread of a
    process that is not itself a daemon (a Dask worker's), which may have children."""
    raw = os.environ.get(ENV, "").strip().lower()
    if raw not in ("", "auto", "serial"):
        raise SceneError(f"{ENV}={raw!r}: give 'auto' (the default: beside the run) or 'serial'.")
    if raw == "serial" or not sys.platform.startswith("linux"):
        return False
    if not hasattr(os, "fork"):
        return False
    if multiprocessing.current_process().daemon or threading.current_thread() is not threading.main_thread():
        return False
    return len(os.sched_getaffinity(0)) >= 2


@dataclass
class Replayed:
    """What the companions sent back: the replays on every step (``full``) and on every
    other (``half``), the scheme's ``order``, how many steps they ``cut`` in two; or
    ``stopped``, ``(error class name, message)`` of the one that stopped (the others None);
    or ``half_stopped``, of the replay on every other step alone (``half`` None)."""

    full: object = None
    half: object = None
    order: int = 2
    cut: int = 0
    stopped: tuple | None = None
    half_stopped: tuple | None = None


class _Streamed(GivenSteps):
    """:class:`GivenSteps` on times that arrive while the run goes (``source``, an iterator)."""

    def __init__(self, source, halvings: int = 0):
        super().__init__([0.0], halvings)
        self._source = source

    def begin(self, stepper, t_end, start):
        state = super().begin(stepper, t_end, start)
        self._stops, self._depth = [], []
        return state

    def propose(self):
        if not self._stops:
            t = next(self._source, None)
            if t is None:
                return None
            self._stops, self._depth = [t], [0]
        return super().propose()


class _Times:
    """The run's times from the pipe ``fd``, its start left out: all of them, or with
    ``every_other`` every other one within each stretch between the motion's ``breaks``,
    each stretch's end kept (:func:`femehl.accuracy.auto.every_other_step` as the times
    come).  ``finished``: the parent sent the end marker (not a closed pipe: the run was
    abandoned)."""

    def __init__(self, fd: int, t_end: float, breaks, every_other: bool):
        self.fd, self.t_end, self.breaks, self.every_other = fd, t_end, breaks, every_other
        self.finished, self.buffer = False, b""

    def _read(self):
        while len(self.buffer) < _RECORD.size:
            chunk = os.read(self.fd, 4096)
            if not chunk:
                return None
            self.buffer += chunk
        (t,) = _RECORD.unpack_from(self.buffer)
        self.buffer = self.buffer[_RECORD.size :]
        if t == _END:
            self.finished = True
            return None
        return t

    def drain(self) -> None:
        """Read on to the end marker (or a closed pipe), the times left unused."""
        while self._read() is not None:
            pass

    def __iter__(self):
        t0 = self._read()  # the run's start
        if t0 is None:
            return
        eps = 1e-9 * max(1.0, abs(self.t_end))
        ends = [b for b in self.breaks if t0 + eps < b < self.t_end - eps] + [self.t_end]
        i = 0
        while (t := self._read()) is not None:
            i += 1
            end = any(abs(t - e) <= eps for e in ends)
            if not self.every_other or end or i % 2 == 0:
                yield t
            if end:
                i = 0


def _child(make, t_end, breaks, halvings, every_other, fd, out):
    """A companion (a forked process that ends here): build its stepper (``make()``),
    replay the times from ``fd`` (a failed step cut in two up to ``halvings`` times), write
    ``(outcome, ...)`` pickled to ``out``; nothing when the run was abandoned."""
    from femehl.solver.loop import run_loop
    from femehl.solver.threads import limited

    times = _Times(fd, t_end, breaks, every_other)
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C stops the run, which ends its companions
        for w in _OPEN:
            os.close(w)
        try:
            with limited():
                stepper = make()
                steps = _Streamed(iter(times), halvings=halvings)
                res = run_loop(stepper, t_end, store_every=0, steps=steps)
            res.scene = res.disc = None  # the parent has both; a user's shape may not pickle
            outcome = ("replayed", res, steps.cut, stepper.scheme.order)
        except (SolverError, MeshError) as exc:
            times.drain()  # the outcome is sent once the run has ended
            outcome = ("stopped", type(exc).__name__, str(exc))
        if times.finished:
            data = pickle.dumps(outcome)
            while data:
                data = data[os.write(out, data) :]
    except BaseException as exc:  # anything else: the parent replays after the run instead
        with contextlib.suppress(BaseException):
            times.drain()  # the run writes on to its end; the outcome is read then
            os.write(out, pickle.dumps(("failed", f"{type(exc).__name__}: {exc}")))
    finally:
        os._exit(0)  # a fork: nothing of the parent's exit (atexit, finalizers, streams) runs


class Companions:
    """The companions of one run, replaying its accepted times as they come.

    ``make()`` builds their stepper (in each process); ``t_end`` is the run's end,
    ``breaks`` the motion's breakpoints, ``halvings`` how many times a step that fails on
    their mesh may be cut in two (:class:`~femehl.solver.stepping.GivenSteps`).  Call the
    object with every accepted State of the run (it is a State handler), then
    :meth:`results`; use it as a context manager so that the processes end with the run
    whatever happens.
    """

    def __init__(self, make, t_end: float, breaks=(), halvings: int = 0):
        self._procs = []
        for stream in (sys.stdout, sys.stderr):  # what the parent has buffered is written once
            with contextlib.suppress(Exception):
                stream.flush()
        with warnings.catch_warnings():  # Python >= 3.12 warns of fork beside BLAS's idle threads
            warnings.simplefilter("ignore", DeprecationWarning)
            for every_other in (False, True):
                r, w = os.pipe()  # the run's times, to the companion
                back, out = os.pipe()  # its outcome, to the run
                _OPEN.add(w)
                pid = os.fork()
                if pid == 0:
                    os.close(back)
                    _child(make, float(t_end), tuple(breaks), halvings, every_other, r, out)
                os.close(r)
                os.close(out)
                os.set_blocking(w, False)
                self._procs.append({"pid": pid, "w": w, "back": back, "pending": b""})

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __call__(self, state) -> None:
        record = _RECORD.pack(float(state.t))
        for p in self._procs:
            p["pending"] += record
            self._send(p)

    @staticmethod
    def _send(p, block: bool = False) -> None:
        if p["w"] is None or not p["pending"]:
            return
        os.set_blocking(p["w"], block)
        try:
            while p["pending"]:
                n = os.write(p["w"], p["pending"])
                p["pending"] = p["pending"][n:]
        except BlockingIOError:  # the pipe is full: the rest goes with the next state
            pass
        except BrokenPipeError:  # the companion has ended (it failed): results() says so
            p["pending"] = b""

    @staticmethod
    def _read_back(p, deadline: float) -> bytes | None:
        """A companion's whole outcome (to the end of its pipe), None if not by ``deadline``."""
        chunks = []
        while (left := deadline - time.monotonic()) > 0.0:
            if not select.select([p["back"]], [], [], left)[0]:
                break
            chunk = os.read(p["back"], 1 << 20)
            if not chunk:
                os.close(p["back"])
                p["back"] = None
                return b"".join(chunks)
            chunks.append(chunk)
        return None

    def results(self, wait: float = 600.0) -> Replayed | None:
        """The :class:`Replayed` of the run that has just ended (the same as
        :func:`femehl.accuracy.auto.replays` would give); None (logged) when a companion
        failed otherwise than by stopping, or gave no answer within ``wait`` seconds:
        replay after the run instead."""
        outcomes = []
        for p in self._procs:
            p["pending"] += _RECORD.pack(_END)
            self._send(p, block=True)
            self._close_pipe(p)
        deadline = time.monotonic() + wait
        for p in self._procs:
            data = self._read_back(p, deadline)
            if data is None:  # no answer in time: a companion hung (a lock held across the fork)
                outcomes.append(("failed", f"no answer within {wait:.0f} s of the run's end"))
                continue
            _, status = os.waitpid(p["pid"], 0)
            p["pid"] = None
            try:
                outcomes.append(pickle.loads(data))
            except Exception:  # nothing, or cut short: it died (killed, out of memory)
                outcomes.append(("failed", f"the process ended with status {status}"))
        self.close()
        failed = [o[1] for o in outcomes if o[0] == "failed"]
        if failed:
            logger.info("femehl: the companions beside the run failed (%s): they replay after it", failed[0])
            return None
        stopped = [o[1:] for o in outcomes if o[0] == "stopped"]
        if stopped:
            return Replayed(stopped=stopped[0])
        (_, full, cut_f, order), (_, half, cut_h, _) = outcomes
        return Replayed(full, half, order, cut_f + cut_h)

    def _close_pipe(self, p) -> None:
        if p["w"] is not None:
            _OPEN.discard(p["w"])
            os.close(p["w"])
            p["w"] = None

    def close(self) -> None:
        """End the companions (a run that stopped or was abandoned) and free their pipes."""
        for p in self._procs:
            self._close_pipe(p)
            if p["back"] is not None:
                os.close(p["back"])
            if p["pid"] is not None:
                with contextlib.suppress(ProcessLookupError):
                    os.kill(p["pid"], signal.SIGTERM)
                os.waitpid(p["pid"], 0)
        self._procs = []
