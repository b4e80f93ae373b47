"""Physics terms of the lagged Reynolds step, each a small plug-in.

Every method writes the Reynolds equation (normalized, see :mod:`femehl.problem.scene`)

    beta div(m grad p) = -V(t) dd/dx + dd/dt,      m = d^3 (Newtonian, no slip)

in residual form on its test rows (weak form for finite elements, node equations for the
polar finite differences):

    beta D(m^*) p  +  V X d^{k+1}  +  T (a0 d^{k+1} - a1 d^k + a2 d^{k-1}) / dt  =  0,

with ``d^{k+1} = h^{k+1} + C p`` on the film points (``C`` the substrate's compliance)
and every nonlinear coefficient taken from known steps (``m^* = m(d^*)``, ``d^*`` the
scheme's lagged film): the step is ONE linear system.  A term contributes to it through
:class:`Contribution`: a matrix acting on ``p`` directly, a film operator ``F`` (fixed,
sparse, test rows x film points) times a coefficient acting on ``d^{k+1}``, and a
right-hand side.  The discretization supplies the operators (``disc.poiseuille``,
``disc.couette``, ``disc.squeeze``); a term only combines them.

Terms are registered in :data:`TERMS` with :func:`register_term`; the stepper assembles
the ones a scene calls for (:func:`terms_for`).  A new physics term is one class with
``name``, ``applies(scene, t_end)``, ``setup(disc)`` and ``contribute(step)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from femehl.errors import SceneError
from femehl.registry import Registry

__all__ = [
    "Contribution",
    "StepContext",
    "Term",
    "TERMS",
    "register_term",
    "terms_for",
    "Squeeze",
    "Couette",
    "Poiseuille",
    "Mobility",
    "Newtonian",
]


@dataclass(frozen=True)
class StepContext:
    """What a term may use to contribute to the step from ``t`` to ``t_new``.

    ``d`` is the film at step k, ``d_lag`` the scheme's lagged film ``d^*``, ``history``
    ``a1 d^k - a2 d^{k-1}``; ``a0, a1, a2`` the scheme's coefficients; ``p`` the pressure
    unknowns at step k; ``V`` the sliding velocity at ``t_new``.
    """

    t_new: float
    dt: float
    a0: float
    d: np.ndarray
    d_lag: np.ndarray
    history: np.ndarray
    p: np.ndarray
    V: float
    beta: float
    a1: float = 1.0
    a2: float = 0.0


@dataclass(frozen=True)
class Contribution:
    """A term's part of ``A p = b``: ``matrix p + film_coefficient F d^{k+1} = rhs``.

    ``F`` is the term's fixed film operator, ``term.film_operator()`` (sparse, test rows x
    film points); the stepper forms ``F C`` once per term name.
    """

    matrix: object = None  # sparse (n, n) acting on p
    film_coefficient: float = 0.0  # multiplies F d^{k+1}
    rhs: np.ndarray | None = None  # added to the right-hand side


class Term(Protocol):
    name: str

    def applies(self, scene, t_end: float | None) -> bool: ...

    def setup(self, disc) -> None: ...

    def contribute(self, step: StepContext) -> Contribution: ...

    def film_operator(self):
        """The fixed sparse ``F`` of the term (only if it ever gives a film coefficient)."""


#: name -> term class, in the order they are assembled
TERMS = Registry("term", key="name")
#: class decorator adding a term to :data:`TERMS` under ``cls.name``
register_term = TERMS.register


def terms_for(scene, t_end=None, extra=()) -> list:
    """Instances of the registered terms that apply to ``scene``, with ``extra`` instances.

    An extra term whose ``name`` is that of a registered one replaces it (e.g.
    ``Poiseuille(mobility=...)``); the others are added after the registered terms.
    """
    extra = list(extra)
    names = [t.name for t in extra]
    if len(set(names)) != len(names):
        raise SceneError(f"terms must have distinct names, got {names}.")
    out = [
        next(t for t in extra if t.name == name) if name in names else cls()
        for name, cls in TERMS.items()
        if cls.applies(scene, t_end)
    ]
    return out + [t for t in extra if t.name not in TERMS]


# ---- mobility: the coefficient of the Poiseuille flux ------------------------------------
class Mobility(Protocol):
    """``m(d, p)`` of the Poiseuille flux ``beta div(m grad p)`` and its derivative in d."""

    def value(self, d: np.ndarray, p_film: np.ndarray | None) -> np.ndarray: ...

    def d_dd(self, d: np.ndarray, p_film: np.ndarray | None) -> np.ndarray: ...


class Newtonian:
    """``m = d^3``: a Newtonian film with no slip (the paper's Eq. 8)."""

    uses_pressure = False

    def value(self, d, p_film=None):
        return d**3

    def d_dd(self, d, p_film=None):
        return 3.0 * d * d


# ---- the paper's three terms --------------------------------------------------------------
@register_term
class Poiseuille:
    """Pressure-driven flux ``beta div(m grad p)``, ``m`` lagged: ``beta D(m(d^*, p^k)) p``.

    The mobility is ``mobility`` if given, else the scene's: ``d^3`` (Newtonian), or
    ``d^3 / r(p^k)`` when the scene has a pressure-dependent viscosity
    (:class:`femehl.problem.viscosity.PiezoviscousMobility`; ``p^k`` averaged to the film points
    by ``disc.average()``).
    """

    name = "poiseuille"

    def __init__(self, mobility: Mobility | None = None):
        self.mobility = mobility

    @staticmethod
    def applies(scene, t_end=None):
        return True

    def setup(self, disc):
        self.disc = disc
        if self.mobility is None:
            model = getattr(disc.scene, "viscosity", None)
            if model is None:
                self.mobility = Newtonian()
            else:
                from femehl.problem.viscosity import PiezoviscousMobility

                self.mobility = PiezoviscousMobility(model)
        self._average = disc.average() if getattr(self.mobility, "uses_pressure", False) else None

    def contribute(self, step):
        d = step.d_lag
        p_film = None if self._average is None else self._average @ step.p
        D = self.disc.poiseuille(d, self.mobility.value(d, p_film), self.mobility.d_dd(d, p_film))
        return Contribution(matrix=D * step.beta)


@register_term
class Squeeze:
    """``dd/dt`` by the scheme's backward difference: ``T (a0 d^{k+1} - history) / dt``."""

    name = "squeeze"
    every_step = True  # its film product F C is formed with the operators, before the first step

    @staticmethod
    def applies(scene, t_end=None):
        return True  # the film's own time derivative is always there (w changes with p)

    def setup(self, disc):
        self.T = disc.squeeze()

    def film_operator(self):
        return self.T

    def contribute(self, step):
        return Contribution(film_coefficient=step.a0 / step.dt, rhs=self.T @ step.history / step.dt)


@register_term
class Couette:
    """Transport of the film by the sliding surface, ``-V dd/dx``: ``V X d^{k+1}``."""

    name = "couette"

    @staticmethod
    def applies(scene, t_end=None):
        return True  # assembled only the first time V(t) != 0

    def setup(self, disc):
        self.disc = disc
        self.X = None

    def film_operator(self):
        if self.X is None:
            self.X = self.disc.couette()
        return self.X

    def contribute(self, step):
        return Contribution(film_coefficient=step.V)
