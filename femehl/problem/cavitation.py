"""Cavitation conditions: where the film cannot hold a pressure below ambient.

Three conditions are registered in :data:`CAVITATION_MODELS` (``Fluid(beta,
cavitation=name)``, ``LineScene(cavitation=name)``, ``[fluid] cavitation = name``):
``"jfo"`` (:class:`JFOCavitation`, mass-conserving), ``"reynolds"``
(:class:`ReynoldsCavitation`, ``p >= 0``) and ``"half-sommerfeld"`` (:class:`HalfSommerfeld`,
negative pressures clipped after the full-Sommerfeld step); without one a run is full
Sommerfeld.  Each keeps one linear system per step.  What each gets wrong, the schemes, a
model's interface and the validation: docs/design.md section 13.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from femehl.errors import SceneError
from femehl.registry import Registry

__all__ = [
    "CAVITATION_MODELS",
    "CAVITATION_COLUMNS",
    "HalfSommerfeld",
    "cavitation_columns",
    "clips_pressure",
    "ReynoldsCavitation",
    "cavitation_model",
    "check_cavitation",
    "check_cavitation_scene",
    "register_cavitation",
]

#: name -> cavitation model class (``Fluid(cavitation=name)``)
CAVITATION_MODELS = Registry("cavitation condition", key="name")
#: JFO and Reynolds: the adaptive steps' estimate leaves out the cells within this many rings
#: of a node that switched set (``settled_cells``).  On the paper case with JFO at
#: tol 1e-2, meshes adapted to its first run (5,900 cells): one ring (the switched node's
#: own cells) stalled at the step floor at t = 1.84, two went on to t = 2.57, three finished
#: (342 steps, 19 rejected, 31 s); on the fitted level 0.707, 911 steps (257 rejected)
#: with one ring, 379 (39) with two (2026-12-05); Reynolds on a rough PDMS ball at 1e-3 m/s
#: (coarse mesh, step_tol 1e-3) stalled at t = 1.09 without it, ran to t = 3 in 1,704 steps
#: with it (the set flickers where the asperities touch: there the film's flux has no sign)
SWITCH_RINGS = 3
#: Reynolds: a node keeps its side of the set while its ``y`` is within SET_BAND of the
#: largest ``|y|`` (the solve's round-off: ReynoldsCavitation.finish).  On the rough PDMS
#: ball in deep contact at 1.8e-8 m/s the median ``|y|`` was 1.5e-7 of the largest
SET_BAND = 1e-6
#: class decorator adding a cavitation model to :data:`CAVITATION_MODELS` under ``cls.name``
register_cavitation = CAVITATION_MODELS.register


def _switched(states) -> np.ndarray | None:
    """The free nodes that changed between full and cavitated over ``states`` (None: none)."""
    sets = [np.asarray(s.own["p_aux"]) < 0.0 for s in states if s.own.get("p_aux") is not None]
    if len(sets) < 2:
        return None
    changed = np.zeros(sets[0].size, dtype=bool)
    for later in sets[1:]:
        changed |= later != sets[0]
    return changed if changed.any() else None


def _set_switched(states) -> bool:
    """Whether the lagged set switched a node over ``states`` (for the adaptive steps' check
    of the lag's period-two mode, :func:`femehl.solver.adaptive._lag_mode`)."""
    return _switched(states) is not None


def _settled_cells(disc, states):
    """The cells more than :data:`SWITCH_RINGS` rings of cells away from every node that
    changed between full and cavitated over ``states`` (None: all of them), for the
    adaptive steps' error estimate: where the lagged set switches a node on the cavity's
    edge, the film around it jumps whatever the step."""
    changed, P = _switched(states), getattr(disc, "P", None)
    if changed is None or P is None:
        return None
    nodes = np.zeros(P.shape[1])
    nodes[disc.free_index] = changed
    near = np.asarray(P @ nodes).ravel() > 0.0
    for _ in range(SWITCH_RINGS - 1):  # the nodes of those cells, then their cells
        ring = (np.asarray(P.T @ near.astype(float)).ravel() > 0.0).astype(float)
        near = np.asarray(P @ ring).ravel() > 0.0
    return ~near


class _Model:
    """What the registered models share (docs/design.md section 13); a step part
    (:class:`femehl.solver.parts.StepPart`): its own variables ``p_aux`` (and JFO's ``gas``)."""

    name = ""
    changes_step = True
    clips_pressure = False  # the reported pressure is the solved one clipped at 0
    columns: tuple = ()
    note = ""
    field_data: dict = {}  # integer field data of the VTK series

    @staticmethod
    def check_scene(scene) -> None:
        """SceneError if the condition cannot be applied to ``scene``."""

    @staticmethod
    def fixed(state) -> np.ndarray:
        """Free-node indices held at p = 0 in the step after ``state`` (none by default)."""
        return np.zeros(0, dtype=np.int64)

    def setup(self, disc) -> None:
        """SceneError if the discretization cannot apply the condition; operators built once."""

    def initial_state(self, state):
        """The initial state with the condition's own fields (by default ``state``)."""
        return state

    # ---- its part in the step ------------------------------------------------------------
    def initial(self, stepper, state):
        state = dataclasses.replace(state, info={**state.info, **self.initial_info()})
        return self.initial_state(state)

    def lagged(self, state, free_index):
        return self.lagged_pressure(state, free_index)

    def film(self, stepper, state, t_new, dt):
        return None

    def rows(self, stepper, system, rhs_list, state, ctx):
        return self.prepare(stepper, system, rhs_list, state, ctx)

    def point_fields(self, disc, state) -> dict:
        """Nodal fields the VTK series writes for the condition (every mesh node)."""
        return {}

    def prepare(self, stepper, op, rhs_list, state, ctx):
        """The step's system: ``(operator, right-hand sides, aux)`` handed to the solver.

        By default the rows :meth:`fixed` are held at ``p = 0``
        (:meth:`~femehl.solver.linsolve.StepOperator.with_fixed`) and ``aux`` is those rows.
        A condition with unknowns of its own (JFO) returns a larger system whose solution
        has them after the pressure; :meth:`finish` gets them as ``unknowns``.
        """
        fixed = self.fixed(state)
        if fixed.size == 0:
            return op, rhs_list, fixed
        out = []
        for b in rhs_list:
            b = np.array(b, dtype=float)
            b[fixed] = 0.0
            out.append(b)
        return op.with_fixed(fixed), out, fixed

    @staticmethod
    def lagged_pressure(state, free_index) -> np.ndarray:
        """The pressure unknowns of ``state`` the next step's lagged coefficients use."""
        return np.asarray(state.p)[free_index]

    def initial_info(self) -> dict:
        """The columns' values at p = 0 (the initial state)."""
        return dict.fromkeys(self.columns, 0.0)

    @staticmethod
    def liquid_fraction(disc, state):
        """The liquid's share of each element's film, which the Couette shear acts on
        (:mod:`femehl.solver.energetics`); None: the whole film, as the Reynolds and
        half-Sommerfeld conditions say nothing of a cavity's content."""
        return None

    def finish(self, stepper, solved, new):
        """The state the step returns, from ``new`` (built from the solved pressure) and
        ``solved`` (:class:`femehl.solver.parts.Solved`: the operator without held rows, its
        right-hand side without the ``-G h`` part, ``A p - b = D p + G d - rhs``, the
        pressure, what :meth:`prepare` returned as ``aux``, the scale ``op.G`` carries, the
        condition's own unknowns after the pressure): ``new`` with the condition's
        ``p_aux``, ``info`` figures and, for a condition that reports otherwise, its
        reported fields."""
        raise NotImplementedError


@register_cavitation
class ReynoldsCavitation(_Model):
    """``p >= 0`` (Swift-Stieber), the cavitated set lagged one step.

    Each step adds to ``state.info``: ``cavitated_area`` (the area, or in line contact
    the length, of the nodes with ``y < 0``: ``sum_i g_i``, ``g`` the node weights of the
    load), ``p_negative_min`` (the lowest pressure off the held set: the one-step
    transient of a node joining it) and ``full_film_source``.

    **The full-film source.**  Each row ``i`` of the step is the weak form of the film's
    mass balance ``dd/dt + div J = 0`` (``J = -beta d^3 grad p - V d e_x``, normalized:
    the film taken as full of liquid) tested with the hat function ``phi_i``:
    ``r_i(p) = int phi_i dd/dt - int J . grad phi_i``, in flux units (normalized volume
    per unit time).  A held row is replaced by ``p_i = 0``, so there the balance is met
    only with a source: ``r_i(p) = lambda_i``, i.e. ``dd/dt + div J = s`` with
    ``int phi_i s = lambda_i``.  The volume per unit time the condition supplies is

        full_film_source = sum over the held nodes of lambda_i = sum_i (A p - b)_i

    over the whole plane (twice the half disk's sum).  Added to the free rows (residual 0
    to the solver's tolerance) it is the balance of the fields, ``d/dt int psi d +
    outflow - inflow`` through the rim (``psi = sum_free phi_i``, 1 but on the rim's
    elements), the check ``tests/test_cavitation.py`` makes.

    What it measures.  The cavitated region holds liquid and gas, and the balance above
    counts it as full.  Let the liquid there be carried by the sliding surface and conserved
    (as JFO has it: ``d(c)/dt + div(-V c e_x) = 0`` for the content ``c = theta d``, and
    ``theta = 1`` where the film ruptures).  Subtracting that from the full-film balance
    over the cavitated region splits the source into three parts:

        full_film_source = (liquid created where the film reforms)
                           + d/dt (gas volume of the cavity) + (gas flowing out through the rim).

    The rupture boundary adds nothing (``dp/dn = 0``, ``theta = 1``): there the Reynolds
    condition conserves mass.  At a steady state whose cavity closes inside the domain, the
    source is exactly the liquid the condition creates where the film reforms (no jump
    condition).  In the paper case the cavity behind the contact opens to the rim, and the
    source is mostly the gas leaving there.  It then depends on L and, to first order, on the
    size of the rim's elements, where the gap is steep.  Steady 1-D slider, the cavity open to
    the outlet: ``full_film_source = V (d(-L) - d_c)``, with ``d_c`` the film at rupture.
    That is the gap's Couette flux leaving minus the liquid's, and all of it is gas.
    """

    name = "reynolds"
    columns = ("cavitated_area", "full_film_source")
    settled_cells = staticmethod(_settled_cells)
    set_switched = staticmethod(_set_switched)
    note = (
        "Reynolds (Swift-Stieber): p >= 0, the cavitated set lagged one step; mass is "
        "conserved at rupture, not where the film reforms"
    )

    @staticmethod
    def fixed(state) -> np.ndarray:
        """Free-node indices held at p = 0 in the step after ``state``."""
        y = state.own.get("p_aux")
        if y is None:
            return np.zeros(0, dtype=np.int64)
        return np.flatnonzero(np.asarray(y) < 0.0)

    def finish(self, stepper, solved, new):
        """``p_aux = y``: ``p`` off the held set, ``-(A p - b)`` on it (the multiplier of the
        unmasked system): the next step's set is ``{y < 0}``, but a node whose ``y`` is
        within :data:`SET_BAND` of the largest ``|y|`` keeps its side (its ``y`` is set to
        that band, signed): where asperities carry the load the film's pressure is the
        solve's round-off, and its sign flipped hundreds of nodes a step.  Area, extremes and
        the mass source go to ``info``."""
        op, rhs, p, fixed, scale = solved.op, solved.rhs, solved.p, solved.aux, solved.scale
        y = np.array(stepper.film_pressure(new, p), dtype=float)
        info = dict(new.info)
        lam = np.zeros(0)
        if fixed.size:  # the residual of the held rows only
            lam = op.D[fixed] @ p + (op.G[fixed] @ new.d) / scale - rhs[fixed]
            y[fixed] = -lam
        held = np.zeros(y.size, dtype=bool)
        held[fixed] = True
        eps = SET_BAND * float(np.max(np.abs(y), initial=0.0))
        band = np.abs(y) <= eps
        y[band] = np.where(held[band], -eps, eps)
        g = stepper.g
        info["cavitated_area"] = float(g[y < 0.0].sum())
        free = np.ones(p.size, dtype=bool)
        free[fixed] = False
        info["p_negative_min"] = float(min(0.0, y[free].min())) if free.any() else 0.0
        info["full_film_source"] = _plane_factor(stepper.disc) * float(lam.sum())
        _mark_unsettled(solved, info)
        return dataclasses.replace(new, info=info).with_own(p_aux=y)


@register_cavitation
class HalfSommerfeld(_Model):
    """Half-Sommerfeld (Guembel): the full-Sommerfeld step, negative pressures clipped after it.

    ``state.p`` (and so the series, the maps, ``pressure_at``), ``state.load`` and
    ``state.p_max`` are those of ``max(p, 0)``; ``state.d`` and ``state.w`` (film and
    deflection) those of the full-Sommerfeld ``p``, which the next step uses
    (``state.p_aux``) -- the run is the full-Sommerfeld run, only reported otherwise.
    ``info["load_full"]`` is the full-Sommerfeld load ``g . p``, ``info["cavitated_area"]``
    the area of the clipped nodes ``sum g_i`` over ``p_i < 0``.

    Under an imposed load (or a free indenter) it is refused: the load row would have to
    balance either the full-Sommerfeld load (then the reported, clipped load would not be
    the load applied) or the clipped one (then film and deflection would no longer be
    those of a solution of any Reynolds equation).  A tribologist imposing a load wants the
    pressure that carries it: that is the Reynolds condition's.
    """

    name = "half-sommerfeld"
    changes_step = False
    clips_pressure = True
    columns = ("load_full", "cavitated_area")
    field_data = {"HalfSommerfeldClipped": 1}
    note = (
        "half-Sommerfeld: negative pressures clipped after the solve; the film and "
        "deflection are those of the full-Sommerfeld solution; mass is not conserved and "
        "the clipped field does not satisfy the Reynolds equation"
    )

    @staticmethod
    def check_scene(scene) -> None:
        motion = getattr(scene, "motion", None)
        if motion is not None and motion.solves_hc:
            what = "a free indenter (mass=...)" if motion.free else "an imposed load"
            raise SceneError(
                f'cavitation="half-sommerfeld" is a post-processing of an imposed-gap run; with '
                f"{what} the load balance would hold for the full-Sommerfeld pressure, not for the "
                'clipped one reported. Use cavitation="reynolds" (p >= 0 carries the load) or '
                "impose the gap (Motion(gap=...))."
            )

    @staticmethod
    def lagged_pressure(state, free_index) -> np.ndarray:
        """The full-Sommerfeld pressure (``p_aux``; the clipped ``p`` before the first step)."""
        y = state.own.get("p_aux")
        return np.asarray(state.p)[free_index] if y is None else np.asarray(y)

    def finish(self, stepper, solved, new):
        """Clip: ``p``, ``load``, ``p_max`` of ``max(p, 0)``; ``p_aux`` the full ``p``."""
        disc, p = stepper.disc, solved.p
        clipped = np.maximum(p, 0.0)
        p_full = disc.expand(clipped)
        i_max = int(np.argmax(p_full))
        info = dict(new.info)
        info["load_full"] = new.load
        info["cavitated_area"] = float(stepper.g[p < 0.0].sum())
        return dataclasses.replace(
            new,
            p=p_full,
            load=float(stepper.g @ clipped),
            p_max=float(p_full[i_max]),
            p_max_at=tuple(float(v) for v in disc.nodes[i_max]),
            info=info,
        ).with_own(p_aux=np.array(p, dtype=float))


@register_cavitation
class JFOCavitation(_Model):
    """Mass-conserving cavitation (Jakobsson-Floberg-Olsson, Elrod-Adams), one linear system per step.

    **Model.**  The film holds liquid and gas: its liquid content is ``c = theta d``
    (``0 <= theta <= 1`` the fractional filling), and the liquid is conserved everywhere,

        dc/dt + div J = 0,      J = -beta d^3 grad p - V c e_x,
        p >= 0,   theta <= 1,   p (1 - theta) = 0,

    full film (``theta = 1``, Reynolds) where ``p > 0``, cavitated (``p = 0``, the content
    carried at the entrainment velocity) where ``theta < 1``.  Flux continuity across a moving
    rupture or reformation front is part of the conservation law: rupture and
    reformation both conserve mass (the jump of ``theta`` at reformation is the JFO
    condition).

    **Unknowns.**  femehl writes the content as ``c = d - P v`` with ``v >= 0`` the *gas
    film* (gas volume per unit area, P1 on the nodes, ``P`` the element average; ``d`` on
    the elements as everywhere), so the content is linear in the unknowns and the step's
    rows are those of the full film minus a sparse operator on ``v``
    (:class:`femehl.discretize._p1p0.GasTransport`)::

        A p - B v = b - m (a1 v^k - a2 v^{k-1}) / dt,     B = V K - |V| D + (a0/dt) diag(m),

    (``K`` the Galerkin Couette operator of a P1 field, ``D`` its discrete upwinding,
    ``m`` the lumped mass: the gas is carried without new extrema).  At each node the
    unknown is ``p`` (full) or ``v`` (cavitated): on the cavitated set ``S``, ``p = 0``
    and ``v`` is solved for; off it ``v = 0``.  The step is ONE linear system
    (:class:`femehl.solver.linsolve.SwitchedOperator`), with the set lagged one step, like
    every other coefficient.  After the solve ``y = p`` off ``S`` and ``y = -(v + tol
    dbar)`` on it decide the next set, ``{y < 0}`` (``state.p_aux``): a full node whose
    pressure went negative ruptures, a cavitated node whose gas went negative beyond
    ``tol dbar`` (more liquid arrived than its cell's gap ``dbar`` holds, filling above
    ``1 + tol``, :attr:`REFORM_TOL` ``= 1e-3``) reforms.  The margin damps the switching
    of a node on the cavity's edge, where both ``p`` and ``v`` are about 0 (a period-2
    cycle of the lagged set on the paper case's fine mesh with a margin of 0, every 3 to 5
    steps with it, its negative pressure <= 5e-4 of the peak); it bounds the overfill of
    a cavitated node, which the liquid balance still counts.  The liquid is conserved by
    every step whatever the set (the rows are the mass balance of the solved content,
    including at the nodes that change), so the set's lag costs a one-step transient -- a
    pressure slightly below 0 at a node about to rupture (``info["p_negative_min"]``) or a
    filling slightly above 1 at one about to reform -- and never mass.

    **Reported per step** (``state.info``, summary columns; whole-plane figures):
    ``cavitated_area`` (``sum g_i`` over the next set), ``liquid_volume`` (the content
    ``sum_q int phi_q c`` over the free nodes), ``net_outflow`` (the liquid leaving
    through the rim minus the liquid entering, per unit time: the rows' flux part),
    ``mass_imbalance`` (the step's discrete mass balance ``d(liquid_volume)/dt +
    net_outflow`` by the scheme's own backward difference, relative to the size of its
    terms: the solver's residual, ~1e-8), ``theta_min`` (the lowest filling ``1 - v/dbar``
    at a cavitated node, ``dbar`` the mean gap of its cell; 1 without a cavity) and ``p_negative_min``.
    ``state.gas`` is the gas film on the free nodes; the series writes ``gas_film`` and
    ``film_content`` (``theta``) beside ``cavitated``.

    Needs a P1 discretization (FE disks, line contact); the polar finite-difference
    reference refuses it.  With no cavity the step is the full-Sommerfeld step (the
    switched set empty), to the solver's tolerance.
    """

    name = "jfo"
    #: a cavitated node reforms when its filling exceeds 1 by more than this
    REFORM_TOL = 1e-3
    columns = (
        "cavitated_area",
        "liquid_volume",
        "net_outflow",
        "mass_imbalance",
        "theta_min",
        "p_negative_min",
    )
    note = (
        "JFO (Jakobsson-Floberg-Olsson / Elrod-Adams): mass-conserving cavitation; p >= 0 and the "
        "film content theta carried through the cavity; rupture and reformation conserve mass; "
        "the full/cavitated set lagged one step"
    )

    def setup(self, disc) -> None:
        transport = getattr(disc, "gas_transport", None)
        if transport is None:
            raise SceneError(
                f'cavitation="jfo" needs a P1 pressure and film content (method "fe" or "line"); '
                f"the {getattr(disc, 'method', type(disc).__name__)!r} discretization has no "
                'gas transport. Use method="fe" (the finite-element disk) or cavitation="reynolds".'
            )
        self.transport = transport()
        self.squeeze = disc.squeeze()  # M[q, e] = int_e phi_q (free nodes x elements)
        self.content_weight = np.asarray(self.squeeze.sum(axis=0)).ravel()  # sum_q int_e phi_q
        self.plane = _plane_factor(disc)

    def initial_state(self, state):
        """No gas yet; the liquid volume is the whole gap's."""
        info = dict(state.info)
        info["liquid_volume"] = self.plane * float(self.content_weight @ state.d)
        return dataclasses.replace(state, info=info).with_own(gas=np.zeros(self.transport.n))

    @staticmethod
    def liquid_fraction(disc, state):
        """Each element's filling ``1 - (P v)/d`` (the gas film's element average over the gap)."""
        v = state.own.get("gas")
        if v is None:
            return None
        return np.clip(1.0 - np.asarray(disc.average() @ v).ravel() / np.asarray(state.d), 0.0, 1.0)

    def point_fields(self, disc, state) -> dict:
        """``gas_film`` (``v``) and ``film_content`` (``theta = 1 - v/dbar``, 1 where full)."""
        v = state.own.get("gas")
        if v is None:
            return {}
        dbar = (disc.squeeze() @ np.asarray(state.d)) / disc.node_weight[disc.free_index]
        theta = 1.0 - np.asarray(v) / dbar
        full = np.ones(disc.expand(v).size)
        full[disc.free_index] = theta
        return {"gas_film": disc.expand(v), "film_content": full}

    def initial_info(self) -> dict:
        info = dict.fromkeys(self.columns, 0.0)
        info["theta_min"] = 1.0
        return info

    settled_cells = staticmethod(_settled_cells)
    set_switched = staticmethod(_set_switched)

    def prepare(self, stepper, op, rhs_list, state, ctx):
        """The switched system: ``p`` or the gas ``v`` at each node, the set from ``state``."""
        from femehl.solver.linsolve import SwitchedOperator

        n = op.D.shape[0]
        y = state.own.get("p_aux")
        switched = np.zeros(n, dtype=bool) if y is None else np.asarray(y) < 0.0
        v = state.own.get("gas", np.zeros(n))
        v_prev = state.own.get("gas_prev", v)
        hist_v = ctx.a1 * v - ctx.a2 * v_prev
        tr = self.transport
        B = tr.operator(ctx.V, ctx.a0 / ctx.dt)
        m = tr.mass
        # the cavitated nodes' content carried upwind with their cell's mean gap (lagged film)
        corr = tr.correction(ctx.V, switched, ctx.d_lag, (self.squeeze @ ctx.d_lag) / m)
        zeros = np.zeros(n)
        out = [np.concatenate([rhs_list[0] - m * hist_v / ctx.dt - corr, zeros])]
        out += [np.concatenate([b, zeros]) for b in rhs_list[1:]]
        aux = {"switched": switched, "B": B, "hist_v": hist_v, "ctx": ctx, "gas": v, "corr": corr}
        return SwitchedOperator(op, B, switched), out, aux

    def finish(self, stepper, solved, new):
        """``p_aux = y`` (``p`` off the set, ``-v`` on it), ``gas = v``, the balance to ``info``."""
        op, rhs, p, fixed, scale, unknowns = (
            solved.op,
            solved.rhs,
            solved.p,
            solved.aux,
            solved.scale,
            solved.unknowns,
        )
        S = fixed["switched"]
        ctx = fixed["ctx"]
        v = np.where(S, np.asarray(unknowns, dtype=float), 0.0)
        m, w = self.transport.mass, self.content_weight
        d = new.d
        dbar = (self.squeeze @ d) / m  # the mean gap of each node's cell
        # the next set: full nodes whose pressure went negative, and the cavitated nodes
        # unless overfilled beyond REFORM_TOL (theta > 1 + REFORM_TOL: the film reforms)
        y = np.where(S, -(v + self.REFORM_TOL * dbar), p)
        # the content rows of the solved step: A p - B v - rhs + m hist_v / dt (~ 0)
        poiseuille_etc = op.D @ p
        film = (op.G @ d) / scale
        res = poiseuille_etc + film - fixed["B"] @ v + fixed["corr"] - rhs + m * fixed["hist_v"] / ctx.dt
        time_part = (w * (ctx.a0 * d - ctx.history)).sum() - (m * (ctx.a0 * v - fixed["hist_v"])).sum()
        time_part /= ctx.dt
        total = float(res.sum())
        size = float(np.abs(poiseuille_etc).sum() + np.abs(film).sum() + np.abs(fixed["B"] @ v).sum())
        size += float(np.abs(fixed["corr"]).sum())
        info = dict(new.info)
        f = self.plane
        info["cavitated_area"] = float(stepper.g[y < 0.0].sum())
        info["liquid_volume"] = f * float(w @ d - m @ v)
        info["net_outflow"] = f * (total - time_part)
        info["mass_imbalance"] = abs(total) / size if size > 0.0 else 0.0
        free = ~S
        info["p_negative_min"] = float(min(0.0, y[free].min())) if free.any() else 0.0
        theta = 1.0
        if S.any():  # 1 - v / dbar, dbar the mean gap of the node's cell (its row's content)
            theta = float(np.min(1.0 - v[S] / dbar[S]))
        info["theta_min"] = theta
        _mark_unsettled(solved, info)
        return dataclasses.replace(new, info=info).with_own(p_aux=y, gas=v, gas_prev=fixed["gas"])


def _mark_unsettled(solved, info) -> None:
    """A step solved before the lagged set existed (the first: every node full, the pressure
    of full Sommerfeld) has a load that is no level of the run's history, whatever the step:
    ``info["load_unsettled"]`` tells the adaptive steps to judge the load from the others."""
    if solved.state.own.get("p_aux") is None:
        info["load_unsettled"] = True


def _plane_factor(disc) -> float:
    """2 for a half disk (its rows integrate over y >= 0), else 1: whole-plane figures."""
    return 2.0 if getattr(disc, "half", False) else 1.0


#: every column a cavitation model may add to summary.csv, in a fixed order
CAVITATION_COLUMNS = (
    "load_full",
    "cavitated_area",
    "full_film_source",
    "liquid_volume",
    "net_outflow",
    "mass_imbalance",
    "theta_min",
    "p_negative_min",
)


def cavitation_model(name):
    """An instance of the registered model ``name``; None for None (full Sommerfeld)."""
    return None if name is None else CAVITATION_MODELS[check_cavitation(name)]()


def clips_pressure(scene) -> bool:
    """True when the scene's condition reports its pressure clipped (half-Sommerfeld)."""
    model = cavitation_model(getattr(scene, "cavitation", None))
    return model is not None and model.clips_pressure


def cavitation_columns(scene) -> tuple:
    """The summary columns the scene's cavitation condition adds (``()``: full Sommerfeld)."""
    model = cavitation_model(getattr(scene, "cavitation", None))
    return () if model is None else tuple(model.columns)


def check_cavitation(name):
    """``name`` if None or a registered model name, else SceneError naming the choices."""
    if name is None or (isinstance(name, str) and name in CAVITATION_MODELS):
        return name
    raise SceneError(
        f"cavitation must be None (full Sommerfeld) or one of {sorted(CAVITATION_MODELS)}, got {name!r}."
    )


def check_cavitation_scene(scene) -> None:
    """SceneError if the scene's cavitation condition cannot be applied to it."""
    model = cavitation_model(getattr(scene, "cavitation", None))
    if model is not None:
        model.check_scene(scene)
