"""femehl's exception classes, all in one place.

Every error femehl raises on purpose is a :class:`FemehlError`.  Errors about
what the user asked for (a scene value, a scene file, a mesh) also derive from
:class:`ValueError`; errors found while a run is going derive from
:class:`RuntimeError`.  Messages say what is wrong *and* what to do about it.
"""

from __future__ import annotations


class FemehlError(Exception):
    """Base class of every error femehl raises on purpose."""


class SceneError(FemehlError, ValueError):
    """A scene value is invalid (non-finite, out of range, inconsistent)."""


class SceneFileError(SceneError):
    """A scene file cannot be read or does not describe a valid scene."""


class MeshError(FemehlError, ValueError):
    """A mesh cannot be read, is not a triangulation, or does not cover the domain."""


class SolverError(FemehlError, RuntimeError):
    """A run cannot go on.  ``t`` is the time of the step that failed."""

    def __init__(self, message: str, t: float | None = None):
        super().__init__(message)
        self.t = t


class FilmRuptureError(SolverError):
    """The film thickness reached zero or became negative (solid contact)."""

    def __init__(self, message: str, t: float, where: tuple[float, float], d_min: float):
        super().__init__(message, t)
        self.where = where
        self.d_min = d_min


class SingularSystemError(SolverError):
    """The step's linear system is singular or its solution is not finite."""


class RelaxationDivergedError(SolverError):
    """The relaxation baseline (:mod:`femehl.reference.baseline`) did not converge within a step.

    ``iterations`` is how many fixed-point iterations were made before giving up.
    """

    def __init__(self, message: str, t: float, iterations: int):
        super().__init__(message, t)
        self.iterations = iterations


class TimeBudgetError(SolverError):
    """No run of the automatic mode finished within its time budget (``max_wall``).

    ``t`` is the time the abandoned run had reached.
    """


class OutputError(FemehlError, ValueError):
    """An output folder cannot be used as asked (holds another run, is a file, is not writable)."""


class CheckpointError(OutputError):
    """A checkpoint to resume from is missing, unreadable or does not fit the run."""
