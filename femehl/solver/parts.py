"""What takes part in a step beside the terms: the motion's unknown hc, a substrate's memory,
a cavitation condition.  The protocol and the step's order: docs/design.md section 8."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femehl.errors import SingularSystemError

__all__ = ["StepPart", "Solved", "GapControl", "ImposedGap", "ImposedLoad", "FreeIndenter", "gap_control"]


class StepPart:
    """A part of every step with variables of its own (``state.own``); every hook optional.

    In the step's order: :meth:`initial` (its variables at t = 0), :meth:`lagged` (the
    pressure the lagged coefficients use), :meth:`film` (a change of the step's film
    ``d = h + offset + scale C p``: a memory), :meth:`rows` (rows held or unknowns added
    to the step's system), :meth:`finish` (its variables after the step).

    Two optional hooks, for a part that changes the terms themselves (a rough surface,
    :class:`femehl.problem.roughness.AsperityContact`): ``context(stepper, state, ctx)``
    returns the terms' lagged context changed (a rough film's mean gap), and
    ``operator(stepper, ctx, D, G)`` returns ``[(F, rhs), ...]``, sparse film operators on
    the step's ``d^{k+1}`` (coefficient 1) and right-hand sides added to the terms' (``D``
    their matrix, ``G`` their film operators summed).  A part that carries a share of the
    pressure unknowns has two more: ``solid_pressure(state)``, that share (the film's
    pressure is the rest: :meth:`LaggedStepper.film_pressure`), and
    ``held_rows(stepper, ctx, held)``, ``(F, rhs)`` that the rows ``held`` at ``p = 0`` (a
    cavitated node) add so that they hold the film's pressure.  A part that changes the film
    says how the substrate takes a load put on at t = 0: ``rest_film(stepper)``, the film
    change of :meth:`film` for it (:meth:`LaggedStepper.at_rest`).
    """

    def initial(self, stepper, state):
        return state

    def lagged(self, state, free_index):
        return None

    def film(self, stepper, state, t_new: float, dt: float):
        return None

    def rows(self, stepper, system, rhs_list, state, ctx):
        return system, rhs_list, None

    def finish(self, stepper, solved: Solved, new):
        return new


@dataclass(frozen=True)
class Solved:
    """What a step solved, handed to each part's :meth:`StepPart.finish`."""

    state: object  # the state the step started from
    ctx: object  # the terms' StepContext
    op: object  # the step's StepOperator, no row held
    rhs: np.ndarray  # its right-hand side without the -G h part
    p: np.ndarray  # the pressure unknowns
    Cp: np.ndarray  # C p on the film points
    unknowns: np.ndarray  # the parts' own unknowns, after the pressure
    aux: object  # what the part's rows() returned as aux
    film: object  # the step's film change (a memory's) or None
    scale: float  # the factor op.G carries (the film's scale)


# ---- the motion's unknown: hc ------------------------------------------------------------
class GapControl(StepPart):
    """How the step gets ``hc``: the right-hand sides it adds and how it closes the solve."""

    def rhs(self, stepper, rhs, G, shape, t_new) -> list:
        raise NotImplementedError

    def close(self, stepper, solutions, state, t_new, dt, ctx):
        """``(x, Cp, hc, own)`` from the solver's ``[(x, Cp), ...]``: the solution, C p, hc
        and the control's own variables after the step."""
        raise NotImplementedError

    def rest_load(self, stepper, t):
        """The load a state at rest at ``t`` carries, or None where hc is given (a gap, or
        a free indenter's position)."""
        return None

    def rest(self, stepper, solutions, state):
        """``(x, Cp, hc)`` of a state at rest (:meth:`LaggedStepper.at_rest`) from the
        solutions for :meth:`rhs`'s right-hand sides."""
        raise NotImplementedError


class ImposedGap(GapControl):
    """``hc(t)`` given: one right-hand side."""

    def rhs(self, stepper, rhs, G, shape, t_new):
        return [rhs - G @ (stepper.scene.motion.hc(t_new) + shape)]

    def close(self, stepper, solutions, state, t_new, dt, ctx):
        ((x, Cp),) = solutions
        return x, Cp, stepper.scene.motion.hc(t_new), {}

    def rest(self, stepper, solutions, state):
        ((x, Cp),) = solutions
        return x, Cp, state.hc


class ImposedLoad(GapControl):
    """``F(t)`` given, ``hc`` one more unknown.  The right-hand side is affine in hc
    (``h = hc + s``): the step's system is ``A p + hc G 1 = b(s)`` with the load row
    ``-g . p + c hc = f`` (:meth:`border`; here ``g . p = F``).  The linear solver takes it
    bordered, one solve (:class:`~femehl.solver.linsolve.BorderedOperator`), where it can;
    otherwise from ``A x1 = b(s)`` and ``A x2 = G 1``: ``p = x1 - hc x2`` and
    ``hc = (f + g . x1) / (c + g . x2)`` (:meth:`hc`)."""

    def rhs(self, stepper, rhs, G, shape, t_new):
        return [rhs - G @ shape, G @ np.ones(shape.size)]

    def border(self, stepper, state, t_new, dt, ctx) -> tuple:
        """``(c, f)`` of the step's load row ``-g . p + c hc = f``."""
        return 0.0, -float(stepper.scene.motion.F(t_new))

    def after(self, stepper, state, hc, t_new, dt, ctx) -> dict:
        """The control's own variables after a step to ``hc``."""
        return {}

    def close(self, stepper, solutions, state, t_new, dt, ctx):
        hc, own = self.hc(stepper, state, t_new, dt, ctx, *self._loads(stepper, solutions))
        return (*self._combined(solutions, hc), hc, own)

    def rest_load(self, stepper, t):
        return stepper.scene.motion.F(t)

    def rest(self, stepper, solutions, state):
        """At rest the load row holds ``F(t)``, hc from it as in a step; where
        :meth:`rest_load` is None (a free indenter's position), hc as ``state`` has it."""
        hc = state.hc
        if self.rest_load(stepper, state.t) is not None:
            hc = self.hc(stepper, state, state.t, 0.0, None, *self._loads(stepper, solutions))[0]
        return (*self._combined(solutions, hc), hc)

    @staticmethod
    def _loads(stepper, solutions) -> tuple:
        """``(g . x1, g . x2)``: the loads of the two solutions (a part's own unknowns follow
        the pressure)."""
        n = stepper.disc.n
        return tuple(float(stepper.g @ x[:n]) for x, _ in solutions)

    @staticmethod
    def _combined(solutions, hc) -> tuple:
        """``(p, C p)`` of the solution at ``hc``: ``x1 - hc x2`` (C p None if not tracked)."""
        (x1, cx1), (x2, cx2) = solutions
        return x1 - hc * x2, (None if cx1 is None or cx2 is None else cx1 - hc * cx2)

    def hc(self, stepper, state, t_new, dt, ctx, g1, g2) -> tuple:
        """``(hc, own)`` from the loads ``g . x1``, ``g . x2`` of the two solutions: the load
        row ``-(g1 - hc g2) + c hc = f``."""
        c, f = self.border(stepper, state, t_new, dt, ctx)
        den = c + g2
        if not np.isfinite(den) or den == 0.0:
            raise SingularSystemError(
                f"step at t = {t_new:.6g}: the load row is singular (the film does not respond to hc).",
                t=t_new,
            )
        hc = (f + g1) / den
        return hc, self.after(stepper, state, hc, t_new, dt, ctx)


class FreeIndenter(ImposedLoad):
    """``m hc'' = load - force``: hc from Newton's row (own variables ``hc_dot``, and
    ``hc_prev``, ``hc_dot_prev`` for BDF2)."""

    def initial(self, stepper, state):
        return state.with_own(hc_dot=stepper.scene.motion.hc_dot0)

    def rest_load(self, stepper, t):
        return None  # its position hc(0) is an initial condition: it starts where it is

    @staticmethod
    def _history(stepper, state, ctx) -> tuple:
        """``(a0, a1 hc - a2 hc_prev, a1 v - a2 v_prev, v)`` of the step's scheme (the
        one-step scheme at the first step, or after a restart without history)."""
        mo = stepper.scene.motion
        a0, a1, a2 = ctx.a0, ctx.a1, ctx.a2
        own = state.own
        v = own.get("hc_dot", mo.hc_dot0)
        if a2 != 0.0 and "hc_prev" in own and "hc_dot_prev" in own:
            return a0, a1 * state.hc - a2 * own["hc_prev"], a1 * v - a2 * own["hc_dot_prev"], v
        return 1.0, state.hc, v, v

    def border(self, stepper, state, t_new, dt, ctx) -> tuple:
        """Newton's row by the step's own scheme (BDF2 with its variable-step coefficients,
        or Euler) on hc and v = hc'::

            a0 hc' - (a1 hc - a2 hc_prev) = dt v',   m (a0 v' - (a1 v - a2 v_prev)) = dt f',

        ``f' = g . p' - force(t')``: eliminating v', ``-g . p' + (m a0^2 / dt^2) hc' =
        (m / dt^2) (a0 h_hist + dt v_hist) - force(t')``.  L-stable: a small mass tends to
        the imposed-load step (``g . p' = force`` at m = 0)."""
        mo = stepper.scene.motion
        a0, h_hist, v_hist, _ = self._history(stepper, state, ctx)
        m = mo.mass
        c = m * a0 * a0 / (dt * dt)
        return c, (m / (dt * dt)) * (a0 * h_hist + dt * v_hist) - float(mo.applied_force(t_new))

    def after(self, stepper, state, hc, t_new, dt, ctx) -> dict:
        a0, h_hist, _, v = self._history(stepper, state, ctx)
        return {"hc_dot": (a0 * hc - h_hist) / dt, "hc_prev": state.hc, "hc_dot_prev": v}


def gap_control(motion) -> GapControl:
    """The motion's: a free indenter, an imposed load, or an imposed gap."""
    if motion.free:
        return FreeIndenter()
    return ImposedLoad() if motion.solves_hc else ImposedGap()
