"""Checkpoints: the last State of a run, so that it can be resumed.

``folder/checkpoint.npz`` holds one :class:`~femehl.solver.stepping.State` (its
arrays and scalars, including ``d_prev``/``dt_prev`` of two-step schemes) and
``folder/checkpoint.json`` the run's parameters: the scene (described field
by field), the method and the discretization actually built (mesh name,
element and node counts, a hash of the node coordinates; FD: dr, dtheta and
grid size).  Both are written atomically (temporary file + rename), so a
run killed at any moment leaves the previous checkpoint intact.

:func:`femehl.api.run_to_folder` writes a checkpoint every
``checkpoint_every`` steps and at the end of the run (also when it stops on a
:class:`~femehl.errors.SolverError`: then it holds the last good state), and
``run_to_folder(..., resume=True)`` continues from it after
:func:`check_params` has confirmed that scene, method and discretization
are the same.  :func:`resume_writer` reopens the summary CSV for appending
(rows past the checkpoint, from a run that went on after it, are cut off)
and the field series with its numbering continued after the highest-numbered
.vtu present: field files already written are never overwritten, and the
index is rebuilt from the files themselves if the .pvd is damaged or missing.

A checkpoint that cannot be used (unreadable, truncated, missing entries, arrays
that do not fit the discretization) raises :class:`~femehl.errors.CheckpointError`
naming the file and what to do.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
import math
import os
import pathlib
import zipfile
import zlib

import numpy as np

from femehl.errors import CheckpointError, SceneError
from femehl.problem.cavitation import CAVITATION_COLUMNS
from femehl.solver.stepping import State

logger = logging.getLogger("femehl")

__all__ = [
    "CHECKPOINT",
    "PARAMS",
    "check_params",
    "check_state",
    "describe",
    "load_checkpoint",
    "read_params",
    "resume_writer",
    "run_params",
    "save_checkpoint",
    "write_params",
]

CHECKPOINT = "checkpoint.npz"
PARAMS = "checkpoint.json"
FORMAT = 1

_ARRAYS = ("p", "w", "d")
_SCALARS = ("step", "t", "hc", "V", "load", "film_center", "film_min", "p_max")
_KEYS = _ARRAYS + _SCALARS + ("film_min_at", "p_max_at", "has_prev", "d_prev", "dt_prev")
_FIX = (
    "restore an intact copy of it, or start the run again with overwrite=True (--overwrite) "
    "or in another folder (--out)"
)


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
    arrays["d_prev"] = np.asarray(state.d_prev, dtype=float) if state.d_prev is not None else np.zeros(0)
    arrays["dt_prev"] = np.asarray(np.nan if state.dt_prev is None else state.dt_prev, dtype=float)
    for k, v in state.own.items():  # the step parts' own variables, as they are
        arrays[OWN + k] = np.asarray(v, dtype=float)
    for k in CAVITATION_COLUMNS:  # a cavitation condition's per-step figures (summary columns)
        if k in (state.info or {}):
            arrays[f"info_{k}"] = np.asarray(float(state.info[k]))
    arrays["format"] = np.asarray(FORMAT)
    path = folder / CHECKPOINT
    _atomic_write(path, lambda fh: np.savez(fh, **arrays))
    return path


def _bad(path, why: str) -> CheckpointError:
    return CheckpointError(f"cannot resume from the checkpoint {str(path)!r}: {why}; {_FIX}.")


def _scalar(a: dict, key: str, path, kind=float):
    v = a[key]
    if v.size != 1:
        raise _bad(path, f"its entry {key!r} is not a single value (shape {v.shape})")
    return kind(v.reshape(()).item())


def load_checkpoint(folder, reference: State | None = None) -> State:
    """The State saved in ``folder/checkpoint.npz``.

    ``reference`` (e.g. ``stepper.initial_state()``) gives the array sizes the run
    needs.  CheckpointError if the file is missing, unreadable, lacks entries or does
    not fit.
    """
    path = pathlib.Path(folder) / CHECKPOINT
    if not path.is_file():
        raise CheckpointError(
            f"no checkpoint in {str(path.parent)!r} ({CHECKPOINT} is missing): "
            "run without resume first, or give the folder of the run to continue."
        )
    try:
        with np.load(path, allow_pickle=False) as z:
            if not hasattr(z, "files"):
                raise _bad(path, "it is a single array, not a femehl checkpoint")
            a = {k: z[k] for k in z.files}
    except CheckpointError:
        raise
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error, KeyError) as exc:
        raise _bad(path, f"it is damaged or truncated ({type(exc).__name__}: {exc})") from None
    missing = [k for k in _KEYS if k not in a]
    if missing:
        raise _bad(path, f"it lacks the entries {missing}")
    try:
        has_prev = _scalar(a, "has_prev", path, bool)
        dt_prev = _scalar(a, "dt_prev", path)
        floats = {k: _scalar(a, k, path) for k in _SCALARS if k != "step"}
        arrays = {k: np.asarray(a[k], dtype=float) for k in _ARRAYS + ("film_min_at", "p_max_at", "d_prev")}
        step = _scalar(a, "step", path, int)
        cav_info = {k: _scalar(a, f"info_{k}", path) for k in CAVITATION_COLUMNS if f"info_{k}" in a}
    except (TypeError, ValueError) as exc:
        raise _bad(path, f"an entry has the wrong type ({exc})") from None
    if step < 0 or not math.isfinite(floats["t"]) or floats["t"] < 0:
        raise _bad(path, f"its step {step} / time {floats['t']} is not a time a run reaches")
    state = State(
        step=step,
        t=floats["t"],
        hc=floats["hc"],
        V=floats["V"],
        p=arrays["p"],
        w=arrays["w"],
        d=arrays["d"],
        load=floats["load"],
        film_center=floats["film_center"],
        film_min=floats["film_min"],
        film_min_at=tuple(arrays["film_min_at"].tolist()),
        p_max=floats["p_max"],
        p_max_at=tuple(arrays["p_max_at"].tolist()),
        info={"resumed": True, **cav_info},
        d_prev=arrays["d_prev"] if has_prev else None,
        dt_prev=None if math.isnan(dt_prev) else dt_prev,
        own=_own(a, path),
    )
    if reference is not None:
        check_state(state, reference, path)
    return state


#: the prefix of a step part's own variable in the file (``state.own``)
OWN = "own_"
#: the fixed names that checkpoints written before 2026-12-05 gave those variables
_LEGACY = ("hc_dot", "hc_prev", "hc_dot_prev", "p_aux", "creep", "creep_prev", "gas", "gas_prev")


def _own(a: dict, path) -> dict:
    """The step parts' own variables of a checkpoint (an older file's under their old names:
    absent, empty or NaN meant "the run has none")."""
    own = {k.removeprefix(OWN): v for k, v in a.items() if k.startswith(OWN)}
    for k in _LEGACY:
        if k in a and a[k].size and not (a[k].size == 1 and math.isnan(float(a[k].reshape(-1)[0]))):
            own.setdefault(k, a[k])
    out = {}
    for k, v in own.items():
        v = np.asarray(v, dtype=float)
        out[k] = _scalar({k: v}, k, path) if v.ndim == 0 else v
    return out


def check_state(state: State, reference: State, path="checkpoint") -> None:
    """CheckpointError unless ``state``'s arrays have the sizes of ``reference``'s and are finite."""
    for k in _ARRAYS:
        got, want = np.shape(getattr(state, k)), np.shape(getattr(reference, k))
        if got != want:
            raise _bad(path, f"its array {k!r} has shape {got}, the discretization needs {want}")
        if not np.all(np.isfinite(getattr(state, k))):
            raise _bad(path, f"its array {k!r} has non-finite values")
    if state.d_prev is not None and np.shape(state.d_prev) != np.shape(reference.d):
        raise _bad(
            path,
            f"its array 'd_prev' has shape {np.shape(state.d_prev)}, "
            f"the discretization needs {np.shape(reference.d)}",
        )
    for k, v in state.own.items():  # the step parts' own variables: finite, sized as the run's
        ref = reference.own.get(k, reference.own.get(k.removesuffix("_prev")))
        want = np.shape(v) if ref is None else np.shape(ref)
        if np.shape(v) != want or not np.all(np.isfinite(v)):
            raise _bad(
                path,
                f"its variable {k!r} has shape {np.shape(v)} or non-finite values; the run "
                f"needs {want} finite values",
            )


# ---- run parameters ------------------------------------------------------------------------
def describe(obj, depth: int = 0):
    """A JSON-able description of a scene (dataclasses field by field, callables by name)."""
    if depth > 20:
        return repr(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        out = {"type": type(obj).__name__}
        for f in dataclasses.fields(obj):
            value = getattr(obj, f.name)
            if f.metadata.get("describe") == "omit_default" and value == f.default:
                continue  # an option added later: scenes without it describe as before
            out[f.name] = describe(value, depth + 1)
        return out
    if isinstance(obj, (bool, str)) or obj is None:
        return obj
    if isinstance(obj, (int, float, np.integer, np.floating)):
        v = float(obj)
        return v if math.isfinite(v) else repr(v)
    if isinstance(obj, np.ndarray):
        return {
            "array_sha1": hashlib.sha1(np.ascontiguousarray(obj).tobytes()).hexdigest(),
            "shape": list(obj.shape),
        }
    if isinstance(obj, (list, tuple)):
        return [describe(v, depth + 1) for v in obj]
    if isinstance(obj, dict):
        return {str(k): describe(v, depth + 1) for k, v in obj.items()}
    if callable(obj):
        name = getattr(obj, "__qualname__", type(obj).__name__)
        return {"callable": f"{getattr(obj, '__module__', '?')}.{name}"}
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
    return {
        "format": FORMAT,
        "method": stepper.method,
        "scene": describe(scene),
        "discretization": _disc_signature(stepper),
        "dt": float(dt),
    }


def write_params(folder, params: dict) -> pathlib.Path:
    path = pathlib.Path(folder) / PARAMS
    text = json.dumps(params, indent=1, sort_keys=True).encode()
    _atomic_write(path, lambda fh: fh.write(text))
    return path


def read_params(folder) -> dict:
    """The run parameters saved beside the checkpoint (CheckpointError if unusable)."""
    path = pathlib.Path(folder) / PARAMS
    try:
        params = json.loads(path.read_text())
    except FileNotFoundError:
        raise CheckpointError(
            f"no {PARAMS} next to the checkpoint in {str(path.parent)!r}: cannot "
            f"check that the run to resume is the same; {_FIX}."
        ) from None
    except (OSError, ValueError) as exc:
        raise CheckpointError(f"cannot read {str(path)!r} ({type(exc).__name__}: {exc}); {_FIX}.") from None
    if not isinstance(params, dict):
        raise CheckpointError(
            f"{str(path)!r} holds a JSON {type(params).__name__}, not the object of "
            f"run parameters femehl writes; {_FIX}."
        )
    missing = [k for k in ("method", "scene", "discretization") if k not in params]
    if missing:
        raise CheckpointError(f"{str(path)!r} lacks the run parameters {missing}; {_FIX}.")
    return params


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
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
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
            raise SceneError(
                f"cannot resume: {path} differs from the checkpointed run "
                f"(checkpoint: {was!r}, now: {now!r}). Resume with the same scene, "
                "method and mesh/grid, or start a new run in another folder."
            )


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


def _align_summary(path: pathlib.Path, columns: tuple) -> None:
    """Make the header of a summary to be appended to read ``columns``.

    A finished run's file may carry the error-estimate columns (added at its end: they do
    not describe the longer run, and rows appended without them would not fit) and a file
    written before a column existed lacks it (older femehl, e.g. ``cavitated_area``): the
    rows are rewritten with exactly ``columns``, an absent cell left empty (NaN when read).
    """
    import csv

    if not path.is_file():
        return
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    if not rows or tuple(rows[0]) == tuple(columns):
        return
    where = {c: i for i, c in enumerate(rows[0])}
    from femehl.output.table import EARLIER_ESTIMATE, ERROR_COLUMNS

    kept = [c for c in ERROR_COLUMNS if c in where]
    earlier = path.with_name(EARLIER_ESTIMATE)
    if kept and not earlier.is_file():  # the finished part's estimate, merged back at the end
        tmp = earlier.with_name(earlier.name + ".tmp")
        with open(tmp, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["t", *kept])
            for r in rows[1:]:
                w.writerow([r[0]] + [r[where[c]] if where[c] < len(r) else "" for c in kept])
        os.replace(tmp, earlier)
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(columns)
        for r in rows[1:]:
            w.writerow([r[where[c]] if c in where and where[c] < len(r) else "" for c in columns])
    os.replace(tmp, path)
    logger.info("femehl: %s rewritten with the columns of the resumed run", path)


def _continue_series(writer, t_ckpt: float) -> None:
    """Point a SeriesWriter at the files present: index up to ``t_ckpt``, numbering after all."""
    from femehl.output.series import scan_series

    tol = 1e-9 * max(1.0, abs(t_ckpt))
    found = scan_series(writer.folder, writer.stem)
    writer.entries = sorted((t, name) for _, name, t in found if t is not None and t <= t_ckpt + tol)
    writer.next_index = max((n for n, _, _ in found), default=-1) + 1
    kept = [name for _, name, t in found if t is None or t > t_ckpt + tol]
    if kept:
        logger.info(
            "femehl: kept %d field file(s) out of the index (past the checkpoint or of unknown time): %s",
            len(kept),
            ", ".join(kept[:5]) + (", ..." if len(kept) > 5 else ""),
        )
    writer._write_index()


def resume_writer(folder, disc, every: int, t_ckpt: float):
    """A :class:`~femehl.output.RunWriter` that appends to the existing outputs of ``folder``."""
    from femehl.output import RunWriter
    from femehl.output.series import SeriesWriter
    from femehl.output.table import SummaryWriter

    folder = pathlib.Path(folder)
    summary = folder / "summary.csv"
    _cut_summary(summary, t_ckpt)
    from femehl.output.table import columns_for

    columns = columns_for(getattr(disc, "scene", None), disc)
    _align_summary(summary, columns)
    series = None
    if every:
        series = SeriesWriter(folder, disc)
        _continue_series(series, t_ckpt)
    writer = SummaryWriter(summary, append=True, columns=columns)
    return RunWriter(folder, disc, every, summary=writer, series=series)
