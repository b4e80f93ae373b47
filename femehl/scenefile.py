"""TOML scene files: the CLI's way to state a scene (and how to run it).

Each table names a *kind* looked up in a registry, never an if/elif chain:
add a shape, substrate or time function by adding it to the registry.
A commented example is ``examples/paper_sphere.toml``; the format::

    [indenter]            kind = "sphere", R = 1.0
    [substrate]           kind = "halfspace" (nu) | "winkler" (k) | "rigid"
    [fluid]               beta = 200.0
    [motion.gap]          kind = "ramp_hold" (h0, h_end, t1) | "constant" (value)
                          | "table" (times = [...], values = [...])
    [motion.velocity]     kind = "tanh" (t1, T, V_ss) | "constant" | "table"
    [domain]              L = 2.0
    [run]                 method, t_end, dt, store_every, mesh, dr, dtheta_divisions

Alternatively a ``[si]`` table (R, G, eta, V_ss, h_inf, nu, h0 [, t1, T, L])
states the paper's experiment in SI units and replaces the tables above.
Every problem raises :class:`~femehl.errors.SceneFileError` naming the file
and the key to fix.
"""

from __future__ import annotations

import inspect
import math
import pathlib

from .errors import SceneError, SceneFileError
from .scene import (Constant, Dimensional, Domain, Fluid, HalfSpace, Motion, RampHold, Rigid,
                    Scene, Sphere, Table, TanhStart, Winkler)

try:
    import tomllib
except ModuleNotFoundError:  # Python < 3.11
    import tomli as tomllib

__all__ = ["load_scene_file", "INDENTERS", "SUBSTRATES", "TIME_FUNCTIONS", "RUN_KEYS"]

INDENTERS = {"sphere": Sphere}
SUBSTRATES = {"halfspace": HalfSpace, "winkler": Winkler, "rigid": Rigid}
TIME_FUNCTIONS = {"constant": Constant, "table": Table, "ramp_hold": RampHold, "tanh": TanhStart}
RUN_KEYS = {"method", "t_end", "dt", "store_every", "mesh", "dr", "dtheta_divisions",
            "linear_solver"}


def _build(registry, table, where, path):
    if not isinstance(table, dict):
        raise SceneFileError(f"{path}: [{where}] must be a table, got {table!r}.")
    table = dict(table)
    kind = table.pop("kind", None)
    if kind not in registry:
        raise SceneFileError(f"{path}: [{where}] kind = {kind!r} is not known; "
                             f"use one of {sorted(registry)}.")
    cls = registry[kind]
    allowed = set(inspect.signature(cls).parameters)
    extra = set(table) - allowed
    if extra:
        raise SceneFileError(f"{path}: [{where}] kind = {kind!r} does not take {sorted(extra)}; "
                             f"it takes {sorted(allowed)}.")
    try:
        return cls(**table)
    except SceneError as exc:
        raise SceneFileError(f"{path}: [{where}]: {exc}") from None
    except TypeError as exc:
        raise SceneFileError(f"{path}: [{where}]: {exc}") from None


def _time_function(value, where, path):
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return Constant(value)
    return _build(TIME_FUNCTIONS, value, where, path)


def load_scene_file(path) -> tuple[Scene, dict]:
    """Read a TOML scene file; return ``(scene, run_options)``.

    Parameters
    ----------
    path : str or pathlib.Path

    Raises
    ------
    SceneFileError
        Unreadable file, TOML syntax error, unknown table/kind/key, invalid value.
    """
    path = pathlib.Path(path)
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SceneFileError(f"scene file {str(path)!r} does not exist: check the path.") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneFileError(f"cannot read scene file {str(path)!r}: {exc}.") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneFileError(f"{path}: not valid TOML ({exc}); see examples/paper_sphere.toml.") from None
    known = {"indenter", "substrate", "fluid", "motion", "domain", "run", "si"}
    unknown = set(raw) - known
    if unknown:
        raise SceneFileError(f"{path}: unknown table(s) {sorted(unknown)}; known: {sorted(known)}.")
    run = dict(raw.get("run", {}))
    extra = set(run) - RUN_KEYS
    if extra:
        raise SceneFileError(f"{path}: [run] does not take {sorted(extra)}; it takes {sorted(RUN_KEYS)}.")
    try:
        if "si" in raw:
            scene = _si_scene(raw, path)
        else:
            scene = _normalized_scene(raw, path)
    except SceneFileError:
        raise
    except SceneError as exc:
        raise SceneFileError(f"{path}: {exc}") from None
    return scene, run


def _si_scene(raw, path):
    clash = {"indenter", "substrate", "fluid", "motion", "domain"} & set(raw)
    if clash:
        raise SceneFileError(f"{path}: [si] replaces {sorted(clash)}; give one or the other.")
    si = dict(raw["si"])
    keys = {"R", "G", "eta", "V_ss", "h_inf", "nu", "h0", "t1", "T", "L"}
    extra = set(si) - keys
    missing = {"R", "G", "eta", "V_ss", "h_inf", "h0"} - set(si)
    if extra or missing:
        raise SceneFileError(f"{path}: [si] needs {sorted(keys - {'nu', 't1', 'T', 'L'})} "
                             f"(optional nu, t1, T, L); missing {sorted(missing)}, unknown {sorted(extra)}.")
    dim = Dimensional(**{k: si[k] for k in ("R", "G", "eta", "V_ss", "h_inf")}, nu=si.get("nu", 0.5))
    return dim.scene(si["h0"], si.get("t1"), si.get("T"), si.get("L", 2.0))


def _normalized_scene(raw, path):
    indenter = _build(INDENTERS, raw.get("indenter", {"kind": "sphere"}), "indenter", path)
    substrate = _build(SUBSTRATES, raw.get("substrate", {"kind": "halfspace"}), "substrate", path)
    fluid = raw.get("fluid", {})
    if not isinstance(fluid, dict) or set(fluid) - {"beta"}:
        raise SceneFileError(f"{path}: [fluid] takes only beta.")
    motion = dict(raw.get("motion", {}))
    extra = set(motion) - {"gap", "velocity"}
    if extra:
        raise SceneFileError(f"{path}: [motion] takes gap and velocity, not {sorted(extra)}.")
    gap = _time_function(motion.get("gap", {"kind": "ramp_hold"}), "motion.gap", path)
    vel = _time_function(motion.get("velocity", 0.0), "motion.velocity", path)
    domain = raw.get("domain", {})
    if not isinstance(domain, dict) or set(domain) - {"L"}:
        raise SceneFileError(f"{path}: [domain] takes only L.")
    return Scene(indenter=indenter, substrate=substrate, fluid=Fluid(**fluid),
                 motion=Motion(gap=gap, velocity=vel), domain=Domain(**domain))


def run_options(run: dict) -> dict:
    """Turn a [run] table into keyword arguments of :func:`femehl.solve`."""
    out = dict(run)
    if "dtheta_divisions" in out:
        n = out.pop("dtheta_divisions")
        if not isinstance(n, int) or n < 2:
            raise SceneFileError(f"[run] dtheta_divisions must be an integer >= 2 (dtheta = pi/n), got {n!r}.")
        out["dtheta"] = math.pi / n
    return out
