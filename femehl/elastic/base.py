"""The substrate protocol (see :mod:`femehl.elastic`)."""

from __future__ import annotations

import math
from typing import Protocol, runtime_checkable

from femehl.registry import Registry

__all__ = [
    "Substrate",
    "SUBSTRATES",
    "register_substrate",
    "OPERATORS",
    "substrate_operators",
    "step_limit",
]

#: kind -> substrate class (the names of ``[substrate] kind`` in scene files)
SUBSTRATES = Registry("substrate", key="kind")

#: the FE elastic operators (``operator=``): a substrate builds all of them unless its
#: ``operators`` says otherwise
OPERATORS = ("dense", "fast", "auto")


def substrate_operators(substrate) -> tuple:
    """The FE elastic operators ``substrate`` builds: its ``operators``, or all of them."""
    return tuple(getattr(substrate, "operators", OPERATORS))


def step_limit(substrate, scene, disc, t_end: float) -> float:
    """The largest time step ``substrate``'s model resolves on ``disc`` up to ``t_end``: its
    ``step_limit(scene, disc, t_end)``, or ``math.inf`` for a substrate without one (no
    memory: an elastic substrate's response is instantaneous)."""
    limit = getattr(substrate, "step_limit", None)
    return math.inf if limit is None else float(limit(scene, disc, t_end))


#: class decorator adding a substrate class to :data:`SUBSTRATES` under ``cls.kind``
register_substrate = SUBSTRATES.register


@runtime_checkable
class Substrate(Protocol):
    """What the stepper needs from a substrate: ``w = -C p`` on film points and elsewhere.

    A substrate whose operators are all sparse (each point deflects under its own
    pressure only: Winkler, rigid) may say so with a class attribute ``local = True``;
    the automatic mode then allows finer meshes (:data:`femehl.accuracy.auto.LOCAL_MAX_ELEMENTS`).
    One whose FE operator is dense only (no hierarchical ``"fast"`` one, as a layer's radial
    kernel) says so with ``operators = ("dense",)``: ``operator="fast"`` is then refused and
    the automatic mode keeps to :data:`femehl.accuracy.auto.MAX_ELEMENTS`.
    A substrate with a memory states the largest time step its model resolves with a
    method ``step_limit(scene, disc, t_end) -> float`` (optional, not part of the protocol's
    check; :func:`step_limit` gives ``math.inf`` without it); the adaptive steps keep below it.
    """

    kind: str

    def compliance_operator(self, disc):
        """``C`` with ``w = -C p`` on ``disc.film_points`` (dense ndarray or sparse)."""

    def deflection_rows(self, disc, points):
        """Rows of ``C`` at ``points`` (n, 2): ``w(points) = -rows @ p``."""
