"""The default path on every substrate and control: ``femehl.solve(scene, t_end, tol)`` with
nothing else given (the automatic mode) runs each built-in substrate and one written here,
under an imposed gap and an imposed load, and agrees with an expert run on another
discretization (the ladder's ``fine`` mesh, BDF2 at a fixed dt) within the requested
tolerance plus the expert run's own estimated error.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import femehl
from femehl import HalfSpace, Layer, Motion, RampHold, Rigid, Viscoelastic, Winkler

TOL = 5e-2
T_END = 0.4


@dataclasses.dataclass(frozen=True)
class SeriesSprings:
    """A substrate written here: two Winkler springs in series (``k1 k2 / (k1 + k2)``)."""

    k1: float
    k2: float
    kind = "series_springs_auto"
    local = True

    def compliance_operator(self, disc):
        return (disc.average() * (1.0 / self.k1 + 1.0 / self.k2)).tocsr()

    def deflection_rows(self, disc, points):
        return (disc.pressure_rows(points) * (1.0 / self.k1 + 1.0 / self.k2)).tocsr()

    def dry_contact(self, shape):
        from femehl.elastic.contact import overlap_contact

        return overlap_contact(shape, 1.0 / (1.0 / self.k1 + 1.0 / self.k2), "the series springs")


SUBSTRATES = {
    "halfspace": HalfSpace(),
    "layer": Layer(thickness=1.0),
    "winkler": Winkler(1.0),
    "viscoelastic": Viscoelastic(G0=2.0, tau=1.0),
    "rigid": Rigid(),
    "series": SeriesSprings(2.0, 2.0),
}
#: an indentation (imposed gap) and an imposed load, both ramped over the run
CONTROLS = {
    "gap": Motion(gap=RampHold(0.1, -0.1, T_END)),
    "load": Motion(gap=0.1, load=RampHold(0.0, 0.05, T_END)),
}
#: a rigid substrate cannot be indented: its gap closes to a thin film, not below 0
RIGID_GAP = Motion(gap=RampHold(0.1, 0.05, T_END))


def scene(sub, control):
    motion = RIGID_GAP if (sub == "rigid" and control == "gap") else CONTROLS[control]
    return dataclasses.replace(femehl.presets.paper_sphere(), substrate=SUBSTRATES[sub], motion=motion)


CASES = [(s, c) for s in SUBSTRATES for c in CONTROLS if not (s == "rigid" and c == "load")]


@pytest.mark.parametrize(("sub", "control"), CASES, ids=[f"{s}-{c}" for s, c in CASES])
def test_automatic_mode_runs_every_substrate_and_control(sub, control):
    sc = scene(sub, control)
    auto = femehl.solve(sc, t_end=T_END, tol=TOL)
    a = auto.info["auto"]
    assert a["reached"], a
    assert len(a["levels"]) >= 2 and a["adapted_at"] == a["levels"][0]  # the first, then adapted
    ref = femehl.solve(sc, t_end=T_END, dt=0.005, mesh="fine", scheme="bdf2")
    # the quantity the control leaves free: the load under a gap, the films under a load
    names = ("load", "film_center") if control == "gap" else ("film_center", "film_min")
    for name in names:
        got, want = auto.value_at(name, T_END), ref.value_at(name, T_END)
        u = ref.uncertainty(name, T_END)["total"]
        ref_err = u if u is not None else 0.0
        assert abs(got - want) <= (TOL + ref_err) * abs(want), (name, got, want, ref_err)
    if control == "load":  # the imposed load is met at every step
        assert np.allclose(auto.load, [sc.motion.F(t) for t in auto.t], rtol=1e-9, atol=1e-12)


def test_substrate_written_here_equals_the_builtin_in_automatic_mode():
    """Springs in series (k = 1) and ``Winkler(1)``: the same choices and the same answer."""
    a = femehl.solve(scene("series", "gap"), t_end=T_END, tol=TOL)
    b = femehl.solve(scene("winkler", "gap"), t_end=T_END, tol=TOL)
    assert a.info["auto"]["elements"] == b.info["auto"]["elements"]
    assert np.allclose(a.load, b.load, rtol=1e-8, atol=1e-12)
