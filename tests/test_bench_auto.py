"""The comparison of ``femehl bench auto`` (benchmarks/auto.py) on series with a known answer.

An adaptive run lands on the motion's breakpoint (t = 1) and restarts with steps far below
the fixed-step reference's 0.005 there, while the quantity relaxes within 0.002 (as the
load does after the paper's ramp stops).  Both series below sample the SAME function
exactly, so every "true error" the comparison reports is its own interpolation error.
"""

import importlib.util
import pathlib
import sys

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def bench():
    sys.path.insert(0, str(ROOT / "benchmarks"))
    spec = importlib.util.spec_from_file_location("femehl_bench_auto", ROOT / "benchmarks" / "auto.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def q(t):
    """0.3 + 0.3 t^2 up to the breakpoint t = 1, then a relaxation by 0.003 in 0.002."""
    t = np.asarray(t, dtype=float)
    after = 0.6 - 0.003 * (1.0 - np.exp(-(t - 1.0) / 0.002)) - 0.05 * (t - 1.0)
    return np.where(t <= 1.0, 0.3 + 0.3 * t**2, after)


def test_an_adaptive_run_is_compared_where_it_is_resolved(bench):
    # adaptive: from 1e-4 growing by 1.2 per step up to 0.03 before the breakpoint, then
    # from 1e-5 growing by 1.15 up to 0.01 (the Winkler run's steps were 3e-4 to 8e-4 over
    # t - 1 in [0.003, 0.01])
    before = np.r_[0.0, np.cumsum(np.minimum(1e-4 * 1.2 ** np.arange(200), 0.03))]
    before = before[before < 1.0]
    after = 1.0 + np.cumsum(np.minimum(1e-5 * 1.15 ** np.arange(200), 0.01))
    t = np.r_[before, 1.0, after[after < 1.5], 1.5]
    tr = np.round(np.arange(0.0, 1.5 + 1e-9, 0.005), 12)
    series = {name: q(t).tolist() for name in bench.QUANTITIES}
    rec = {"kind": "auto", "scene": "sphere_b20_sliding", "tol": 1e-2, "t": t.tolist(), **series}
    rec["estimate"] = {name: np.full(t.size, 1e-3).tolist() for name in bench.QUANTITIES}
    ref = {
        "t": tr.tolist(),
        "reference": {name: q(tr).tolist() for name in bench.QUANTITIES},
        "t_from": 0.04,
        "uncertainty": {name: 0.0 for name in bench.QUANTITIES},
    }
    errors = bench.true_errors(rec, ref)
    # its own interpolation error only: PCHIP on steps of 0.03 before the breakpoint, within
    # a fifth of linear interpolation's bound there (h^2 q'' / 8 / q = 1.1e-4; measured 8e-6)
    assert max(e["true"] for e in errors.values()) < 2e-5
    # the artefact it replaces: the reference linearly interpolated at the run's times right
    # after the breakpoint is off by about a quarter of the relaxation (0.003 / 0.6)
    keep = t > 1.0
    naive = np.abs(np.interp(t[keep], tr, q(tr)) - q(t[keep])) / q(t[keep])
    assert naive.max() > 1e-3


def test_a_fixed_step_run_is_compared_at_its_own_times(bench):
    tr = np.round(np.arange(0.0, 1.5 + 1e-9, 0.005), 12)
    t = np.round(np.arange(0.0, 1.5 + 1e-9, 0.02), 12)
    values = q(t) * (1.0 + 2e-3)  # 0.2 % off everywhere
    rec = {"kind": "hand", "scene": "sphere_b20_sliding", "t": t.tolist()}
    rec.update({name: values.tolist() for name in bench.QUANTITIES})
    ref = {
        "t": tr.tolist(),
        "reference": {name: q(tr).tolist() for name in bench.QUANTITIES},
        "t_from": 0.04,
        "uncertainty": {},
    }
    for e in bench.true_errors(rec, ref).values():
        assert e["true"] == pytest.approx(2e-3, rel=1e-9)


def test_redo_reruns_only_the_tolerances_asked_for(bench, tmp_path, monkeypatch):
    # a scene with runs at two tolerances: `--tol 1e-3 --redo s` reruns the 1e-3 run and keeps
    # the 1e-2 one (it used to drop every automatic run of the scene)
    import json

    runs = tmp_path / "auto_runs.jsonl"
    old = [
        {"kind": "auto", "scene": "punch", "tol": 0.01, "status": "ok", "mark": "kept"},
        {"kind": "auto", "scene": "punch", "tol": 0.001, "status": "ok", "mark": "old"},
        {"kind": "hand", "scene": "punch", "level": 1.0, "dt": 0.01, "status": "ok", "mark": "kept"},
    ]
    runs.write_text("".join(json.dumps(r) + "\n" for r in old))
    ran = []

    def fake_run(spec, cap=None):
        ran.append(spec)
        return dict(spec, status="ok", mark="new")

    monkeypatch.setattr(bench, "RUNS", runs)
    monkeypatch.setattr(bench, "REFERENCE", tmp_path / "none.json")
    monkeypatch.setattr(bench, "HERE", tmp_path)
    monkeypatch.setattr(bench, "run_in_subprocess", fake_run)
    monkeypatch.setattr(bench, "analyze", lambda records, refs: "")
    bench.main(["--tol", "1e-3", "--only", "punch", "--no-hand", "--resume", "--redo", "punch"])
    assert ran == [{"kind": "auto", "scene": "punch", "tol": 0.001}]
    kept = map(json.loads, runs.read_text().splitlines())
    marks = sorted((r["kind"], r.get("tol"), r["mark"]) for r in kept)
    assert marks == [("auto", 0.001, "new"), ("auto", 0.01, "kept"), ("hand", None, "kept")]


@pytest.fixture(scope="module")
def margin():
    sys.path.insert(0, str(ROOT / "benchmarks"))
    path = ROOT / "benchmarks" / "auto_margin.py"
    spec = importlib.util.spec_from_file_location("femehl_bench_margin", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _pair(level, est, true, unc, kind="sequence"):
    p = {"level": level, "elements": 100, "kind": kind}
    for q, e, t, u in zip(("load", "film_center", "film_min"), est, true, unc, strict=True):
        p[q] = {"estimate": e, "true": t, "reference": u}
    return p


def test_the_margin_is_worst_true_over_worst_estimate(margin):
    """The acceptance bounds the worst estimate of the three quantities, so the ratio is the
    worst true error over the worst estimate, not a per-quantity one: here the central film's
    true error (0.6 %) is 3 times its estimate but under the minimum film's estimate."""
    tol = 1e-2
    p = _pair(1.0, (1e-4, 2e-3, 8e-3), (1e-4, 6e-3, 5e-3), (0.0, 1e-3, 1e-3))
    ratio, judged = margin._worst_ratio(p, tol)
    assert ratio == pytest.approx(6e-3 / 8e-3) and judged
    # a pilot (level 2) is never judged; nor a true error under twice the reference's uncertainty
    assert not margin._worst_ratio(_pair(2.0, (1e-4, 2e-3, 8e-3), (1e-4, 6e-3, 5e-3), (0, 0, 0)), tol)[1]
    ratio, judged = margin._worst_ratio(_pair(0.7, (0, 0, 4e-3), (0, 0, 5e-3), (0, 0, 3e-3)), tol)
    assert ratio == pytest.approx(1.25) and not judged
    text = margin.report([{"scene": "s", "tol": tol, "accept": 0.75, "pairs": [p]}])
    assert "| 0.75 |" in text and "Judged: 1 pairs; worst true / worst estimate at most 0.75" in text


def test_a_refined_reference_replaces_its_window_only():
    """Manufactured series q(t, h, dt) = f(t) + C h^2 + D dt^2 (the error model the reference
    assumes): over the refinement's window the reference is f + D (dt/2)^2 exactly, its time
    error the D (dt/2)^2 it carries, its correction C h_b^2 / f; beyond it the scene's own."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import auto_reference_scenes as ars

    f = lambda t: 0.4 + 0.1 * np.sin(3 * t)  # noqa: E731
    C, D, dt = 0.05, 40.0, 0.005

    def run(level, step, t_end):
        t = np.round(np.arange(0.0, t_end + 1e-9, step), 12)
        v = (f(t) + C * level**2 + D * step**2).tolist()
        return {"level": level, "dt": step, "t": t.tolist(), **{q: v for q in ars.QUANTITIES}}

    entry = {
        "runs": {"a": run(0.25, dt, 2.0), "b": run(0.18, dt, 2.0), "a_dt2": run(0.25, 2 * dt, 2.0)},
        "refined": {
            "t_end": 1.0,
            "dt": dt / 2,
            "a": run(0.25, dt / 2, 1.0),
            "b": run(0.18, dt / 2, 1.0),
            "a_dt": run(0.25, dt, 1.0),
        },
    }
    tu, u, te, e, qx = ars._series_errors(entry, "film_min")
    t = np.asarray(entry["runs"]["b"]["t"])
    inside = t <= 1.0 + 1e-9
    np.testing.assert_allclose(qx[inside], f(t[inside]) + D * (dt / 2) ** 2, rtol=1e-12)
    np.testing.assert_allclose(qx[~inside], f(t[~inside]) + D * dt**2, rtol=1e-12)
    # the time errors: of the dt / 2 runs inside, of the dt runs after
    e_in, e_out = e[te <= 1.0 + 1e-9], e[te > 1.0 + 1e-9]
    qa = lambda tt: f(tt) + C * 0.25**2 + D * dt**2  # noqa: E731  (relative to the level-a run at dt)
    np.testing.assert_allclose(e_in, D * (dt / 2) ** 2 / qa(te[te <= 1.0 + 1e-9]), rtol=1e-9)
    np.testing.assert_allclose(e_out, D * dt**2 / qa(te[te > 1.0 + 1e-9]), rtol=1e-9)
    # the Richardson correction C h_b^2 relative to the reference, both sides
    np.testing.assert_allclose(u, C * 0.18**2 / qx[1:], rtol=1e-9)
    assert tu[0] > 0 and np.all(np.diff(tu) > 0) and np.all(np.diff(te) > 0)
    # a refinement at other levels than the scene's is refused, not mixed in
    entry["refined"]["b"] = run(0.2, dt / 2, 1.0)
    with pytest.raises(RuntimeError, match="levels"):
        ars._series_errors(entry, "film_min")
    # ... and so is a time error measured across two meshes (the fitted mesh changed)
    entry["refined"]["b"] = run(0.18, dt / 2, 1.0)
    entry["refined"]["a"]["elements"], entry["refined"]["a_dt"]["elements"] = 137888, 91854
    with pytest.raises(RuntimeError, match="meshes"):
        ars._series_errors(entry, "film_min")


def test_the_pair_estimate_is_exact_on_an_order_two_error(bench):
    """q(level) = f + C level^2: the pair estimate of the finer run is its error C l_b^2 / q_b."""
    t = np.round(np.arange(0.0, 2.0 + 1e-9, 0.01), 12)
    f = 0.3 + 0.1 * np.cos(2 * t)

    def run(level):
        series = (f + 0.02 * level**2).tolist()
        return {"level": level, "t": t.tolist(), **{q: series for q in bench.QUANTITIES}}

    est = bench.pair_estimate(run(1.41), run(0.5), t_from=0.04)
    keep = t >= 0.04
    assert est == pytest.approx(np.max(0.02 * 0.25 / (f[keep] + 0.005)), rel=1e-9)
