"""Line contact: a rigid cylinder sliding on a Winkler foundation (paper section 4).

:func:`LineScene` (a :class:`Cylinder`, or a rigid gap :class:`Profile` ``s(x)``, on a
Winkler foundation ``w = -p/k`` over a :class:`LineDomain`) is a scene like the 2-D ones,
with the same conventions: ``d = hc + s + p/k``, the cylinder sliding toward +x.  Its P1
finite-element step is ONE sparse linear system, under an imposed gap or load, with
backward Euler or BDF2.  The problem, the scheme and the imposed load: docs/design.md
section 4 ("Line contact"); the exact steady solution: :mod:`femehl.reference.line_steady`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from femehl.elastic import Viscoelastic, Winkler
from femehl.errors import SceneError
from femehl.problem.scene import (
    Constant,
    Fluid,
    Motion,
    RampHold,
    Scene,
    Table,
    TanhStart,
    _as_time_function,
    check_finite,
    check_positive,
)
from femehl.validation import check_shape_values

__all__ = ["Cylinder", "Profile", "LineDomain", "LineScene", "contact_halfwidth", "line_nodes"]


def _default_motion() -> Motion:
    return Motion(gap=RampHold(0.1, -0.5, 1.0), velocity=TanhStart(1.0, 1.0))


# --------------------------------------------------------------------------
# the line contact's indenters and domain
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class Cylinder:
    """A rigid cylinder along y (radius ``R``, normalized): the gap ``x^2 / (2 R)``."""

    R: float = 1.0
    dimension = 1

    def __post_init__(self):
        object.__setattr__(self, "R", check_positive("cylinder radius R", self.R))

    def line_gap(self, x) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        return 0.5 * x * x if self.R == 1.0 else 0.5 * x * x / self.R

    def gap(self, x, y=None) -> np.ndarray:
        return self.line_gap(x)


@dataclass(frozen=True)
class Profile:
    """A slider's rigid gap ``s(x)`` (line contact): a vectorized function of an array of x
    returning one finite value per point (a textured or inclined slider)."""

    s: Callable
    dimension = 1

    def __post_init__(self):
        if not callable(self.s):
            raise SceneError(
                f"LineScene(profile=...) must be a callable s(x) (the rigid gap), got "
                f"{type(self.s).__name__}: pass e.g. profile=lambda x: 0.5 * x**2, or None "
                "for the cylinder."
            )

    def line_gap(self, x) -> np.ndarray:
        """``s(x)`` as a new float array of x's shape (SceneError naming the fix)."""
        x = np.asarray(x, dtype=float)
        try:
            v = self.s(x)
        except SceneError:
            raise
        except Exception as exc:  # noqa: BLE001 - the user's code: say which function failed
            raise SceneError(
                f"LineScene profile s(x) raised {type(exc).__name__} on an array of x ({exc}): "
                "it must accept a numpy array and return one value per point (vectorize with numpy)."
            ) from None
        v = np.asarray(v)
        if v.shape != x.shape:
            raise SceneError(
                f"LineScene profile s(x) returned shape {v.shape} for x of shape {x.shape}: "
                "return one value per point (vectorize with numpy, e.g. 0 * x + c for a constant)."
            )
        return check_shape_values("LineScene profile s(x)", v, x.shape)

    def gap(self, x, y=None) -> np.ndarray:
        return self.line_gap(x)


@dataclass(frozen=True)
class LineDomain:
    """A line contact's domain ``[-L, L]`` (p = 0 at both ends); its method is ``"line"``."""

    L: float = 2.0
    dimension = 1
    default_method = "line"

    def __post_init__(self):
        object.__setattr__(
            self,
            "L",
            check_positive("domain half length L", self.L, "The domain is [-L, L]; L = 2 suits hc >= -0.5."),
        )

    def check(self, scene) -> None:
        """SceneError unless ``scene`` is a line contact this domain holds: a 1-D indenter on a
        local substrate, the film open at t = 0, a load that never pulls, the contact inside."""
        if getattr(scene.indenter, "dimension", 2) != 1:
            raise SceneError(
                f"a line contact's indenter is a femehl.line.Cylinder or a Profile(s), got "
                f"{type(scene.indenter).__name__}: use femehl.Domain for a 2-D indenter."
            )
        if not getattr(scene.substrate, "local", False):
            raise SceneError(
                f"line contact takes local substrates only (Winkler, a viscoelastic Winkler, rigid), "
                f"got {type(scene.substrate).__name__}: the plane-strain deflection of a half space "
                "is not modelled in 1-D."
            )
        motion = scene.motion
        motion.surface_speeds(0.0)
        if motion.load_controlled:
            times = np.union1d(np.linspace(0.0, 10.0, 201), getattr(motion.load, "times", ()))
            for t in times[times >= 0.0]:
                motion.F(t)  # refuses a negative (pulling) load up front, naming the time
        hc0 = motion.hc(0.0)
        xs = np.linspace(-self.L, self.L, 1001)
        s = scene.indenter.line_gap(xs)
        if not np.all(np.isfinite(s)):
            bad = xs[~np.isfinite(s)][0]
            raise SceneError(
                f"LineScene profile s(x) is not finite at x = {bad:.4g}: the rigid gap must be "
                f"finite on the whole domain [-{self.L:g}, {self.L:g}]."
            )
        i, low = int(np.argmin(s)), scene.lowest_initial_film
        if s[i] + hc0 <= low:
            if isinstance(scene.indenter, Cylinder):
                raise SceneError(
                    f"initial clearance hc(0) = {hc0:g} must be > {low:g}{scene._start_hint()}: with "
                    "p = 0 at t = 0 the film thickness d = hc + x^2/2 would be too low at x = 0. Start "
                    "with a larger gap and indent with a ramp, e.g. RampHold(h0=0.1, h_end=-0.5, t1=1.0)."
                )
            raise SceneError(
                f"initial film hc(0) + s(x) = {s[i] + hc0:g} <= {low:g}{scene._start_hint()} at x = "
                f"{xs[i]:.4g}: with p = 0 at t = 0 the film must be open everywhere on [-L, L]. Start "
                f"with hc(0) > {low - s[i]:g} (and indent with a ramp), or raise the profile."
            )
        a = contact_halfwidth(scene)
        if a is not None and self.L < 1.5 * a:
            raise SceneError(
                f"domain half length L = {self.L:g} is too small to hold the contact: the dry "
                f"contact of this run reaches |x| = {a:.3g}, and the pressure must decay "
                f"before x = +-L. Use L >= {1.5 * a:.3g}."
            )


def contact_halfwidth(scene) -> float | None:
    """Largest dry contact half width of a line contact's run, when it can be told: the
    cylinder's (a user profile: None), under a gap or load history whose extreme is known
    (RampHold, Table, Constant; other callables: None), from the substrate's own dry contact
    (:meth:`dry_contact` on :class:`femehl.elastic.contact.LineShape`)."""
    from femehl.elastic.contact import LineShape, _dry_contact

    if not isinstance(scene.indenter, Cylinder):
        return None
    motion = scene.motion
    history = motion.load if motion.load_controlled else motion.gap
    if isinstance(history, RampHold):
        values = (history.h0, history.h_end)
    elif isinstance(history, Table):
        values = tuple(history.values)
    elif isinstance(history, Constant):
        values = (history.value,)
    else:
        return None
    dry = _dry_contact(scene.substrate, LineShape(scene.indenter.R))
    if motion.load_controlled:
        F = max(0.0, max(values))
        if F == 0.0 or dry.load is None:
            return 0.0
        depth = dry.depth(F)
    else:
        depth = max(0.0, -min(values))
    return float(dry.axes(depth)[0]) if depth > 0.0 else 0.0


def LineScene(  # noqa: N802 - the line contact's scene, built as the 2-D one is
    k: float = 1.0,
    beta: float = 10.0,
    motion: Motion | None = None,
    L: float = 2.0,
    load=None,
    viscosity=None,
    cavitation: str | None = None,
    viscoelastic=None,
    profile: Callable | None = None,
    roughness=None,
) -> Scene:
    """A line contact: a :class:`femehl.Scene` with a :class:`LineDomain`, a rigid cylinder
    (or a ``profile``) on a Winkler foundation ``w = -p/k`` (normalized units, docs/design.md section 4).

    Parameters
    ----------
    k : float, default: 1.0
        Winkler stiffness, ``w = -p/k`` (> 0; a large k is a nearly rigid substrate).
    beta : float, default: 10.0
        The paper's film parameter multiplying ``d/dx(d^3 dp/dx)`` (> 0).
    motion : femehl.Motion, default: ramp 0.1 -> -0.5 for t <= 1, then tanh(t - 1) sliding
        Tip clearance hc(t), velocity V(t) and slide-to-roll ratio (the film entrained toward
        -x; by default the cylinder slides toward +x, its surface still).
        With an imposed load, ``motion.gap`` only gives the initial clearance hc(0).
    L : float, default: 2.0
        Half length of the domain ``[-L, L]``; p = 0 at both ends.
    load : callable or float or None, default: None
        Imposed load per unit length ``F(t) = int p dx``; None imposes the gap
        instead (``Motion(load=...)`` too; give one of them).
    viscosity, cavitation
        The fluid's (:class:`femehl.Fluid`).
    viscoelastic : femehl.Viscoelastic, optional
        A viscoelastic foundation relaxing the Winkler(k) (its ``elastic`` is replaced).
    profile : callable, optional
        The rigid gap ``s(x)`` of a slider (:class:`Profile`); None: the cylinder ``x^2/2``.
    roughness : femehl.Roughness, optional
        The surfaces' combined roughness and asperity contact (:class:`femehl.Scene`'s).
    """
    motion = _default_motion() if motion is None else motion
    if not isinstance(motion, Motion):
        raise SceneError(
            f"LineScene.motion must be a femehl.Motion, got {type(motion).__name__}: "
            "wrap the gap and velocity as Motion(gap=..., velocity=...)."
        )
    if load is not None:
        if motion.load is not None:
            raise SceneError("the load is imposed twice (LineScene.load and Motion.load): give only one.")
        load = _as_time_function("LineScene load F(t)", load)
        check_finite("load F(t=0)", load(0.0), "The load history must return finite values.")
        motion = dataclasses.replace(motion, load=load)
    k = check_positive("Winkler stiffness k", k, "Use a large k for a nearly rigid substrate.")
    beta = check_positive("beta", beta, "beta multiplies d/dx(d^3 dp/dx) in the normalized equation.")
    substrate = Winkler(k)
    if viscoelastic is not None:
        if not isinstance(viscoelastic, Viscoelastic):
            raise SceneError(
                f"LineScene(viscoelastic=...) must be a femehl.Viscoelastic(G0, tau), got "
                f"{type(viscoelastic).__name__}."
            )
        substrate = dataclasses.replace(viscoelastic, elastic=substrate)
    return Scene(
        indenter=Cylinder() if profile is None else Profile(profile),
        substrate=substrate,
        fluid=Fluid(beta, viscosity=viscosity, cavitation=cavitation),
        motion=motion,
        domain=LineDomain(L),
        roughness=roughness,
    )


# --------------------------------------------------------------------------
# mesh
# --------------------------------------------------------------------------
def line_nodes(L: float, n_elements: int, grading="uniform", fine: float | None = None):
    """Node coordinates of a 1-D mesh of ``[-L, L]`` with ``n_elements`` elements.

    Parameters
    ----------
    L : float
        Half length of the domain.
    n_elements : int
        Number of elements (>= 4).
    grading : "uniform", float or callable, default: "uniform"
        "uniform": equal elements.  A float ``r >= 1``: elements are ``r`` times
        smaller in ``|x| <= fine`` than near the ends, with a linear change of
        the node density over a width ``0.25 L`` outside that zone.  A callable
        ``rho(x) > 0``: node density (element size proportional to ``1/rho``).
        The nodes are the quantiles of the density, so doubling ``n_elements``
        halves every element (clean refinement studies).
    fine : float, optional
        Half width of the fine zone for a float ``grading``; default ``L/2``.

    Returns
    -------
    numpy.ndarray
        ``n_elements + 1`` increasing node coordinates, ``-L`` and ``L`` included.
    """
    L = check_positive("domain half length L", L)
    if isinstance(n_elements, bool) or not isinstance(n_elements, (int, np.integer)) or n_elements < 4:
        raise SceneError(f"n_elements must be an integer >= 4, got {n_elements!r}.")
    n = int(n_elements)
    if isinstance(grading, str):
        if grading != "uniform":
            raise SceneError(
                f"grading must be 'uniform', a size ratio >= 1 or a density function, got {grading!r}."
            )
        return np.linspace(-L, L, n + 1)
    if callable(grading):
        rho = grading
    else:
        r = check_finite(
            "grading (size ratio)", grading, "Give 'uniform', a ratio >= 1 or a density function rho(x)."
        )
        if r < 1.0:
            raise SceneError(f"grading ratio must be >= 1 (fine/coarse element size), got {r:g}.")
        xf = 0.5 * L if fine is None else check_positive("fine zone half width", fine)
        width = 0.25 * L

        def rho(x):
            u = np.clip((np.abs(x) - xf) / width, 0.0, 1.0)
            return r + (1.0 - r) * u

    xs = np.linspace(-L, L, 200 * n + 1)
    try:
        dens = np.asarray(rho(xs), dtype=float) * np.ones_like(xs)
    except Exception as exc:  # noqa: BLE001 - a user callable may fail any way
        raise SceneError(f"the grading density rho(x) failed on an array of x: {exc}") from None
    if not (np.all(np.isfinite(dens)) and np.all(dens > 0.0)):
        raise SceneError("the grading density rho(x) must be finite and > 0 on [-L, L].")
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (dens[1:] + dens[:-1]) * np.diff(xs))])
    x = np.interp(np.linspace(0.0, cum[-1], n + 1), cum, xs)
    x[0], x[-1] = -L, L
    return x
