"""The outcome of a run: per-step scalars and stored fields, with interpolation.

A :class:`Result` is filled by consuming the states of
:func:`femehl.solver.stepping.march`; it never steps anything itself.  Fields are
interpolated by the discretization that produced them (FD: bilinear in
(theta, r); FE: P1 pressure, element-constant film), and linearly in time
between the two stored states around the requested time.
"""

from __future__ import annotations

import pathlib
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from femehl.errors import SceneError
from femehl.solver.stepping import State

if TYPE_CHECKING:
    from femehl.accuracy.estimate import Estimate

__all__ = ["Result"]

_SCALARS = ("t", "hc", "V", "load", "film_center", "film_min", "p_max")
#: per-step records of the time stepping (``state.info``): step size and local error estimate
_STEPPING = ("dt", "error_estimate", "hc_dot")


@dataclass
class Result:
    """Arrays with one entry per step (``t``, ``load``, ``film_center``, ...).

    A run with a cavitation condition has its figures too (:attr:`cavitation_columns`:
    ``cavitated_area``, ``full_film_source`` or ``load_full``), as in ``summary.csv``.

    Attributes
    ----------
    scene : femehl.problem.scene.Scene
    method : str
        Name of the solver that produced it ("fd" or "fe").
    disc : object
        The discretization (grid or mesh), able to interpolate its fields.
    """

    scene: object
    method: str
    disc: object
    _rows: dict = field(
        default_factory=lambda: {k: [] for k in _SCALARS + _STEPPING + ("film_min_at", "p_max_at")}
    )
    _stored: list = field(default_factory=list)
    info: dict = field(default_factory=dict)
    #: error estimate (:mod:`femehl.accuracy.auto`; None for a fixed-step expert run):
    #: ``{"t": times, name: {"space": ..., "time": ..., "total": ...}}``, relative errors;
    #: an expert run with adaptive steps has the time part only (``space``, ``total`` None)
    estimate: Estimate | None = None

    def __post_init__(self):
        from femehl.output.table import extra_columns
        from femehl.problem.cavitation import cavitation_columns

        self._cavitation_columns = cavitation_columns(self.scene)
        self._extra_columns = extra_columns(self.scene, self.disc)
        for k in self._extra_columns:
            self._rows.setdefault(k, [])

    @property
    def cavitation_columns(self) -> tuple:
        """The per-step figures the scene's cavitation condition adds (``()``: full
        Sommerfeld): ``cavitated_area``, and ``full_film_source`` (Reynolds) or ``load_full``
        (half-Sommerfeld), see :mod:`femehl.problem.cavitation`."""
        return self._cavitation_columns

    @property
    def extra_columns(self) -> tuple:
        """Every per-step figure beyond the standard ones, as in ``summary.csv``: the
        cavitation condition's, the friction force and its parts (``friction``,
        ``shear_couette``, ``shear_poiseuille``, ``pressure_drag``; finite elements), the
        substrate's (a viscoelastic solid's ``dissipation_film``, ``power_sliding``) and a
        free indenter's (:mod:`femehl.solver.energetics`)."""
        return self._extra_columns

    def record(self, state: State, store_fields: bool = True) -> None:
        """Append one state's scalars (and its fields when ``store_fields``)."""
        for k in _SCALARS:
            self._rows[k].append(float(getattr(state, k)))
        for k in self.extra_columns:  # NaN where a state does not carry it
            self._rows[k].append(float((state.info or {}).get(k, np.nan)))
        self._rows["film_min_at"].append(tuple(state.film_min_at))
        self._rows["p_max_at"].append(tuple(state.p_max_at))
        info = state.info or {}
        self._rows["dt"].append(float(info.get("dt", 0.0)))
        self._rows["error_estimate"].append(float(info.get("error_estimate", np.nan)))
        hc_dot = state.own.get("hc_dot")  # a free indenter's velocity (NaN: hc imposed)
        self._rows["hc_dot"].append(np.nan if hc_dot is None else float(hc_dot))
        if store_fields:
            self._stored.append(state)

    # ---- per-step arrays ----------------------------------------------------
    def __getattr__(self, name):
        rows = self.__dict__.get("_rows", {})
        if name in rows:
            return np.asarray(rows[name], dtype=float)
        raise AttributeError(name)

    @property
    def nsteps(self) -> int:
        return len(self._rows["t"]) - 1

    @property
    def stored_times(self) -> np.ndarray:
        return np.array([s.t for s in self._stored])

    @property
    def final(self) -> State:
        """The last stored state of the run."""
        if not self._stored:
            raise SceneError("this result stored no fields: run with store_every >= 1.")
        return self._stored[-1]

    @property
    def states(self) -> list:
        """The stored states, in time order."""
        return list(self._stored)

    def state_at(self, t: float) -> State:
        """The stored state whose time is closest to ``t``."""
        ts = self.stored_times
        if ts.size == 0:
            raise SceneError("this result stored no fields: run with store_every >= 1.")
        return self._stored[int(np.argmin(np.abs(ts - t)))]

    # ---- interpolation ------------------------------------------------------
    def _bracket(self, t):
        ts = self.stored_times
        if ts.size == 0:
            raise SceneError("this result stored no fields: run with store_every >= 1.")
        t = float(t)
        tol = 1e-9 * max(1.0, abs(ts[-1]))
        if not np.isfinite(t) or t < ts[0] - tol or t > ts[-1] + tol:
            raise SceneError(f"t = {t} is outside the stored times [{ts[0]:g}, {ts[-1]:g}].")
        j = int(np.searchsorted(ts, t))
        if j < ts.size and abs(ts[j] - t) <= tol:
            return [(self._stored[j], 1.0)]
        if j > 0 and abs(ts[j - 1] - t) <= tol:
            return [(self._stored[j - 1], 1.0)]
        a = (t - ts[j - 1]) / (ts[j] - ts[j - 1])
        return [(self._stored[j - 1], 1.0 - a), (self._stored[j], a)]

    @staticmethod
    def _points(points):
        pts = np.asarray(points, dtype=float)
        if pts.ndim == 1 and pts.size == 2:
            pts = pts[None, :]
        if pts.ndim != 2 or pts.shape[1] != 2:
            raise SceneError(f"points must have shape (n, 2), got {pts.shape}.")
        if not np.all(np.isfinite(pts)):
            raise SceneError("points must be finite.")
        return pts

    # Inside the domain the fields are the discretization's (FE: P1 pressure, element-
    # constant film and deflection; FD: bilinear).  Outside it (r > L; line contact
    # |x| > L) they are the model's own: p = 0 (the pressure vanishes beyond the rim),
    # w from the substrate's operator at those points (the exact Boussinesq integral of
    # the discrete pressure for a half space; -p/k = 0 for Winkler) and d = hc + s - w.
    # So pressure, deflection and film are defined and consistent everywhere.
    def _outside(self, pts):
        return self.disc.outside(pts)

    def _model_deflection(self, state, pts):
        rows = self.scene.substrate.deflection_rows(self.disc, pts)
        return -np.asarray(rows @ np.asarray(state.p)[self.disc.free_index]).ravel()

    def pressure_at(self, points, t: float) -> np.ndarray:
        """Pressure at ``points`` (n, 2) and time ``t`` (normalized); 0 outside the domain."""
        pts = self._points(points)
        out = self._outside(pts)
        val = sum(wt * self.disc.pressure_at(s.p, pts) for s, wt in self._bracket(t))
        return np.where(out, 0.0, val)

    def _element_field(self, points, t, inside, outside):
        """Blend in time ``inside(state, pts)`` within the domain, ``outside(state, pts)`` beyond it."""
        pts = self._points(points)
        out = self._outside(pts)
        val = np.zeros(pts.shape[0])
        for s, wt in self._bracket(t):
            v = np.empty(pts.shape[0])
            v[~out] = inside(s, pts[~out])
            if out.any():
                v[out] = outside(s, pts[out])
            val += wt * v
        return val

    def deflection_at(self, points, t: float) -> np.ndarray:
        """Surface deflection w (negative under pressure) at ``points`` and time ``t``."""
        return self._element_field(
            points, t, lambda s, q: self.disc.deflection_at(s.w, q), self._model_deflection
        )

    def film_at(self, points, t: float) -> np.ndarray:
        """Film thickness d = h - w at ``points`` (n, 2) and time ``t``."""
        return self._element_field(
            points,
            t,
            lambda s, q: self.disc.film_at(s.d, q),
            lambda s, q: s.hc + self.disc.gap(q) - self._model_deflection(s, q),
        )

    # ---- tables -------------------------------------------------------------
    def summary(self) -> dict:
        """Per-step columns as a dict of arrays (the summary CSV's content)."""
        out = {k: getattr(self, k) for k in _SCALARS}
        at = np.asarray(self._rows["film_min_at"], dtype=float).reshape(-1, 2)
        pa = np.asarray(self._rows["p_max_at"], dtype=float).reshape(-1, 2)
        out.update(film_min_x=at[:, 0], film_min_y=at[:, 1], p_max_x=pa[:, 0], p_max_y=pa[:, 1])
        out.update({k: getattr(self, k) for k in self.extra_columns})
        return out

    def impact(self) -> dict:
        """A free indenter's collision: approach and rebound speed, restitution, thinnest film.

        ``v_in``: the fastest approach (most negative dhc/dt) before the deepest point
        ``hc_min`` (at ``t_hc_min``); ``v_out``: the fastest rebound after it (0 if the
        indenter never moves back up); ``restitution = v_out / |v_in|``; ``film_min`` and
        ``t_film_min``: the thinnest film of the run (the true minimum, nodes included).
        """
        v = self.hc_dot
        if not np.any(np.isfinite(v)):
            raise SceneError("impact() describes a free indenter: give the motion a mass (Motion(mass=...)).")
        hc, t = self.hc, self.t
        k = int(np.argmin(hc))
        v_in = float(np.nanmin(v[: k + 1]))
        v_out = max(0.0, float(np.nanmax(v[k:])))
        j = int(np.argmin(self.film_min))
        return {
            "v_in": v_in,
            "v_out": v_out,
            "restitution": v_out / abs(v_in) if v_in < 0 else float("nan"),
            "hc_min": float(hc[k]),
            "t_hc_min": float(t[k]),
            "film_min": float(self.film_min[j]),
            "t_film_min": float(t[j]),
            "rebounded": bool(v_out > 0.0),
        }

    def value_at(self, name: str, t: float) -> float:
        """A per-step scalar (e.g. "load") at time ``t``, linear in time between steps."""
        names = list(_SCALARS) + list(self.extra_columns)
        if name not in names:
            raise SceneError(f"unknown quantity {name!r}: value_at takes one of {names}.")
        ts = self.t
        t = float(t)
        tol = 1e-9 * max(1.0, abs(ts[-1]))
        if not np.isfinite(t) or t < ts[0] - tol or t > ts[-1] + tol:
            raise SceneError(
                f"t = {t} is outside the run [{ts[0]:g}, {ts[-1]:g}]: give a time the run reached."
            )
        return float(np.interp(t, ts, getattr(self, name)))

    def uncertainty(self, name: str, t: float) -> dict:
        """Estimated relative error of ``name`` at ``t``: ``dict(total=, space=, time=)``.

        Linear in time between the steps of :attr:`estimate` (see :mod:`femehl.accuracy.auto` for
        the estimators).  An automatic run (:func:`femehl.solve` without ``dt`` or mesh
        options) has all three parts; an expert run with adaptive steps (``tol`` and a
        mesh) only the time part, its ``space`` and ``total`` are None.
        """
        if self.estimate is None:
            raise SceneError(
                "this result carries no error estimate: run femehl.solve without dt= and mesh "
                "options (automatic, to tol), or give tol= for the time part."
            )
        return self.estimate.at(name, t)

    def save(self, folder, *, overwrite: bool = False) -> pathlib.Path:
        """Write the summary CSV, the field series and the PNGs to ``folder``.

        A folder that already holds a run is refused unless ``overwrite=True`` (which
        replaces femehl's files of that run only; other files stay).
        """
        from femehl.output import write_all

        return write_all(self, folder, overwrite=overwrite)
