"""Parameter sweeps on a Dask LocalCluster: the table, failures, resumption, a killed
worker, and the errors of a bad sweep description."""

from __future__ import annotations

import json
import os
import pathlib
import sys

import numpy as np
import pytest

pytest.importorskip("distributed")
pytest.importorskip("pyarrow")

import femehl  # noqa: E402
from femehl.cli import main  # noqa: E402
from femehl.studies import sweeps as sw  # noqa: E402

RUN = {"t_end": 0.2, "dt": 0.05, "mesh": "coarse", "store_every": 2}


def _counting_runner(case, folder):
    """run_case, leaving a mark per call (to count the runs a sweep made)."""
    marks = pathlib.Path(folder).parent.parent / "marks"
    marks.mkdir(exist_ok=True)
    (marks / f"{case.key}-{os.getpid()}-{len(list(marks.iterdir()))}").touch()
    return sw.run_case(case, folder)


def _killing_runner(case, folder):
    """Kills its worker process the first time it meets beta = 200, then runs normally."""
    marker = pathlib.Path(folder).parent / f"{case.key}.killed"
    if case.params.get("fluid.beta") == 200 and not marker.exists():
        marker.parent.mkdir(parents=True, exist_ok=True)
        marker.touch()
        os._exit(1)
    return sw.run_case(case, folder)


@pytest.fixture(scope="module", autouse=True)
def _pickle_runners_by_value():
    """The workers cannot import this test module: send its runners by value."""
    import cloudpickle

    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    yield
    cloudpickle.unregister_pickle_by_value(sys.modules[__name__])


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """Four short cases on two workers: beta x L; one more with a mesh file that does not
    exist (a bad combination, failing on its worker)."""
    out = tmp_path_factory.mktemp("sweep")
    cases = [{"fluid.beta": b, "domain.L": L} for b in (50.0, 200.0) for L in (2.0, 2.5)]
    cases.append({"fluid.beta": 50.0, "run.mesh": str(out / "no-such-mesh.msh")})
    table = sw.sweep(None, cases=cases, run=RUN, out=out, workers=2, progress=False, runner=_counting_runner)
    return table, out, cases


def test_table_has_a_row_per_case_and_stored_time(swept):
    table, out, cases = swept
    done = table[table.status == "done"]
    assert done["case"].nunique() == 4
    # stored every 2 steps of 0.05 to 0.2: t = 0, 0.1, 0.2 for each case
    assert sorted(done.groupby("case").size().unique()) == [3]
    assert np.allclose(sorted(set(done["t"])), [0.0, 0.1, 0.2])
    # the table is each case's own run: compare one case with a direct solve
    one = done[(done["fluid.beta"] == 200.0) & (done["domain.L"] == 2.0)].sort_values("t")
    res = femehl.solve(_beta(200.0), t_end=0.2, dt=0.05, mesh="coarse", estimate=False)
    assert np.allclose(one["load"], [res.value_at("load", t) for t in one["t"]], rtol=1e-9, atol=1e-12)
    assert (out / "results.parquet").is_file()
    back = sw.read_results(out)
    assert len(back) == len(table) and list(back.columns) == list(table.columns)


def _beta(beta):
    import dataclasses

    sc = femehl.presets.paper_sphere()
    return dataclasses.replace(sc, fluid=dataclasses.replace(sc.fluid, beta=beta))


def test_a_failing_case_is_recorded_and_the_others_finish(swept):
    table, out, cases = swept
    bad = table[table.status == "failed"]
    assert bad["case"].nunique() == 1 and len(bad) == 1
    assert "no-such-mesh" in bad["error"].iloc[0] and np.isnan(bad["t"].iloc[0])
    rec = json.loads((out / "cases" / bad["case"].iloc[0] / "case.json").read_text())
    assert rec["status"] == "failed" and rec["error"].startswith(("MeshError", "SceneError", "OutputError"))


def test_a_second_run_does_no_work(swept):
    table, out, cases = swept
    marks = len(list((out / "marks").iterdir()))
    assert marks == 5  # one run per case
    again = sw.sweep(None, cases=cases, run=RUN, out=out, workers=2, progress=False, runner=_counting_runner)
    assert len(list((out / "marks").iterdir())) == marks  # nothing ran
    assert again.attrs["sweep"]["ran"] == 0 and again.attrs["sweep"]["skipped"] == 5
    cols = ["case", "t", "load", "film_min"]
    assert again[cols].equals(table[cols])


def test_a_killed_worker_is_survived(tmp_path):
    cases = [{"fluid.beta": b} for b in (50.0, 200.0)]
    table = sw.sweep(
        None, cases=cases, run=RUN, out=tmp_path, workers=2, progress=False, runner=_killing_runner
    )
    killed = list((tmp_path / "cases").glob("*.killed"))
    assert len(killed) == 1  # the worker running beta = 200 died once ...
    st = table.drop_duplicates("case").set_index("fluid.beta")["status"]
    assert st[200.0] == "done" and st[50.0] == "done"  # ... and Dask ran the case again


def test_a_script_without_the_main_guard_gets_femehls_error(tmp_path):
    """A script that starts a sweep at import: each Dask worker, a new Python process that
    imports the script, starts it again and dies, and the cluster raised distributed's bare
    "Nanny failed to start".  femehl's error names the guard (measured: 3 s)."""
    import subprocess

    script = tmp_path / "sweep_script.py"
    script.write_text(
        "from femehl.studies import sweeps\n"
        f"sweeps.sweep(None, cases=[{{'fluid.beta': 50.0}}], run={RUN!r}, out={str(tmp_path / 'out')!r}, "
        "workers=1, progress=False)\n"
    )
    env = dict(os.environ, OMP_NUM_THREADS="1")
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, env=env)
    assert out.returncode != 0
    last = out.stderr.strip().splitlines()[-1]
    assert last.startswith("femehl.errors.SolverError") and 'if __name__ == "__main__":' in last


def test_another_sweep_in_the_same_folder_is_refused(swept, tmp_path):
    table, out, cases = swept
    with pytest.raises(femehl.errors.OutputError, match="holds another sweep"):
        sw.sweep(None, cases=cases[:2], run=RUN, out=out, workers=1, progress=False)


@pytest.mark.parametrize(
    "grid,words",
    [
        ({"fluid.betta": [1.0]}, "betta"),
        ({}, "grid is empty"),
        ({"fluid.beta": []}, "is empty"),
        ({"fluid.beta": {"logspace": [0, 10], "num": 3}}, "positive ends"),
        ({"fluid.beta": {"logspace": [1, 10]}}, "num = N"),
        ({"fluid.beta": [-1.0]}, "beta"),
        ({"flud.beta": [1.0]}, "flud"),
    ],
)
def test_bad_sweep_descriptions(grid, words):
    with pytest.raises(sw.SweepError, match=words):
        sw.plan_sweep(None, grid, run=RUN)
    # the same through a scene file's tables (dotted names into the TOML)
    base = pathlib.Path(__file__).parents[1] / "examples" / "paper_sphere.toml"
    with pytest.raises(sw.SweepError, match=words):
        sw.plan_sweep(base, grid, run=RUN)


def test_grid_values_and_keys():
    plan = sw.plan_sweep(
        None, {"fluid.beta": {"logspace": [20, 20000], "num": 4}, "domain.L": [2.0, 3.0]}, run=RUN
    )
    betas = sorted({c.params["fluid.beta"] for c in plan.cases})
    assert np.allclose(betas, [20, 200, 2000, 20000])
    assert len(plan.cases) == 8 and len({c.key for c in plan.cases}) == 8
    again = sw.plan_sweep(
        None, {"domain.L": [3.0, 2.0], "fluid.beta": {"logspace": [20, 20000], "num": 4}}, run=RUN
    )
    assert {c.key for c in again.cases} == {c.key for c in plan.cases}  # content, not order
    sample = sw.plan_sweep(
        None, sample={"n": 5, "seed": 3, "fluid.beta": {"loguniform": [20, 2000]}}, run=RUN
    )
    b = [c.params["fluid.beta"] for c in sample.cases]
    assert len(b) == 5 and all(20 <= x <= 2000 for x in b)


def test_sweep_file_and_cli_errors(tmp_path, capsys):
    f = tmp_path / "s.toml"
    f.write_text('[sweep]\nscene = "nope.toml"\n[grid]\n"fluid.beta" = [20.0]\n')
    assert main(["sweep", str(f)]) == 2
    assert "does not exist" in capsys.readouterr().err
    f.write_text('[grid]\n"fluid.beta" = [20.0]\n[clutser]\nworkers = 2\n')
    assert main(["sweep", str(f)]) == 2
    assert "clutser" in capsys.readouterr().err
    assert main(["sweep", "plot", str(tmp_path)]) == 2
    assert "no results.parquet" in capsys.readouterr().err


def test_fit_power_recovers_an_exponent():
    from femehl.studies.sweep_plot import fit_power

    x = np.geomspace(20, 20000, 7)
    n, c = fit_power(x, 3.0 * x**-0.6)
    assert n == pytest.approx(-0.6, abs=1e-12) and c == pytest.approx(3.0, rel=1e-12)
    assert np.isnan(fit_power([1.0], [2.0])[0])  # one point: no fit


def test_master_curves_of_the_small_sweep(swept, capsys):
    """One curve per value of the other parameter (L); exponents printed; the classical
    predictions drawn where x is beta."""
    import matplotlib

    matplotlib.use("Agg")
    from femehl.studies.sweep_plot import plot_master_curves

    table, out, cases = swept
    png, lines = plot_master_curves(out, x="fluid.beta")
    assert png.stat().st_size > 10_000 and (out / "master_curves.md").is_file()
    fits = [ln for ln in lines if ln.startswith("minimum film")]
    assert len(fits) == 2 and all("fluid.beta^" in ln for ln in fits)  # L = 2 and L = 2.5
    # these short cases end before sliding starts (t = 1): no steady-sliding prediction
    assert any("not every case slides" in ln for ln in lines)
    assert main(["sweep", "plot", str(out), "--x", "domain.L"]) == 0
    assert main(["sweep", "plot", str(out), "--x", "fluid.bta"]) == 2
    assert "not a swept parameter" in capsys.readouterr().err
    # run.mesh is swept (the failing case's mesh file) but is text: femehl's error, not numpy's
    assert main(["sweep", "plot", str(out), "--x", "run.mesh"]) == 2
    err = capsys.readouterr().err
    assert "is not a number in every case" in err and "fluid.beta" in err


def test_retry_failed_runs_the_failed_case_again(swept, capsys):
    """--retry-failed: the failed case runs again (and fails again: its mesh file is still
    missing), the finished ones are not touched."""
    table, out, cases = swept
    marks = len(list((out / "marks").iterdir()))
    again = sw.sweep(
        None,
        cases=cases,
        run=RUN,
        out=out,
        workers=1,
        progress=False,
        runner=_counting_runner,
        retry_failed=True,
    )
    assert len(list((out / "marks").iterdir())) == marks + 1
    assert again.attrs["sweep"]["ran"] == 1
    assert (again.drop_duplicates("case")["status"] == "failed").sum() == 1


def test_the_example_sweep_and_its_committed_table():
    """examples/sweep_beta.toml: 12 log-spaced beta x 2 shapes; the committed table
    (benchmarks/sweep_beta) holds exactly its cases, each done, steady and near Hertz."""
    import pandas as pd

    root = pathlib.Path(__file__).parents[1]
    plan = sw.load_sweep_file(root / "examples" / "sweep_beta.toml")
    assert len(plan.cases) == 24 and plan.spec["cluster"] == {"workers": 2}
    betas = sorted({c.params["fluid.beta"] for c in plan.cases})
    assert np.allclose(betas, np.geomspace(20, 20000, 12), rtol=1e-12)
    assert {c.options["mesh"] for c in plan.cases} == {"fitted"} and all(
        c.options["t_end"] == 8.0 for c in plan.cases
    )
    df = pd.read_parquet(root / "benchmarks" / "sweep_beta" / "results.parquet")
    assert set(df["case"]) == {c.key for c in plan.cases}  # the table is of this sweep
    last = df[df["t"] == 8.0]
    assert len(last) == 24 and set(last["status"]) == {"done"}
    # at beta = 20000 the film is thin (about 1e-3): the load is within 1 % of the dry Hertz
    # load of the same indentation (4/(3 pi) for the sphere)
    from femehl.reference.theory import hertz_load

    big = last[last["fluid.beta"] == last["fluid.beta"].max()]
    for _, r in big.iterrows():
        ind = json.loads(r["indenter"])
        dry = hertz_load(1.0, ind.get("Rx", ind.get("R")), ind.get("Ry", ind.get("R")))
        assert r["load"] == pytest.approx(dry, rel=0.01)
