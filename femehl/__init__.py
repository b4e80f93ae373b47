"""femehl: transient soft elastohydrodynamic lubrication, one linear system per step.

Implements Wu, Hui et al., "Solving transient problems in soft
elasto-hydrodynamic lubrication", JMPS 2022: a finite-element solver in
scikit-fem (default) and the paper's polar finite-difference scheme (the
reference).  Quick start::

    import femehl
    scene = femehl.presets.paper_sphere(beta=200.0, h0=0.1)
    result = femehl.solve(scene, t_end=5.0, dt=0.01)          # FE, "medium" mesh
    result.load, result.film_min                               # one entry per step
    result.pressure_at([[0.0, 0.0], [-1.0, 0.0]], t=2.0)
"""

from femehl.accuracy import auto
from femehl.api import make_stepper, methods, solve, solve_line, steps
from femehl.discretize import METHODS
from femehl.elastic import Viscoelastic
from femehl.errors import (
    FemehlError,
    FilmRuptureError,
    MeshError,
    SceneError,
    SceneFileError,
    SingularSystemError,
    SolverError,
    TimeBudgetError,
)
from femehl.output.result import Result
from femehl.problem import indenters, line, presets
from femehl.problem.indenters import INDENTERS, Ellipsoid, FlatPunch, HeightMap, Shape
from femehl.problem.roughness import Roughness
from femehl.problem.scene import (
    Constant,
    Dimensional,
    Domain,
    Fluid,
    HalfSpace,
    Layer,
    Motion,
    RampHold,
    Rigid,
    Scene,
    Sphere,
    Table,
    TanhStart,
    Winkler,
)
from femehl.problem.viscosity import Barus, Roelands
from femehl.solver.stepping import State, march
from femehl.studies.sweeps import sweep

__version__ = "0.1.0"

__all__ = [
    "Barus",
    "Roelands",
    "Roughness",
    "sweep",
    "presets",
    "auto",
    "indenters",
    "line",
    "solve",
    "solve_line",
    "steps",
    "make_stepper",
    "march",
    "METHODS",
    "methods",
    "Result",
    "State",
    "Scene",
    "Sphere",
    "Ellipsoid",
    "FlatPunch",
    "Shape",
    "HeightMap",
    "INDENTERS",
    "HalfSpace",
    "Layer",
    "Rigid",
    "Winkler",
    "Viscoelastic",
    "Fluid",
    "Motion",
    "Domain",
    "Dimensional",
    "Constant",
    "Table",
    "RampHold",
    "TanhStart",
    "FemehlError",
    "SceneError",
    "SceneFileError",
    "MeshError",
    "SolverError",
    "FilmRuptureError",
    "SingularSystemError",
    "TimeBudgetError",
]
