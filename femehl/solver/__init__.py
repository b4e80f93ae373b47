"""The one solver core: terms, the lagged stepper and the linear solvers.

* :mod:`femehl.solver.terms` -- the physics terms of the Reynolds step (plug-ins);
* :mod:`femehl.solver.stepper` -- the one stepper every method uses (imposed load, states,
  film checks);
* :mod:`femehl.solver.linsolve` -- the linear solvers (direct LU, recycled GCR) with
  explicit state.

Discretizations live in :mod:`femehl.discretize`, substrates in
:mod:`femehl.elastic`; the driver loop is :func:`femehl.api.run_loop`.
"""

from femehl.solver.linsolve import LINEAR_SOLVERS, register_linear_solver
from femehl.solver.stepper import LaggedStepper
from femehl.solver.terms import TERMS, Contribution, register_term

__all__ = [
    "LaggedStepper",
    "TERMS",
    "register_term",
    "Contribution",
    "LINEAR_SOLVERS",
    "register_linear_solver",
]
