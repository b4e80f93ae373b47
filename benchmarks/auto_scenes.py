"""The scenes of the accuracy benchmark ``femehl bench auto``: ``SCENES[name] = (factory, t_end)``.

Every scene is built from femehl's public API only; ``factory()`` takes no argument and
returns a fresh :class:`femehl.Scene`.  Lengths and times are in the paper's units
(README, "Normalization").  "Approach" is the paper's gap ramp ``RampHold(0.1, -1, 1)``
with no sliding (velocity 0); "sliding" is the paper's motion (that ramp, then
``V = tanh(t - 1)``, :func:`femehl.problem.presets.paper_sphere`).  The end times are short so
that converged references (benchmarks/auto_reference_scenes.py) stay affordable on a
2-core machine, but each reaches the regime it is there for.

Scenes and why
--------------
``paper``
    :func:`femehl.problem.presets.paper_sphere` (beta = 200, h0 = 0.1, L = 2) to t = 5: the
    paper's case and the default of ``femehl run``; sliding start-up to near steady.
``sphere_b{20,2000,20000}_approach``, t_end 1.5
    The paper sphere's squeeze only (indent to hc = -1 at t = 1, hold), at three beta
    (film thickness ~ beta^(-0.6)): the trapped dimple, from thick films (beta = 20)
    to very thin ones (beta = 20000, the fitted mesh's band floor).
``sphere_b{20,2000,20000}_sliding``, t_end 2
    The paper's motion at the same beta: the sliding start-up (t in [1, 2]), when the
    exit constriction forms; the narrow exit zone at large beta is the hard part.
``steady_b1000``, t_end 12
    The sphere sliding at beta = 1000 on a larger domain L = 3, run long enough
    (11 time units of sliding) to reach steady sliding: the long-time accuracy, and the
    steady film (central and minimum) as a quantity of its own.
``ellipsoid_x``, ``ellipsoid_y``, t_end 3
    The shipped example (``examples/ellipsoid_sliding.py:scene()``, Ellipsoid(Rx = 0.5,
    Ry = 2), hc -> -0.5): the contact elongated across the sliding direction; and turned
    by 90 degrees (Rx = 2, Ry = 0.5, long axis along sliding).  Non-circular contacts.
``punch``, t_end 2
    FlatPunch(a = 0.5, edge_radius = 0.5) pressed to hc = -0.3 (a shallow indentation:
    the flat face is in contact as soon as hc < 0 and the contact spreads onto the
    rounded edge, Sneddon radius 0.81 here; as in tests/test_fitted_mesh.py), then
    sliding with the paper's tanh start: the pressure peaks at the edge, not the centre.
``user_shape``, t_end 2
    A :class:`femehl.problem.indenters.Shape` from a Python callable, the sphere plus a ripple
    across the sliding direction ``s = r^2/2 + 0.05 (1 - cos 6x)`` (the Shape docstring's
    example, ``symmetric_y=True``: half disk), with the paper's motion.  The user-shape
    path (Sneddon ray by ray for the fitted mesh) and a non-monotone film.
``load_controlled``, t_end 2
    The paper sphere under an imposed load ``Motion(gap=0.1, load=F(t))``: F ramps from 0
    to the Hertz load 4/(3 pi) of hc = -1 over t in [0, 1] (``RampHold(0, 4/(3 pi), 1)``:
    a load history like the paper's gap ramp), then the paper's sliding.  hc(t) is an
    unknown (one extra row per step); the load then holds to the solve's tolerance (1e-8) and the
    films carry the error.
``winkler``, t_end 2
    The sphere on a Winkler foundation k = 0.25 (w = -p/k), pressed to hc = -0.5 (contact
    radius sqrt(2 * 0.5) = 1; dry peak pressure k * 0.5 = 0.125 and load
    k pi a^2 delta / 2 = 0.20, of the order of the paper's Hertz contact, p0 = 0.20 and
    load 0.42), then the paper's sliding: the local substrate model.  (A stiffer k = 1,
    the first choice, makes the exit constriction too sharp for the fitted mesh: its
    minimum film converged at order 0.5 only, 5 % apart between levels 0.5 and 0.36.)
``compressible``, t_end 2
    The paper sphere and motion on a compressible half space HalfSpace(nu = 0.3)
    (compliance 2 (1 - nu) = 1.4): the Boussinesq factor path.
``layer``, t_end 2
    The paper sphere and motion on an incompressible elastic layer bonded to a rigid base,
    ``Layer(thickness=1)`` (nu = 0.5), the thickness of the order of the contact radius
    (a = 1 on the half space at hc = -1): the layered-solid kernel (a dense operator only,
    no fast one: the automatic run's cell budget is the dense one), a stiffer, smaller,
    higher-pressure contact than the half space's at the same indentation.
``viscoelastic``, t_end 2
    The paper sphere and motion on a standard linear solid over the half space,
    ``Viscoelastic(G0=2, tau=0.5)`` (G_inf = 1, the paper's modulus; creep time
    tau_c = tau G0 / G_inf = 1): the load relaxes during the ramp and the sliding start
    (t in [1, 2], Deborah number 2 V tau_c / a of order 1), the moving-frame history
    integral of the relaxing solid.
``free_indenter``, t_end 2
    The paper sphere (beta = 200, L = 2) let go at hc(0) = 0.1 at rest as a free indenter
    ``Motion(mass=0.1, force=4/(3 pi))`` (its weight the Hertz load of hc = -1), no
    sliding: it falls onto the film, squeezes it and settles towards hc = -1 in a
    film-damped oscillation (Newton's law, one more row per step; deepest hc = -1.72 at
    t = 1.34, hc = -0.80 at t = 2).  The load is the film's force, not imposed (it differs
    from the weight by m hc''), so all three quantities are checked.  Its fitted meshes (the
    references' and the hand grid's) are fitted to :data:`MESH_SCENES` ``["free_indenter"]``,
    the same sphere under an imposed gap down to hc = -1.75: ``femehl.discretize.fitted``
    reads a free indenter's contact from its ``gap``, the initial clearance 0.1 held, so it
    fits no contact at all (contact radius floored at 0.05 L = 0.1 instead of 1.3), and the
    references' film_min on those meshes did not converge (levels 0.7, 0.5, 0.357:
    0.0379, 0.0354, 0.0372 at t = 1.5).
``jfo``, t_end 3
    The paper sphere and motion with JFO mass-conserving cavitation
    (``Fluid(200, cavitation="jfo")``): the cavity behind the contact in the sliding
    start, the film content carried through it and the film reforming at its rim.  To
    t = 3, not 2: at t = 2 the minimum film is within 0.1 % of the full-Sommerfeld run's,
    at t = 3 it is 6 % thicker (the exit constriction then sits on the cavity's rim; load
    +1.9 %; fitted level 1, dt = 0.02).
``barus``, t_end 2
    The paper sphere and motion with Barus pressure-viscosity ``Barus(alpha=10)``
    (alpha p_max about 2; benchmarks/viscosity.md): against the isoviscous run the minimum
    film is 20 % thicker at t = 1 and 10 % at t = 2, the central one 45-55 % (fitted level 1,
    dt = 0.02): the viscosity lagged one step in the Poiseuille flux.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import math
import pathlib

import numpy as np

import femehl
from femehl import (
    Barus,
    Domain,
    Fluid,
    HalfSpace,
    Layer,
    Motion,
    RampHold,
    Scene,
    Sphere,
    TanhStart,
    Viscoelastic,
    Winkler,
)
from femehl.problem.indenters import FlatPunch, Shape

__all__ = ["SCENES", "MESH_SCENES", "HERTZ_LOAD", "mesh_scene"]

HERE = pathlib.Path(__file__).resolve().parent
#: normalized Hertz load of the unit sphere at hc = -1 (incompressible half space)
HERTZ_LOAD = 4.0 / (3.0 * math.pi)


def _example_scene():
    """``scene(Rx, Ry, h_end, beta)`` of the shipped example examples/ellipsoid_sliding.py."""
    spec = importlib.util.spec_from_file_location(
        "femehl_example_ellipsoid", HERE.parent / "examples" / "ellipsoid_sliding.py"
    )
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.scene


def _paper_motion() -> Motion:
    return Motion(gap=RampHold(0.1, -1.0, 1.0), velocity=TanhStart(1.0, 1.0))


def sphere_approach(beta: float) -> Scene:
    """The paper sphere's squeeze only: RampHold(0.1, -1, 1), no sliding."""
    return Scene(
        indenter=Sphere(1.0),
        substrate=HalfSpace(0.5),
        fluid=Fluid(beta),
        motion=Motion(gap=RampHold(0.1, -1.0, 1.0), velocity=0.0),
        domain=Domain(2.0),
    )


def sphere_sliding(beta: float, L: float = 2.0) -> Scene:
    """The paper sphere and motion at ``beta`` (domain radius ``L``)."""
    return femehl.presets.paper_sphere(beta=beta, L=L)


def ellipsoid_x() -> Scene:
    """The shipped example's scene: Ellipsoid(0.5, 2), hc -> -0.5, paper sliding."""
    return _example_scene()()


def ellipsoid_y() -> Scene:
    """The example's scene turned by 90 degrees: Ellipsoid(2, 0.5)."""
    return _example_scene()(2.0, 0.5)


def punch() -> Scene:
    """FlatPunch(0.5, 0.5) pressed to hc = -0.3 over t in [0, 1], then the paper's sliding."""
    return Scene(
        indenter=FlatPunch(a=0.5, edge_radius=0.5),
        substrate=HalfSpace(0.5),
        fluid=Fluid(200.0),
        motion=Motion(gap=RampHold(0.1, -0.3, 1.0), velocity=TanhStart(1.0, 1.0)),
        domain=Domain(2.0),
    )


def rippled_sphere(x, y):
    """The unit sphere plus a ripple across the sliding direction (>= 0, zero at the tip)."""
    return 0.5 * (x * x + y * y) + 0.05 * (1.0 - np.cos(6.0 * x))


def user_shape() -> Scene:
    """Shape(rippled_sphere, symmetric_y=True) with the paper's motion."""
    return Scene(
        indenter=Shape(rippled_sphere, symmetric_y=True, name="rippled_sphere"),
        substrate=HalfSpace(0.5),
        fluid=Fluid(200.0),
        motion=_paper_motion(),
        domain=Domain(2.0),
    )


def load_controlled() -> Scene:
    """The paper sphere under F(t) = RampHold(0, 4/(3 pi), 1), hc(0) = 0.1, then the paper's sliding."""
    return Scene(
        indenter=Sphere(1.0),
        substrate=HalfSpace(0.5),
        fluid=Fluid(200.0),
        motion=Motion(gap=0.1, velocity=TanhStart(1.0, 1.0), load=RampHold(0.0, HERTZ_LOAD, 1.0)),
        domain=Domain(2.0),
    )


def winkler() -> Scene:
    """The sphere on Winkler(k = 0.25) pressed to hc = -0.5 (contact radius 1), then the paper's sliding."""
    return Scene(
        indenter=Sphere(1.0),
        substrate=Winkler(0.25),
        fluid=Fluid(200.0),
        motion=Motion(gap=RampHold(0.1, -0.5, 1.0), velocity=TanhStart(1.0, 1.0)),
        domain=Domain(2.0),
    )


def compressible() -> Scene:
    """The paper sphere and motion on HalfSpace(nu = 0.3)."""
    return Scene(
        indenter=Sphere(1.0),
        substrate=HalfSpace(nu=0.3),
        fluid=Fluid(200.0),
        motion=_paper_motion(),
        domain=Domain(2.0),
    )


def _paper_with(**parts) -> Scene:
    """The paper sphere and motion (beta = 200, L = 2) with some of its parts replaced."""
    return dataclasses.replace(femehl.presets.paper_sphere(), **parts)


def layer() -> Scene:
    """The paper sphere and motion on Layer(thickness = 1) bonded to a rigid base (nu = 0.5)."""
    return _paper_with(substrate=Layer(1.0))


def viscoelastic() -> Scene:
    """The paper sphere and motion on Viscoelastic(G0 = 2, tau = 0.5) over the half space."""
    return _paper_with(substrate=Viscoelastic(G0=2.0, tau=0.5))


def free_indenter() -> Scene:
    """The paper sphere let go at hc(0) = 0.1 at rest: mass 0.1, weight 4/(3 pi), no sliding."""
    return _paper_with(motion=Motion(gap=0.1, velocity=0.0, mass=0.1, force=HERTZ_LOAD))


def free_indenter_mesh() -> Scene:
    """The scene the free indenter's fitted meshes are fitted to: the paper sphere under an
    imposed gap down to hc = -1.75 (the free run's deepest is -1.72), no sliding."""
    return _paper_with(motion=Motion(gap=RampHold(0.1, -1.75, 1.0), velocity=0.0))


def jfo() -> Scene:
    """The paper sphere and motion with JFO cavitation."""
    return _paper_with(fluid=Fluid(200.0, cavitation="jfo"))


def barus() -> Scene:
    """The paper sphere and motion with Barus(alpha = 10) pressure-viscosity."""
    return _paper_with(fluid=Fluid(200.0, viscosity=Barus(alpha=10.0)))


def _at(f, *args):
    """A no-argument factory ``f(*args)`` (a named function, unlike a lambda in a loop)."""

    def factory() -> Scene:
        return f(*args)

    factory.__name__ = f"{f.__name__}{args!r}"
    return factory


#: name -> (scene factory with no arguments, t_end)
SCENES: dict = {
    "paper": (femehl.presets.paper_sphere, 5.0),
    "sphere_b20_approach": (_at(sphere_approach, 20.0), 1.5),
    "sphere_b20_sliding": (_at(sphere_sliding, 20.0), 2.0),
    "sphere_b2000_approach": (_at(sphere_approach, 2000.0), 1.5),
    "sphere_b2000_sliding": (_at(sphere_sliding, 2000.0), 2.0),
    "sphere_b20000_approach": (_at(sphere_approach, 20000.0), 1.5),
    "sphere_b20000_sliding": (_at(sphere_sliding, 20000.0), 2.0),
    "steady_b1000": (_at(sphere_sliding, 1000.0, 3.0), 12.0),
    "ellipsoid_x": (ellipsoid_x, 3.0),
    "ellipsoid_y": (ellipsoid_y, 3.0),
    "punch": (punch, 2.0),
    "user_shape": (user_shape, 2.0),
    "load_controlled": (load_controlled, 2.0),
    "winkler": (winkler, 2.0),
    "compressible": (compressible, 2.0),
    "layer": (layer, 2.0),
    "viscoelastic": (viscoelastic, 2.0),
    "free_indenter": (free_indenter, 2.0),
    "jfo": (jfo, 3.0),
    "barus": (barus, 2.0),
}

#: name -> factory of the scene its fitted meshes (``fitted_disk(MESH_SCENES[name](), t_end,
#: level)``) are fitted to, where that is not the scene itself (the references' and the hand
#: grid's meshes; the automatic runs choose their own)
MESH_SCENES: dict = {"free_indenter": free_indenter_mesh}


def mesh_scene(name: str) -> Scene:
    """The scene the fitted meshes of scene ``name`` are fitted to."""
    return MESH_SCENES.get(name, SCENES[name][0])()
