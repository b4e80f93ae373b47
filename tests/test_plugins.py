"""The one core is open: substrates, physics terms and mobilities written here, in the test
module only, run through FE and FD without any change to femehl's own files.

Each plug-in is checked against an independent route to the same physics:

* a Winkler foundation of two springs in series (new substrate class) equals the built-in
  ``Winkler(k1 k2 / (k1 + k2))``, FE and FD, to round-off;
* a compressible half space written from the discretization's Boussinesq primitive (new
  substrate class) equals the built-in ``HalfSpace(nu)`` with the same factor 2(1 - nu);
* a subclass of a built-in substrate works unchanged;
* a Newtonian film of viscosity 2 (new mobility, m = d^3/2) equals beta/2, FE and FD;
* sliding along y (a new Couette term, FE) equals sliding along x rotated by 90 degrees,
  up to the mesh's orientation error.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
from skfem import BilinearForm, asm

import femehl
from femehl.problem.scene import Domain, Fluid, HalfSpace, Motion, RampHold, Scene, Sphere, TanhStart, Winkler
from femehl.solver.terms import Contribution, Poiseuille

FE = dict(method="fe", mesh="coarse", linear_solver="lu")  # exact comparisons: direct solves
FD = dict(method="fd", dr=0.1, dtheta=math.pi / 12)
RUN = dict(t_end=1.6, dt=0.04, store_every=10)


SLIDE = TanhStart(1.0, 1.0)


def paper_like(substrate, beta=200.0, velocity=SLIDE):
    return Scene(
        indenter=Sphere(),
        substrate=substrate,
        fluid=Fluid(beta),
        motion=Motion(gap=RampHold(0.1, -0.4, 1.0), velocity=velocity),
        domain=Domain(2.0),
    )


def assert_same_run(a, b, rtol):
    for name in ("load", "film_center", "film_min", "p_max", "hc"):
        x, y = getattr(a, name), getattr(b, name)
        assert np.allclose(x, y, rtol=rtol, atol=rtol * np.abs(x).max()), name
    for s, t in zip(a.states, b.states, strict=True):
        assert np.allclose(s.d, t.d, rtol=rtol, atol=0)


# ---- a new substrate: two Winkler springs in series -------------------------------------
@dataclass(frozen=True)
class SeriesSprings:
    k1: float
    k2: float
    kind = "series_springs"

    def compliance_operator(self, disc):
        return (disc.average() * (1.0 / self.k1 + 1.0 / self.k2)).tocsr()

    def deflection_rows(self, disc, points):
        return (disc.pressure_rows(points) * (1.0 / self.k1 + 1.0 / self.k2)).tocsr()


# ---- a new substrate from the Boussinesq primitive ----------------------------------------
@dataclass(frozen=True)
class ScaledHalfSpace:
    factor: float
    kind = "scaled_halfspace"

    def compliance_operator(self, disc):
        return self.factor * disc.boussinesq()

    def deflection_rows(self, disc, points):
        return self.factor * disc.boussinesq_rows(points)


@dataclass(frozen=True)
class MyHalfSpace(HalfSpace):
    """A user's subclass of a built-in substrate (e.g. to carry a label)."""

    label: str = "PDMS"


@pytest.mark.parametrize("method", [FE, FD], ids=["fe", "fd"])
def test_new_local_substrate_equals_builtin(method):
    k1, k2 = 8.0, 4.0
    # indentation and hold only: the coarse FD grid ruptures when a Winkler contact slides
    a = femehl.solve(paper_like(SeriesSprings(k1, k2), velocity=0.0), **method, **RUN)
    b = femehl.solve(paper_like(Winkler(k1 * k2 / (k1 + k2)), velocity=0.0), **method, **RUN)
    assert a.info["substrate"] == "SeriesSprings"
    assert not isinstance(femehl.make_stepper(paper_like(SeriesSprings(k1, k2)), **method).C, np.ndarray)
    # same operator up to the rounding of 1/k1 + 1/k2 against 1/k: a few ulp, carried
    # through the lagged steps
    assert_same_run(a, b, rtol=1e-11)


@pytest.mark.parametrize("method", [FE, FD], ids=["fe", "fd"])
def test_new_nonlocal_substrate_equals_builtin(method):
    nu = 0.3
    a = femehl.solve(paper_like(ScaledHalfSpace(2.0 * (1.0 - nu))), **method, **RUN)
    b = femehl.solve(paper_like(HalfSpace(nu)), **method, **RUN)
    c = femehl.solve(paper_like(MyHalfSpace(nu)), **method, **RUN)
    assert_same_run(a, b, rtol=1e-10)
    assert_same_run(c, b, rtol=1e-13)


# ---- a new mobility: a Newtonian film of viscosity eta ---------------------------------------
class Viscous:
    """``m = d^3 / eta``: the film's viscosity ``eta`` times that of beta's definition."""

    def __init__(self, eta):
        self.eta = eta

    def value(self, d, p_film=None):
        return d**3 / self.eta

    def d_dd(self, d, p_film=None):
        return 3.0 * d * d / self.eta


@pytest.mark.parametrize("method", [FE, FD], ids=["fe", "fd"])
def test_new_mobility_equals_rescaled_beta(method):
    """beta div(d^3/eta grad p) is the equation with beta/eta: same run to round-off."""
    a = femehl.solve(
        paper_like(HalfSpace(), beta=200.0), **method, **RUN, terms=[Poiseuille(mobility=Viscous(2.0))]
    )
    b = femehl.solve(paper_like(HalfSpace(), beta=100.0), **method, **RUN)
    assert a.info["terms"] == ["poiseuille", "squeeze", "couette"]
    assert_same_run(a, b, rtol=1e-9)


# ---- a new physics term: sliding along y --------------------------------------------------
@BilinearForm
def couette_y(d, q, w):
    """Couette flux along y of an element-constant film against dq/dy."""
    return d * q.grad[1]


class TransverseCouette:
    """``-Vy dd/dy``: the substrate sliding along -y under the indenter (FE weak form)."""

    name = "couette_y"

    def __init__(self, Vy):
        self.Vy = Vy

    @staticmethod
    def applies(scene, t_end=None):
        return True

    def setup(self, disc):
        self.disc = disc

    def film_operator(self):
        return asm(couette_y, self.disc.basis0, self.disc.basis).tocsr()[self.disc.free]

    def contribute(self, step):
        return Contribution(film_coefficient=self.Vy(step.t_new))


def test_new_term_sliding_along_y_is_sliding_along_x_rotated():
    """A sphere sliding along +y is the +x case rotated by 90 degrees.

    The full-disk mesh is not rotation invariant, so the two runs differ by the mesh's
    orientation error; measured at t = 2.5 (beta = 50, BDF2, dt = 0.05): load 6e-6 /
    2e-5, central film 2.7e-4 / 2.3e-4, minimum film 3.2e-3 / 5.0e-4 on coarse / medium
    (it shrinks with the mesh).  Asserted on coarse with ~3x margin.  The thinnest film
    sits in a side lobe at the exit: (x, y) ~ (-0.71, +-0.46) for x-sliding, so
    (+-0.46, -0.71) for y-sliding, within an element size (0.1 there).
    """
    velocity = TanhStart(1.0, 1.0)
    gap = RampHold(0.1, -0.5, 1.0)
    kw = dict(mesh="coarse", half=False, t_end=2.5, dt=0.05, scheme="bdf2", store_every=0)
    rx = femehl.solve(Scene(motion=Motion(gap=gap, velocity=velocity), fluid=Fluid(50.0)), **kw)
    ry = femehl.solve(
        Scene(motion=Motion(gap=gap, velocity=0.0), fluid=Fluid(50.0)),
        **kw,
        terms=[TransverseCouette(velocity)],
    )
    assert "couette_y" in ry.info["terms"]
    for name, tol in (("load", 5e-5), ("film_center", 1e-3), ("film_min", 1e-2)):
        assert ry.value_at(name, 2.5) == pytest.approx(rx.value_at(name, 2.5), rel=tol), name
    sx, sy = rx.summary(), ry.summary()
    assert abs(sy["film_min_y"][-1] - sx["film_min_x"][-1]) < 0.1  # exit at y < 0
    assert abs(abs(sy["film_min_x"][-1]) - abs(sx["film_min_y"][-1])) < 0.1
    # without the term the y run is pure indentation: its pressure stays symmetric in y
    assert abs(sx["film_min_y"][-1]) > 0.3 and sy["film_min_y"][-1] < -0.5


# ---- the registries ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "name", sorted(femehl.solver.linsolve.LINEAR_SOLVERS) if hasattr(femehl, "core") else ["lu", "gmres"]
)
def test_every_linear_solver_solves_the_paper_step(name):
    """Every registered linear solver gives the direct solve's films (rtol 1e-10 per step)."""
    sc = femehl.presets.paper_sphere()
    opts = {} if name == "lu" else {"rtol": 1e-10}
    a = femehl.solve(sc, mesh="coarse", t_end=1.2, dt=0.04, store_every=10, linear_solver=name, **opts)
    b = femehl.solve(sc, mesh="coarse", t_end=1.2, dt=0.04, store_every=10, linear_solver="lu")
    assert_same_run(a, b, rtol=1e-7)


def test_terms_must_have_distinct_names():
    with pytest.raises(femehl.SceneError, match="distinct"):
        femehl.make_stepper(femehl.presets.paper_sphere(), mesh="coarse", terms=[Poiseuille(), Poiseuille()])


def test_registered_substrate_is_a_scene_file_kind(tmp_path, monkeypatch):
    """A substrate registered from outside femehl is a ``[substrate] kind`` of TOML files."""
    from femehl.elastic import SUBSTRATES
    from femehl.problem.scenefile import load_scene_file

    monkeypatch.setitem(SUBSTRATES, SeriesSprings.kind, SeriesSprings)
    path = tmp_path / "springs.toml"
    path.write_text('[substrate]\nkind = "series_springs"\nk1 = 8.0\nk2 = 4.0\n[fluid]\nbeta = 200.0\n')
    scene, _ = load_scene_file(path)
    assert scene.substrate == SeriesSprings(8.0, 4.0)
