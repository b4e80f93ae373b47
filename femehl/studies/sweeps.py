"""Parameter studies on a Dask cluster: a base scene, a grid of parameters, one tidy table.

:func:`sweep` (``femehl sweep SWEEP.toml``) runs each case of a grid, a list or a random
sample over dotted scene fields as a plain femehl run in its own folder ``OUT/cases/<key>``
(:func:`case_key`: finished cases are skipped, shared ones computed once) on
``dask.distributed`` (a local cluster or any scheduler) and writes one table,
``OUT/results.parquet``.  A failed case is recorded, never lost; every case is checked
before the cluster starts.  The sweep file, the dotted names, the folders and the checks:
docs/sweeps.md.
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

from femehl.errors import FemehlError, OutputError, SceneError, SolverError

__all__ = [
    "MAX_CASES",
    "RESULT_COLUMNS",
    "Case",
    "SweepPlan",
    "case_key",
    "check_case_options",
    "check_cluster",
    "check_max_cases",
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
#: of a cavitation condition (:data:`femehl.problem.cavitation.CAVITATION_COLUMNS`), the
#: friction force and its parts (:data:`femehl.solver.energetics.FRICTION_COLUMNS`) and a
#: viscoelastic substrate's energy budget and a rough surface's asperities
#: (:data:`femehl.problem.roughness.ROUGH_COLUMNS`); NaN for a case without one, or without that figure
RESULT_COLUMNS = (
    ("t", "hc", "V", "load", "film_center", "film_min", "p_max")
    + tuple(f"err_{q}{part}" for q in ("load", "film_center", "film_min") for part in ("", "_space", "_time"))
    + ("load_full", "cavitated_area", "full_film_source")
    + ("friction", "shear_couette", "shear_poiseuille", "pressure_drag", "side_force")
    + ("dissipation_film", "power_sliding", "elastic_energy")
    + ("asperity_load", "asperity_share", "asperity_friction")
)
#: statuses a case.json can have; "done" and "failed" are finished (skipped on a re-run)
FINISHED = ("done", "failed")
DEFAULT_OUT = "femehl-out/sweeps"
#: the most cases a sweep may have (counted before the grid is expanded); raise it with
#: ``max_cases`` (``[sweep] max_cases = N``) or split the sweep into several
MAX_CASES = 10_000
#: run options the sweep sets itself (each case runs into its own folder)
_SWEEP_SETS = ("folder", "resume", "overwrite", "progress", "log")


class SweepError(SceneError):
    """A sweep description that cannot run (unknown field, empty grid, bad value)."""


class _NameError(SweepError):
    """A parameter name that addresses nothing (the same for every case: raised at once)."""


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
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise SweepError(
            f"[sample] seed must be an integer >= 0, got {seed!r} ({type(seed).__name__}): give e.g. "
            "seed = 1, or leave it out for 0."
        )
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


def _count(name, spec) -> int:
    """How many values a grid entry has, without making them (a huge ``num`` is not allocated)."""
    if isinstance(spec, list):
        return len(spec)
    if isinstance(spec, dict) and ("logspace" in spec or "linspace" in spec):
        num = spec.get("num")
        if isinstance(num, bool) or not isinstance(num, int) or num < 1:
            kind = "logspace" if "logspace" in spec else "linspace"
            raise SweepError(
                f"grid {name!r}: give {{{kind} = [first, last], num = N}} with two numbers and N >= 1, "
                f"got {spec!r}."
            )
        return num
    return 1


def check_max_cases(max_cases) -> int:
    """``max_cases`` (None: :data:`MAX_CASES`) as a positive integer."""
    if max_cases is None:
        return MAX_CASES
    if isinstance(max_cases, bool) or not isinstance(max_cases, int) or max_cases < 1:
        raise SweepError(
            f"max_cases must be a positive integer, got {max_cases!r} ({type(max_cases).__name__}): "
            f"give e.g. max_cases = 20000, or leave it out for {MAX_CASES}."
        )
    return max_cases


def _too_many(n: int, what: str, max_cases: int) -> None:
    if n > max_cases:
        raise SweepError(
            f"the sweep has {n:,} cases ({what}), more than the limit of {max_cases:,}: split it into "
            "several sweeps (each with its own out), or raise the limit with max_cases = N in [sweep] "
            "(plan_sweep(..., max_cases=N)) if this many runs is meant."
        )


def expand(
    grid: dict | None = None, cases: list | None = None, sample: dict | None = None, max_cases=None
) -> list[dict]:
    """The parameter dicts of a sweep: the grid's every combination, a list, or a sample.

    The number of cases is counted first: more than ``max_cases`` (default
    :data:`MAX_CASES`) is refused before anything is expanded.
    """
    max_cases = check_max_cases(max_cases)
    given = [x is not None for x in (grid, cases, sample)]
    if sum(given) != 1:
        raise SweepError("a sweep needs exactly one of grid (every combination), cases (a list) or sample.")
    if grid is not None:
        if not isinstance(grid, dict) or not grid:
            raise SweepError(
                "the grid is empty: give at least one parameter, e.g. {'fluid.beta': [20, 200]}."
            )
        names = list(grid)
        counts = [_count(n, grid[n]) for n in names]
        _too_many(
            math.prod(counts), " x ".join(f"{c:,} {n}" for n, c in zip(names, counts, strict=True)), max_cases
        )
        lists = [_values(n, grid[n]) for n in names]
        return [dict(zip(names, combo, strict=True)) for combo in itertools.product(*lists)]
    if cases is not None:
        if not isinstance(cases, list) or not cases or not all(isinstance(c, dict) and c for c in cases):
            raise SweepError("cases must be a non-empty list of {name: value} tables.")
        _too_many(len(cases), "the list of cases", max_cases)
        return [dict(c) for c in cases]
    if not isinstance(sample, dict):
        raise SweepError("sample must be a table: n, seed and {name = {uniform|loguniform = [a, b]}}.")
    n = sample.get("n")
    if isinstance(n, int) and not isinstance(n, bool):
        _too_many(n, "[sample] n", max_cases)
    return _sample(sample)


# ---- applying parameters -----------------------------------------------------------------
def _set_dotted(raw: dict, name: str, value) -> None:
    parts = name.split(".")
    if not all(parts):
        raise _NameError(f"parameter {name!r}: a dotted name such as 'fluid.beta' (no empty parts).")
    node = raw
    for i, part in enumerate(parts[:-1]):
        nxt = node.get(part)
        if nxt is None:
            nxt = node[part] = {}
        if not isinstance(nxt, dict):
            raise _NameError(f"parameter {name!r}: {'.'.join(parts[: i + 1])} is a value, not a table.")
        node = nxt
    node[parts[-1]] = copy.deepcopy(value)


def _replace_dotted(obj, name: str, value):
    """``dataclasses.replace`` along a dotted path of a Scene (validated by the dataclasses)."""
    head, _, rest = name.partition(".")
    if not dataclasses.is_dataclass(obj) or head not in {f.name for f in dataclasses.fields(obj)}:
        fields = sorted(f.name for f in dataclasses.fields(obj)) if dataclasses.is_dataclass(obj) else []
        raise _NameError(
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
    from femehl.output.checkpoint import describe

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


#: the run options every case takes besides its method's
RUN_OPTIONS = ("method", "t_end", "dt", "store_every", "checkpoint_every", "tol", "step_tol")


def check_case_options(scene, options: dict) -> dict:
    """Refuse, before anything runs, run options :func:`femehl.api.run_to_folder` would refuse.

    The same checks as the run makes before it writes anything (the method and the scene,
    ``t_end``/``dt``/``store_every``/``checkpoint_every``, ``tol``, ``max_wall``, the
    options of the automatic mode against an expert run, option names the method does not
    take), without building a mesh: a sweep of bad cases is refused before its cluster
    starts.  Values only the discretization can judge (a mesh file's content) are still
    found on the worker (the case is recorded as failed).
    """
    import inspect

    from femehl.accuracy.auto import check_max_wall
    from femehl.api import AUTO_ONLY, check_tolerances, is_automatic, refuse_auto_only
    from femehl.output._validation import check_run_options, check_tol
    from femehl.solver.linsolve import LINEAR_SOLVERS
    from femehl.solver.loop import _registry

    if not all(isinstance(k, str) for k in options):
        raise SceneError(f"run option names must be strings, got {sorted(map(repr, options))}.")
    sets = sorted(k for k in options if k in _SWEEP_SETS)
    if sets:
        raise SceneError(
            f"run option(s) {', '.join(sets)}: the sweep sets these itself (each case runs into its own "
            "folder, finished cases are skipped); remove them from [run]."
        )
    methods = _registry()
    method = options.get("method", getattr(scene, "default_method", "fe"))
    if not isinstance(method, str) or method not in methods:
        raise SceneError(f"unknown method {method!r}: choose one of {sorted(methods)}.")
    if (method == "line") != (scene.default_method == "line"):
        raise SceneError(
            f"method {method!r} does not fit this scene (its method is {scene.default_method!r}): "
            "leave method out, or give a scene of that kind."
        )
    check_tol(options.get("tol"))
    check_tol(options.get("step_tol"), "step_tol")
    if "max_wall" in options:
        check_max_wall(options["max_wall"])
    dt = options.get("dt")
    check_run_options(
        options.get("t_end", 5.0),
        0.01 if dt is None else dt,
        options.get("store_every", 10),
        options.get("checkpoint_every"),
    )
    rest = {k: v for k, v in options.items() if k not in RUN_OPTIONS}
    automatic = is_automatic(scene, method, dt, rest)
    check_tolerances(automatic, options.get("tol"), options.get("step_tol"))
    if not automatic:
        refuse_auto_only(rest)
    takes = set(inspect.signature(methods[method]).parameters) - {"scene"}
    takes |= {"scheme", "linear_solver", "terms"} | set(AUTO_ONLY)
    for sol in LINEAR_SOLVERS.values():
        takes |= set(inspect.signature(sol).parameters)
    unknown = sorted(set(rest) - takes)
    if unknown:
        raise SceneError(
            f"method {method!r} does not take the run option(s) {unknown}: check the spelling; it takes "
            f"{sorted(takes | set(RUN_OPTIONS))}."
        )
    return options


def plan_sweep(
    base=None,
    grid: dict | None = None,
    *,
    cases: list | None = None,
    sample: dict | None = None,
    run: dict | None = None,
    out=None,
    base_path=None,
    max_cases=None,
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
    max_cases : int, optional
        The most cases allowed (default :data:`MAX_CASES`), counted before expanding.

    Raises
    ------
    SweepError
        An unknown field, an empty grid, too many cases, a value the scene refuses, a run
        option a case refuses (:func:`check_case_options`): naming the parameter, and
        every case that cannot run.
    """
    from femehl.problem import presets
    from femehl.problem.scenefile import run_options, scene_from_mapping

    params_list = expand(grid, cases, sample, max_cases)
    if run is not None and not isinstance(run, dict):
        raise SweepError(
            f"run must be a table of run options (e.g. {{t_end = 8.0, tol = 0.01}}), got {run!r} "
            f"({type(run).__name__})."
        )
    run = dict(run or {})
    raw = None
    if isinstance(base, (str, os.PathLike)):
        from femehl.problem.scenefile import tomllib

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
    elif not dataclasses.is_dataclass(base) or not hasattr(base, "default_method"):
        raise SweepError(
            f"base must be a Scene, a scene file's path or its tables (a dict), or None (the paper "
            f"case), got {type(base).__name__}."
        )
    where = pathlib.Path(base_path) if base_path is not None else pathlib.Path("sweep.toml")
    built, names, bad = [], list(dict.fromkeys(k for p in params_list for k in p)), []
    for params in params_list:
        scene_p, run_p = _split_run(params)
        try:
            if raw is not None:
                case_raw = copy.deepcopy(raw)
                for k, v in scene_p.items():
                    _set_dotted(case_raw, k, v)
                scene, file_run = scene_from_mapping(case_raw, where)
                file_run.pop("_dimensional", None)
                options = run_options({**file_run, **run, **run_p})
            else:
                scene = base
                for k, v in scene_p.items():
                    scene = _replace_dotted(scene, k, v)
                options = {**run, **run_p}
            options.setdefault("store_every", 10)
            check_case_options(scene, options)
        except _NameError:
            raise
        except (FemehlError, TypeError, ValueError) as exc:
            bad.append(f"case {_show(params)}: {str(exc).rstrip('.')}")
            continue
        built.append(Case(case_key(scene, options), _jsonable(params), scene, options))
    if bad:
        shown = "; ".join(bad[:5]) + (f"; and {len(bad) - 5} more" if len(bad) > 5 else "")
        raise SweepError(
            f"{len(bad)} of {len(params_list)} cases cannot run (nothing was started): {shown}. "
            "Fix the values (the grid, [run] or the run.* parameters) and run the sweep again."
        )
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
    """A :class:`SweepPlan` from a sweep TOML file (its format: docs/sweeps.md)."""
    from femehl.problem.scenefile import tomllib

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
    for name in known - {"cases"}:
        if name in raw and not isinstance(raw[name], dict):
            raise SweepError(
                f"{path}: {name} must be a table ([{name}] with key = value lines), got {raw[name]!r} "
                f"({type(raw[name]).__name__}): write it as a [{name}] section."
            )
    if "cases" in raw and not (
        isinstance(raw["cases"], list) and all(isinstance(c, dict) for c in raw["cases"])
    ):
        raise SweepError(
            f"{path}: cases must be an array of tables ([[cases]] sections, each with name = value "
            f"lines), got {raw['cases']!r}: write each case as a [[cases]] section."
        )
    head = raw.get("sweep", {})
    if set(head) - {"scene", "out", "max_cases"}:
        raise SweepError(f"{path}: [sweep] takes scene, out and max_cases, got {sorted(head)}.")
    for key, fix in (
        ("scene", 'a path relative to this file, e.g. scene = "paper_sphere.toml"'),
        ("out", 'a folder, e.g. out = "femehl-out/sweeps/beta"'),
    ):
        if key in head and (not isinstance(head[key], str) or not head[key].strip()):
            raise SweepError(
                f"{path}: [sweep] {key} must be a string (a path), got {head[key]!r} "
                f"({type(head[key]).__name__}): give {fix}, in quotes."
            )
    try:
        max_cases = check_max_cases(head.get("max_cases"))
    except SweepError as exc:
        raise SweepError(f"{path}: [sweep] {exc}") from None
    cluster = raw.get("cluster", {})
    if set(cluster) - {"scheduler", "workers", "memory_limit"}:
        raise SweepError(f"{path}: [cluster] takes scheduler, workers, memory_limit; got {sorted(cluster)}.")
    try:
        check_cluster(cluster.get("scheduler"), cluster.get("workers"), cluster.get("memory_limit"))
    except SweepError as exc:
        raise SweepError(f"{path}: [cluster] {exc}") from None
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
            max_cases=max_cases,
        )
    except SweepError as exc:
        raise SweepError(f"{path}: {exc}") from None
    return dataclasses.replace(plan, spec={**plan.spec, "cluster": cluster})


def check_cluster(scheduler=None, workers=None, memory_limit=None) -> None:
    """Refuse cluster settings of the wrong type before anything starts (SweepError naming the fix).

    ``scheduler``: an address string; ``workers``: a positive integer (None: one per
    core; 0 is refused, not read as "all cores"); ``memory_limit``: a size such as
    ``"4GiB"``, ``"auto"``, a number of bytes, or a fraction <= 1 of the machine's memory.
    """
    if scheduler is not None and (not isinstance(scheduler, str) or not scheduler.strip()):
        raise SweepError(
            f"scheduler must be a string (a Dask scheduler address), got {scheduler!r} "
            f'({type(scheduler).__name__}): give e.g. scheduler = "tcp://host:8786", or leave it out '
            "for a local cluster."
        )
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise SweepError(
            f"workers must be a positive integer (local worker processes), got {workers!r} "
            f"({type(workers).__name__}): give e.g. workers = 2 (--workers 2), or leave it out for one "
            f"per core ({os.cpu_count() or 1} here)."
        )
    if memory_limit is None:
        return
    ok = False
    if isinstance(memory_limit, str):
        from dask.utils import parse_bytes

        try:
            ok = memory_limit == "auto" or parse_bytes(memory_limit) > 0
        except (ValueError, TypeError):
            ok = False
    elif isinstance(memory_limit, (int, float)) and not isinstance(memory_limit, bool):
        ok = math.isfinite(memory_limit) and memory_limit > 0
    if not ok:
        raise SweepError(
            f'memory_limit must be a size such as "4GiB" (or "auto", a number of bytes, a fraction '
            f"<= 1 of the memory), got {memory_limit!r} ({type(memory_limit).__name__}): give e.g. "
            'memory_limit = "4GiB", or leave it out for a share of the memory.'
        )


# ---- one case (runs on a worker) ----------------------------------------------------------
def _atomic_json(path: pathlib.Path, data: dict) -> None:
    from femehl.output._files import write_atomic

    text = json.dumps(data, indent=1, default=float)
    write_atomic(path, lambda tmp: tmp.write_text(text))


def read_case(folder) -> dict | None:
    """A case folder's ``case.json`` (None if absent or unreadable: the case is to run)."""
    try:
        return json.loads((pathlib.Path(folder) / "case.json").read_text())
    except (OSError, ValueError):
        return None


def _rows(folder: pathlib.Path) -> list[dict]:
    """The case's summary at its stored times (all steps if it stored no fields)."""
    from femehl.output.series import scan_series
    from femehl.output.table import read_summary

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
    from femehl import __version__
    from femehl.api import run_to_folder
    from femehl.output.checkpoint import describe

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
    from femehl.output._files import writing

    if plan.out.exists() and not plan.out.is_dir():
        raise OutputError(f"{plan.out} is a file, not a folder: give another out for the sweep.")
    with writing(plan.out, "create the sweep folder"):
        plan.out.mkdir(parents=True, exist_ok=True)
    spec_file = plan.out / "sweep.json"
    if spec_file.exists() and not overwrite:
        try:
            old = json.loads(spec_file.read_text())
        except (OSError, ValueError):
            raise OutputError(
                f"{spec_file} is damaged (not readable JSON), so whether {plan.out} holds this sweep is "
                "unknown: give overwrite=True (--overwrite) if it is this sweep's folder (finished case "
                "folders are reused, the table is rewritten), or another out."
            ) from None
        if not isinstance(old, dict) or old.get("cases") != plan.spec["cases"]:
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
    check_cluster(scheduler, workers, memory_limit)
    n = workers if workers is not None else (os.cpu_count() or 1)
    try:
        cluster = LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            memory_limit=memory_limit if memory_limit is not None else "auto",
            dashboard_address=":0",  # a free port: two sweeps on one machine do not collide
        )
    except RuntimeError as exc:  # a worker process that could not start ("Nanny failed to start")
        raise SolverError(
            f"the local Dask cluster's worker processes ({n}) did not start ({exc}). In a script, "
            'start the sweep under `if __name__ == "__main__":` (each worker is a new Python '
            "process that imports the script, and would start the sweep again); or give the "
            "address of a Dask scheduler already running (scheduler=...)."
        ) from None
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

    from femehl.output._validation import check_flag

    check_cluster(scheduler, workers, memory_limit)
    overwrite, retry_failed = check_flag("overwrite", overwrite), check_flag("retry_failed", retry_failed)
    if plan is None:
        plan = plan_sweep(base, grid, cases=cases, sample=sample, run=run, out=out)
    _check_out(plan, overwrite)
    runner = runner or run_case
    records, todo = {}, []
    for c in plan.cases:
        rec = read_case(plan.out / "cases" / c.key)
        if rec is not None and rec.get("key") != c.key:
            rec = None  # not this case's record (a damaged or misplaced case.json): run it
        again = rec is not None and rec.get("status") == "failed" and retry_failed
        if rec is not None and rec.get("status") in FINISHED and not again:
            records[c.key] = rec
        else:
            todo.append(c)
    logger.info(
        "femehl sweep: %d cases, %d finished before, %d to run", len(plan.cases), len(records), len(todo)
    )
    t0 = time.perf_counter()
    interrupted = False
    if todo:
        client, cluster = _client(scheduler, workers, memory_limit)
        try:
            # the task key names the folder too: two sweeps sharing a case on one scheduler
            # each get their own task (never the record of another folder)
            where = hashlib.sha256(str(plan.out.resolve()).encode()).hexdigest()[:8]
            futures = {
                client.submit(
                    runner, c, str(plan.out / "cases" / c.key), key=f"femehl-case-{c.key}-{where}", pure=False
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
        except KeyboardInterrupt:
            interrupted = True  # the table of what finished is written below, then re-raised
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    wall = time.perf_counter() - t0
    table = _table(plan, records)
    _write_parquet(table, plan.out / "results.parquet")
    if interrupted:
        raise KeyboardInterrupt
    ran = [records[c.key].get("wall_s", 0.0) or 0.0 for c in todo if c.key in records]
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
    from femehl.output._files import write_atomic

    write_atomic(path, lambda tmp: df.to_parquet(tmp, index=False), "write the table")


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
