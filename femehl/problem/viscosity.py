"""Pressure-dependent viscosity: Barus and Roelands, lagged one step in the Poiseuille flux.

In femehl's normalization (:mod:`femehl.problem.scene`) the Reynolds equation of a fluid whose
viscosity rises with pressure, ``eta = eta0 r(p)``, is

    beta div( d^3 / r(p) grad p ) = -V dd/dx + dd/dt,

``beta`` formed with the ambient viscosity ``eta0``.  The scheme keeps its promise of one
linear system per step: the ratio ``r`` is taken at the known pressure of the previous
step, ``r(p^k)``, inside the lagged mobility ``m = d^3 / r`` (exactly as ``d^3`` is taken
from the lagged film); :class:`PiezoviscousMobility` is that mobility, used by the
Poiseuille term when the scene's :class:`~femehl.problem.scene.Fluid` has a ``viscosity``.  An
isoviscous scene (``viscosity=None``) assembles exactly what it did before.

Models (pressures in femehl's units ``p = p*/(4 pi G sqrt(h_inf/R))``):

* :class:`Barus`: ``r = exp(alpha p)`` (Barus 1893); ``alpha = alpha* p_s``, the SI
  pressure-viscosity coefficient ``alpha*`` [1/Pa] times the pressure scale ``p_s``
  [Pa] (:meth:`Barus.from_si`);
* :class:`Roelands`: ``r = exp( (alpha p_r / Z) ((1 + p/p_r)^Z - 1) )`` (Roelands 1966),
  written so that its slope at ``p = 0`` is ``alpha`` like Barus: the usual SI form
  ``ln(eta/eta0) = (ln eta0 + 9.67) ((1 + p*/p0)^Z - 1)`` with ``p0 = 1.96e8 Pa`` gives
  ``p_r = p0/p_s`` and ``alpha = (ln eta0 + 9.67) Z / p_r`` (:meth:`Roelands.from_si`).
  It grows more slowly than Barus at high pressure.  Below ``p = -p_r`` (far beyond any
  film pressure) ``1 + p/p_r`` is held at 0.

How far the lagged ratio stays stable and accurate is measured in
``benchmarks/viscosity.md`` (``alpha p_max`` against the error of a run with a much smaller
step), not assumed.  The finite-difference reference keeps the paper's isoviscous
non-conservative form and refuses a pressure-dependent viscosity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from femehl.errors import SceneError
from femehl.registry import Registry
from femehl.validation import check_nonnegative, check_positive

__all__ = ["VISCOSITY_MODELS", "Barus", "PiezoviscousMobility", "Roelands", "register_viscosity"]

#: kind -> viscosity model class (TOML ``[fluid.viscosity] kind = ...``)
VISCOSITY_MODELS = Registry("viscosity model", key="kind")
#: class decorator adding a viscosity model to :data:`VISCOSITY_MODELS` under ``cls.kind``
register_viscosity = VISCOSITY_MODELS.register


def _pressure_scale(dim) -> float:
    """The SI pressure of femehl's unit pressure, from a :class:`~femehl.problem.scene.Dimensional`."""
    try:
        return float(dim.to_si("pressure", 1.0))
    except AttributeError:
        raise SceneError(
            "give the experiment's femehl.Dimensional(R, G, eta, V_ss, h_inf, nu): it sets the "
            "pressure scale that converts the SI coefficient."
        ) from None


@register_viscosity
@dataclass(frozen=True)
class Barus:
    """``eta / eta0 = exp(alpha p)`` with ``alpha`` in femehl's units (``alpha = 0``: isoviscous)."""

    kind = "barus"
    alpha: float = 0.0

    def __post_init__(self):
        hint = "alpha = alpha_SI [1/Pa] x the pressure scale; Barus.from_si(alpha_SI, dim) converts it."
        object.__setattr__(self, "alpha", check_nonnegative("Barus alpha", self.alpha, hint))

    @classmethod
    def from_si(cls, alpha_si: float, dim) -> Barus:
        """From the SI coefficient ``alpha_si`` [1/Pa] and the experiment's Dimensional."""
        a = check_nonnegative("alpha_si", alpha_si, "in 1/Pa, e.g. 2e-8 for a mineral oil.")
        return cls(alpha=a * _pressure_scale(dim))

    def ratio(self, p):
        """``eta(p) / eta0``."""
        return np.exp(self.alpha * np.asarray(p, dtype=float))


@register_viscosity
@dataclass(frozen=True)
class Roelands:
    """``eta / eta0 = exp((alpha p_r / Z)((1 + p/p_r)^Z - 1))``: slope ``alpha`` at p = 0."""

    kind = "roelands"
    alpha: float = 0.0
    p_r: float = 1.0
    Z: float = 0.6

    def __post_init__(self):
        hint = "Roelands.from_si(eta0, dim, Z=0.6) converts the SI form (p0 = 1.96e8 Pa)."
        object.__setattr__(self, "alpha", check_nonnegative("Roelands alpha", self.alpha, hint))
        object.__setattr__(self, "p_r", check_positive("Roelands p_r", self.p_r, hint))
        Z = check_positive("Roelands Z", self.Z, "Z is about 0.6 for mineral oils (0 < Z <= 1.5).")
        object.__setattr__(self, "Z", Z)

    @classmethod
    def from_si(cls, eta0: float, dim, Z: float = 0.6, p0: float = 1.96e8) -> Roelands:
        """From the ambient viscosity ``eta0`` [Pa s], the Dimensional, ``Z`` and ``p0`` [Pa]."""
        eta0 = check_positive("eta0", eta0, "the ambient viscosity in Pa s.")
        p0 = check_positive("p0", p0, "Roelands' reference pressure, 1.96e8 Pa.")
        Z = check_positive("Roelands Z", Z, "Z is about 0.6 for mineral oils (0 < Z <= 1.5).")
        A = math.log(eta0) + 9.67
        if A <= 0.0:
            raise SceneError(
                f"Roelands needs ln(eta0) + 9.67 > 0 (eta0 > 6.3e-5 Pa s), got eta0 = {eta0!r}: "
                "the fluid is thinner than Roelands' fit covers; use Barus."
            )
        p_r = p0 / _pressure_scale(dim)
        return cls(alpha=A * Z / p_r, p_r=p_r, Z=Z)

    def ratio(self, p):
        """``eta(p) / eta0``."""
        s = np.maximum(1.0 + np.asarray(p, dtype=float) / self.p_r, 0.0)
        return np.exp(self.alpha * self.p_r / self.Z * (s**self.Z - 1.0))


def check_viscosity(model):
    """``model`` if it is None or a viscosity model (has ``ratio(p)``), else SceneError."""
    if model is None or callable(getattr(model, "ratio", None)):
        return model
    kinds = ", ".join(sorted(VISCOSITY_MODELS))
    raise SceneError(
        f"viscosity must be None (isoviscous) or a model such as femehl.Barus(alpha) "
        f"(kinds: {kinds}), got {type(model).__name__}."
    )


class PiezoviscousMobility:
    """``m = d^3 / r(p)`` with the ratio at the lagged pressure on the film points."""

    uses_pressure = True

    def __init__(self, model):
        self.model = model

    def value(self, d, p_film):
        return d**3 / self.model.ratio(p_film)

    def d_dd(self, d, p_film):
        return 3.0 * d * d / self.model.ratio(p_film)
