"""Frozen descriptions of a soft-EHL problem: indenter, substrate, fluid, motion, domain.

Conventions (docs/design.md, sections 1-2; Wu, Hui et al., JMPS 2022, Eqs. 8, 10, 12)
-------------------------------------------------------------------------------------
Everything in a :class:`Scene` is in the paper's normalized variables::

    r = r*/sqrt(R h_inf)     t = V_ss t*/(2 sqrt(R h_inf))
    h, w, d = (.)*/h_inf     p = p*/(4 pi G sqrt(h_inf/R))
    beta = (2/3) (h_inf^2/R) (pi G)/(eta V_ss)

so the problem solved is::

    beta div(d^3 grad p) = -V(t) dd/dx + dd/dt          (Eq. 10a in Cartesian form)
    d = h - w,   h = hc(t) + s(x, y),   w = -c * int p/|x - x'| dA'     (Eq. 10b)

with ``c = 2 (1 - nu)`` (1 for the incompressible half space of the paper).
Signs: w < 0 under positive pressure; hc > 0 is a gap, hc < 0 an indentation;
the indenter slides toward +x, so in its frame the substrate moves toward -x,
the inlet is at +x and the exit constriction near x = -1.  (The paper's
Eq. 2c writes h = hc - r^2/2R, a sign slip; femehl uses + as in Eq. 12.)

:class:`Dimensional` converts SI inputs to a scene and back.
Scenes are immutable; validation happens at construction and raises
:class:`femehl.errors.SceneError` with a message that names the fix (the
validators live in :mod:`femehl.validation`; ``check_finite`` and
``check_positive`` are re-exported here).  A time history (gap, velocity,
load) that raises is reported as a SceneError naming the history and the time.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import ClassVar, Protocol, runtime_checkable

import numpy as np

from femehl.elastic import HalfSpace, Layer, Rigid, Winkler  # noqa: F401  (re-exported)
from femehl.errors import SceneError
from femehl.problem.indenters import (
    Sphere,  # indenters live in femehl.indenters; Sphere stays importable here
)

# the validators live in femehl.validation; re-exported here (other modules import them from scene)
from femehl.validation import _short, call_time_function, check_finite, check_positive, check_shape_values

__all__ = [
    "Constant",
    "Dimensional",
    "Domain",
    "Fluid",
    "HalfSpace",
    "Layer",
    "Motion",
    "RampHold",
    "Rigid",
    "Scene",
    "Sphere",
    "Table",
    "TanhStart",
    "TimeFunction",
    "Winkler",
    "check_finite",
    "check_positive",
]


# --------------------------------------------------------------------------
# time functions (gap history hc(t), sliding velocity V(t), imposed load F(t))
# --------------------------------------------------------------------------
@runtime_checkable
class TimeFunction(Protocol):
    """A scalar function of normalized time; ``f(t)`` returns a float."""

    def __call__(self, t: float) -> float: ...


@dataclass(frozen=True)
class Constant:
    """``f(t) = value`` for all t."""

    value: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "value", check_finite("Constant value", self.value))

    def __call__(self, t: float) -> float:
        return self.value

    @property
    def breakpoints(self) -> tuple:
        """Times where the function or its derivative jumps: none."""
        return ()


@dataclass(frozen=True)
class Table:
    """Piecewise-linear function through ``(times[i], values[i])``, constant outside.

    Parameters
    ----------
    times : sequence of float
        Strictly increasing sample times (at least one).
    values : sequence of float
        Values at those times, same length, finite.
    """

    times: tuple
    values: tuple

    def __post_init__(self):
        def numbers_of(seq, what):
            if isinstance(seq, (str, bytes)):
                raise SceneError(f"Table {what} must be a sequence of numbers, got {_short(seq)}.")
            try:
                items = np.asarray(seq, dtype=object).ravel().tolist()
            except (TypeError, ValueError):
                raise SceneError(f"Table {what} must be a sequence of numbers.") from None
            bad = [x for x in items if isinstance(x, (bool, np.bool_)) or not isinstance(x, numbers.Real)]
            if bad:
                raise SceneError(f"Table {what} must hold real numbers, got {_short(bad[0])}.")
            try:
                return np.array([float(x) for x in items], dtype=float)
            except OverflowError:
                raise SceneError(f"Table {what} hold a number too large for a float.") from None

        t = numbers_of(self.times, "times")
        v = numbers_of(self.values, "values")
        if t.size == 0:
            raise SceneError("Table is empty: give at least one (time, value) pair.")
        if t.size != v.size:
            raise SceneError(f"Table has {t.size} times but {v.size} values: give one value per time.")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
            raise SceneError("Table times and values must be finite (no NaN or inf).")
        if np.any(np.diff(t) <= 0):
            raise SceneError("Table times must be strictly increasing: sort the rows and remove duplicates.")
        object.__setattr__(self, "times", tuple(t.tolist()))
        object.__setattr__(self, "values", tuple(v.tolist()))

    def __call__(self, t: float) -> float:
        return float(np.interp(t, self.times, self.values))

    @property
    def breakpoints(self) -> tuple:
        """Times where the slope may jump: the sample times."""
        return tuple(self.times)


@dataclass(frozen=True)
class RampHold:
    """The paper's gap history (Eq. 12a): a linear ramp from ``h0`` to ``h_end`` then hold.

    ``hc(t) = h0 + (h_end - h0) t / t1`` for ``t <= t1``, ``hc = h_end`` after.
    """

    h0: float = 0.1
    h_end: float = -1.0
    t1: float = 1.0

    def __post_init__(self):
        object.__setattr__(self, "h0", check_finite("h0", self.h0))
        object.__setattr__(self, "h_end", check_finite("h_end", self.h_end))
        object.__setattr__(self, "t1", check_positive("t1 (end of the ramp)", self.t1))

    def __call__(self, t: float) -> float:
        s = min(max(t / self.t1, 0.0), 1.0)
        return self.h0 + (self.h_end - self.h0) * s

    @property
    def breakpoints(self) -> tuple:
        """Times where the slope jumps: the end of the ramp ``t1``."""
        return (self.t1,)


@dataclass(frozen=True)
class TanhStart:
    """The paper's sliding start (Eq. 5, 12c): ``V = V_ss tanh((t - t1)/T)`` for t >= t1, else 0."""

    t1: float = 1.0
    T: float = 1.0
    V_ss: float = 1.0

    def __post_init__(self):
        object.__setattr__(self, "t1", check_finite("t1 (start of sliding)", self.t1))
        object.__setattr__(self, "T", check_positive("T (sliding ramp time)", self.T))
        object.__setattr__(self, "V_ss", check_finite("V_ss", self.V_ss))

    def __call__(self, t: float) -> float:
        return 0.0 if t < self.t1 else self.V_ss * math.tanh((t - self.t1) / self.T)

    @property
    def breakpoints(self) -> tuple:
        """Times where the slope jumps: the start of sliding ``t1``."""
        return (self.t1,)


#: Accepted rise max(s) - min(s) of the indenter's gap across the domain (units of h_inf).
GAP_RISE = (1e-6, 1e6)
#: An indenter declaring symmetric_y must satisfy |s(x, -y) - s(x, y)| <= SYMMETRY_RTOL * scale,
#: scale = max(range of s, max |s|) on the domain (round-off of a symmetric shape passes).
SYMMETRY_RTOL = 1e-9

#: The domain must reach CONTACT_MARGIN times the geometric overlap radius a_geo of the
#: deepest indentation: 1.5/sqrt(2) ~ 1.06, i.e. L >= 1.5 a_Hertz for a sphere.
CONTACT_MARGIN = 1.5 / math.sqrt(2.0)


def _as_time_function(name: str, f) -> Callable[[float], float]:
    if isinstance(f, (int, float)) and not isinstance(f, bool):
        return Constant(f)
    if not callable(f):
        raise SceneError(f"{name} must be a number or a callable of time, got {type(f).__name__}.")
    return f


# --------------------------------------------------------------------------
# substrates
# --------------------------------------------------------------------------
# HalfSpace, Layer, Rigid, Winkler live in femehl.elastic (each owns its operator)


# --------------------------------------------------------------------------
# fluid, motion, domain, scene
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class Fluid:
    """The film's fluid, through the paper's ``beta`` (Eq. 10e) at the ambient viscosity.

    ``viscosity``: None (isoviscous, the paper's) or a pressure-viscosity model,
    :class:`femehl.Barus` or :class:`femehl.Roelands` (:mod:`femehl.problem.viscosity`), lagged one
    step in the Poiseuille flux.  ``cavitation``: None (full Sommerfeld, the paper's),
    ``"jfo"`` (mass-conserving: the film content carried through the cavity),
    ``"reynolds"`` (``p >= 0``) or ``"half-sommerfeld"`` (the full-Sommerfeld run with its
    negative pressures clipped in what is reported), see :mod:`femehl.problem.cavitation`.
    """

    beta: float = 200.0
    viscosity: object = field(default=None, metadata={"describe": "omit_default"})
    cavitation: str | None = field(default=None, metadata={"describe": "omit_default"})

    def __post_init__(self):
        from femehl.problem.cavitation import check_cavitation
        from femehl.problem.viscosity import check_viscosity

        check_cavitation(self.cavitation)

        object.__setattr__(
            self,
            "beta",
            check_positive(
                "beta",
                self.beta,
                "beta = (2/3)(h_inf^2/R)(pi G)/(eta V_ss); use Dimensional(...) to compute it.",
            ),
        )
        check_viscosity(self.viscosity)


@dataclass(frozen=True)
class Motion:
    """Tip clearance ``hc(t)``, surface velocities ``V(t)`` and ``slide_roll(t)`` (the film
    is entrained toward -x: in the paper the indenter slides toward +x).

    Parameters
    ----------
    gap : callable or float, default: RampHold()
        Tip clearance hc(t); hc > 0 is a gap, hc < 0 an indentation.
    velocity : callable or float, default: 0.0
        V(t): the sum of the two surfaces' speeds along -x in the contact's frame, in units
        of V_ss (twice the entrainment speed; the paper's sliding velocity, whose indenter
        surface is still).  The Reynolds equation's transport is ``V dd/dx``.
    slide_roll : callable or float, default: 2.0
        The slide-to-roll ratio SRR(t) = (u_substrate - u_indenter) / u_entrainment of the
        surfaces' speeds along -x: 2 is pure sliding of the substrate under an indenter
        whose surface is still (the paper), 0 pure rolling, -2 the indenter's surface
        sliding over a still substrate.  The substrate's surface moves at
        ``V (1 + SRR/2) / 2``, the indenter's at ``V (1 - SRR/2) / 2`` (units of V_ss): the
        first carries a viscoelastic substrate's memory, their difference ``V SRR / 2``
        shears the film (:meth:`surface_speeds`).
    load : callable or float, optional
        Imposed load F(t) = int p dA, >= 0 (the film cannot pull: a negative
        load at t = 0 or any sampled time is refused).  Then hc(t) is solved for at every step
        (one more unknown, one more row: the step stays one linear system) and
        ``gap`` only gives the initial clearance hc(0).
    mass : float, optional
        A *free* indenter of this (normalized) mass: hc(t) follows Newton's law
        ``mass hc'' = int p dA - force(t)`` (the film pushes it up, ``force`` down), as one
        more unknown and row of the same linear system.  ``gap`` gives hc(0).
    force : callable or float, default: 0 with ``mass``
        The applied force pressing the free indenter toward the substrate (gravity, a
        spring, a history); any sign.
    hc_dot0 : float, default: 0.0
        Initial velocity of the free indenter (negative: approaching, a drop).
    """

    gap: Callable[[float], float] = field(default_factory=RampHold)
    velocity: Callable[[float], float] = field(default_factory=Constant)
    load: Callable[[float], float] | None = None
    slide_roll: Callable[[float], float] = field(default=Constant(2.0), metadata={"describe": "omit_default"})
    mass: float | None = field(default=None, metadata={"describe": "omit_default"})
    force: Callable[[float], float] | None = field(default=None, metadata={"describe": "omit_default"})
    hc_dot0: float = field(default=0.0, metadata={"describe": "omit_default"})

    def __post_init__(self):
        object.__setattr__(self, "gap", _as_time_function("Motion gap hc(t)", self.gap))
        object.__setattr__(self, "velocity", _as_time_function("Motion velocity V(t)", self.velocity))
        object.__setattr__(
            self, "slide_roll", _as_time_function("Motion slide-to-roll ratio SRR(t)", self.slide_roll)
        )
        if self.load is not None:
            object.__setattr__(self, "load", _as_time_function("Motion load F(t)", self.load))
        if self.mass is None:
            if self.force is not None or self.hc_dot0 != 0.0:
                raise SceneError(
                    "force and hc_dot0 belong to a free indenter: give mass=... too (or load=... "
                    "for an indenter whose load the film carries at every instant)."
                )
            return
        if self.load is not None:
            raise SceneError(
                "give either load (the film carries it at every instant) or mass and force (a free "
                "indenter with inertia), not both."
            )
        object.__setattr__(
            self, "mass", check_positive("mass", self.mass, "The free indenter's normalized mass (> 0).")
        )
        object.__setattr__(self, "hc_dot0", check_finite("hc_dot0", self.hc_dot0, "An initial velocity."))
        force = 0.0 if self.force is None else self.force
        object.__setattr__(self, "force", _as_time_function("Motion force(t)", force))

    @property
    def free(self) -> bool:
        """True for a free indenter (hc(t) from Newton's law with ``mass`` and ``force``)."""
        return self.mass is not None

    @property
    def solves_hc(self) -> bool:
        """hc(t) is an unknown of each step: an imposed load or a free indenter."""
        return self.load is not None or self.mass is not None

    def applied_force(self, t: float) -> float:
        """The free indenter's applied force at ``t`` (finite)."""
        return call_time_function(
            "the force history force(t)",
            "force",
            self.force,
            t,
            "The force history must return finite values.",
        )

    @property
    def load_controlled(self) -> bool:
        """True when the load F(t) is imposed and hc(t) is an unknown (gap gives hc(0))."""
        return self.load is not None

    @property
    def breakpoints(self) -> tuple:
        """Sorted times where a history (or its slope) jumps: the ``breakpoints`` of the
        velocity and of the gap (or, under imposed load, of the load: the gap then only
        gives hc(0)).  A callable without a ``breakpoints`` attribute contributes none.
        Adaptive time stepping (:mod:`femehl.solver.adaptive`) lands on these times."""
        funcs = [
            self.velocity,
            self.slide_roll,
            self.load if self.load_controlled else (self.force if self.free else self.gap),
        ]
        times = set()
        for f in funcs:
            for t in getattr(f, "breakpoints", ()) or ():
                if isinstance(t, (int, float)) and math.isfinite(t):
                    times.add(float(t))
        return tuple(sorted(times))

    def F(self, t: float) -> float:
        """The imposed load F(t) (finite, >= 0: the lubricated contact cannot pull)."""
        F = call_time_function(
            "the load history F(t)", "F", self.load, t, "The load history must return finite values."
        )
        if F < 0.0:
            raise SceneError(_negative_load_message(F, t))
        return F

    def hc(self, t: float) -> float:
        return call_time_function(
            "the gap history hc(t)", "hc", self.gap, t, "The gap history must return finite values."
        )

    def V(self, t: float) -> float:
        return call_time_function(
            "the velocity history V(t)",
            "V",
            self.velocity,
            t,
            "The velocity history must return finite values.",
        )

    def SRR(self, t: float) -> float:
        """The slide-to-roll ratio at ``t`` (finite)."""
        return call_time_function(
            "the slide-to-roll ratio SRR(t)",
            "SRR",
            self.slide_roll,
            t,
            "The slide-to-roll ratio must return finite values (2: pure sliding, 0: pure rolling).",
        )

    def surface_speeds(self, t: float) -> tuple:
        """``(u_indenter, u_substrate)``: the two surfaces' speeds along -x at ``t`` in units
        of V_ss, ``V (1 -+ SRR/2) / 2``; their mean is the entrainment ``V/2``."""
        V, srr = self.V(t), self.SRR(t)
        return 0.5 * V * (1.0 - 0.5 * srr), 0.5 * V * (1.0 + 0.5 * srr)

    def substrate_speed(self, t: float) -> float:
        """The substrate's surface speed along -x at ``t`` (units of V_ss): its material, and
        a viscoelastic substrate's memory, moves at ``-2 substrate_speed`` in normalized
        lengths per normalized time (docs/design.md section 15)."""
        return self.surface_speeds(t)[1]


def _negative_load_message(F: float, t: float) -> str:
    return (
        f"the imposed load F(t={t:g}) = {F:g} is negative: the lubricated model cannot pull "
        "the indenter (the film would be in tension, i.e. cavitate). Give a load history "
        "with F(t) >= 0 at all times, or impose the gap hc(t) instead (Motion(gap=...))."
    )


@dataclass(frozen=True)
class Domain:
    """Computational disk ``r <= L`` (pressure vanishes on r = L); its method is ``"fe"``.

    A domain checks the scene it holds (:meth:`check`) and names the scene's default
    method; a line contact's is :class:`femehl.problem.line.LineDomain`.
    """

    L: float = 2.0
    dimension = 2
    default_method = "fe"

    def __post_init__(self):
        object.__setattr__(self, "L", check_positive("Domain radius L", self.L))

    def check(self, scene) -> None:
        """SceneError unless the disk holds ``scene``'s run (film open at t = 0, contact inside)."""
        hc0 = scene.motion.hc(0.0)
        scene.motion.surface_speeds(0.0)  # a velocity or SRR history that fails at t = 0 is refused now
        low = scene.lowest_initial_film
        if hc0 <= low:
            gap = "a positive gap" if low == 0.0 else f"a gap above {low:g}"
            raise SceneError(
                f"initial tip clearance hc(0) = h0 = {hc0:g} must be > {low:g}{scene._start_hint()}: "
                "with p = 0 at t = 0 the film thickness d = hc + s would be too low at the tip. "
                f"Start with {gap} (the paper case uses h0 = +0.1)."
            )
        scene._check_domain_holds_contact()


@dataclass(frozen=True)
class Scene:
    """Everything a solver needs to know about the physics, in normalized units."""

    indenter: Sphere = field(default_factory=Sphere)
    substrate: HalfSpace | Layer | Rigid | Winkler = field(default_factory=HalfSpace)
    fluid: Fluid = field(default_factory=Fluid)
    motion: Motion = field(default_factory=Motion)
    domain: Domain = field(default_factory=Domain)
    #: the surfaces' combined roughness and asperity contact (:class:`femehl.Roughness`);
    #: None: smooth surfaces, the film must stay open
    roughness: object = field(default=None, metadata={"describe": "omit_default"})

    @property
    def viscosity(self):
        """The fluid's pressure-viscosity model (None: isoviscous)."""
        return self.fluid.viscosity

    @property
    def cavitation(self):
        """The fluid's cavitation condition (None: full Sommerfeld)."""
        return self.fluid.cavitation

    def has_sliding(self, t_end: float, n: int = 2001) -> bool:
        ts = np.linspace(0.0, t_end, n)
        return any(self.motion.V(t) != 0.0 for t in ts)

    def has_squeeze(self, t_end: float, n: int = 2001) -> bool:
        if self.motion.solves_hc:
            return True
        ts = np.linspace(0.0, t_end, n)
        h = [self.motion.hc(t) for t in ts]
        return max(h) != min(h)

    def effects(self, t_end: float) -> dict:
        """The terms the solver must assemble for a run to ``t_end``."""
        return {
            "squeeze": self.has_squeeze(t_end),
            "sliding": self.has_sliding(t_end),
            "elasticity": self.substrate.kind,
            "imposed_load": self.motion.load_controlled,
            **({"free_indenter": True} if self.motion.free else {}),
        }

    @property
    def default_method(self) -> str:
        """The method ``femehl.solve`` uses when none is given: the domain's."""
        return self.domain.default_method

    def __post_init__(self):
        for name, cls in (("fluid", Fluid), ("motion", Motion)):
            if not isinstance(getattr(self, name), cls):
                raise SceneError(
                    f"Scene.{name} must be a {cls.__name__}, got {type(getattr(self, name)).__name__}."
                )
        if not (callable(getattr(self.domain, "check", None)) and hasattr(self.domain, "default_method")):
            raise SceneError(
                f"Scene.domain must be a femehl.Domain (a disk) or a femehl.line.LineDomain (line "
                f"contact), got {type(self.domain).__name__}."
            )
        if not hasattr(self.indenter, "gap"):
            raise SceneError("Scene.indenter must have a gap(x, y) method (e.g. Sphere()).")
        from femehl.problem.cavitation import check_cavitation_scene
        from femehl.problem.roughness import check_roughness

        check_roughness(self.roughness)
        self.domain.check(self)
        check_cavitation_scene(self)
        if self.roughness is not None:
            self.roughness.check_scene(self)

    @property
    def lowest_initial_film(self) -> float:
        """The initial film ``hc(0) + s`` must be above this: 0 (p = 0 at t = 0 on an open
        film), or with a roughness its lowest film (``-10 sigma``: the mean planes may
        overlap, the run starts on the asperities)."""
        return 0.0 if self.roughness is None else self.roughness.lowest_film

    def _start_hint(self) -> str:
        if self.roughness is None:
            return ""
        return f" (with this roughness: above {self.lowest_initial_film:g}, -10 sigma)"

    def _check_domain_holds_contact(self):
        """The domain must reach well past the largest contact of the run, for any indenter.

        The rule is ``L >= CONTACT_MARGIN * a_geo`` with ``a_geo`` the largest radius
        of the geometric overlap ``s < delta`` at the deepest indentation ``delta``
        (for a sphere ``sqrt(2)`` times the Hertz radius, so ``L >= 1.5 a_Hertz``):
        ``-min hc`` over ``t`` in [0, 10] (and every table time), or under an imposed
        load the depth at which the substrate's own dry contact carries the largest
        ``F(t)`` (:func:`femehl.elastic.contact.indentation`).

        Also checks that the indenter covers the domain (``check_domain(L)``
        of a height map), that its gap is one finite real value per point on
        the domain, that an analytic indenter's gap rises by ``GAP_RISE`` =
        (1e-6, 1e6) across the domain (a radius neither so large that the
        indenter is flat on the domain nor so small that its contact is a dot
        or its gap overflows), that an indenter declaring ``symmetric_y`` is
        symmetric in y on the domain, that the initial film ``hc(0) + s`` is
        positive everywhere, and that an imposed load is >= 0 at every
        sampled time (the lubricated model cannot pull).
        """
        L = self.domain.L
        ind = self.indenter
        check = getattr(ind, "check_domain", None)
        if callable(check):
            check(L)
        extent = float(getattr(ind, "extent", math.inf))
        rmax = min(1.5 * L, max(extent, L))
        nr, nth = 401, 96
        r = np.union1d(np.linspace(0.0, rmax, nr), [L])  # r = L is a sample
        nr = r.size
        half = bool(getattr(ind, "symmetric_y", False))
        th = np.linspace(0.0, math.pi if half else 2.0 * math.pi, nth + 1 if half else nth, endpoint=half)
        TH, RR = np.meshgrid(th, r, indexing="ij")  # (nth, nr)
        X, Y = RR * np.cos(TH), RR * np.sin(TH)
        inside = RR <= L
        s_in = self._sample_gap(X[inside], Y[inside])
        self._check_gap_rise(s_in)
        if half:
            self._check_symmetric_y(X[inside], Y[inside], s_in)
        S = np.full(X.shape, np.inf)
        S[inside] = s_in
        if (~inside).any():
            try:
                with np.errstate(all="ignore"):
                    s_out = np.asarray(ind.gap(X[~inside], Y[~inside]), dtype=float)
                if s_out.shape == X[~inside].shape:
                    # beyond the domain a non-finite gap counts as "no contact"
                    S[~inside] = np.where(np.isfinite(s_out), s_out, np.inf)
            except Exception:  # noqa: BLE001, S110 - beyond the domain a failing gap is "no contact"
                pass
        hc0 = self.motion.hc(0.0)
        dmin = hc0 + float(s_in.min())
        if dmin <= self.lowest_initial_film:
            raise SceneError(
                f"the initial film hc(0) + s(x, y) reaches {dmin:.3g} <= {self.lowest_initial_film:g}"
                f"{self._start_hint()} on the domain: the "
                f"indenter's gap has a minimum {float(s_in.min()):.3g} below its tip. Shift the "
                "shape so that s >= 0 with s(0, 0) = 0, or start with a larger gap hc(0)."
            )

        from femehl.elastic.contact import indentation, sample_shape

        shape = None
        times = self._check_times()
        if self.motion.load_controlled:
            Fs = []
            for t in times:
                try:
                    Ft = call_time_function(
                        "the load history F(t)",
                        "F",
                        self.motion.load,
                        t,
                        "The load history must return finite values.",
                    )
                except SceneError:
                    if t == 0.0:
                        raise
                    continue  # the run reports a failing load when it gets there
                if Ft < 0.0:
                    raise SceneError(_negative_load_message(Ft, t))
                Fs.append(Ft)
            F = max(Fs, default=0.0)
            shape = sample_shape(self) if F > 0.0 else None  # sampled once: depth and overlap
            depth = indentation(self, load=F, shape=shape)[2]
            what = (
                f"the largest imposed load |F| = {F:g} (sampled over t in [0, {times[-1]:g}]) "
                f"presses the indenter about {depth:.3g} deep (dry-contact estimate)"
            )
        else:
            hs = []
            for t in times:
                try:
                    hs.append(self.motion.hc(t))
                except SceneError:
                    continue
            hmin = min(hs, default=hc0)
            depth = -hmin
            what = f"an indentation hc = {hmin:g}"
        a = (shape or sample_shape(self)).overlap_radius(depth) if depth > 0.0 else 0.0
        need = CONTACT_MARGIN * a
        if L < need * (1.0 - 1e-9):  # the depth's bisection lands within 1e-15 above it
            raise SceneError(
                f"Domain radius L = {L:g} is too small to hold the contact: {what}, which the "
                f"indenter overlaps out to r = {a:.3g} (a contact of radius about {a / math.sqrt(2.0):.3g} "
                "for a sphere), "
                f"and the pressure must decay before r = L. Use L >= {need:.3g} (the paper uses "
                "L = 2a)" + (", and extend the height map to cover it." if math.isfinite(extent) else ".")
            )

    def _describe_indenter(self) -> str:
        name = getattr(self.indenter, "name", None)
        if isinstance(name, str):
            return f"the indenter {type(self.indenter).__name__} {name!r}"
        return f"the indenter {_short(self.indenter, 60)}"

    def _sample_gap(self, x, y) -> np.ndarray:
        """The indenter's gap on the points (x, y) of the domain: one finite real value per point."""
        L = self.domain.L
        what = f"{self._describe_indenter()}: gap(x, y) on the domain r <= {L:g}"
        try:
            with np.errstate(all="ignore"):
                raw = self.indenter.gap(x, y)
        except SceneError:
            raise
        except Exception as exc:  # noqa: BLE001 - the user's shape: name the failure
            raise SceneError(
                f"the indenter's gap(x, y) failed on the domain r <= {L:g} "
                f"({type(exc).__name__}: {exc}); fix the shape function."
            ) from None
        s = check_shape_values(what, raw, x.shape, "Fix the shape function.")
        bad = ~np.isfinite(s)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            if np.isinf(s[k]) and callable(getattr(self.indenter, "domain_hint", None)):
                raise SceneError(
                    f"{self._describe_indenter()} is too sharp for the domain r <= {L:g}: its gap "
                    f"overflows to inf at (x, y) = ({x[k]:.3g}, {y[k]:.3g}). {self._rise_hint()}"
                )
            cause = "overflows to inf" if np.isinf(s[k]) else "is NaN"
            raise SceneError(
                f"{what} {cause} at (x, y) = ({x[k]:.3g}, {y[k]:.3g}): it must return one finite value "
                f"per point. {self._rise_hint()}"
            )
        return s

    def _rise_hint(self) -> str:
        hint = getattr(self.indenter, "domain_hint", None)
        if callable(hint):
            return hint(self.domain.L, GAP_RISE)
        return (
            f"Rescale the shape so that its rise across the domain lies in "
            f"[{GAP_RISE[0]:g}, {GAP_RISE[1]:g}] (units of h_inf), or fix the shape function."
        )

    def _check_gap_rise(self, s) -> None:
        """An analytic indenter's gap must rise by GAP_RISE[0] .. GAP_RISE[1] across the domain.

        (Units of h_inf.)  Only indenters with a ``domain_hint`` (the radii of Sphere,
        Ellipsoid, FlatPunch) are checked: a height map or user shape may be a flat plate.

        Below: the indenter is flat on the domain (a huge radius, a punch face wider than
        the domain): no contact edge lies inside it and the pressure cannot decay before
        r = L.  Above: the contact is a dot far below any mesh size (a tiny radius) and
        the film d^3 spans more than 18 decades.
        """
        if not callable(getattr(self.indenter, "domain_hint", None)):
            return  # a height map or user shape is taken as given (it may be a flat plate)
        L = self.domain.L
        rise = float(np.max(s) - np.min(s))
        lo, hi = GAP_RISE
        if rise < lo:
            raise SceneError(
                f"{self._describe_indenter()} is flat on the domain r <= {L:g}: its gap rises only "
                f"{rise:.3g} (units of h_inf, less than {lo:g}), so the domain holds no contact "
                f"edge and the pressure cannot decay before r = L. {self._rise_hint()}"
            )
        if rise > hi:
            raise SceneError(
                f"{self._describe_indenter()} is too sharp for the domain r <= {L:g}: its gap rises "
                f"to {rise:.3g} (units of h_inf, more than {hi:g}), so the contact is a dot far "
                f"smaller than any mesh of the domain. {self._rise_hint()}"
            )

    def _check_symmetric_y(self, x, y, s) -> None:
        """An indenter that declares symmetric_y must have s(x, -y) = s(x, y) on the domain."""
        s_m = self._sample_gap(x, -y)
        tol = SYMMETRY_RTOL * max(float(np.ptp(s)), float(np.max(np.abs(s))), np.finfo(float).tiny)
        err = np.abs(s_m - s)
        if np.any(err > tol):
            k = int(np.argmax(err))
            raise SceneError(
                f"{self._describe_indenter()} declares symmetric_y=True, but its gap is not "
                f"symmetric in y on the domain r <= {self.domain.L:g}: s({x[k]:.3g}, {y[k]:.3g}) = "
                f"{s[k]:.6g} but s({x[k]:.3g}, {-y[k]:.3g}) = {s_m[k]:.6g}. Pass symmetric_y=False "
                "(the solver then uses the full disk), or make the shape symmetric."
            )

    def _check_times(self):
        """Times at which the gap / load histories are sampled by the domain check."""
        t_hi = 10.0
        extra = []
        for f in (self.motion.gap, self.motion.load):
            for attr in ("times",):
                extra.extend(getattr(f, attr, ()) or ())
            for attr in ("t1",):
                v = getattr(f, attr, None)
                if isinstance(v, (int, float)):
                    extra.append(float(v))
        extra = [t for t in extra if math.isfinite(t) and t >= 0.0]
        t_hi = max([t_hi] + extra)
        return np.unique(np.concatenate([np.linspace(0.0, t_hi, 1001), extra]))


# --------------------------------------------------------------------------
# SI <-> normalized
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class Dimensional:
    """A real experiment in SI units and the paper's scales (Eq. 8, 10e).

    Parameters
    ----------
    R : float
        Sphere radius [m].
    G : float
        Shear modulus of the substrate [Pa].
    eta : float
        Fluid viscosity [Pa s].
    V_ss : float
        Steady speed [m/s] (also sets the time scale): the sum of the two surfaces' speeds,
        twice the entrainment speed; in the paper's pure sliding, the sliding speed.
    h_inf : float
        Final indentation depth [m] (length scale of film and deflection).
    nu : float, default: 0.5
        Poisson ratio of the substrate.
    """

    R: float
    G: float
    eta: float
    V_ss: float
    h_inf: float
    nu: float = 0.5

    def __post_init__(self):
        for name in ("R", "G", "eta", "V_ss", "h_inf"):
            object.__setattr__(self, name, check_positive(f"{name} [SI]", getattr(self, name)))
        HalfSpace(self.nu)

    @property
    def beta(self) -> float:
        """beta = (2/3)(h_inf^2/R)(pi G)/(eta V_ss)   (Eq. 10e)."""
        return (2.0 / 3.0) * (self.h_inf**2 / self.R) * math.pi * self.G / (self.eta * self.V_ss)

    @property
    def length(self) -> float:
        """In-plane scale sqrt(R h_inf) [m] (the Hertz contact radius)."""
        return math.sqrt(self.R * self.h_inf)

    @property
    def height(self) -> float:
        """Film / deflection scale h_inf [m]."""
        return self.h_inf

    @property
    def time(self) -> float:
        """Time scale 2 sqrt(R h_inf)/V_ss [s]."""
        return 2.0 * self.length / self.V_ss

    @property
    def pressure(self) -> float:
        """Pressure scale 4 pi G sqrt(h_inf/R) [Pa]."""
        return 4.0 * math.pi * self.G * math.sqrt(self.h_inf / self.R)

    @property
    def force(self) -> float:
        """Load scale = pressure * length^2 [N]."""
        return self.pressure * self.length**2

    @property
    def velocity(self) -> float:
        return self.V_ss

    @property
    def area(self) -> float:
        """Area scale = length^2 [m^2] (a cavitated area)."""
        return self.length**2

    @property
    def volume_rate(self) -> float:
        """Volume per unit time = length^2 height / time [m^3/s] (a film flux integral)."""
        return self.length**2 * self.height / self.time

    @property
    def tangential_force(self) -> float:
        """Friction-force scale = pressure * height * length [N] (femehl.solver.energetics)."""
        return self.pressure * self.height * self.length

    @property
    def power(self) -> float:
        """Power scale = tangential force * V_ss [W] (femehl.solver.energetics)."""
        return self.tangential_force * self.V_ss

    @property
    def energy(self) -> float:
        """Energy scale = force * height [J] (a free indenter's budget, femehl.solver.energetics)."""
        return self.force * self.height

    @property
    def mass(self) -> float:
        """Mass scale of a free indenter = force * time^2 / height [kg] (Motion(mass=...))."""
        return self.force * self.time**2 / self.height

    @property
    def approach_speed(self) -> float:
        """Speed scale of the tip clearance, dhc/dt = height / time [m/s] (Motion(hc_dot0=...))."""
        return self.height / self.time

    #: the quantities :meth:`to_si` converts
    QUANTITIES: ClassVar[tuple] = (
        "tangential_force",
        "power",
        "energy",
        "mass",
        "approach_speed",
        "length",
        "height",
        "time",
        "pressure",
        "force",
        "velocity",
        "area",
        "volume_rate",
    )

    def to_si(self, quantity: str, value):
        """Multiply a normalized ``value`` by the scale of ``quantity``.

        ``quantity`` is one of :attr:`QUANTITIES`: length, height, time, pressure, force,
        velocity, area, volume_rate.
        """
        scales = {q: getattr(self, q) for q in self.QUANTITIES}
        if quantity not in scales:
            raise SceneError(f"unknown quantity {quantity!r}; choose one of {sorted(scales)}.")
        return np.asarray(value) * scales[quantity]

    def from_si(self, quantity: str, value):
        """Inverse of :meth:`to_si`."""
        return np.asarray(value) / self.to_si(quantity, 1.0)

    #: columns of :meth:`result_table` -> (normalized Result column, scale, SI unit)
    RESULT_COLUMNS: ClassVar[dict] = {
        "t": ("t", "time", "s"),
        "hc": ("hc", "height", "m"),
        "load": ("load", "force", "N"),
        "film_center": ("film_center", "height", "m"),
        "film_min": ("film_min", "height", "m"),
        "film_min_x": ("film_min_x", "length", "m"),
        "film_min_y": ("film_min_y", "length", "m"),
        "p_max": ("p_max", "pressure", "Pa"),
        "p_max_x": ("p_max_x", "length", "m"),
        "p_max_y": ("p_max_y", "length", "m"),
        # a cavitation condition's figures (only where the result has them)
        "load_full": ("load_full", "force", "N"),
        "cavitated_area": ("cavitated_area", "area", "m2"),
        "full_film_source": ("full_film_source", "volume_rate", "m3/s"),
        # the friction force and its parts (finite elements), a viscoelastic substrate's
        # energy budget, a free indenter's (femehl.solver.energetics)
        "friction": ("friction", "tangential_force", "N"),
        "shear_couette": ("shear_couette", "tangential_force", "N"),
        "shear_poiseuille": ("shear_poiseuille", "tangential_force", "N"),
        "pressure_drag": ("pressure_drag", "tangential_force", "N"),
        "side_force": ("side_force", "tangential_force", "N"),
        "dissipation_film": ("dissipation_film", "power", "W"),
        "power_sliding": ("power_sliding", "power", "W"),
        "elastic_energy": ("elastic_energy", "energy", "J"),
        # a rough surface's asperities (femehl.problem.roughness)
        "asperity_load": ("asperity_load", "force", "N"),
        "asperity_friction": ("asperity_friction", "tangential_force", "N"),
    }

    #: columns :meth:`result_table` derives from the others -> SI unit
    DERIVED_COLUMNS: ClassVar[dict] = {"friction_coefficient": "1", "asperity_share": "1"}

    def unit(self, column: str) -> str:
        """The SI unit of a column of :meth:`result_table`."""
        units = {**{k: v[2] for k, v in self.RESULT_COLUMNS.items()}, **self.DERIVED_COLUMNS}
        if column not in units:
            raise SceneError(f"no SI column {column!r}; the columns are {sorted(units)}.")
        return units[column]

    def result_table(self, result) -> dict:
        """The per-step table of a normalized ``result`` in SI units.

        Parameters
        ----------
        result : femehl.output.result.Result
            A run of the scene of this experiment (normalized units).

        Returns
        -------
        dict of numpy arrays
            ``t`` [s], ``hc`` [m], ``load`` [N], ``film_center`` [m], ``film_min`` [m],
            ``film_min_x``, ``film_min_y`` [m], ``p_max`` [Pa], ``p_max_x``,
            ``p_max_y`` [m], and a cavitation condition's ``load_full`` [N],
            ``cavitated_area`` [m^2], ``full_film_source`` [m^3/s], the friction force and
            its parts [N] where the result has them (the units are in
            :attr:`RESULT_COLUMNS`), and with the friction the friction coefficient
            ``friction_coefficient = friction / load`` (NaN while the load is 0); a rough
            surface's ``asperity_load``, ``asperity_friction`` [N] and ``asperity_share``.
        """
        s = result.summary()
        out = {
            name: np.asarray(self.to_si(scale, s[col]), dtype=float)
            for name, (col, scale, _unit) in self.RESULT_COLUMNS.items()
            if col in s
        }
        if "friction" in out:  # the friction coefficient, undefined (NaN) where nothing is carried
            with np.errstate(divide="ignore", invalid="ignore"):
                out["friction_coefficient"] = np.where(
                    out["load"] > 0.0, out["friction"] / out["load"], np.nan
                )
        if "asperity_load" in out:  # the asperities' share of the load
            with np.errstate(divide="ignore", invalid="ignore"):
                out["asperity_share"] = np.where(
                    out["load"] > 0.0, out["asperity_load"] / out["load"], np.nan
                )
        return out

    @property
    def aspect(self) -> float:
        """``sqrt(h_inf/R)``: the height scale over the length scale."""
        return math.sqrt(self.h_inf / self.R)

    def roughness(self, rms, density, radius, summit_rms=None, friction=0.0):
        """A Greenwood-Tripp :class:`femehl.Roughness` from the surfaces' statistics [SI].

        ``rms`` the combined rms roughness sigma* [m], ``density`` the asperity density n_a
        [1/m^2], ``radius`` the asperities' radius beta_a [m], ``summit_rms`` the rms of
        their summits' heights sigma_s [m] (default ``rms``), ``friction`` their boundary
        friction coefficient. Greenwood & Tripp (1970)::

            p_a = (8 sqrt(2)/15) pi (n_a beta_a sigma_s)^2 sqrt(sigma_s/beta_a) E' F_{5/2}(d/sigma*)

        with ``E' = 2 G/(1 - nu)`` the substrate's plane-strain modulus (the indenter rigid).
        """
        from femehl.problem.roughness import Roughness

        rms = check_positive("[si] roughness_rms [m]", rms, "the combined rms roughness of both surfaces")
        n_a = check_positive("[si] asperity_density [1/m2]", density, "asperities per square metre")
        b_a = check_positive("[si] asperity_radius [m]", radius, "the asperities' summit radius")
        s_s = rms if summit_rms is None else check_positive("[si] summit_rms [m]", summit_rms)
        e_prime = 2.0 * self.G / (1.0 - self.nu)
        k_si = (
            (8.0 * math.sqrt(2.0) / 15.0) * math.pi * (n_a * b_a * s_s) ** 2 * math.sqrt(s_s / b_a) * e_prime
        )
        return Roughness(rms / self.h_inf, k_si / self.pressure, friction=friction, aspect=self.aspect)

    def scene(self, h0: float, t1: float | None = None, T: float | None = None, L: float = 2.0) -> Scene:
        """The paper's ramp-hold-slide experiment for these SI values.

        Parameters
        ----------
        h0 : float
            Initial clearance [m] (> 0).
        t1 : float, default: one time scale
            End of the indentation ramp and start of sliding [s].
        T : float, default: t1
            Sliding ramp time [s].
        L : float, default: 2.0
            Normalized domain radius.
        """
        h0 = check_positive("h0 [m] (initial clearance)", h0)
        t1n = 1.0 if t1 is None else check_positive("t1 [s]", t1) / self.time
        Tn = t1n if T is None else check_positive("T [s]", T) / self.time
        return Scene(
            indenter=Sphere(1.0),
            substrate=HalfSpace(self.nu),
            fluid=Fluid(self.beta),
            motion=Motion(gap=RampHold(h0 / self.h_inf, -1.0, t1n), velocity=TanhStart(t1n, Tn)),
            domain=Domain(L),
        )
