"""Converged reference solutions of the scenes of ``femehl bench auto`` (benchmarks/auto_scenes.py).

For each scene of :data:`auto_scenes.SCENES` the time series of ``load``, ``film_center``
and ``film_min`` (and where the minimum film is) to ``t_end``:

* FE, BDF2 at the FIXED step ``DT = 0.005`` (``DT / 2`` for the scenes of
  :data:`DT_OVERRIDES`, the time error there as large as the errors checked), on the fitted meshes
  ``femehl.discretize.fitted.fitted_disk(scene, t_end, level)`` (fitted to
  ``auto_scenes.MESH_SCENES[name]()`` instead of the scene where it has one) at two levels ``L_a = 0.7`` and
  ``L_b = 0.5`` (size ratio ``r = L_a / L_b = 1.4``, about twice the elements);
* the reference is the Richardson extrapolation in h of order 2 at every time of the
  series (both runs have the same fixed times):
  ``q_ref = q_b + (q_b - q_a) / (r^2 - 1)``;
* its uncertainty per quantity is ``max_t |q_ref - q_b| / scale`` (the size of the
  correction), and the time-discretization error is measured once per scene by a third
  run at level ``L_a`` with ``dt = 2 DT``: ``max_t |q(2 DT) - q(DT)| / 3 / scale`` (BDF2,
  order 2: the error of the ``DT`` run).  ``scale = max(|q|, 0.1)`` for the load (a load
  growing from 0 has no relative error; the floor of :mod:`femehl.accuracy.auto`) and ``|q|`` for
  the films.  t = 0 is left out of the maxima.

Budget rule: a scene whose level-0.5 mesh would exceed ``MAX_ELEMENTS_B = 16000``
elements (``fitted_sizes(...).estimate_elements``), or whose three runs are estimated to
take more than ``MAX_SCENE_S = 480`` s, uses the levels ``(1.0, 0.7)`` instead (ratio
1/0.7); the levels used and why are recorded.  The cost estimate (:func:`estimate`) runs
the whole scene on the level-1 mesh at ``dt = 2 DT`` (the probe; with the levels
(1.0, 0.7) it is the time-error run itself) and scales its wall time by the square of the
estimated element count (the dense influence operator).  :data:`LEVEL_OVERRIDES` sets the
levels of a scene by hand (winkler: finer, its operator is sparse) and adds a third, coarser
level ("coarse") for the observed order.  ``diagnostics`` per quantity in the JSON: the
times of the maxima, the values at ``t_end`` and the maxima over ``t >= 1``.

Each run is a fresh subprocess with ``OMP_NUM_THREADS = OPENBLAS_NUM_THREADS =
MKL_NUM_THREADS = 1`` set in its environment before numpy is imported, one at a time.
Results go to benchmarks/auto_reference_scenes.json as they come (every finished run is
kept: a killed script resumes with ``--resume`` and reruns only what is missing; without
``--resume`` the named scenes are redone and the others kept; ``--refine`` adds the finer
reference over the first part of a run of :data:`REFINE`, about 32 minutes on one core for
beta = 2000); a run that stops
(FilmRuptureError, ...) is recorded with the reason and the scene is marked failed.
The JSON keeps per scene: ``t_end``, ``levels``, ``reference`` (``t``, the three series,
``film_min_x`` / ``film_min_y`` of the finer run), ``uncertainty``, ``time_error``,
``total_error``, ``diagnostics``, ``runs`` (series, elements, wall, load averages, peak
memory of each run), ``estimate`` and ``machine``.

Run (48 minutes for the committed JSON on the 2-core machine, one core; the other was
in use)::

    nohup python benchmarks/auto_reference_scenes.py --resume > ref.log 2>&1 &
    python benchmarks/auto_reference_scenes.py --estimate          # the probes and cost table
    python benchmarks/auto_reference_scenes.py --only paper,punch --resume
    python benchmarks/auto_reference_scenes.py --refine sphere_b2000_approach,sphere_b2000_sliding
    python benchmarks/auto_reference_scenes.py --recompute         # references from the stored runs
    python benchmarks/auto_reference_scenes.py --table             # rebuild the .md from the .json
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import pathlib  # noqa: E402
import platform  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

HERE = pathlib.Path(__file__).resolve().parent
OUT = HERE / "auto_reference_scenes.json"
TABLE = HERE / "auto_reference_scenes.md"
DT = 0.005
LEVELS = (0.7, 0.5)
LEVELS_BIG = (1.0, 0.7)
ORDER = 2
MAX_ELEMENTS_B = 16_000
MAX_SCENE_S = 480.0
QUANTITIES = ("load", "film_center", "film_min")
LOAD_FLOOR = 0.1  # femehl.solver.adaptive.LOAD_FLOOR, as femehl.auto uses it
SIG = 10  # significant digits kept in the JSON
#: scene -> (levels, reason): levels chosen by hand after a first reference.  Each such
#: scene also gets a run at ``ratio * L_a`` ("coarse"), so three levels give the
#: observed order.
LEVEL_OVERRIDES = {
    "winkler": (
        (0.25, 0.25 / 1.4),
        "Winkler: the substrate operator is sparse (local), so finer meshes are cheap (no dense "
        "operator); two levels finer than the default (the automatic mode's budget on a local "
        "substrate reaches level 0.25), and three levels for the observed order",
    ),
    **{
        name: (
            (0.25, 0.18),
            "beta = 2000: at levels (1, 0.7) the film_min correction was 2.9 %, as large as the "
            "tolerance it checks; the fast elastic operator (from 12,000 elements on) makes "
            "levels 0.25 and 0.18 (about 89,000 and 171,000 elements) affordable, and three "
            "levels give the observed order",
        )
        for name in ("sphere_b2000_approach", "sphere_b2000_sliding")
    },
    **{
        name: (
            (0.18, 0.13),
            "the check of tol = 1e-3: at levels (0.7, 0.5) the films' correction was 0.3-0.4 %; "
            "levels 0.18 and 0.13 (about 51,000 and 97,000 elements, the fast operator) are "
            "finer than the automatic run's last level (0.25 at tol = 1e-3), and three levels "
            "give the observed order",
        )
        for name in ("sphere_b20_sliding", "sphere_b20_approach")
    },
    "sphere_b20000_approach": (
        (0.5, 0.5 / 1.4),
        "beta = 20000: the fitted mesh's contact zone capped at 2.4 edge sizes (2026-12-03; "
        "before, levels (1, 0.7) differed by 17 % in film_min during the approach); at levels "
        "(1, 0.7) of the capped mesh the film_min correction was 1.2 % at t = 0.715 (three levels "
        "not monotone there) and the automatic run at tol = 1e-2 ended at 81,000 cells, about "
        "the finer one; levels 0.5 and 0.357 (about 98,000 and 192,000 elements, the fast "
        "operator) at dt = 0.0025, level 0.7 the third, coarser one (2026-12-05)",
    ),
    "sphere_b20000_sliding": (
        (1.0, 0.7),
        "beta = 20000: the fitted mesh's contact zone capped at 2.4 edge sizes (2026-12-03; "
        "before, levels (1, 0.7) differed by 17 % in film_min during the approach); levels 1 "
        "and 0.7 of the capped mesh (about 25,000 and 52,000 elements, the fast operator) at "
        "dt = 0.0025, and three levels for the observed order",
    ),
    "ellipsoid_x": (
        (0.5, 0.35),
        "at levels (1, 0.7) the film_min correction was 0.7 %, as large as the tolerance it "
        "checks, and the automatic run ended on the finer reference mesh; levels 0.5 and 0.35 "
        "(about 22,000 and 45,000 elements, the fast operator) and three levels for the "
        "observed order",
    ),
    "ellipsoid_y": (
        (0.35, 0.245),
        "at levels (1, 0.7) the film_min correction was 1.1 %; at levels (0.5, 0.35) 0.47 %, "
        "largest at t = 2.09, where the minimum film moves between elements and three levels "
        "(0.71, 0.5, 0.35) were not in the asymptotic range (differences 0.24 % then 0.49 %); "
        "levels 0.35 and 0.245 (about 43,000 and 89,000 elements, the fast operator), the "
        "level-0.5 run the third, coarser level",
    ),
    "user_shape": (
        (0.35, 0.25),
        "at levels (0.7, 0.5) the films' correction was 0.7-1.2 %, as large as the tolerance it "
        "checks, and the automatic run ended on the finer reference mesh; levels 0.35 and 0.25 "
        "(about 23,000 and 46,000 elements, the fast operator) and three levels for the observed "
        "order",
    ),
    **{
        name: (
            (0.35, 0.25),
            "the check of tol = 1e-3: at levels (0.7, 0.5) the film_min correction was "
            "0.16-0.25 %, more than the 0.1 % it checks; levels 0.35 and 0.25 (about 23,000 and "
            "46,000 elements, the fast operator) and three levels for the observed order",
        )
        for name in ("punch", "load_controlled", "compressible")
    },
    "paper": (
        (0.35, 0.25),
        "at levels (0.7, 0.5) the film_min correction was 0.54 %, and the automatic run at "
        "tol = 1e-2 ended on the finer reference mesh (level 0.5); levels 0.35 and 0.25 (about "
        "23,000 and 46,000 elements, the fast operator) and three levels for the observed order",
    ),
    **{
        name: (
            (0.5, 0.5 / 1.4),
            "the plug-in scenes on the half space (fast operator from 12,000 elements on): the paper's "
            "sphere and motion, whose film_min correction at levels (0.7, 0.5) was 0.54 % (paper, "
            "t = 5), half the tolerance it checks; levels 0.5 and 0.357 (about 12,000 and 23,000 "
            "elements; free_indenter about 1.4 times more) and level 0.7 the third, coarser one "
            "(2026-12-05)",
        )
        for name in ("barus", "free_indenter")
    },
    "viscoelastic": (
        (0.5 / 1.4, 0.5 / 1.96),
        "at levels (0.5, 0.357) the film_min correction was 1.07 % at t = 1.96 (the exit "
        "constriction of the sliding start; observed order 1.7 there against level 0.7, so "
        "asymptotic but with a large constant) and the film_center one 0.49 %; levels 0.357 and "
        "0.255 (about 21,000 and 41,000 elements, the fast operator), level 0.5 the third, "
        "coarser one (2026-12-05)",
    ),
    "jfo": (
        (0.7, 0.5),
        "JFO to t = 3: the cavitated set's switching makes each step 2-3 times dearer than the "
        "isoviscous run's (benchmarks/cavitation.md); levels 0.7 and 0.5 (about 6,000 and 12,000 "
        "elements over 600 steps) and a third, coarser level 0.98 for the observed order "
        "(2026-12-05)",
    ),
    "layer": (
        (0.5, 0.5 / 1.4),
        "Layer(1) has a dense operator only (no fast one); at levels (0.7, 0.5) the film_min "
        "correction was 1.47 % at t = 1.63 (the exit constriction; three levels 0.98, 0.7, 0.5 not "
        "monotone there); levels 0.5 and 0.357 (about 10,600 and 20,600 elements, dense), level "
        "0.7 the third, coarser one (2026-12-05)",
    ),
    "steady_b1000": (
        (0.5, 0.35),
        "at levels (1, 0.7) the films' correction was 1.0-1.5 %; levels 0.5 and 0.35 (about "
        "19,000 and 38,000 elements over 2,400 steps, the fast operator) and three levels for "
        "the observed order",
    ),
}


#: scene -> a fixed step other than DT: the check of tol = 1e-3 at beta = 200, where at
#: dt = 0.005 the films' time error was 0.07-0.09 %, as large as the errors it checks (the
#: dt = 0.005 run is then the time-error run)
DT_OVERRIDES = {
    "load_controlled": DT / 2,
    "compressible": DT / 2,
    # beta = 20000: at dt = 0.005 the films' time error was 1.4-1.9 %
    "sphere_b20000_approach": DT / 2,
    "sphere_b20000_sliding": DT / 2,
}


#: scene -> a finer reference over the first part of its run: both levels run again at
#: ``dt`` over ``t <= t_end``; there the reference is their Richardson extrapolation and
#: the time error that of the ``dt`` run, measured against the level-L_a run at the scene's
#: own step (``|q(2 dt) - q(dt)| / 3``).  The rest of the run keeps the reference above.
REFINE = {
    "sphere_b2000_approach": {
        "t_end": 1.0,
        "dt": DT / 2,
        "reason": (
            "the automatic runs' film_min at tol = 1e-2 (0.70 % at t = 0.735) could not be "
            "decided: the reference's uncertainty there was 0.42 % (Richardson 0.19 %, time "
            "error 0.23 % at dt = 0.005); both levels again at dt = 0.0025 over the approach "
            "ramp t <= 1, where that maximum is"
        ),
    },
    "sphere_b20000_approach": {
        "t_end": 1.5,
        "dt": DT / 4,
        "reason": (
            "the automatic run at tol = 1e-2 was 0.99 % off at t = 1.5 against a reference "
            "0.57 % uncertain there (Richardson 0.28 %, time error 0.28 % at dt = 0.0025); a "
            "fixed-step run at its own last level and dt = 0.0025 was 0.77 % off and an "
            "adaptive one at a quarter of its time tolerance 1.02 %: the difference is the "
            "reference's time error, which fixed-step runs at its dt share; both levels again "
            "at dt = 0.00125 over the whole run, the level-0.5 run at dt = 0.0025 the time check"
        ),
    },
}
#: scene -> the scene whose refinement it takes: the same scene up to the refinement's
#: ``t_end`` (the same motion there, so the same solution; also the same fitted meshes,
#: 137,888 elements each at level 0.25 on 2026-12-05, and their base runs at both levels
#: agree there to 1e-6 relative, the fast operator's tolerance)
REFINE_SHARED = {"sphere_b2000_sliding": "sphere_b2000_approach"}
#: what a refinement keeps of a run: the series
_SERIES = ("t", *QUANTITIES)


def scene_dt(name: str) -> float:
    """The fixed step of scene ``name``'s reference runs."""
    return DT_OVERRIDES.get(name, DT)


def _r(v: float) -> float:
    return float(f"{v:.{SIG}g}")


def machine() -> dict:
    """nproc, the cpu model (/proc/cpuinfo) and the load average now."""
    from _machine import cpu

    try:
        load = [float(v) for v in pathlib.Path("/proc/loadavg").read_text().split()[:3]]
    except OSError:
        load = None
    return {"nproc": os.cpu_count(), "cpu": cpu(), "loadavg": load, "python": platform.python_version()}


# ---------------------------------------------------------------------------
# one run (in a child process)


def _scene(name: str):
    sys.path.insert(0, str(HERE))
    from auto_scenes import SCENES

    factory, t_end = SCENES[name]
    return factory(), t_end


def child(name: str, level: float, dt: float, t_end: float | None) -> dict:
    """One fixed-step BDF2 run of scene ``name`` on the fitted mesh at ``level``.

    The mesh is fitted to the scene's own ``t_end`` whatever ``t_end`` the run stops at
    (the cost probe runs a few steps on the same mesh as the real runs).
    """
    import numpy as np
    from auto_scenes import mesh_scene

    import femehl
    from femehl.discretize.fitted import fitted_disk

    scene, t_scene = _scene(name)
    t_run = t_scene if t_end is None else t_end
    t0 = time.perf_counter()
    dm = fitted_disk(mesh_scene(name), t_scene, level=level)
    t_mesh = time.perf_counter() - t0
    stamps = []

    def cb(state):
        stamps.append(time.perf_counter())

    out = {"level": level, "dt": dt, "t_end": t_run, "elements": int(dm.mesh.t.shape[1])}
    out["nodes"] = int(dm.mesh.p.shape[1])
    out["loadavg_start"] = machine()["loadavg"]
    t1 = time.perf_counter()
    try:
        res = femehl.solve(
            scene, "fe", t_end=t_run, dt=dt, scheme="bdf2", mesh=dm, store_every=0, callback=cb
        )
    except femehl.FemehlError as exc:
        out.update(error=f"{type(exc).__name__}: {exc}", wall_s=round(time.perf_counter() - t1, 2))
        out["t_reached"] = None
        return out
    wall = time.perf_counter() - t1
    s = res.summary()
    out.update({q: [_r(v) for v in getattr(res, q)] for q in QUANTITIES})
    out.update(t=[_r(v) for v in res.t], hc=[_r(v) for v in res.hc])
    out.update(film_min_x=[_r(v) for v in s["film_min_x"]], film_min_y=[_r(v) for v in s["film_min_y"]])
    out.update(wall_s=round(wall, 2), mesh_s=round(t_mesh, 2), nsteps=int(res.nsteps))
    # set-up = time to the first state (the initial one); steps: the rest
    if len(stamps) >= 2:
        out["setup_s"] = round(stamps[0] - t1, 2)
        d = np.diff(stamps)
        out["step_s"] = round(float(np.median(d[len(d) // 2 :])), 4)
    out["loadavg_end"] = machine()["loadavg"]
    try:
        import resource

        out["peak_rss_gb"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6, 2)
    except ImportError:
        pass
    return out


def run_child(name: str, level: float, dt: float, t_end: float | None = None) -> dict:
    """:func:`child` in a fresh process pinned to one BLAS thread."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    env["PYTHONPATH"] = os.pathsep.join([str(HERE.parent), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    args = [sys.executable, __file__, "--child", name, repr(level), repr(dt), repr(t_end)]
    p = subprocess.run(args, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        tail = (p.stderr or "").strip().splitlines()[-3:]
        return {"level": level, "dt": dt, "error": f"child exited {p.returncode}: {' | '.join(tail)}"}
    return json.loads(p.stdout.strip().splitlines()[-1])


# ---------------------------------------------------------------------------
# cost estimate and levels


def estimate(name: str) -> dict:
    """Elements at levels 1, 0.7, 0.5 and the estimated wall time of the scene's three runs.

    The probe is the whole run at level 1 with ``dt = 2 DT`` (its per-step cost includes
    the sliding phase, where GMRES needs more matvecs than at the start); a run at level
    ``l`` and step ``dt`` is estimated as ``probe wall * (N_l / N_1)^2 * (2 DT / dt)``
    with ``N`` the estimated element counts (dense operator: set-up and matvecs scale as
    N^2; measured N^1.8-2.1 on the ladder).  With the levels (1.0, 0.7) the probe is the
    time-error run itself.
    """
    from auto_scenes import mesh_scene

    from femehl.discretize.fitted import fitted_sizes

    scene, t_end = _scene(name)
    half = bool(getattr(scene.indenter, "symmetric_y", False))
    ne = {lev: fitted_sizes(mesh_scene(name), t_end, lev).estimate_elements(half) for lev in (1.0, 0.7, 0.5)}
    probe = run_child(name, 1.0, 2 * DT)
    out = {"elements_est": {f"{k:g}": round(v) for k, v in ne.items()}, "probe": probe, "cost_s": {}}
    if "error" in probe:
        return out

    def cost(level, dt):
        return probe["wall_s"] * (ne[level] / ne[1.0]) ** 2 * (2 * DT / dt)

    out["cost_s"] = {
        "levels_0.7_0.5": round(cost(0.7, DT) + cost(0.5, DT) + cost(0.7, 2 * DT)),
        "levels_1.0_0.7": round(cost(1.0, DT) + cost(0.7, DT) + cost(1.0, 2 * DT)),
    }
    return out


def choose_levels(est: dict, name: str = "") -> tuple[tuple[float, float], str]:
    if name in LEVEL_OVERRIDES:
        return LEVEL_OVERRIDES[name]
    if "error" in est["probe"]:
        return LEVELS_BIG, f"the level-1 probe failed: {est['probe']['error']}"
    ne_b = est["elements_est"]["0.5"]
    c = est["cost_s"].get("levels_0.7_0.5")
    if ne_b > MAX_ELEMENTS_B:
        return LEVELS_BIG, f"level 0.5 would have ~{ne_b} elements > {MAX_ELEMENTS_B}"
    if c is not None and c > MAX_SCENE_S:
        return LEVELS_BIG, f"levels (0.7, 0.5) estimated {c} s > {MAX_SCENE_S:g} s"
    return LEVELS, "default"


# ---------------------------------------------------------------------------
# reference


def _scale(q: str, v):
    import numpy as np

    return np.maximum(np.abs(v), LOAD_FLOOR if q == "load" else 0.0)


def _series_errors(entry: dict, q: str):
    """``(tu, u, te, e, qx)`` of quantity ``q``: the relative Richardson correction ``u``
    at the times ``tu`` and the time error ``e`` at the times ``te`` of the ``2 DT`` run,
    t = 0 left out; and the reference series ``qx`` (every time)."""
    import numpy as np

    ra, rb, rt = (entry["runs"][k] for k in ("a", "b", "a_dt2"))
    ratio = ra["level"] / rb["level"]
    ta, tb = np.asarray(ra["t"]), np.asarray(rb["t"])
    if ta.shape != tb.shape or np.max(np.abs(ta - tb)) > 1e-9:
        raise RuntimeError(f"{entry.get('name', '?')}: the two levels have different times")
    tt = np.asarray(rt["t"])
    idx = np.searchsorted(ta, tt - 1e-9)
    if np.max(np.abs(ta[idx] - tt)) > 1e-9:
        raise RuntimeError(
            f"{entry.get('name', '?')}: the dt = {rt['dt']} run's times are not in the DT run's"
        )
    qa, qb = np.asarray(ra[q]), np.asarray(rb[q])
    qx = qb + (qb - qa) / (ratio**ORDER - 1.0)
    u = (np.abs(qx - qb) / _scale(q, qx))[1:]
    q2 = np.asarray(rt[q])
    e = (np.abs(q2 - qa[idx]) / (2**ORDER - 1.0) / _scale(q, qa[idx]))[1:]
    tu, te = ta[1:], tt[1:]
    if "refined" in entry:
        tu, u, te, e, qx = _refined_errors(entry["refined"], q, ratio, ta, tu, u, te, e, qx)
    return tu, u, te, e, qx


def _same_times(t_from, t_in, what: str):
    """Indices of the times ``t_from`` in ``t_in`` (every one must be there)."""
    import numpy as np

    idx = np.minimum(np.searchsorted(t_in, t_from - 1e-9), t_in.size - 1)
    if t_from.size and np.max(np.abs(t_in[idx] - t_from)) > 1e-9:
        raise RuntimeError(f"refined reference: {what}")
    return idx


def _refined_errors(rf: dict, q: str, ratio: float, ta, tu, u, te, e, qx):
    """:func:`_series_errors` with the refinement ``rf`` over ``t <= rf["t_end"]``: there
    the reference is the Richardson extrapolation of the refined pair (``rf["a"]``,
    ``rf["b"]`` at ``rf["dt"]``), ``u`` its correction, and the time error that of the
    refined step, ``|q_a(2 rf_dt) - q_a(rf_dt)| / 3`` with ``rf["a_dt"]`` the level-L_a run
    at the scene's step."""
    import numpy as np

    fa, fb, fd = rf["a"], rf["b"], rf["a_dt"]
    if not math.isclose(fa["level"] / fb["level"], ratio) or not math.isclose(fd["level"], fa["level"]):
        raise RuntimeError("refined reference: its levels are not the scene's (redo the refinement)")
    if fd.get("elements") != fa.get("elements"):
        raise RuntimeError("refined reference: its two steps ran on different meshes (redo the refinement)")
    tf = np.asarray(fa["t"])
    if np.asarray(fb["t"]).shape != tf.shape or np.max(np.abs(np.asarray(fb["t"]) - tf)) > 1e-9:
        raise RuntimeError("refined reference: the two levels have different times")
    qfa, qfb = np.asarray(fa[q]), np.asarray(fb[q])
    qfx = qfb + (qfb - qfa) / (ratio**ORDER - 1.0)
    uf = np.abs(qfx - qfb) / _scale(q, qfx)
    td = np.asarray(fd["t"])
    within = (td > 0) & (td <= rf["t_end"] + 1e-9)
    td, qd = td[within], np.asarray(fd[q])[within]
    ef = np.abs(qd - qfa[_same_times(td, tf, "the step's times are not the refined run's")])
    ef = ef / (2**ORDER - 1.0) / _scale(q, qd)
    inside = ta <= rf["t_end"] + 1e-9
    k = _same_times(ta[inside], tf, "the scene's times are not the refined run's")
    qx = qx.copy()
    qx[inside] = qfx[k]
    keep_u = tu > rf["t_end"] + 1e-9
    u = np.concatenate([uf[k][1:], u[keep_u]])
    tu = np.concatenate([ta[inside][1:], tu[keep_u]])
    keep_e = te > rf["t_end"] + 1e-9
    return tu, u, np.concatenate([td, te[keep_e]]), np.concatenate([ef, e[keep_e]]), qx


def window_error(entry: dict, t_from: float) -> dict:
    """The reference's uncertainty plus time error per quantity over ``t >= t_from`` only
    (the window ``femehl bench auto`` compares in: the maxima of :func:`reference` include
    the first steps from rest, where the ``2 DT`` run's time error peaks)."""
    import numpy as np

    out = {}
    for q in QUANTITIES:
        ta, u, tt, e, _ = _series_errors(entry, q)
        ua, ea = u[ta >= t_from - 1e-9], e[tt >= t_from - 1e-9]
        out[q] = float((np.max(ua) if ua.size else 0.0) + (np.max(ea) if ea.size else 0.0))
    return out


def reference(entry: dict) -> None:
    """Richardson reference, its uncertainty and the time error, from ``entry["runs"]``."""
    import numpy as np

    ra, rb = entry["runs"]["a"], entry["runs"]["b"]
    ratio = ra["level"] / rb["level"]
    ref = {"t": rb["t"], "ratio": ratio}
    unc, terr = {}, {}
    diag = {}
    rc = entry["runs"].get("coarse")
    for q in QUANTITIES:
        tu, u, te, e, qx = _series_errors(entry, q)  # t > 0
        qa, qb = np.asarray(ra[q]), np.asarray(rb[q])
        ref[q] = [_r(v) for v in qx]
        unc[q] = float(np.max(u))
        terr[q] = float(np.max(e))
        iu, ie = int(np.argmax(u)), int(np.argmax(e))
        diag[q] = {
            "uncertainty_t": _r(tu[iu]),
            "uncertainty_end": _r(u[-1]),
            "uncertainty_t_ge_1": _r(np.max(u[tu >= 1.0 - 1e-9])),
            "time_error_t": _r(te[ie]),
            "time_error_end": _r(e[-1]),
            "time_error_t_ge_1": _r(np.max(e[te >= 1.0 - 1e-9])),
        }
        if rc is not None:  # three levels: the observed order, and the coarser pair's correction
            qc = np.asarray(rc[q])
            with np.errstate(all="ignore"):
                p = np.log(np.abs(qc - qa) / np.abs(qa - qb)) / np.log(ratio)
            qx2 = qa + (qa - qc) / (ratio**ORDER - 1.0)
            diag[q].update(
                observed_order_end=_r(p[-1]),
                observed_order_at_max=_r(p[iu + 1]),
                coarse_pair_levels=[rc["level"], ra["level"]],
                coarse_pair_uncertainty=_r(np.max((np.abs(qx2 - qa) / _scale(q, qx2))[1:])),
                coarse_pair_vs_reference=_r(np.max((np.abs(qx2 - qx) / _scale(q, qx))[1:])),
            )
    ref["film_min_x"], ref["film_min_y"] = rb["film_min_x"], rb["film_min_y"]
    entry["reference"] = ref
    entry["uncertainty"] = {q: _r(v) for q, v in unc.items()}
    entry["time_error"] = {q: _r(v) for q, v in terr.items()}
    entry["total_error"] = {q: _r(unc[q] + terr[q]) for q in QUANTITIES}
    entry["diagnostics"] = diag


def compact(entry: dict) -> None:
    """Drop series the reference does not need: the probe's (when the probe is the
    time-error run, its series are in ``runs["a_dt2"]``) and ``hc`` / ``film_min_x`` /
    ``film_min_y`` of every run but the finer one."""
    probe = entry.get("estimate", {}).get("probe", {})
    rt = entry["runs"].get("a_dt2", {})
    if probe.get("level") == rt.get("level") and probe.get("dt") == rt.get("dt"):
        probe["series_in"] = "runs.a_dt2"
    for k in ("t", "hc", "film_min_x", "film_min_y", *QUANTITIES):
        probe.pop(k, None)
    for key, run in entry["runs"].items():
        if key != "b":
            for k in ("hc", "film_min_x", "film_min_y"):
                run.pop(k, None)


# ---------------------------------------------------------------------------
# driver


def load() -> dict:
    if OUT.is_file():
        return json.loads(OUT.read_text())
    return {}


def save(data: dict, names=None) -> None:
    """Write ``data``; with ``names``, only those scenes (and the run's config and machine)
    over what the file holds now, so that runs of other scenes in another process (another
    ``--only``) are kept."""
    import fcntl

    # one process at a time reads, merges and replaces the file: without the lock a process
    # that read the file before another's write would write the other's scene back as it was
    with open(OUT.with_suffix(".json.lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if names is not None:
            disk = load()
            scenes = disk.setdefault("scenes", {})
            for n in names:
                if n in data.get("scenes", {}):
                    scenes[n] = data["scenes"][n]
            for k in ("config", "machine", "machine_end"):
                if k in data:
                    disk[k] = data[k]
            data = disk
        tmp = OUT.with_suffix(f".json.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(data, separators=(",", ":")))
        tmp.replace(OUT)


def config() -> dict:
    return {
        "scheme": "bdf2",
        "dt": DT,
        "dt_time_check": 2 * DT,
        "levels": LEVELS,
        "levels_big": LEVELS_BIG,
        "order": ORDER,
        "max_elements_level_b": MAX_ELEMENTS_B,
        "max_scene_s": MAX_SCENE_S,
        "load_floor": LOAD_FLOOR,
        "quantities": QUANTITIES,
        "mesh": "femehl.discretize.fitted.fitted_disk(scene, t_end, level)",
    }


def scene_estimate(name: str, data: dict, log) -> dict:
    """The scene's entry with its estimate and levels (computed once, kept in the JSON)."""
    scenes = data.setdefault("scenes", {})
    entry = scenes.get(name)
    if entry is None or "estimate" not in entry:
        _, t_end = _scene(name)
        entry = {"name": name, "t_end": t_end, "status": "estimated", "runs": {}}
        entry["estimate"] = estimate(name)
        entry["levels"], entry["levels_reason"] = choose_levels(entry["estimate"], name)
        scenes[name] = entry
        save(data, [name])
    return entry


def do_scene(name: str, data: dict, log) -> None:
    entry = scene_estimate(name, data, log)
    probe = entry["estimate"]["probe"]
    if "error" in probe:
        entry["status"] = "failed"
        entry["reason"] = f"level-1 probe (dt {2 * DT}): {probe['error']}"
        entry["machine"] = machine()
        save(data, [name])
        log(f"{name}: failed: {entry['reason']}")
        return
    la, lb = entry["levels"]
    dt0 = scene_dt(name)
    plan = {"a": (la, dt0), "b": (lb, dt0), "a_dt2": (la, 2 * dt0)}
    if name in LEVEL_OVERRIDES:
        plan["coarse"] = (round(la * la / lb, 12), dt0)
    # a finished run with the series of a planned (level, dt) is reused: the level-1 probe
    # (the time-error run of levels (1, 0.7)), or a run of an earlier plan (levels or dt changed)
    kept = (r for r in (probe, *entry["runs"].values()) if "error" not in r and "t" in r)
    done = {(r["level"], r["dt"]): r for r in kept}
    entry["runs"] = {k: done[lv_dt] for k, lv_dt in plan.items() if lv_dt in done}
    log(
        f"{name}: t_end {entry['t_end']}, levels {la}, {lb} ({entry['levels_reason']}), "
        f"estimated {entry['estimate']['cost_s']}"
    )
    entry["status"] = "running"
    for key, (lev, dt) in plan.items():
        if key in entry["runs"]:
            continue
        run = run_child(name, lev, dt)
        entry["runs"][key] = run
        log(
            f"  {key}: level {lev}, dt {dt}: {run.get('elements')} elements, "
            f"{run.get('wall_s')} s{'  ERROR ' + run['error'] if 'error' in run else ''}"
        )
        if "error" in run:
            entry["status"] = "failed"
            entry["reason"] = f"run {key} (level {lev}, dt {dt}): {run['error']}"
            entry["machine"] = machine()
            save(data, [name])
            return
        save(data, [name])
    reference(entry)
    compact(entry)
    entry["status"] = "done"
    entry["machine"] = machine()
    entry["wall_s"] = round(sum(r["wall_s"] for r in entry["runs"].values()), 1)
    save(data, [name])
    log(f"  uncertainty {entry['uncertainty']}  time error {entry['time_error']}")


def refine(name: str, data: dict, log) -> None:
    """The refinement of scene ``name`` (:data:`REFINE`, or the one it shares,
    :data:`REFINE_SHARED`): the refined runs that are missing, then its reference again.

    The base reference (runs a, b, a_dt2) must be done.  Three runs over ``t <= t_end``,
    on today's fitted meshes (which may have changed since the base runs: their element
    counts are recorded): ``a`` and ``b`` at the refined ``dt``, and ``a_dt``, level L_a at
    the scene's own step, for the time error.  They are kept in the source scene's entry
    (``refined``: ``t_end``, ``dt``, ``reason`` and the runs, each with its wall time and
    machine); a sharing scene gets a copy of their series (``source`` names the scene)."""
    source = REFINE_SHARED.get(name, name)
    if source not in REFINE:
        raise SystemExit(
            f"--refine: {name} has no refinement; scenes with one: {sorted(REFINE) + sorted(REFINE_SHARED)}"
        )
    scenes = data.get("scenes", {})
    for n in dict.fromkeys((source, name)):
        if scenes.get(n, {}).get("status") != "done":
            raise SystemExit(f"--refine {name}: the reference of {n} is not done; run it first (--only {n}).")
    spec, src = REFINE[source], scenes[source]
    la, lb = src["levels"]
    rf = src.setdefault("refined", {})
    rf.update(t_end=spec["t_end"], dt=spec["dt"], reason=spec["reason"])
    for key, lev, dt in (("a", la, spec["dt"]), ("b", lb, spec["dt"]), ("a_dt", la, scene_dt(source))):
        if "t" in rf.get(key, {}):
            continue
        run = run_child(source, lev, dt, spec["t_end"])
        log(
            f"{source} refined {key}: level {lev}, dt {spec['dt']}, t <= {spec['t_end']}: "
            f"{run.get('wall_s')} s"
        )
        if "error" in run:
            raise SystemExit(f"--refine {name}: run {key} stopped: {run['error']}")
        run["machine"] = machine()
        for k in ("hc", "film_min_x", "film_min_y"):
            run.pop(k, None)
        rf[key] = run
        save(data, [source])

    def kept(run):
        return {k: run[k] for k in (*_SERIES, "level", "dt", "elements")}

    if name != source:
        entry = scenes[name]
        entry["refined"] = {
            **{k: rf[k] for k in ("t_end", "dt", "reason")},
            "source": source,
            **{k: kept(rf[k]) for k in ("a", "b", "a_dt")},
        }
    for n in dict.fromkeys((source, name)):
        reference(scenes[n])
        compact(scenes[n])
    save(data, list(dict.fromkeys((source, name))))


def _pct(v) -> str:
    return "-" if v is None else f"{100 * v:.3f}"


def _loads(data: dict) -> tuple[float, float]:
    """The smallest and largest 1-minute load average seen at the starts and ends of the runs."""
    vals = []
    for e in data.get("scenes", {}).values():
        for r in e.get("runs", {}).values():
            vals += [r[k][0] for k in ("loadavg_start", "loadavg_end") if r.get(k)]
    return (min(vals), max(vals)) if vals else (math.nan, math.nan)


NOTES = """
Notes

* The time error's maximum over t is at the start from rest (t = 0.01 for the load, the
  first steps of BDF2; t <= 0.22 for the films), except beta = 20000 (film_min, t = 0.44).
  Over t >= 1 (`time_error_t_ge_1` in the JSON `diagnostics`) it is at most 0.01 % (load)
  and 0.26 % (films), 0.38 % at beta = 20000 (dt = 0.0025).  The column "film_min t >= 1"
  is the film_min uncertainty over t >= 1 (`uncertainty_t_ge_1`).
* beta = 2000 and 20000, approach phase: the minimum film is on the rim of the trapped
  dimple, which moves out from r ~ 0.2 to the contact edge during the ramp through the
  contact zone of the fitted mesh.  The `_sliding` scenes share that phase (identical up
  to t = 1).  beta = 2000 (levels 0.25, 0.18, before the contact zone was capped): the
  film_min correction peaks at t ~ 0.6, 0.19 %, and the time error at dt = 0.005 was
  0.23 % at t = 0.735.  Refined over t <= 1 on 2026-12-05 (`REFINE`: both levels at
  dt = 0.0025 on the capped meshes, 137,888 and 265,528 elements): over t <= 1 the
  film_min correction is at most 0.045 % (t = 0.73) and the time error 0.058 % from
  t = 0.04 on (0.16 % at t = 0.015, the start from rest); the refined reference is within
  0.28 % (film_min), 0.14 % (film_center) and 0.09 % (load) of the one it replaces there,
  inside that one's stated uncertainty.  After t = 1 the reference is the one above (time
  error up to 0.26 %).  beta = 20000: with the contact zone
  0.095 a (9.3 edge sizes, before 2026-12-03) levels 1 and 0.7 differed by 17 % at
  t ~ 0.6 and the reference was not in the asymptotic range; refined on 2026-12-03 on the
  capped fitted meshes (`femehl.discretize.fitted.C_CONTACT_EDGE`, `benchmarks/fitted_thin.md`),
  levels (1, 0.7), 24,736 and 50,120 elements, at dt = 0.0025: the film_min correction
  is 1.18 % at t = 0.715 in the approach (three levels not monotone there: not yet
  asymptotic) and 1.74 % at t = 1.985 in the sliding (observed order 2.8), time error
  0.39 %.  A check of tol = 1e-2 there is as uncertain as the tolerance.  The approach
  again on 2026-12-05 at levels 0.5 and 0.357 (97,562 and 190,344 elements, dt = 0.0025,
  level 0.7 the third): the film_min correction is 0.30 % (largest at t = 1.14; observed
  order 1.8 at t = 1.5, 2.7 at that maximum: asymptotic now), the time error 0.38 %
  (t = 0.545), 0.28 % at t = 1.5; the coarser pair (0.7, 0.5) extrapolates to within
  0.67 % of it.  Then refined over the whole run at dt = 0.00125 (`REFINE`, both levels,
  the level-0.5 run at dt = 0.0025 the time check): time error 0.07 % at t = 1.5 (0.09 %
  at most from t = 0.04 on), the film_min correction still 0.30 %.
* Levels (1, 0.7) for the beta = 20000 sliding (the capped mesh at level 0.5 has about
  100,000 elements over 800 steps).  With the fast operator (from 12,000 elements on)
  and a third, coarser level each, refined on 2026-12-02: beta = 2000 (0.25, 0.18),
  steady_b1000 (0.5, 0.35) and
  sphere_b20_sliding (0.18, 0.13) to check the automatic runs after the cell budget was
  raised and tol = 1e-3; then the ellipsoids (0.5, 0.35), user_shape and paper (0.35,
  0.25), where the automatic run at tol = 1e-2 had ended on the reference's finer mesh;
  and for tol = 1e-3 sphere_b20_approach (0.18, 0.13), punch, load_controlled and
  compressible (0.35, 0.25).  ellipsoid_y: at (0.5, 0.35) the film_min correction was
  0.47 % at t = 2.09, where the minimum film moves between elements and the three levels
  (0.71, 0.5, 0.35) were not in the asymptotic range (differences 0.24 % then 0.49 %); at
  (0.35, 0.245), with level 0.5 the third, 0.15 % (at t = 1.82; observed order 1.9 at
  t = 3, still not asymptotic at the maximum).  At tol = 1e-3 the fixed step dt = 0.005
  limits the references at beta = 200 (load_controlled, compressible, punch: time error
  0.01-0.09 % in the films), as large as the errors they check there.  winkler:
  levels (0.5, 0.357) (cheap: sparse substrate operator) and a third level 0.7: observed
  order 2.1 / 2.0 / 4.0 at t = 2 (load / film_center / film_min; JSON `diagnostics`).
  The first winkler choice k = 1 converged at order 0.46 in film_min (5 % between levels
  0.5 and 0.357): replaced by k = 0.25.
* The plug-in scenes (2026-12-05; `LEVEL_OVERRIDES`, three levels each).  barus (0.5, 0.357)
  and jfo (0.7, 0.5, to t = 3): film_min correction 0.06 % and 0.53 %.  layer (dense
  operator only): at (0.7, 0.5) the film_min correction was 1.47 % (levels not monotone at
  its maximum), at (0.5, 0.357) 0.42 % (t = 1.79); its time error is 0.27 % in film_min
  (t = 1.07) and 0.75 % in the load at t = 0.01 (the start from rest; 0.01 % from t = 1
  on).  viscoelastic: NOT converged well below the tolerance in film_min: at (0.5, 0.357)
  1.07 %, at (0.357, 0.255) 0.67 % (t = 1.87), the three levels' successive differences
  about 0.5 % each near t = 2 (no h^2 decrease at the exit lobes, y ~ 0.94, where the creep
  memory is carried on its own uniform grid, `femehl.elastic.viscoelastic.CreepMemory`);
  film_center 0.23 %, load 0.01 %.  free_indenter: on meshes fitted to the scene itself
  (`fitted_disk` reads a free indenter's contact from its `gap`, hc(0) = 0.1 held: no
  contact) the film_min at levels 0.7, 0.5, 0.357 was 0.0379, 0.0354, 0.0372 at t = 1.5
  (correction 5.5 %); on meshes fitted to `auto_scenes.MESH_SCENES["free_indenter"]` (the
  imposed gap down to hc = -1.75) 0.51 %.
"""


def _cpus(data: dict) -> dict:
    """CPU model -> the scenes whose runs it made (each scene's ``machine``)."""
    out: dict = {}
    for name, e in data.get("scenes", {}).items():
        out.setdefault(e.get("machine", {}).get("cpu", "not recorded"), []).append(name)
    return out


def table(data: dict) -> str:
    """The markdown table of benchmarks/auto_reference_scenes.md."""
    sys.path.insert(0, str(HERE))
    from auto_scenes import SCENES

    m = data.get("machine", {})
    lo, hi = _loads(data)
    lines = [
        "# Reference solutions of the `femehl bench auto` scenes",
        "",
        "Written by `benchmarks/auto_reference_scenes.py` (see its docstring) from "
        "`auto_reference_scenes.json`; scenes in `benchmarks/auto_scenes.py`.",
        f"FE, BDF2, fixed dt = {DT} (column dt where it differs: `DT_OVERRIDES`), fitted "
        "meshes at levels (L_a, L_b), Richardson in h "
        "(order 2, ratio L_a/L_b). Uncertainty = max_t |q_ref - q_b| / |q_ref| (the "
        "correction); time error = max_t |q(2 dt) - q(dt)| / 3 relative, at L_a. "
        "Load relative to max(|q|, 0.1). All in %. Elements are the actual mesh counts.",
        "",
        f"Machine: {m.get('nproc')} cores; 1 BLAS thread per run, at most two runs at a "
        f"time, on two scenes (1-minute load average {lo:.2f}-{hi:.2f} at the starts and "
        "ends of the runs; per run in the JSON). CPU: "
        + "; ".join(f"{cpu} ({', '.join(names)})" for cpu, names in _cpus(data).items())
        + ".",
        "",
        "| scene | t_end | levels | dt | elements (a / b) | wall per run a / b / a,2 dt (s) "
        "| uncertainty load / film_center / film_min | film_min t >= 1 "
        "| time error load / film_center / film_min |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    scenes = data.get("scenes", {})
    for name in [n for n in SCENES if n in scenes] + [n for n in scenes if n not in SCENES]:
        e = scenes[name]
        runs = e.get("runs", {})
        els = " / ".join(str(runs[k].get("elements", "-")) for k in ("a", "b") if k in runs)
        walls = " / ".join(str(runs[k].get("wall_s", "-")) for k in ("a", "b", "a_dt2") if k in runs)
        lev = ", ".join(f"{v:.3g}" for v in e.get("levels", ()))
        if e.get("status") == "done":
            u = " / ".join(_pct(e["uncertainty"][q]) for q in QUANTITIES)
            u1 = _pct(e["diagnostics"]["film_min"]["uncertainty_t_ge_1"])
            te = " / ".join(_pct(e["time_error"][q]) for q in QUANTITIES)
        else:
            u = f"{e.get('status')}: {e.get('reason', '')}".replace("|", "/")
            u1 = te = "-"
        dt = runs["a"].get("dt", DT) if "a" in runs else scene_dt(name)
        lines.append(f"| {name} | {e.get('t_end')} | {lev} | {dt:g} | {els} | {walls} | {u} | {u1} | {te} |")
    refined = {n: e["refined"] for n, e in scenes.items() if "refined" in e}
    if refined:
        lines += ["", "Refined over the first part of the run (`REFINE`; the columns above include it):", ""]
    for name, rf in refined.items():
        src = scenes[rf.get("source", name)]["refined"]
        walls = " / ".join(str(src[k].get("wall_s", "-")) for k in ("a", "b", "a_dt"))
        els = " / ".join(str(src[k].get("elements", "-")) for k in ("a", "b"))
        shared = f", the runs of {rf['source']} (`REFINE_SHARED`)" if "source" in rf else ""
        lines.append(
            f"* {name}: t <= {rf['t_end']:g}, both levels at dt = {rf['dt']:g}{shared}, on the fitted "
            f"meshes of the day ({els} elements), wall per run a / b / a at the scene's dt {walls} s: "
            f"{rf['reason']}."
        )
    return "\n".join(lines) + "\n" + NOTES


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", help="comma-separated scene names")
    ap.add_argument("--resume", action="store_true", help="keep the JSON's finished scenes and runs")
    ap.add_argument("--estimate", action="store_true", help="print the cost table only")
    ap.add_argument("--table", action="store_true", help="rebuild the .md from the JSON only")
    ap.add_argument(
        "--recompute", action="store_true", help="recompute references of finished scenes (no runs)"
    )
    ap.add_argument(
        "--refine", help="comma-separated scenes: their finer reference over the first part (REFINE)"
    )
    ap.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.child:
        name, lev, dt, t_end = a.child
        t_end = None if t_end == "None" else float(t_end)
        print(json.dumps(child(name, float(lev), float(dt), t_end)))
        return
    sys.path.insert(0, str(HERE))
    from auto_scenes import SCENES

    def log(msg):
        print(time.strftime("%H:%M:%S"), msg, flush=True)

    names = list(SCENES) if not a.only else [s.strip() for s in a.only.split(",") if s.strip()]
    unknown = [n for n in names if n not in SCENES]
    if unknown:
        raise SystemExit(f"unknown scenes {unknown}; known: {list(SCENES)}")
    data = load()  # without --resume the named scenes are redone, the others kept
    if a.refine:
        for n in a.refine.split(","):
            refine(n.strip(), data, log)
        TABLE.write_text(table(load()))
        return
    if a.recompute:
        for n in names:
            e = data.get("scenes", {}).get(n)
            if e is not None and e.get("status") == "done":
                reference(e)
                compact(e)
        save(data, names)
    if a.table or a.recompute:
        TABLE.write_text(table(load()))
        return
    if a.estimate:
        data["config"] = config()
        print(
            f"{'scene':24s} {'t_end':>5s} {'el 1.0':>7s} {'el 0.7':>7s} {'el 0.5':>7s} "
            f"{'probe el':>8s} {'probe s':>7s} {'cost(.7,.5)':>11s} {'cost(1,.7)':>10s}  levels"
        )
        total = 0.0
        for n in names:
            e = scene_estimate(n, data, log)
            lv = e["levels"]
            c = e["estimate"]["cost_s"]
            key = "levels_0.7_0.5" if tuple(lv) == LEVELS else "levels_1.0_0.7"
            ee, p = e["estimate"]["elements_est"], e["estimate"]["probe"]
            total += c.get(key, 0.0) - (p.get("wall_s", 0.0) if key == "levels_1.0_0.7" else 0.0)
            print(
                f"{n:24s} {SCENES[n][1]:5g} {ee['1']:7d} {ee['0.7']:7d} {ee['0.5']:7d} "
                f"{p.get('elements', '-'):>8} {p.get('wall_s', '-'):>7} "
                f"{c.get('levels_0.7_0.5', '-'):>11} {c.get('levels_1.0_0.7', '-'):>10}  "
                f"{tuple(lv)} {e['levels_reason']}",
                flush=True,
            )
        print(f"estimated remaining {total / 60:.1f} min (the probes done)")
        return
    data["config"] = config()
    data["machine"] = machine()
    for n in names:
        e = data.get("scenes", {}).get(n)
        if a.resume and e is not None and e.get("status") in ("done", "failed"):
            log(f"{n}: {e['status']} already, skipped")
            continue
        if e is not None and not a.resume:
            data["scenes"].pop(n)
        do_scene(n, data, log)
        TABLE.write_text(table(load()))
    data["machine_end"] = machine()
    save(data, names)
    TABLE.write_text(table(load()))


if __name__ == "__main__":
    main()
