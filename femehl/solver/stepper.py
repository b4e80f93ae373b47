"""The one stepper: a scene's lagged Reynolds step, assembled from terms, for any method.

Per step (the paper's section 3: every nonlinear coefficient lagged, so ONE linear system)

    sum_terms [ matrix p + c_term F_term d^{k+1} ] = sum_terms rhs,    d^{k+1} = h^{k+1} + C p,

that is ``A p = b`` with ``A = D + G C``, ``G = sum c_term F_term`` and
``b = rhs - G h^{k+1}`` (see :mod:`femehl.solver.terms`).  The discretization supplies the
operators, the substrate its compliance ``C`` (``w = -C p`` on the film points, see
:mod:`femehl.elastic`), the linear solver (:mod:`femehl.solver.linsolve`) solves.

Beside the terms, the step's parts (:mod:`femehl.solver.parts`): the motion's unknown hc
(imposed gap, imposed load, free indenter), a substrate's memory, a cavitation condition.

After the solve the film is known everywhere the discretization can tell: on its film
points, at the origin (exact compliance row) and at the nodes where a cheap estimate of
the nodal film is thinnest (exact compliance rows there).  ``State.film_min`` is the
smallest of them (so the central film is never below it; ``info["film_points_min"]`` is
the film points' own minimum), and a film <= 0 anywhere raises
:class:`~femehl.errors.FilmRuptureError` from :func:`femehl.solver.stepping.march`.
"""

from __future__ import annotations

import logging
import time

import numpy as np
import scipy.sparse as sp

from femehl.elastic.dense import SingleCompliance, is_dense, stored
from femehl.errors import SceneError, SingularSystemError
from femehl.solver.linsolve import (
    BorderedOperator,
    StepOperator,
    StepProduct,
    SwitchedOperator,
    film_tolerances,
    make_linear_solver,
)
from femehl.solver.parts import Solved, gap_control
from femehl.solver.stepping import State, get_scheme
from femehl.solver.terms import StepContext, terms_for

logger = logging.getLogger("femehl")

__all__ = ["LaggedStepper"]

_PROBE_FRACTION = 0.5  # nodes whose estimated film is below this x the film minimum are checked exactly
_MAX_PROBES = 64
_ALWAYS_PROBED = 8  # the nodes of smallest estimated film, checked exactly at every step
_ROW_CACHE = 512  # compliance rows of probed nodes kept between steps


def _nbytes(a) -> int:
    if is_dense(a) or getattr(a, "is_fast", False):
        return int(a.nbytes)
    if sp.issparse(a):
        a = a.tocsr()
        return a.data.nbytes + a.indices.nbytes + a.indptr.nbytes
    return 0


def _deflection(rows_p, mem, points) -> np.ndarray:
    """``-w`` at ``points`` from the compliance rows times p (viscoelastic: scaled, plus the
    material's history there)."""
    u = np.asarray(rows_p, dtype=float).ravel()
    return u if mem is None else mem.scale * u + mem.offset_at(points)


class LaggedStepper:
    """Advance a discretized scene by one lagged linear step.

    Parameters
    ----------
    disc : Discretization
        Built from the scene (see :mod:`femehl.discretize`).
    scheme : {"euler", "bdf2"}, default: "euler"
        "euler" is the paper's first-order scheme; "bdf2" is second order, still one
        linear system per step (:data:`femehl.solver.stepping.SCHEMES`).
    linear_solver : str, optional
        A key of :data:`femehl.solver.linsolve.LINEAR_SOLVERS`; default: the
        discretization's (``"gmres"`` for FE disks, ``"lu"`` for the FD reference and
        line contact).
    terms : sequence of Term, optional
        Extra physics terms added to the registered ones.
    **solver_options
        Options of the linear solver (``rtol``, ``refactor_after``, ``recycle``).
    """

    def __init__(
        self, disc, scheme: str = "euler", linear_solver: str | None = None, terms=(), **solver_options
    ):
        t0 = time.perf_counter()
        scene = disc.scene
        self.scene = scene
        self.disc = disc
        self.method = disc.method
        self.scheme = get_scheme(scheme)
        self.beta = scene.fluid.beta
        self.terms = terms_for(scene, None, terms)
        for term in self.terms:
            term.setup(disc)
        name = disc.default_linear_solver if linear_solver is None else linear_solver
        if not isinstance(name, str):
            raise SceneError(f"linear_solver must be a name such as 'gmres' or 'lu', got {name!r}.")
        if name == "lu" and solver_options:
            raise SceneError(f"linear_solver='lu' takes no options, got {sorted(solver_options)}.")
        self.solver = make_linear_solver(name, **solver_options)
        self._solver_spec = (name, solver_options)
        if name == "lu" and disc.info.get("operator") == "dense":  # a double-precision LU
            from femehl.discretize.mesh import check_mesh_memory

            check_mesh_memory(disc.info["elements"], disc.info["unknowns"], disc.info["mesh"], lu_itemsize=8)
        substrate = scene.substrate
        t1 = time.perf_counter()
        self.C = stored(substrate.compliance_operator(disc))  # large and dense: single precision
        self.dense = is_dense(self.C)
        self.fast = bool(getattr(self.C, "is_fast", False))
        if self.fast and name == "lu":
            raise SceneError(
                "linear_solver='lu' needs the dense elastic operator: use operator='dense' "
                "(if the mesh fits) or linear_solver='gmres' with the fast operator."
            )
        t2 = time.perf_counter()
        self.origin = np.zeros((1, 2))
        self.centre_row = substrate.deflection_rows(disc, self.origin)
        self.s0 = float(np.asarray(disc.gap(self.origin)).ravel()[0])
        self.shape = disc.shape
        self.g = disc.load_weights
        self._load_row = None  # the load weights on a bordered system's unknowns (_border)
        from femehl.problem.cavitation import cavitation_model

        self.cavitation = cavitation_model(getattr(scene, "cavitation", None))
        if self.cavitation is not None:
            self.cavitation.check_scene(scene)
            self.cavitation.setup(disc)
        memory = getattr(substrate, "memory", None)  # a viscoelastic substrate's internal variable
        self.memory = None if memory is None else memory(disc)
        rough = getattr(scene, "roughness", None)
        self.roughness = None if rough is None else rough.part(disc)
        #: what takes part in the step beside the terms (femehl.solver.parts): the motion's
        #: unknown hc, then the substrate's memory, the surfaces' roughness and the fluid's
        #: cavitation condition (after the roughness: it holds the film's share of the pressure)
        self.gap = gap_control(scene.motion)
        self.parts = [part for part in (self.memory, self.roughness, self.cavitation) if part is not None]
        from femehl.output.table import extra_columns
        from femehl.solver.energetics import TRIBOLOGY_COLUMNS

        # the energy budget's figures the scene reports (femehl.solver.energetics), where the method has them
        self._tribology = [c for c in extra_columns(scene, disc) if c in TRIBOLOGY_COLUMNS]
        self._FC: dict[str, object] = {}
        self._rows_cache: dict[int, np.ndarray] = {}
        self.info = dict(disc.info)
        self.info.update(
            {
                "method": self.method,
                "scheme": self.scheme.name,
                "substrate": type(substrate).__name__,
                "linear_solver": name,
                "terms": [t.name for t in self.terms],
                "elastic_build_s": t2 - t1,
                **({"fast_operator": dict(self.C.info)} if self.fast else {}),
                "operator_bytes": int(_nbytes(self.C)),
                **{f"{t.name}_assembled": False for t in self.terms},
                "factorizations": 0,
                "krylov_iterations": 0,
            }
        )
        if self.dense:  # float32 storage for a large C (femehl.elastic.dense), products in float64
            self.info["operator_storage"] = "float32" if isinstance(self.C, SingleCompliance) else "float64"
        if self.cavitation is not None:  # how the reported fields are to be read
            self.info.update(cavitation=self.cavitation.name, cavitation_note=self.cavitation.note)
        for term in self.terms:  # film products every step needs: formed here, once
            if getattr(term, "every_step", False):
                self._film_product(term)
        self.info["setup_s"] = disc.info.get("setup_s", 0.0) + time.perf_counter() - t0

    # ---- operators ----------------------------------------------------------------------
    @property
    def film_products(self) -> dict:
        """The fixed products ``F C`` formed so far, by term name (dense or sparse)."""
        return {name: FC for name, (_, FC) in self._FC.items()}

    def _film_product(self, term):
        """``(F, F C)`` of a term, asked of the term and formed once, the first time needed."""
        pair = self._FC.get(term.name)
        if pair is None:
            F = term.film_operator()
            if self.fast:  # never formed: the sparse near-field product, for the preconditioner
                FC = sp.csr_matrix(F @ self.C.preconditioner)
            else:
                FC = np.asarray(F @ self.C) if self.dense else sp.csr_matrix(F @ self.C)
            pair = self._FC[term.name] = (F, FC)
            self.info["operator_bytes"] += _nbytes(FC)
            self.info[f"{term.name}_assembled"] = True
        return pair

    def operator(self, ctx: StepContext, scale: float = 1.0):
        """The step's :class:`StepOperator` and its right-hand side without the ``-G h`` part.

        ``scale`` multiplies the compliance (``d = h + scale C p``; a viscoelastic step's
        ``J_eff``): it scales the film coefficients, so ``op.G`` is ``scale`` times the
        terms' ``G``."""
        D = None
        films = []
        rhs = np.zeros(self.disc.n)
        for term in self.terms:
            c = term.contribute(ctx)
            if c.matrix is not None:
                D = c.matrix if D is None else D + c.matrix
            if c.film_coefficient != 0.0:
                films.append((c.film_coefficient * scale, *self._film_product(term)))
            if c.rhs is not None:
                rhs += c.rhs
        if D is None:
            D = sp.csr_matrix((self.disc.n, self.disc.n))
        D = D.tocsr()
        adds = [part.operator for part in self.parts if hasattr(part, "operator")]
        if adds:
            G = sum((F * (c / scale) for c, F, _ in films), sp.csr_matrix((self.disc.n, self.C.shape[0])))
            for add in adds:  # film operators of this step only (a rough film's)
                for F, r in add(self, ctx, D, G):
                    films.append((scale, F, self._step_product(F)))
                    rhs += r
        return StepOperator(D=D, films=films, C=self.C, key=ctx.a0 / ctx.dt), rhs

    def _step_product(self, F):
        """``F C`` of a film operator of one step: only the columns F uses are touched."""
        F = sp.csr_matrix(F)
        if self.dense and not self.fast:  # read only when the solver refreshes its preconditioner
            return StepProduct(F, self.C)
        cols = np.unique(F.indices)
        C = self.C.preconditioner if self.fast else self.C
        return sp.csr_matrix(F[:, cols] @ sp.csr_matrix(C)[cols])

    # ---- states -------------------------------------------------------------------------
    def _state(self, step, t, hc, V, p, Cp=None, d_prev=None, dt_prev=None, info=None, mem=None) -> State:
        disc = self.disc
        if Cp is None:
            Cp = np.asarray(self.C @ p).ravel()
        defl = Cp if mem is None else mem.scale * Cp + mem.offset  # -w on the film points
        w = -defl
        d = hc + self.shape + defl
        p_full = disc.expand(p)
        i_min = int(np.argmin(d))
        i_max = int(np.argmax(p_full))
        info = dict(info or {})
        info.update(self._probe(hc, p, defl, float(d[i_min]), mem))
        film_center = hc + self.s0 + float(_deflection(self.centre_row @ p, mem, self.origin)[0])
        # the reported minimum is the true minimum of the discrete film: film points, the
        # origin and the probed nodes (the central film is never below it)
        info["film_points_min"] = float(d[i_min])
        lows = [
            (float(d[i_min]), tuple(float(v) for v in disc.film_points[i_min])),
            (film_center, (0.0, 0.0)),
        ]
        if "node_film_min" in info:
            lows.append((info["node_film_min"], info["node_film_min_at"]))
        film_min, film_min_at = min(lows, key=lambda c: c[0] if np.isfinite(c[0]) else -np.inf)
        return State(
            step=step,
            t=t,
            hc=hc,
            V=V,
            p=p_full,
            w=w,
            d=d,
            load=float(self.g @ p),
            film_center=film_center,
            film_min=film_min,
            film_min_at=film_min_at,
            p_max=float(p_full[i_max]),
            p_max_at=tuple(float(v) for v in disc.nodes[i_max]),
            info=info,
            d_prev=d_prev,
            dt_prev=dt_prev,
        )

    def _probe(self, hc, p, defl, d_min, mem=None):
        """The exact film at the nodes where a cheap nodal estimate says it is thinnest.

        The estimate is ``hc + s(node) +`` the mean of ``C p`` over the elements around the
        node; the ``_ALWAYS_PROBED`` smallest, and every node below ``_PROBE_FRACTION``
        times the film-point minimum (at most ``_MAX_PROBES``), get the exact value from
        the substrate's rows at the node (kept between steps: the thin nodes move slowly).
        """
        avg = self.disc.node_average
        if avg is None:
            return {}
        est = hc + self.disc.node_shape + avg @ defl
        k = min(_ALWAYS_PROBED, est.size)
        near = np.argpartition(est, k - 1)[:k]
        thin = np.flatnonzero(est < _PROBE_FRACTION * d_min)
        thin = thin[np.argsort(est[thin])[:_MAX_PROBES]]
        nodes = np.union1d(near, thin)
        rows = self._node_rows(nodes)
        exact = hc + self.disc.node_shape[nodes] + _deflection(rows @ p, mem, self.disc.nodes[nodes])
        j = int(np.argmin(exact))
        return {
            "node_film_min": float(exact[j]),
            "node_film_min_at": tuple(float(v) for v in self.disc.nodes[nodes[j]]),
        }

    def _node_rows(self, nodes):
        """Dense compliance rows at the given node indices, from a bounded cache."""
        cache = self._rows_cache
        new = [i for i in nodes if i not in cache]
        if new:
            R = self.scene.substrate.deflection_rows(self.disc, self.disc.nodes[new])
            R = R.toarray() if sp.issparse(R) else np.asarray(R)
            for i, r in zip(new, R, strict=True):
                cache[i] = r
        rows = np.array([cache[i] for i in nodes])
        while len(cache) > _ROW_CACHE:  # the oldest first (after reading: they may be this step's)
            cache.pop(next(iter(cache)))
        return rows

    def initial_state(self) -> State:
        mo = self.scene.motion
        state = self._state(0, 0.0, mo.hc(0.0), mo.V(0.0), np.zeros(self.disc.n))
        for part in (self.gap, *self.parts):  # their own variables at rest
            state = part.initial(self, state)
        self._budget(state)
        return state

    def linear_solver(self):
        """A new linear solver of the kind and options the steps use (a part's own solves:
        :meth:`at_rest`), so the steps' recycled space and preconditioner start as in any run."""
        name, options = self._solver_spec
        return make_linear_solver(name, **options)

    def at_rest(self, state: State, F=None, rhs=None, solver=None) -> State:
        """``state`` (at rest, ``p = 0``) with the pressure unknowns ``p`` solving every row
        held, ``p + F C p = rhs - F h`` (``F`` a sparse film operator, ``h = hc + s`` the
        film at ``p = 0``), by ``solver`` (:meth:`linear_solver`), with hc as the motion's
        control has it at rest (:meth:`GapControl.rest`: given, or carrying the imposed
        load): a part's consistent start (a rough surface's asperities pressing at t = 0,
        :meth:`AsperityContact.initial`).  A memory's part answers for the substrate
        (``rest_film``: a viscoelastic solid's glassy response to a load put on at t = 0).
        ``F = None``: nothing presses, ``p = 0`` at ``state.hc``."""
        if F is None:
            new = self._state(state.step, state.t, state.hc, state.V, np.zeros(self.disc.n), info=state.info)
            return new.with_own(**state.own)
        F = sp.csr_matrix(F)
        eye = sp.identity(self.disc.n, format="csr")
        films = [f for f in (getattr(part, "rest_film", None) for part in self.parts) if f is not None]
        film = films[0](self) if films else None  # a memory's response to a load put on now
        scale = 1.0 if film is None else film.scale
        op = StepOperator(D=eye, films=[(scale, F, self._step_product(F))], C=self.C, key=np.inf)
        rhs_list = self.gap.rhs(self, np.asarray(rhs, dtype=float), F, self.shape, state.t)
        p, Cp, hc = self.gap.rest(self, solver.solve(op, rhs_list, state.t), state)
        if not (np.all(np.isfinite(p)) and np.isfinite(hc)):
            raise SingularSystemError(
                f"the state at rest at t = {state.t:.6g} has a non-finite pressure: the static "
                "system is singular. Start the run with the surfaces further apart.",
                t=state.t,
            )
        if Cp is None:
            Cp = np.asarray(self.C @ p).ravel()
        new = self._state(state.step, state.t, hc, state.V, p, Cp, info=state.info, mem=film)
        return new.with_own(**{**state.own, **({} if film is None else film.own(Cp))})

    def _budget(self, state):
        """The energy budget's figures the scene reports (femehl.solver.energetics), into ``state.info``."""
        if self._tribology:
            from femehl.solver.energetics import sliding_energetics

            speeds = self.scene.motion.surface_speeds(state.t)
            liquid = None if self.cavitation is None else self.cavitation.liquid_fraction(self.disc, state)
            rough = {"liquid": liquid} if self.roughness is None else self.roughness.budget(state)
            e = sliding_energetics(self.disc, state, self.beta, speeds, **rough)
            state.info.update({k: e[k] for k in self._tribology})

    # ---- one step -----------------------------------------------------------------------
    def step(self, state: State, t_new: float, dt: float) -> State:
        """One lagged step: terms -> extra unknowns -> ONE linear solve -> state."""
        ctx = self._context(state, t_new, dt)
        film = self._film(state, t_new, dt)
        scale = 1.0 if film is None else film.scale
        floor = (state.info or {}).get("film_error_floor", 0.0)  # the film the solve must resolve
        self.solver.rtol_scale, self.solver.film_atol = film_tolerances(ctx.d, state.w, floor, scale)
        op, rhs = self.operator(ctx, scale)
        G = op.G if film is None else op.G / scale  # the terms' G (op.G carries the film's scale)
        shape = self.shape if film is None else self.shape + film.offset
        system, rhs_list = op, self.gap.rhs(self, rhs, G, shape, t_new)
        auxes = []
        for part in self.parts:  # rows held, or unknowns added
            system, rhs_list, aux = part.rows(self, system, rhs_list, state, ctx)
            auxes.append(aux)
        if getattr(system, "held", None) is not None:
            system, rhs_list = self._held(system, rhs_list, ctx, shape, scale)
        its0 = self.solver.info.get("krylov_iterations", 0)
        border = self._border(system, rhs_list, scale)
        solved = None
        if border is not None:  # hc one more unknown of the one solve
            try:
                solved = self._solve_bordered(system, rhs_list, border, state, ctx, scale)
            except SingularSystemError as exc:  # solved again apart, which says so if it fails too
                logger.debug(
                    "femehl: the bordered solve at t = %.6g failed (%s): two right-hand sides", t_new, exc
                )
        if solved is None:
            solutions = self.solver.solve(system, rhs_list, t_new)
            solved = self.gap.close(self, solutions, state, t_new, dt, ctx)
        x, Cp, hc, own = solved
        if not (np.all(np.isfinite(x)) and np.isfinite(hc)):  # a part's unknowns too
            raise SingularSystemError(
                f"step at t = {t_new:.6g} produced non-finite pressure: the system is singular "
                "or ill-conditioned. Try a smaller dt or a finer discretization.",
                t=t_new,
            )
        n = self.disc.n
        p = x[:n]
        self.info.update(self.solver.info)
        info = {"krylov_iterations": self.solver.info.get("krylov_iterations", 0) - its0}
        if self.solver.residuals:
            info["residual"] = max(self.solver.residuals)
        if Cp is None:
            Cp = np.asarray(self.C @ p).ravel()
        new = self._state(state.step + 1, t_new, hc, ctx.V, p, Cp, state.d, dt, info, film)
        if own:
            new = new.with_own(**own)
        for part, aux in zip(self.parts, auxes, strict=True):
            solved = Solved(state, ctx, op, rhs, p, Cp, x[n:], aux, film, scale)
            new = part.finish(self, solved, new)
        self._budget(new)  # from the parts' own variables too (a cavity's gas)
        return new

    def _solve_bordered(self, system, rhs_list, border, state, ctx, scale) -> tuple:
        """``(x, C p, hc, own)`` of a step solved bordered: the unknown is hc's change from the
        last state, so that it is solved to the relative residual of that change (a free
        indenter's velocity ``(hc - h_hist)/dt`` at dt = 1e-5 otherwise took the error of hc
        itself over dt: hc 2e-4 off after 23 steps); the row scaled to the right-hand side's
        size, so the relative residual holds for the pressure rows and the row alike (a free
        indenter's row at small dt, ``m a0^2 / dt^2 ~ 2e3``, left the films 3e-5 off, against
        5e-7 solved apart)."""
        c, f = self.gap.border(self, state, ctx.t_new, ctx.dt, ctx)
        hc0 = float(state.hc)
        b, f = rhs_list[0] - hc0 * rhs_list[1], f - c * hc0
        size = max(abs(f), abs(float(state.load)))
        rho = float(np.linalg.norm(b)) / size if size > 0.0 else 1.0
        rho = rho if np.isfinite(rho) and rho > 0.0 else 1.0
        row, column = border
        bordered = BorderedOperator(system, rho * row, rho * c * scale, column)
        ((xe, cxe),) = self.solver.solve(bordered, [np.append(b, rho * f)], ctx.t_new)
        hc = hc0 + scale * float(xe[-1])
        Cp = None if cxe is None else cxe - xe[-1]  # C p: the film's change less eta's
        return xe[:-1], Cp, hc, self.gap.after(self, state, hc, ctx.t_new, ctx.dt, ctx)

    def _border(self, system, rhs_list, scale):
        """``(l, G 1)``: the load row (the load weights on the pressure unknowns) and the
        column of the step's operator for hc, when this step is solved bordered
        (:class:`~femehl.solver.linsolve.BorderedOperator`: the gap control has a row, the
        solver takes it, the system is a dense or fast
        :class:`~femehl.solver.linsolve.StepOperator` or JFO's switched one, and its second
        right-hand side is that column over ``scale``); None: two right-hand sides."""
        if not (hasattr(self.gap, "border") and getattr(self.solver, "borders", False)):
            return None
        if type(system) not in (StepOperator, SwitchedOperator) or len(rhs_list) != 2:
            return None
        if not (system.dense or system.fast):
            return None
        column = np.asarray(system.G @ np.ones(system.G.shape[1])).ravel()
        given = scale * np.asarray(rhs_list[1])
        if not np.allclose(
            column, given, rtol=1e-12, atol=1e-14 * float(np.max(np.abs(column), initial=0.0))
        ):
            return None  # a part changed the second right-hand side: it is solved as given
        size = system.D.shape[0]
        if self._load_row is None or self._load_row.size != size:  # the mesh's: once per size
            self._load_row = np.zeros(size)
            self._load_row[: self.disc.n] = self.g
        return self._load_row, column

    def _held(self, system, rhs_list, ctx, shape, scale):
        """A held row says ``p = 0`` of the film's pressure: the parts that carry a share of
        the pressure (``held_rows``: a rough surface's asperities) add theirs to it."""
        for part in self.parts:
            if hasattr(part, "held_rows"):
                F, r = part.held_rows(self, ctx, system.held)  # film operator on d^{k+1}, rhs
                system = system.with_film(scale, F, self._step_product(F))
                extra = self.gap.rhs(self, r, F, shape, ctx.t_new)
                rhs_list = [b + e for b, e in zip(rhs_list, extra, strict=True)]
        return system, rhs_list

    def film_pressure(self, state, p):
        """The film's share of the pressure unknowns ``p`` of ``state``: ``p`` less what the
        parts carry (``solid_pressure``: a rough surface's asperities)."""
        for part in self.parts:
            if hasattr(part, "solid_pressure"):
                p = p - part.solid_pressure(state)
        return p

    def _context(self, state: State, t_new: float, dt: float) -> StepContext:
        """The terms' lagged context: the scheme's coefficients, the lagged film and pressure."""
        omega = None if state.d_prev is None or not state.dt_prev else dt / state.dt_prev
        a0, a1, a2, l0, l1 = self.scheme.coefficients(omega)
        if l1 == 0.0:
            d_lag, hist = state.d, state.d
        else:  # extrapolated coefficient, kept positive (a film through contact, d <= 0: as is)
            d_lag = l0 * state.d - l1 * state.d_prev
            d_lag = np.where(state.d > 0.0, np.maximum(d_lag, 0.5 * state.d), d_lag)
            hist = a1 * state.d - a2 * state.d_prev
        free_index = self.disc.free_index
        p_old = state.p[free_index]
        for part in self.parts:
            lagged = part.lagged(state, free_index)
            p_old = p_old if lagged is None else lagged
        ctx = StepContext(
            t_new=t_new,
            dt=dt,
            a0=a0,
            d=state.d,
            d_lag=d_lag,
            history=hist,
            p=p_old,
            V=self.scene.motion.V(t_new),
            beta=self.beta,
            a1=a1,
            a2=a2,
        )
        for part in self.parts:
            if hasattr(part, "context"):
                ctx = part.context(self, state, ctx)
        return ctx

    def _film(self, state: State, t_new: float, dt: float):
        """The step's change of the film (``d = h + offset + scale C p``), at most one part's."""
        films = [f for f in (part.film(self, state, t_new, dt) for part in self.parts) if f is not None]
        if len(films) > 1:
            raise SceneError("two step parts change the film: femehl composes at most one.")
        return films[0] if films else None
