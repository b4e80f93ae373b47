"""The one error-estimate type: :class:`Estimate` (docs/design.md sections 8 and 9).

Made in :mod:`femehl.accuracy.auto` only (:func:`~femehl.accuracy.auto.one_run_estimate`,
:func:`~femehl.accuracy.auto.expert_estimate`); read by
:meth:`femehl.output.result.Result.uncertainty` and written by
:func:`femehl.output.table.add_error_columns`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from femehl.errors import SceneError

__all__ = ["Estimate", "PARTS", "HOWS"]

#: the parts of each quantity's estimate
PARTS = ("total", "space", "time")
#: how an estimate was made: a run's coarser companions (its space and time parts), its
#: step controller only (time), or a companion on the run's steps (space) with the step
#: controller's time part (the companion on steps twice as long stopped)
HOWS = ("companion", "controller", "companion+controller")


@dataclass(frozen=True)
class Estimate:
    """Relative errors of a run's headline quantities on its times ``t``.

    ``errors[name][part]`` is an array on ``t`` (or None: that part is not known) for
    ``part`` in :data:`PARTS`; ``how`` is one of :data:`HOWS`, ``ratio`` the level ratio
    of the pair or companion, ``levels`` the pair's levels (fine, coarse).
    """

    t: np.ndarray
    errors: Mapping[str, Mapping[str, np.ndarray | None]]
    how: str
    ratio: float | None = None
    levels: tuple = field(default=())

    def __post_init__(self):
        if self.how not in HOWS:
            raise SceneError(f"an Estimate is made by one of {HOWS}, got how={self.how!r}.")

    @property
    def names(self) -> list[str]:
        """The quantities estimated."""
        return list(self.errors)

    def __getitem__(self, name: str) -> Mapping[str, np.ndarray | None]:
        """``{"total", "space", "time"}`` of ``name``."""
        return self.errors[name]

    def at(self, name: str, t: float) -> dict:
        """``{"total", "space", "time"}`` of ``name`` at ``t`` (linear between the steps)."""
        if name not in self.errors:
            raise SceneError(f"no error estimate for {name!r}: uncertainty takes one of {self.names}.")
        ts = np.asarray(self.t, dtype=float)
        t = float(t)
        tol = 1e-9 * max(1.0, abs(ts[-1]))
        if not np.isfinite(t) or t < ts[0] - tol or t > ts[-1] + tol:
            raise SceneError(f"t = {t} is outside the run [{ts[0]:g}, {ts[-1]:g}].")
        parts = self.errors[name]
        return {k: None if parts[k] is None else float(np.interp(t, ts, parts[k])) for k in PARTS}

    def worst(self, part: str = "total") -> float:
        """The largest ``part`` over the quantities and times."""
        return max(float(np.max(self.errors[q][part])) for q in self.errors)

    def where(self) -> str:
        """``"film_min at t = 0.04"``: the quantity and time of the largest total estimate."""
        name = max(self.errors, key=lambda q: float(np.max(self.errors[q]["total"])))
        k = int(np.argmax(self.errors[name]["total"]))
        return f"{name} at t = {float(self.t[k]):.4g}"
