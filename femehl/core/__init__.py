"""The one solver core: terms, the lagged stepper and the linear solvers.

* :mod:`femehl.core.terms` -- the physics terms of the Reynolds step (plug-ins);
* :mod:`femehl.core.stepper` -- the one stepper every method uses (imposed load, states,
  film checks);
* :mod:`femehl.core.linsolve` -- the linear solvers (direct LU, recycled GCR) with
  explicit state.

Discretizations live in :mod:`femehl.discretizations`, substrates in
:mod:`femehl.substrates`; the driver loop is :func:`femehl.api.run_loop`.
"""

from .linsolve import LINEAR_SOLVERS, register_linear_solver
from .stepper import LaggedStepper
from .terms import TERMS, Contribution, register_term

__all__ = [
    "LaggedStepper",
    "TERMS",
    "register_term",
    "Contribution",
    "LINEAR_SOLVERS",
    "register_linear_solver",
]
