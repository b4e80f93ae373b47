"""Cavitation conditions: where the film cannot hold a pressure below ambient.

Every femehl run without one is full Sommerfeld (the pressure may go below ambient).
``Fluid(beta, cavitation="reynolds")`` imposes the Reynolds (Swift-Stieber) condition
``p >= 0``: the pressure is 0 on a cavitated set, the Reynolds equation holds elsewhere,
and on the set its residual (the multiplier ``lambda = A p - b``) is non-negative.  The
step stays ONE linear system: the set is lagged one step, like every other coefficient.
The cavitated rows of the step's system are replaced by ``p_i = 0``
(:meth:`femehl.core.linsolve.StepOperator.with_fixed`), and after the solve the
complementarity variable ``y = p`` off the set and ``y = -lambda`` on it decides the next
set: ``{y < 0}`` (a primal-dual active-set rule applied once per step).  At a steady
state the set stops changing and the discrete Reynolds condition holds exactly; while it
moves, a node can be negative for the one step before it joins the set (its value is
reported as ``state.info["p_negative_min"]``).

The Reynolds condition does not conserve mass where the film reforms (the
Jakobsson-Floberg-Olsson model does; not in femehl yet).  Models are registered in
:data:`CAVITATION_MODELS` by name.
"""

from __future__ import annotations

import numpy as np

from .errors import SceneError

__all__ = ["CAVITATION_MODELS", "ReynoldsCavitation", "check_cavitation", "register_cavitation"]

#: name -> cavitation model class (``Fluid(cavitation=name)``)
CAVITATION_MODELS: dict[str, type] = {}


def register_cavitation(cls):
    """Class decorator adding a cavitation model to :data:`CAVITATION_MODELS`."""
    CAVITATION_MODELS[cls.name] = cls
    return cls


@register_cavitation
class ReynoldsCavitation:
    """``p >= 0`` (Swift-Stieber), the cavitated set lagged one step."""

    name = "reynolds"

    @staticmethod
    def fixed(state) -> np.ndarray:
        """Free-node indices held at p = 0 in the step after ``state``."""
        y = getattr(state, "p_aux", None)
        if y is None:
            return np.zeros(0, dtype=np.int64)
        return np.flatnonzero(np.asarray(y) < 0.0)


def check_cavitation(name):
    """``name`` if None or a registered model name, else SceneError naming the choices."""
    if name is None or (isinstance(name, str) and name in CAVITATION_MODELS):
        return name
    raise SceneError(
        f"cavitation must be None (full Sommerfeld) or one of {sorted(CAVITATION_MODELS)}, got {name!r}."
    )
