"""The one stepper: a scene's lagged Reynolds step, assembled from terms, for any method.

Per step (the paper's section 3: every nonlinear coefficient lagged, so ONE linear system)

    sum_terms [ matrix p + c_term F_term d^{k+1} ] = sum_terms rhs,    d^{k+1} = h^{k+1} + C p,

that is ``A p = b`` with ``A = D + G C``, ``G = sum c_term F_term`` and
``b = rhs - G h^{k+1}`` (see :mod:`femehl.core.terms`).  The discretization supplies the
operators, the substrate its compliance ``C`` (``w = -C p`` on the film points, see
:mod:`femehl.substrates`), the linear solver (:mod:`femehl.core.linsolve`) solves.

Imposed load ``F(t)`` instead of an imposed gap: ``hc^{k+1}`` is one more unknown.  The
right-hand side is affine in hc (``h = hc + s``), so with ``A x1 = b(h = s)`` and
``A x2 = G 1`` the bordered system ``A p + hc G 1 = b(s)``, ``g . p = F`` gives
``hc = (g . x1 - F) / (g . x2)`` and ``p = x1 - hc x2``: one operator, two right-hand
sides, still one linear system per step.  This is the only place it is written.

After the solve the film is known everywhere the discretization can tell: on its film
points, at the origin (exact compliance row) and at the nodes where a cheap estimate of
the nodal film is thinnest (exact compliance rows there).  ``State.film_min`` is the
smallest of them (so the central film is never below it; ``info["film_points_min"]`` is
the film points' own minimum), and a film <= 0 anywhere raises
:class:`~femehl.errors.FilmRuptureError` from :func:`femehl.stepping.march`.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import scipy.sparse as sp

from ..errors import SceneError, SingularSystemError
from ..stepping import State, get_scheme
from .linsolve import StepOperator, film_rtol_scale, make_linear_solver
from .terms import StepContext, terms_for

__all__ = ["LaggedStepper"]

_PROBE_FRACTION = 0.5  # nodes whose estimated film is below this x the film minimum are checked exactly
_MAX_PROBES = 64
_ALWAYS_PROBED = 8  # the nodes of smallest estimated film, checked exactly at every step
_ROW_CACHE = 512  # compliance rows of probed nodes kept between steps


def _nbytes(a) -> int:
    if isinstance(a, np.ndarray) or getattr(a, "is_fast", False):
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
        Built from the scene (see :mod:`femehl.discretizations`).
    scheme : {"euler", "bdf2"}, default: "euler"
        "euler" is the paper's first-order scheme; "bdf2" is second order, still one
        linear system per step (:data:`femehl.stepping.SCHEMES`).
    linear_solver : str, optional
        A key of :data:`femehl.core.linsolve.LINEAR_SOLVERS`; default: the
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
        if name == "lu" and disc.info.get("operator") == "dense":  # a double-precision LU
            from ..fe.mesh import check_mesh_memory

            check_mesh_memory(disc.info["elements"], disc.info["unknowns"], disc.info["mesh"], lu_itemsize=8)
        substrate = scene.substrate
        t1 = time.perf_counter()
        self.C = substrate.compliance_operator(disc)
        self.dense = isinstance(self.C, np.ndarray)
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
        from ..cavitation import cavitation_model

        self.cavitation = cavitation_model(getattr(scene, "cavitation", None))
        if self.cavitation is not None:
            self.cavitation.check_scene(scene)
            self.cavitation.setup(disc)
        memory = getattr(substrate, "memory", None)  # a viscoelastic substrate's internal variable
        self.memory = None if memory is None else memory(disc)
        from ..output.table import extra_columns
        from ..tribology import TRIBOLOGY_COLUMNS

        # the energy budget's figures the scene reports (femehl.tribology), where the method has them
        self._tribology = [c for c in extra_columns(scene) if c in TRIBOLOGY_COLUMNS]
        if not hasattr(disc, "pressure_gradient"):
            self._tribology = []
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
        return StepOperator(D=D.tocsr(), films=films, C=self.C, key=ctx.a0 / ctx.dt), rhs

    # ---- states -------------------------------------------------------------------------
    def _state(
        self, step, t, hc, V, p, Cp=None, d_prev=None, dt_prev=None, info=None, hc_dot=None, mem=None
    ) -> State:
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
            hc_dot=hc_dot,
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
            while len(cache) > _ROW_CACHE:
                cache.pop(next(iter(cache)))
        return np.array([cache[i] for i in nodes])

    def initial_state(self) -> State:
        mo = self.scene.motion
        hc_dot = mo.hc_dot0 if mo.free else None
        info = self.cavitation.initial_info() if self.cavitation is not None else None
        state = self._state(0, 0.0, mo.hc(0.0), mo.V(0.0), np.zeros(self.disc.n), info=info, hc_dot=hc_dot)
        if self.memory is not None:  # the material at rest, unloaded
            state = dataclasses.replace(state, creep=np.zeros(self.memory.size))
        if self.cavitation is not None:  # a condition's own fields (JFO: no gas yet)
            state = self.cavitation.initial_state(state)
        self._budget(state)
        return state

    def _budget(self, state):
        """The energy budget's figures the scene reports (femehl.tribology), into ``state.info``."""
        if self._tribology:
            from ..tribology import sliding_energetics

            e = sliding_energetics(self.disc, state, self.beta)
            state.info.update({k: e[k] for k in self._tribology})

    # ---- one step -----------------------------------------------------------------------
    def step(self, state: State, t_new: float, dt: float) -> State:
        """One lagged step: ONE linear system (bordered by one row under imposed load)."""
        mo = self.scene.motion
        V = mo.V(t_new)
        omega = None if state.d_prev is None or not state.dt_prev else dt / state.dt_prev
        a0, a1, a2, l0, l1 = self.scheme.coefficients(omega)
        if l1 == 0.0:
            d_lag, hist = state.d, state.d
        else:  # extrapolated coefficient, kept positive
            d_lag = np.maximum(l0 * state.d - l1 * state.d_prev, 0.5 * state.d)
            hist = a1 * state.d - a2 * state.d_prev
        cav = self.cavitation
        free_index = self.disc.free_index
        p_old = state.p[free_index] if cav is None else cav.lagged_pressure(state, free_index)
        its0 = self.solver.info.get("krylov_iterations", 0)
        self.solver.rtol_scale = film_rtol_scale(state.d, state.w)  # the residual follows the film
        ctx = StepContext(
            t_new=t_new,
            dt=dt,
            a0=a0,
            d=state.d,
            d_lag=d_lag,
            history=hist,
            p=p_old,
            V=V,
            beta=self.beta,
            a1=a1,
            a2=a2,
        )
        mem = None
        if self.memory is not None:  # viscoelastic: d = h + offset + J_eff C p
            mem = self.memory.step(state, t_new, dt, a0, a1, a2, mo.V)
        scale = 1.0 if mem is None else mem.scale
        shape = self.shape if mem is None else self.shape + mem.offset
        op, rhs = self.operator(ctx, scale)
        G = op.G if mem is None else op.G / scale  # the terms' G (op.G carries the scale)
        hc_dot = None
        if mo.solves_hc:  # p = x1 - hc x2, and one more row for hc
            rhs_list = [rhs - G @ shape, G @ np.ones(self.shape.size)]
        else:
            hc = mo.hc(t_new)
            rhs_list = [rhs - G @ (hc + shape)]
        system, aux = op, None
        if cav is not None:  # the condition's system: held rows, or more unknowns
            system, rhs_list, aux = cav.prepare(self, op, rhs_list, state, ctx)
        if mo.solves_hc:
            (x1, cx1), (x2, cx2) = self.solver.solve(system, rhs_list, t_new)
            n = self.disc.n  # a condition's own unknowns follow the pressure
            g1, g2 = float(self.g @ x1[:n]), float(self.g @ x2[:n])
            if mo.free:
                hc, hc_dot = self._newton_row(state, t_new, dt, g1, g2, a0, a1, a2)
            else:  # the load row: g . p = F
                if not np.isfinite(g2) or g2 == 0.0:
                    raise SingularSystemError(
                        f"step at t = {t_new:.6g}: the load row is singular (the film does not "
                        "respond to hc).",
                        t=t_new,
                    )
                hc = (g1 - mo.F(t_new)) / g2
            x = x1 - hc * x2
            Cp = None if cx1 is None or cx2 is None else cx1 - hc * cx2
        else:
            ((x, Cp),) = self.solver.solve(system, rhs_list, t_new)
        p, unknowns = x[: self.disc.n], x[self.disc.n :]
        if not (np.all(np.isfinite(x)) and np.isfinite(hc)):  # a condition's unknowns too
            raise SingularSystemError(
                f"step at t = {t_new:.6g} produced non-finite pressure: the system is singular "
                "or ill-conditioned. Try a smaller dt or a finer discretization.",
                t=t_new,
            )
        self.info.update(self.solver.info)
        info = {"krylov_iterations": self.solver.info.get("krylov_iterations", 0) - its0}
        if self.solver.residuals:
            info["residual"] = max(self.solver.residuals)
        new = self._state(
            state.step + 1, t_new, hc, V, p, Cp, d_prev=state.d, dt_prev=dt, info=info, hc_dot=hc_dot, mem=mem
        )
        extra = {}
        if mem is not None:
            u = Cp if Cp is not None else np.asarray(self.C @ p).ravel()
            extra.update(creep=mem.creep(u), creep_prev=state.creep)
        self._budget(new)
        if hc_dot is not None:
            extra.update(hc_prev=state.hc, hc_dot_prev=state.hc_dot)
        if extra:
            new = dataclasses.replace(new, **extra)
        if cav is not None:  # the condition's part after the solve (unmasked system)
            new = cav.finish(self, op, rhs, p, new, aux, scale, unknowns)
        return new

    def _newton_row(self, state, t_new, dt, g1, g2, a0, a1, a2):
        """hc and dhc/dt of a free indenter: ``m hc'' = load - force`` by the step's own
        scheme (BDF2 with its variable-step coefficients, or Euler) on hc and v = hc':

            a0 hc' - (a1 hc - a2 hc_prev) = dt v',   m (a0 v' - (a1 v - a2 v_prev)) = dt f',

        ``f' = g . p' - force(t')`` with ``g . p' = g1 - hc' g2`` linear in hc': one more
        row, solved in closed form.  L-stable: a small mass tends to the imposed-load step
        (``hc' = (g1 - force)/g2`` at m = 0)."""
        mo = self.scene.motion
        m = mo.mass
        v = state.hc_dot if state.hc_dot is not None else mo.hc_dot0
        if a2 != 0.0 and state.hc_prev is not None and state.hc_dot_prev is not None:
            h_hist, v_hist = a1 * state.hc - a2 * state.hc_prev, a1 * v - a2 * state.hc_dot_prev
        else:  # the first step (or after a restart without history): the one-step scheme
            a0, h_hist, v_hist = 1.0, state.hc, v
        F_new = mo.applied_force(t_new)
        den = m * a0 * a0 / dt + dt * g2
        if not np.isfinite(den) or den == 0.0:
            raise SingularSystemError(
                f"step at t = {t_new:.6g}: the free indenter's row is singular (m a0^2/dt + dt g.x2 = 0).",
                t=t_new,
            )
        hc = (dt * (g1 - F_new) + (m / dt) * (a0 * h_hist + dt * v_hist)) / den
        return hc, (a0 * hc - h_hist) / dt
