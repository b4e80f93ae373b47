"""The classic relaxation approach femehl replaces, for contrast (paper section 1).

Per time step, the traditional EHL solver iterates between the Reynolds
equation and elasticity with an under-relaxation factor on the pressure
(Hamrock & Dowson 1976; Davis et al. 1986)::

    p <- p^k                                   (initial guess: previous step)
    repeat
        d   = h^{k+1} + C p                    film of the current iterate (w = -C p)
        p*  = solution of the Reynolds equation with that film FIXED:
              beta K(d) p* = -V Bx d - M (d - d^k)/dt
        p   <- (1 - omega) p + omega p*        under-relaxation
    until ||p* - p_old|| / ||p*|| < tol        (at most max_iter times)

It is built on the FE discretization (same mesh, same operators K, Bx, M and
C of femehl's stepper for method "fe", which it wraps and does not modify),
so the only difference to femehl's scheme is *how* one time step is solved:
a fixed-point iteration between Reynolds and elasticity, converged to a fully
implicit step (K evaluated at d^{k+1}), instead of ONE linear
system with the coefficients lagged.  A step that does not converge raises
:class:`~femehl.errors.RelaxationDivergedError` with the iteration count.

The fixed-point map's sensitivity dp*/dp ~ (beta K)^{-1} (V Bx + M/dt) C
grows like (deflection / film^3) / (beta dt): thin films, soft solids and
short steps make it large, and then only a tiny omega converges -- slowly.
That is the regime the paper's scheme was built for.

:func:`mass_balance_residual` evaluates the discrete weak form of a step
from two consecutive States; the stress benchmark uses it for both solvers.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse.linalg as spla

from femehl.errors import RelaxationDivergedError, SceneError
from femehl.problem.scene import Scene
from femehl.solver.stepping import State

__all__ = ["RelaxationStepper", "mass_balance_residual"]


def mass_balance_residual(stepper, prev: State, new: State, coefficient: str = "lagged") -> float:
    """Relative residual of the discrete Reynolds equation of one step, from the States alone.

    ``|| beta D(d*) p + V X d + T (d - d^k)/dt || / (|| T (d - d^k)/dt || + || V X d ||)``

    with the discretization's operators (:mod:`femehl.solver.terms`: FE weak form or FD
    node equations), ``d = new.d``, ``d^k = prev.d``, ``p`` the pressure unknowns of
    ``new`` and ``d* = d^k`` (``coefficient="lagged"``: femehl's Euler scheme) or
    ``d* = d`` (``"implicit"``: the equation the relaxation baseline converges to).
    ``stepper`` is a stepper of the run (any method) or a :class:`RelaxationStepper`.
    Returns 0 when both terms vanish.
    """
    disc = getattr(stepper, "fe", stepper).disc
    dt = new.t - prev.t
    p = np.asarray(new.p)[disc.free_index]
    d_coef = prev.d if coefficient == "lagged" else new.d
    squeeze = disc.squeeze() @ (new.d - prev.d) / dt
    couette = np.zeros_like(squeeze)
    if new.V != 0.0:
        couette = new.V * (disc.couette() @ new.d)
    D = disc.poiseuille(d_coef, d_coef**3, 3.0 * d_coef**2)
    r = stepper.scene.fluid.beta * (D @ p) + couette + squeeze
    scale = float(np.linalg.norm(squeeze) + np.linalg.norm(couette))
    rn = float(np.linalg.norm(r))
    if scale == 0.0:
        return 0.0 if rn == 0.0 else math.inf
    return rn / scale


class RelaxationStepper:
    """Fixed-point (Reynolds <-> elasticity) iteration with pressure under-relaxation.

    Parameters
    ----------
    scene : femehl.problem.scene.Scene
        Imposed-gap scenes only (the baseline has no load row).
    mesh : str or mesh, default: "coarse"
        As for method "fe".
    omega : float, default: 0.1
        Under-relaxation factor on the pressure, 0 < omega <= 1.
    tol : float, default: 1e-6
        Converged when ``||p* - p|| / ||p*|| < tol``.
    max_iter : int, default: 200
        Iterations allowed per step before :class:`RelaxationDivergedError`.
    **fe_options
        Passed to the FE discretization (e.g. ``half``).

    ``info`` counts ``iterations`` (total) and ``steps``; every State's
    ``info["iterations"]`` is that step's count.
    """

    method = "relax"

    def __init__(
        self,
        scene: Scene,
        mesh="coarse",
        omega: float = 0.1,
        tol: float = 1e-6,
        max_iter: int = 200,
        **fe_options,
    ):
        from femehl.api import make_stepper

        try:
            omega = float(omega)
            tol = float(tol)
        except (TypeError, ValueError):
            raise SceneError(f"omega and tol must be numbers, got {omega!r}, {tol!r}.") from None
        if not (0.0 < omega <= 1.0):
            raise SceneError(f"omega must be in (0, 1], got {omega!r}.")
        if not (0.0 < tol < 1.0):
            raise SceneError(f"tol must be in (0, 1), got {tol!r}.")
        if isinstance(max_iter, bool) or not isinstance(max_iter, int) or max_iter < 1:
            raise SceneError(f"max_iter must be an integer >= 1, got {max_iter!r}.")
        if scene.motion.solves_hc:
            raise SceneError("the relaxation baseline handles imposed-gap scenes only.")
        self.fe = make_stepper(scene, "fe", mesh=mesh, **fe_options)
        self.scene = scene
        self.disc = self.fe.disc
        self.omega = omega
        self.tol = tol
        self.max_iter = max_iter
        self.info = dict(self.fe.info)
        self._Bx = None
        self.info.update(
            method="relax",
            omega=omega,
            tol=tol,
            max_iter=max_iter,
            iterations=0,
            steps=0,
            max_step_iterations=0,
        )

    def initial_state(self) -> State:
        return self.fe.initial_state()

    def _film(self, hc, p):
        return hc + self.fe.shape + np.asarray(self.fe.C @ p).ravel()

    def step(self, state: State, t_new: float, dt: float) -> State:
        fe = self.fe
        mo = self.scene.motion
        hc, V = mo.hc(t_new), mo.V(t_new)
        disc = fe.disc
        if V != 0.0 and self._Bx is None:
            self._Bx = disc.couette()
        Bx = self._Bx if V != 0.0 else None
        M = disc.squeeze()
        p = np.asarray(state.p)[disc.free_index].copy()
        d_old = state.d
        it = 0
        change = math.inf
        while True:
            it += 1
            d = self._film(hc, p)
            if not np.all(np.isfinite(d)) or d.min() <= 0.0:
                bad = int(np.argmin(np.where(np.isfinite(d), d, -np.inf)))
                x, y = fe.disc.centroids[bad]
                raise RelaxationDivergedError(
                    f"relaxation (omega = {self.omega:g}) diverged at t = {t_new:.6g} after {it} "
                    f"iterations: the iterate's film became {d[bad]:.3g} <= 0 at (x, y) = "
                    f"({x:.3g}, {y:.3g}). Try a smaller omega (more iterations) -- or femehl's "
                    "non-iterative scheme (method 'fe').",
                    t=t_new,
                    iterations=it,
                )
            rhs = -M @ (d - d_old) / dt
            if Bx is not None:
                rhs -= V * (Bx @ d)
            K = disc.poiseuille(d, d**3)
            p_star = spla.spsolve((fe.beta * K).tocsc(), rhs)
            ns = float(np.linalg.norm(p_star))
            change = (
                float(np.linalg.norm(p_star - p)) / ns if ns > 0.0 else (0.0 if not np.any(p) else math.inf)
            )
            if not np.isfinite(change):
                raise RelaxationDivergedError(
                    f"relaxation (omega = {self.omega:g}) produced a non-finite pressure at "
                    f"t = {t_new:.6g} after {it} iterations. Try a smaller omega.",
                    t=t_new,
                    iterations=it,
                )
            p = (1.0 - self.omega) * p + self.omega * p_star
            if change < self.tol:
                break
            if it >= self.max_iter:
                raise RelaxationDivergedError(
                    f"relaxation (omega = {self.omega:g}) did not converge at t = {t_new:.6g}: "
                    f"pressure change still {change:.3g} > tol = {self.tol:g} after {it} iterations. "
                    "Try another omega, more iterations, a larger dt -- or femehl's non-iterative "
                    "scheme (method 'fe').",
                    t=t_new,
                    iterations=it,
                )
        self.info["iterations"] += it
        self.info["steps"] += 1
        self.info["max_step_iterations"] = max(self.info["max_step_iterations"], it)
        return fe._state(
            state.step + 1,
            t_new,
            hc,
            V,
            p,
            d_prev=state.d,
            dt_prev=dt,
            info={"iterations": it, "change": change},
        )
