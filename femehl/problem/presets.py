"""Named scenes.  ``paper_sphere`` is the problem of Wu, Hui et al. 2022, Eq. 12."""

from __future__ import annotations

from femehl.problem.scene import Domain, Fluid, HalfSpace, Motion, RampHold, Scene, Sphere, TanhStart
from femehl.validation import check_positive

__all__ = ["paper_sphere"]


def paper_sphere(beta: float = 200.0, h0: float = 0.1, L: float = 2.0) -> Scene:
    """The paper's sphere: ramp indentation to hc = -1 at t = 1, then tanh sliding (Eq. 12).

    Parameters
    ----------
    beta : float, default: 200.0
        The paper's beta (Eq. 10e): inverse sliding speed and loading rate.
    h0 : float, default: 0.1
        Initial tip clearance (> 0; the paper's printed -0.1 is a sign slip,
        see docs/design.md, section 2).
    L : float, default: 2.0
        Domain radius.
    """
    check_positive("h0", h0, "The initial clearance must be a gap (the paper case uses h0 = 0.1).")
    return Scene(
        indenter=Sphere(1.0),
        substrate=HalfSpace(0.5),
        fluid=Fluid(beta),
        motion=Motion(gap=RampHold(h0=h0, h_end=-1.0, t1=1.0), velocity=TanhStart(t1=1.0, T=1.0)),
        domain=Domain(L),
    )
