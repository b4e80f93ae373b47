"""Parameter studies on a Dask cluster: a base scene, a grid of parameters, one tidy table.

A *sweep* is a base scene (a TOML scene file, its content as a dict, a
:class:`~femehl.scene.Scene`, or the built-in paper case), a set of parameter values
(a full grid, a list of cases, or a random sample) over dotted scene fields, and the
run options (``tol``, ``t_end``, ``method``, ...).  Each case is a plain femehl run
(:func:`femehl.run.run_to_folder`) in its own folder ``OUT/cases/<key>``, ``key`` the
content hash of the case's scene and options (:func:`case_key`), so

* re-running a sweep skips every case already finished (its ``case.json`` is there),
  and an interrupted sweep resumes where it stopped;
* two sweeps that share a case compute it once.

The cases run on ``dask.distributed``: by default a ``LocalCluster`` on this machine
(one worker process per core, one thread each; the Dask nanny pins BLAS to one thread,
``distributed.nanny.pre-spawn-environ``), or an existing cluster by its scheduler
address (a workstation, an HPC allocation started with dask-jobqueue, a cloud
cluster), unchanged.  A case that fails (FilmRuptureError, a bad combination) is
recorded with its error and the others go on; a case whose worker dies is rescheduled
by Dask on another worker (``distributed.scheduler.allowed-failures`` times) and then
recorded as failed, never lost.

The results are one table, ``OUT/results.parquet`` (Parquet: one row per case and
stored time, the parameters as columns, the headline quantities with their estimated
errors, wall time, status; columnar, typed, read by pandas, polars, DuckDB or Spark
without femehl), rewritten atomically at the end of each sweep run.  ``OUT/sweep.json``
records the sweep; another sweep is refused in the same folder unless
``overwrite=True`` (its table is replaced; the case folders stay and are reused).

Dotted names address the scene file's tables: ``fluid.beta``, ``indenter.Rx``,
``motion.load`` (a number: a constant imposed load), ``motion.velocity.V_ss``,
``domain.L``, ``si.V_ss`` (a scene stated in SI units), or a whole table
(``indenter = {kind = "ellipsoid", Rx = 1, Ry = 2}``).  With a Scene object the names
are its dataclass fields (``fluid.beta``, ``indenter.Rx``, ``domain.L``).  The run
options are ``run.<option>`` (``run.tol``) or the sweep's ``[run]`` table.

Sweep file (``femehl sweep SWEEP.toml``)::

    [sweep]
    scene = "../examples/paper_sphere.toml"   # relative to this file; default: paper case
    out = "femehl-out/sweeps/beta"            # default: femehl-out/sweeps/<file name>

    [grid]                                    # every combination (or [[cases]], [sample])
    "fluid.beta" = { logspace = [20, 20000], num = 12 }
    indenter = [ { kind = "sphere", R = 1.0 }, { kind = "ellipsoid", Rx = 1.0, Ry = 2.0 } ]

    [run]                                     # options of every case
    t_end = 8.0

    [cluster]                                 # optional: scheduler = "tcp://host:8786",
    workers = 2                               #   memory_limit = "4GiB"
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import itertools
import json
import logging
import math
import os
import pathlib
import time

import numpy as np

from .errors import FemehlError, OutputError, SceneError

__all__ = [
    "RESULT_COLUMNS",
    "Case",
    "SweepPlan",
    "case_key",
    "load_sweep_file",
    "plan_sweep",
    "read_results",
    "run_case",
    "sweep",
]

logger = logging.getLogger("femehl")

#: the headline columns of the table (each case's summary at its stored times): the
#: estimated relative errors ``err_<q>`` (total) and their space and time parts (an
#: expert run, e.g. ``mesh = "fitted"`` with ``dt``, has the parts only), and the figures
#: of a cavitation condition (:data:`femehl.cavitation.CAVITATION_COLUMNS`) and of a
#: viscoelastic substrate (:data:`femehl.tribology.ENERGETICS_COLUMNS`); NaN for a case
#: without one, or without that figure
RESULT_COLUMNS = (
    ("t", "hc", "V", "load", "film_center", "film_min", "p_max")
    + tuple(f"err_{q}{part}" for q in ("load", "film_center", "film_min") for part in ("", "_space", "_time"))
    + ("load_full", "cavitated_area", "full_film_source")
    + ("friction", "dissipation_film", "power_sliding", "elastic_energy")
)
#: statuses a case.json can have; "done" and "failed" are finished (skipped on a re-run)
FINISHED = ("done", "failed")
DEFAULT_OUT = "femehl-out/sweeps"


class SweepError(SceneError):
    """A sweep description that cannot run (unknown field, empty grid, bad value)."""


@dataclasses.dataclass(frozen=True)
class Case:
    """One run of a sweep: its parameters, scene, run options and content key."""

    key: str
    params: dict
    scene: object
    options: dict


@dataclasses.dataclass(frozen=True)
class SweepPlan:
    """Every case of a sweep, the output folder and the sweep's own description."""

    cases: tuple
    out: pathlib.Path
    spec: dict  # JSON-able: parameters and options (sweep.json)
    names: tuple  # the swept parameter names, in order


def _need_extra() -> None:
    """The sweep extra (dask.distributed, pandas, pyarrow) is installed, or femehl's error."""
    import importlib.util

    missing = [m for m in ("distributed", "pandas", "pyarrow") if importlib.util.find_spec(m) is None]
    if missing:
        raise FemehlError(
            f"sweeps need {', '.join(missing)}: install them with  python -m pip install 'femehl[sweep]'"
            "  (or  pip install -e '.[sweep]'  in a checkout)."
        )


# ---- parameter values --------------------------------------------------------------------
def _values(name, spec):
    """The list of values of one grid entry: a list, or {logspace|linspace = [a, b], num = n}."""
    if isinstance(spec, list):
        vals = spec
    elif isinstance(spec, dict) and ("logspace" in spec or "linspace" in spec):
        kind = "logspace" if "logspace" in spec else "linspace"
        ends, num = spec[kind], spec.get("num")
        ok = isinstance(ends, list) and len(ends) == 2 and all(_is_number(v) for v in ends)
        if not ok or isinstance(num, bool) or not isinstance(num, int) or num < 1:
            raise SweepError(
                f"grid {name!r}: give {{{kind} = [first, last], num = N}} with two numbers and N >= 1, "
                f"got {spec!r}."
            )
        if set(spec) - {kind, "num"}:
            raise SweepError(f"grid {name!r}: {kind} takes only num besides the ends, got {sorted(spec)}.")
        if kind == "logspace":
            if min(ends) <= 0:
                raise SweepError(f"grid {name!r}: logspace needs positive ends, got {ends}; use linspace.")
            vals = np.geomspace(ends[0], ends[1], num).tolist()
        else:
            vals = np.linspace(ends[0], ends[1], num).tolist()
    else:
        vals = [spec]
    if not vals:
        raise SweepError(f"grid {name!r} is empty: give at least one value.")
    return vals


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _sample(spec: dict) -> list[dict]:
    """``n`` random cases: each name = {uniform|loguniform = [a, b]} (seeded)."""
    spec = dict(spec)
    n, seed = spec.pop("n", None), spec.pop("seed", 0)
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise SweepError(f"[sample] needs n = number of cases (an integer >= 1), got {n!r}.")
    if not spec:
        raise SweepError('[sample] names no parameter: add e.g. "fluid.beta" = { loguniform = [20, 20000] }.')
    rng = np.random.default_rng(seed)
    cols = {}
    for name, r in spec.items():
        kind = next((k for k in ("uniform", "loguniform") if isinstance(r, dict) and k in r), None)
        ends = r.get(kind) if kind else None
        if kind is None or not (isinstance(ends, list) and len(ends) == 2 and all(map(_is_number, ends))):
            raise SweepError(
                f"[sample] {name!r}: give {{uniform = [a, b]}} or {{loguniform = [a, b]}}, got {r!r}."
            )
        if kind == "loguniform":
            if min(ends) <= 0:
                raise SweepError(f"[sample] {name!r}: loguniform needs positive ends, got {ends}.")
            cols[name] = np.exp(rng.uniform(math.log(ends[0]), math.log(ends[1]), n)).tolist()
        else:
            cols[name] = rng.uniform(ends[0], ends[1], n).tolist()
    return [{k: cols[k][i] for k in cols} for i in range(n)]


def expand(grid: dict | None = None, cases: list | None = None, sample: dict | None = None) -> list[dict]:
    """The parameter dicts of a sweep: the grid's every combination, a list, or a sample."""
    given = [x is not None for x in (grid, cases, sample)]
    if sum(given) != 1:
        raise SweepError("a sweep needs exactly one of grid (every combination), cases (a list) or sample.")
    if grid is not None:
        if not isinstance(grid, dict) or not grid:
            raise SweepError(
                "the grid is empty: give at least one parameter, e.g. {'fluid.beta': [20, 200]}."
            )
        names = list(grid)
        lists = [_values(n, grid[n]) for n in names]
        return [dict(zip(names, combo, strict=True)) for combo in itertools.product(*lists)]
    if cases is not None:
        if not isinstance(cases, list) or not cases or not all(isinstance(c, dict) and c for c in cases):
            raise SweepError("cases must be a non-empty list of {name: value} tables.")
        return [dict(c) for c in cases]
    if not isinstance(sample, dict):
        raise SweepError("sample must be a table: n, seed and {name = {uniform|loguniform = [a, b]}}.")
    return _sample(sample)


# ---- applying parameters -----------------------------------------------------------------
def _set_dotted(raw: dict, name: str, value) -> None:
    parts = name.split(".")
    if not all(parts):
        raise SweepError(f"parameter {name!r}: a dotted name such as 'fluid.beta' (no empty parts).")
    node = raw
    for i, part in enumerate(parts[:-1]):
        nxt = node.get(part)
        if nxt is None:
            nxt = node[part] = {}
        if not isinstance(nxt, dict):
            raise SweepError(f"parameter {name!r}: {'.'.join(parts[: i + 1])} is a value, not a table.")
        node = nxt
    node[parts[-1]] = copy.deepcopy(value)


def _replace_dotted(obj, name: str, value):
    """``dataclasses.replace`` along a dotted path of a Scene (validated by the dataclasses)."""
    head, _, rest = name.partition(".")
    if not dataclasses.is_dataclass(obj) or head not in {f.name for f in dataclasses.fields(obj)}:
        fields = sorted(f.name for f in dataclasses.fields(obj)) if dataclasses.is_dataclass(obj) else []
        raise SweepError(
            f"parameter {name!r}: {type(obj).__name__} has no field {head!r}"
            + (f"; it has {fields}." if fields else ".")
        )
    new = value if not rest else _replace_dotted(getattr(obj, head), rest, value)
    return dataclasses.replace(obj, **{head: new})


def _split_run(params: dict) -> tuple[dict, dict]:
    scene_p = {k: v for k, v in params.items() if not k.startswith("run.")}
    run_p = {k[4:]: v for k, v in params.items() if k.startswith("run.")}
    return scene_p, run_p


def case_key(scene, options: dict) -> str:
    """Content hash (16 hex digits) of a case's scene and run options."""
    from .output.checkpoint import describe

    blob = json.dumps({"scene": describe(scene), "options": describe(options)}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def _jsonable(v):
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    if isinstance(v, dict):
        return {str(k): _jsonable(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    return v


def plan_sweep(
    base=None,
    grid: dict | None = None,
    *,
    cases: list | None = None,
    sample: dict | None = None,
    run: dict | None = None,
    out=None,
    base_path=None,
) -> SweepPlan:
    """Every case of a sweep, built and checked before anything runs.

    Parameters
    ----------
    base : Scene, dict, str or path, optional
        The base scene: a Scene object, a scene file's content (dict of tables), a TOML
        scene file, or None for the paper case.
    grid, cases, sample : optional
        Exactly one: ``{name: values}`` (every combination; values a list or
        ``{"logspace": [a, b], "num": n}`` / linspace), a list of ``{name: value}``, or
        ``{"n": n, "seed": s, name: {"uniform" | "loguniform": [a, b]}}``.
    run : dict, optional
        Run options of every case (``t_end``, ``tol``, ``method``, ``dt``, ``mesh``, ...);
        with a scene file its ``[run]`` table first.
    out : path, optional
        Output folder (default ``femehl-out/sweeps/sweep``).
    base_path : path, optional
        The file a dict ``base`` came from (messages, relative paths).

    Raises
    ------
    SweepError
        An unknown field, an empty grid, a value the scene refuses: naming the parameter.
    """
    from . import presets
    from .scenefile import run_options, scene_from_mapping

    params_list = expand(grid, cases, sample)
    run = dict(run or {})
    raw = None
    if isinstance(base, (str, os.PathLike)):
        from .scenefile import tomllib

        base_path = pathlib.Path(base)
        try:
            raw = tomllib.loads(base_path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise SweepError(f"base scene file {str(base_path)!r} does not exist: check the path.") from None
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
            raise SweepError(f"cannot read the base scene {str(base_path)!r}: {exc}.") from None
    elif isinstance(base, dict):
        raw = base
    elif base is None:
        base = presets.paper_sphere()
    where = pathlib.Path(base_path) if base_path is not None else pathlib.Path("sweep.toml")
    built, names = [], list(dict.fromkeys(k for p in params_list for k in p))
    for params in params_list:
        scene_p, run_p = _split_run(params)
        if raw is not None:
            case_raw = copy.deepcopy(raw)
            for k, v in scene_p.items():
                _set_dotted(case_raw, k, v)
            try:
                scene, file_run = scene_from_mapping(case_raw, where)
            except FemehlError as exc:
                raise SweepError(f"case {_show(params)}: {exc}") from None
            file_run.pop("_dimensional", None)
            try:
                options = run_options({**file_run, **run, **run_p})
            except FemehlError as exc:
                raise SweepError(f"case {_show(params)}: {exc}") from None
        else:
            scene = base
            for k, v in scene_p.items():
                try:
                    scene = _replace_dotted(scene, k, v)
                except SweepError:
                    raise
                except (FemehlError, TypeError, ValueError) as exc:
                    raise SweepError(f"case {_show(params)}: {exc}") from None
            options = {**run, **run_p}
        options.setdefault("store_every", 10)
        built.append(Case(case_key(scene, options), _jsonable(params), scene, options))
    keys = [c.key for c in built]
    if len(set(keys)) < len(keys):
        raise SweepError(
            "two cases of the sweep are the same scene and options: remove the duplicate values."
        )
    out = pathlib.Path(out) if out is not None else pathlib.Path(DEFAULT_OUT) / "sweep"
    spec = {"names": names, "cases": {c.key: c.params for c in built}, "run": _jsonable(run)}
    return SweepPlan(tuple(built), out, spec, tuple(names))


def _show(params: dict) -> str:
    return ", ".join(f"{k} = {v!r}" for k, v in params.items())


def load_sweep_file(path) -> SweepPlan:
    """A :class:`SweepPlan` from a sweep TOML file (see the module docstring)."""
    from .scenefile import tomllib

    path = pathlib.Path(path)
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SweepError(f"sweep file {str(path)!r} does not exist: check the path.") from None
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise SweepError(f"cannot read sweep file {str(path)!r}: {exc}.") from None
    known = {"sweep", "grid", "cases", "sample", "run", "cluster"}
    if set(raw) - known:
        raise SweepError(f"{path}: unknown table(s) {sorted(set(raw) - known)}; known: {sorted(known)}.")
    head = raw.get("sweep", {})
    if set(head) - {"scene", "out"}:
        raise SweepError(f"{path}: [sweep] takes scene and out, got {sorted(head)}.")
    base = head.get("scene")
    base = (path.parent / base) if base is not None else None
    out = head.get("out", str(pathlib.Path(DEFAULT_OUT) / path.stem))
    try:
        plan = plan_sweep(
            base,
            raw.get("grid"),
            cases=raw.get("cases"),
            sample=raw.get("sample"),
            run=raw.get("run"),
            out=out,
        )
    except SweepError as exc:
        raise SweepError(f"{path}: {exc}") from None
    cluster = raw.get("cluster", {})
    if set(cluster) - {"scheduler", "workers", "memory_limit"}:
        raise SweepError(f"{path}: [cluster] takes scheduler, workers, memory_limit; got {sorted(cluster)}.")
    return dataclasses.replace(plan, spec={**plan.spec, "cluster": cluster})


# ---- one case (runs on a worker) ----------------------------------------------------------
def _atomic_json(path: pathlib.Path, data: dict) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=1, default=float))
    os.replace(tmp, path)


def read_case(folder) -> dict | None:
    """A case folder's ``case.json`` (None if absent or unreadable: the case is to run)."""
    try:
        return json.loads((pathlib.Path(folder) / "case.json").read_text())
    except (OSError, ValueError):
        return None


def _rows(folder: pathlib.Path) -> list[dict]:
    """The case's summary at its stored times (all steps if it stored no fields)."""
    from .output.series import scan_series
    from .output.table import read_summary

    try:
        table = read_summary(folder / "summary.csv")
    except OutputError:
        return []
    t = table["t"]
    stored = sorted({ts for _, _, ts in scan_series(folder) if ts is not None})
    if stored:
        idx = [int(np.argmin(np.abs(t - s))) for s in stored if t.size]
        idx = sorted(set(idx))
    else:
        idx = list(range(t.size))
    nan = np.full(t.size, np.nan)
    return [{c: float(table.get(c, nan)[i]) for c in RESULT_COLUMNS} for i in idx]


def run_case(case: Case, folder) -> dict:
    """Run one case into ``folder`` (its ``case.json`` last, atomically); returns the record.

    A femehl error (film rupture, a refused combination) is recorded as ``status =
    "failed"`` with its message; what the run wrote before it stays.  Another exception
    (a bug) is recorded as ``"error"``.  A folder whose ``case.json`` says done is
    returned as it is (a rescheduled task does not run twice).
    """
    from . import __version__
    from .output.checkpoint import describe
    from .run import run_to_folder

    folder = pathlib.Path(folder)
    done = read_case(folder)
    if done is not None and done.get("status") == "done" and done.get("key") == case.key:
        return done  # already run (a rescheduled task); a failed one is run again when asked
    folder.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    record = {
        "key": case.key,
        "params": case.params,
        "options": _jsonable(case.options),
        "scene": describe(case.scene),
        "femehl": __version__,
        "host": os.uname().nodename if hasattr(os, "uname") else "",
        "blas_threads": os.environ.get("OPENBLAS_NUM_THREADS"),
    }
    log = folder / "run.log"
    with open(log, "w") as fh:

        def say(msg):
            fh.write(str(msg) + "\n")
            fh.flush()

        try:
            res = run_to_folder(case.scene, folder, overwrite=True, progress=False, log=say, **case.options)
            record.update(status="done", error=None, elements=res.info.get("elements"), steps=res.nsteps)
        except FemehlError as exc:
            record.update(status="failed", error=f"{type(exc).__name__}: {exc}")
            say(record["error"])
        except Exception as exc:  # noqa: BLE001 - recorded; the sweep goes on
            import traceback

            record.update(status="error", error=f"{type(exc).__name__}: {exc}")
            say(traceback.format_exc())
    record["wall_s"] = time.perf_counter() - t0
    record["rows"] = _rows(folder)
    _atomic_json(folder / "case.json", record)
    return record


# ---- the sweep ---------------------------------------------------------------------------
def _check_out(plan: SweepPlan, overwrite: bool) -> None:
    plan.out.mkdir(parents=True, exist_ok=True)
    spec_file = plan.out / "sweep.json"
    if spec_file.is_file() and not overwrite:
        try:
            old = json.loads(spec_file.read_text())
        except ValueError:
            old = None
        if old is None or old.get("cases") != plan.spec["cases"]:
            raise OutputError(
                f"{plan.out} holds another sweep (its sweep.json differs): give another out, or "
                "overwrite=True (--overwrite) to replace its table (the case folders stay and are reused)."
            )
    _atomic_json(spec_file, plan.spec)


def _client(scheduler, workers, memory_limit):
    """A client of the given scheduler, or of a new LocalCluster (and the cluster to close)."""
    from distributed import Client, LocalCluster

    if scheduler:
        try:
            return Client(scheduler, timeout="20s"), None
        except (OSError, TimeoutError) as exc:
            raise OutputError(
                f"cannot reach the Dask scheduler at {scheduler!r} ({exc}): check the address, or leave "
                "scheduler out to run on a local cluster."
            ) from None
    n = workers or os.cpu_count() or 1
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise SweepError(f"workers must be an integer >= 1, got {workers!r}.")
    cluster = LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        memory_limit=memory_limit if memory_limit is not None else "auto",
        dashboard_address=":0",  # a free port: two sweeps on one machine do not collide
    )
    return Client(cluster), cluster


def sweep(
    base=None,
    grid: dict | None = None,
    *,
    cases: list | None = None,
    sample: dict | None = None,
    run: dict | None = None,
    out=None,
    scheduler: str | None = None,
    workers: int | None = None,
    memory_limit=None,
    overwrite: bool = False,
    retry_failed: bool = False,
    progress: bool = True,
    plan: SweepPlan | None = None,
    runner=None,
):
    """Run a sweep on Dask and return its table (a pandas DataFrame, also ``OUT/results.parquet``).

    Parameters
    ----------
    base, grid, cases, sample, run, out
        The sweep (:func:`plan_sweep`), or ``plan`` built already.
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:8786``); default: a new
        LocalCluster with ``workers`` processes (default: the cores), one thread each.
    memory_limit : str or int, optional
        Memory per local worker (e.g. ``"4GiB"``); Dask restarts a worker above it and the
        case is retried, then recorded as failed.
    overwrite : bool
        Replace the table of another sweep in ``out`` (case folders are kept).
    retry_failed : bool
        Run again the cases recorded as failed (default: finished cases are skipped).
    progress : bool
        A progress bar over cases with the running count of failures.
    runner : callable, optional
        ``runner(case, folder) -> record`` instead of :func:`run_case` (tests).

    Returns
    -------
    pandas.DataFrame
        One row per case and stored time (one row with empty headline columns for a case
        that stored nothing): ``case``, ``status``, ``error``, ``wall_s``, ``elements``,
        the parameters (dotted names) and :data:`RESULT_COLUMNS`.
    """
    _need_extra()
    from distributed import as_completed

    if plan is None:
        plan = plan_sweep(base, grid, cases=cases, sample=sample, run=run, out=out)
    _check_out(plan, overwrite)
    runner = runner or run_case
    records, todo = {}, []
    for c in plan.cases:
        rec = read_case(plan.out / "cases" / c.key)
        again = rec is not None and rec.get("status") == "failed" and retry_failed
        if rec is not None and rec.get("status") in FINISHED and not again:
            records[c.key] = rec
        else:
            todo.append(c)
    logger.info(
        "femehl sweep: %d cases, %d finished before, %d to run", len(plan.cases), len(records), len(todo)
    )
    t0 = time.perf_counter()
    if todo:
        client, cluster = _client(scheduler, workers, memory_limit)
        try:
            futures = {
                client.submit(
                    runner, c, str(plan.out / "cases" / c.key), key=f"femehl-case-{c.key}", pure=False
                ): c
                for c in todo
            }
            bar = _bar(len(todo), progress)
            failed = 0
            for fut in as_completed(futures):
                c = futures[fut]
                try:
                    rec = fut.result()
                except Exception as exc:  # noqa: BLE001 - a worker died (KilledWorker) or the runner raised
                    rec = {
                        "key": c.key,
                        "params": c.params,
                        "status": "failed",
                        "error": f"{type(exc).__name__}: {exc} (the worker died or the case could not run)",
                        "rows": [],
                    }
                    folder = plan.out / "cases" / c.key
                    folder.mkdir(parents=True, exist_ok=True)
                    _atomic_json(folder / "case.json", rec)
                records[c.key] = rec
                failed += rec.get("status") != "done"
                if bar is not None:
                    bar.set_postfix(failed=failed)
                    bar.update(1)
            if bar is not None:
                bar.close()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    wall = time.perf_counter() - t0
    table = _table(plan, records)
    _write_parquet(table, plan.out / "results.parquet")
    ran = [records[c.key].get("wall_s", 0.0) or 0.0 for c in todo]
    info = {
        "wall_s": wall,
        "cases_s": float(sum(ran)),
        "ran": len(todo),
        "skipped": len(plan.cases) - len(todo),
    }
    _atomic_json(plan.out / "last_run.json", info)
    table.attrs["sweep"] = info
    return table


def _bar(n, progress):
    if not progress:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=n, desc="femehl sweep", unit="case")


def _cell(v):
    """A parameter value as a table cell: numbers and strings as they are, tables as JSON."""
    if isinstance(v, (int, float, str, bool)) or v is None:
        return v
    return json.dumps(v, sort_keys=True)


def _table(plan: SweepPlan, records: dict):
    import pandas as pd

    rows = []
    for c in plan.cases:
        rec = records.get(c.key, {"status": "missing", "rows": []})
        base = {
            "case": c.key,
            "status": rec.get("status"),
            "error": rec.get("error"),
            "wall_s": rec.get("wall_s"),
            "elements": rec.get("elements"),
        }
        base.update({n: _cell(c.params.get(n)) for n in plan.names})
        # the case's own files where this machine sees them (a shared file system), else
        # what its worker returned
        found = _rows(plan.out / "cases" / c.key) if rec.get("status") != "missing" else []
        for r in found or rec.get("rows") or [dict.fromkeys(RESULT_COLUMNS, np.nan)]:
            rows.append({**base, **{k: r.get(k, np.nan) for k in RESULT_COLUMNS}})
    df = pd.DataFrame(rows)
    for n in plan.names:  # a column of numbers and JSON strings: all as text
        if df[n].map(type).nunique() > 1:
            df[n] = df[n].map(lambda v: v if isinstance(v, str) else json.dumps(v))
    return df


def _write_parquet(df, path: pathlib.Path) -> None:
    tmp = path.with_name(path.name + ".tmp")
    df.to_parquet(tmp, index=False)
    os.replace(tmp, path)


def read_results(out):
    """The table of a sweep folder (``OUT/results.parquet``) as a pandas DataFrame."""
    _need_extra()
    import pandas as pd

    path = pathlib.Path(out) / "results.parquet"
    if not path.is_file():
        raise OutputError(f"{out} has no results.parquet: run the sweep first (femehl sweep SWEEP.toml).")
    try:
        return pd.read_parquet(path)
    except Exception as exc:  # noqa: BLE001 - pyarrow raises many kinds
        raise OutputError(
            f"cannot read {path} ({type(exc).__name__}: {exc}); rerun the sweep to rewrite it."
        ) from None
