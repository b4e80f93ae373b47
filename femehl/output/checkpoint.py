"""Checkpoints: the last State of a run, so that it can be resumed.

``folder/checkpoint.npz`` holds one :class:`~femehl.stepping.State` (its
arrays and scalars, including ``d_prev``/``dt_prev`` of two-step schemes) and
``folder/checkpoint.json`` the run's parameters: the scene (described field
by field), the method and the discretization actually built (mesh name,
element and node counts, a hash of the node coordinates; FD: dr, dtheta and
grid size).  Both are written atomically (temporary file + rename), so a
run killed at any moment leaves the previous checkpoint intact.

:func:`femehl.run.run_to_folder` writes a checkpoint every
``checkpoint_every`` steps and at the end of the run (also when it stops on a
:class:`~femehl.errors.SolverError`: then it holds the last good state), and
``run_to_folder(..., resume=True)`` continues from it after
:func:`check_params` has confirmed that scene, method and discretization
are the same.  :func:`resume_writer` reopens the summary CSV for appending
(rows past the checkpoint, from a run that went on after it, are cut off)
and the field series with its numbering continued.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
import pathlib
import xml.etree.ElementTree as ET

import numpy as np

from ..errors import SceneError
from ..stepping import State

__all__ = ["CHECKPOINT", "PARAMS", "save_checkpoint", "load_checkpoint", "run_params",
           "check_params", "resume_writer", "describe"]

CHECKPOINT = "checkpoint.npz"
PARAMS = "checkpoint.json"
FORMAT = 1

_ARRAYS = ("p", "w", "d")
_SCALARS = ("step", "t", "hc", "V", "load", "film_center", "film_min", "p_max")


def _atomic_write(path: pathlib.Path, write):
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "wb") as fh:
        write(fh)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def save_checkpoint(folder, state: State) -> pathlib.Path:
    """Write ``state`` to ``folder/checkpoint.npz`` atomically."""
    folder = pathlib.Path(folder)
    arrays = {k: np.asarray(getattr(state, k), dtype=float) for k in _ARRAYS}
    arrays.update({k: np.asarray(getattr(state, k)) for k in _SCALARS})
    arrays["film_min_at"] = np.asarray(state.film_min_at, dtype=float)
    arrays["p_max_at"] = np.asarray(state.p_max_at, dtype=float)
    arrays["has_prev"] = np.asarray(state.d_prev is not None)
    arrays["d_prev"] = (np.asarray(state.d_prev, dtype=float) if state.d_prev is not None
                        else np.zeros(0))
    arrays["dt_prev"] = np.asarray(np.nan if state.dt_prev is None else state.dt_prev, dtype=float)
    arrays["format"] = np.asarray(FORMAT)
    path = folder / CHECKPOINT
    _atomic_write(path, lambda fh: np.savez(fh, **arrays))
    return path


def load_checkpoint(folder) -> State:
    """The State saved in ``folder/checkpoint.npz`` (SceneError if there is none or it is unreadable)."""
    path = pathlib.Path(folder) / CHECKPOINT
    if not path.is_file():
        raise SceneError(f"no checkpoint in {str(path.parent)!r} ({CHECKPOINT} is missing): "
                         "run without resume first, or give the folder of the run to continue.")
    try:
        with np.load(path, allow_pickle=False) as z:
            a = {k: z[k] for k in z.files}
        has_prev = bool(a["has_prev"])
        dt_prev = float(a["dt_prev"])
        state = State(step=int(a["step"]), t=float(a["t"]), hc=float(a["hc"]), V=float(a["V"]),
                      p=a["p"], w=a["w"], d=a["d"], load=float(a["load"]),
                      film_center=float(a["film_center"]), film_min=float(a["film_min"]),
                      film_min_at=tuple(a["film_min_at"].tolist()), p_max=float(a["p_max"]),
                      p_max_at=tuple(a["p_max_at"].tolist()), info={"resumed": True},
                      d_prev=a["d_prev"] if has_prev else None,
                      dt_prev=None if math.isnan(dt_prev) else dt_prev)
    except (OSError, ValueError, KeyError, TypeError, EOFError) as exc:
        raise SceneError(f"cannot read the checkpoint {str(path)!r} ({type(exc).__name__}: {exc}); "
                         "start the run again without resume.") from None
    return state


# ---- run parameters ------------------------------------------------------------------------
def describe(obj, depth: int = 0):
    """A JSON-able description of a scene (dataclasses field by field, callables by name)."""
    if depth > 20:
        return repr(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        out = {"type": type(obj).__name__}
        for f in dataclasses.fields(obj):
            out[f.name] = describe(getattr(obj, f.name), depth + 1)
        return out
    if isinstance(obj, (bool, str)) or obj is None:
        return obj
    if isinstance(obj, (int, float, np.integer, np.floating)):
        v = float(obj)
        return v if math.isfinite(v) else repr(v)
    if isinstance(obj, np.ndarray):
        return {"array_sha1": hashlib.sha1(np.ascontiguousarray(obj).tobytes()).hexdigest(),
                "shape": list(obj.shape)}
    if isinstance(obj, (list, tuple)):
        return [describe(v, depth + 1) for v in obj]
    if isinstance(obj, dict):
        return {str(k): describe(v, depth + 1) for k, v in obj.items()}
    if callable(obj):
        return {"callable": f"{getattr(obj, '__module__', '?')}.{getattr(obj, '__qualname__', type(obj).__name__)}"}
    return repr(obj)


def _disc_signature(stepper) -> dict:
    disc = stepper.disc
    sig = {}
    info = getattr(stepper, "info", {}) or {}
    for k in ("mesh", "half", "elements", "nodes", "unknowns", "scheme", "omega"):
        if k in info:
            sig[k] = describe(info[k])
    grid = getattr(stepper, "grid", None)
    if grid is not None:
        for k in ("dr", "dtheta", "m", "n"):
            if hasattr(grid, k):
                sig[k] = describe(getattr(grid, k))
    nodes = getattr(disc, "nodes", None)
    if nodes is None and hasattr(disc, "xy"):
        nodes = disc.xy()
    if nodes is not None:
        sig["nodes_sha1"] = hashlib.sha1(np.ascontiguousarray(nodes, dtype=float).tobytes()).hexdigest()
    return sig


def run_params(scene, stepper, dt: float) -> dict:
    """What must match for a resume: scene, method, discretization (dt is informative)."""
    return {"format": FORMAT, "method": stepper.method, "scene": describe(scene),
            "discretization": _disc_signature(stepper), "dt": float(dt)}


def write_params(folder, params: dict) -> pathlib.Path:
    path = pathlib.Path(folder) / PARAMS
    text = json.dumps(params, indent=1, sort_keys=True).encode()
    _atomic_write(path, lambda fh: fh.write(text))
    return path


def read_params(folder) -> dict:
    path = pathlib.Path(folder) / PARAMS
    try:
        return json.loads(path.read_text())
    except FileNotFoundError:
        raise SceneError(f"no {PARAMS} next to the checkpoint in {str(path.parent)!r}: cannot check "
                         "that the run to resume is the same; start it again without resume.") from None
    except (OSError, ValueError) as exc:
        raise SceneError(f"cannot read {str(path)!r} ({exc}); start the run again without resume.") from None


def _diff(a, b, where=""):
    """First path where two descriptions differ, with both values (None if equal)."""
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                return f"{where}.{k}".lstrip("."), a.get(k, "<absent>"), b.get(k, "<absent>")
            d = _diff(a[k], b[k], f"{where}.{k}")
            if d:
                return d
        return None
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b)):
            d = _diff(x, y, f"{where}[{i}]")
            if d:
                return d
        return None
    return None if a == b else (where.lstrip(".") or "<root>", a, b)


def check_params(saved: dict, current: dict) -> None:
    """Raise SceneError naming the first mismatch of scene, method or discretization."""
    for key in ("method", "scene", "discretization"):
        d = _diff(saved.get(key), current.get(key), key)
        if d:
            path, was, now = d
            raise SceneError(f"cannot resume: {path} differs from the checkpointed run "
                             f"(checkpoint: {was!r}, now: {now!r}). Resume with the same scene, "
                             "method and mesh/grid, or start a new run in another folder.")


# ---- reopening the outputs ------------------------------------------------------------------
def _cut_summary(path: pathlib.Path, t_ckpt: float) -> None:
    """Drop summary rows with t > t_ckpt (a run that went on past its last checkpoint)."""
    if not path.is_file():
        return
    tol = 1e-9 * max(1.0, abs(t_ckpt))
    with open(path, "rb+") as fh:
        keep = 0
        first = True
        for line in iter(fh.readline, b""):
            if first:
                first = False
                keep = fh.tell()
                continue
            try:
                t = float(line.split(b",", 1)[0])
            except ValueError:
                break
            if not line.endswith(b"\n") or t > t_ckpt + tol:
                break
            keep = fh.tell()
        fh.truncate(keep)


def _series_entries(folder: pathlib.Path, stem: str, t_ckpt: float):
    pvd = folder / f"{stem}.pvd"
    if not pvd.is_file():
        return []
    try:
        root = ET.parse(pvd).getroot()
    except (ET.ParseError, OSError):
        return []
    tol = 1e-9 * max(1.0, abs(t_ckpt))
    out = []
    for ds in root.iter("DataSet"):
        try:
            t = float(ds.get("timestep"))
        except (TypeError, ValueError):
            continue
        name = ds.get("file")
        if name and t <= t_ckpt + tol and (folder / name).is_file():
            out.append((t, name))
    return out


def resume_writer(folder, disc, every: int, t_ckpt: float):
    """A :class:`~femehl.output.RunWriter` that appends to the existing outputs of ``folder``."""
    from . import RunWriter
    from .table import COLUMNS, SummaryWriter

    folder = pathlib.Path(folder)
    summary = folder / "summary.csv"
    _cut_summary(summary, t_ckpt)

    class _Appending(SummaryWriter):
        def __init__(self, path):          # open for appending; header only for a new file
            import csv
            self.path = pathlib.Path(path)
            new = not self.path.is_file() or self.path.stat().st_size == 0
            self._fh = open(self.path, "a", newline="")
            self._csv = csv.writer(self._fh)
            if new:
                self._csv.writerow(COLUMNS)
            self._fh.flush()

    writer = RunWriter.__new__(RunWriter)
    writer.folder = folder
    writer.summary = _Appending(summary)
    writer.every = every
    writer.last = None
    writer.series = None
    if every:
        from .series import SeriesWriter
        writer.series = SeriesWriter(folder, disc)
        writer.series.entries = _series_entries(folder, writer.series.stem, t_ckpt)
        writer.series._write_index()
    return writer
