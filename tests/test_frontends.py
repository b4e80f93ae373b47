"""The sweep and plot front ends: femehl's own errors (never a bare traceback), nothing
lost or mixed.

Sweeps: wrong types in the sweep file's tables, run options checked before the cluster
starts, ``workers = 0``, a grid too large to expand, a sweep with failed cases (exit 3
naming them), Ctrl-C (the truth about what finished, the command that goes on), and a
property-based test over sweep-folder states (finished, interrupted, damaged files).
Plots: write faults, ``--out`` a folder, a damaged last frame, ``--t`` between the stored
times, and the import graph of ``femehl.output``.
"""

from __future__ import annotations

import ast
import dataclasses
import errno
import json
import pathlib
import re
import shutil
import sys
import tempfile
import time

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import femehl  # noqa: E402
from femehl.cli import main  # noqa: E402
from femehl.errors import OutputError  # noqa: E402

ROOT = pathlib.Path(__file__).parents[1]
RUN = {"t_end": 0.1, "dt": 0.05, "mesh": "coarse", "store_every": 2}
RUN_TOML = '[run]\nt_end = 0.1\ndt = 0.05\nmesh = "coarse"\nstore_every = 2\n'


# ---- fixtures ----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def run_folder(tmp_path_factory):
    """The paper case on the coarse mesh to t = 0.8, fields stored at 0, 0.2, ..., 0.8."""
    folder = tmp_path_factory.mktemp("run")
    from femehl.api import run_to_folder

    run_to_folder(
        femehl.presets.paper_sphere(),
        folder,
        mesh="coarse",
        t_end=0.8,
        dt=0.1,
        store_every=2,
        log=lambda *a: None,
    )
    return folder


@pytest.fixture
def copy_of(run_folder, tmp_path):
    """A fresh copy of the run folder (tests that damage it)."""
    dst = tmp_path / "copy"
    shutil.copytree(run_folder, dst)
    return dst


@pytest.fixture(scope="module")
def scheduler():
    """One in-process Dask cluster for the module (no process start-up per sweep)."""
    pytest.importorskip("distributed")
    pytest.importorskip("pyarrow")
    import cloudpickle
    from distributed import LocalCluster

    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0")
    yield cluster.scheduler_address
    cluster.close()
    cloudpickle.unregister_pickle_by_value(sys.modules[__name__])


def _sweep_file(tmp_path, body, name="s.toml"):
    f = tmp_path / name
    f.write_text(body.replace("OUT", str(tmp_path / "out")))
    return f


# ---- 1. wrong value types in the sweep file's tables ---------------------------------------
@pytest.mark.parametrize(
    "body,words",
    [
        (
            '[sweep]\nscene = 3\n[grid]\n"fluid.beta" = [20.0]\n',
            ["[sweep] scene must be a string", "in quotes"],
        ),
        (
            '[sweep]\nout = ["a"]\n[grid]\n"fluid.beta" = [20.0]\n',
            ["[sweep] out must be a string", "give a folder"],
        ),
        (
            '[sweep]\nmax_cases = "many"\n[grid]\n"fluid.beta" = [20.0]\n',
            ["max_cases must be a positive integer"],
        ),
        (
            '[grid]\n"fluid.beta" = [20.0]\n[cluster]\nworkers = "2"\n',
            ["[cluster] workers must be a positive integer", "workers = 2"],
        ),
        (
            '[grid]\n"fluid.beta" = [20.0]\n[cluster]\nworkers = 2.5\n',
            ["workers must be a positive integer", "(float)"],
        ),
        (
            '[grid]\n"fluid.beta" = [20.0]\n[cluster]\nscheduler = 8786\n',
            ["scheduler must be a string", "tcp://"],
        ),
        (
            '[grid]\n"fluid.beta" = [20.0]\n[cluster]\nmemory_limit = "lots"\n',
            ["memory_limit must be a size", "4GiB"],
        ),
        ('[grid]\n"fluid.beta" = [20.0]\n[cluster]\nmemory_limit = -1\n', ["memory_limit must be a size"]),
        ('sweep = 3\n[grid]\n"fluid.beta" = [20.0]\n', ["sweep must be a table", "[sweep] section"]),
        ('cluster = "big"\n[grid]\n"fluid.beta" = [20.0]\n', ["cluster must be a table"]),
        ('run = 5\n[grid]\n"fluid.beta" = [20.0]\n', ["run must be a table"]),
        ("cases = [1, 2]\n", ["cases must be an array of tables", "[[cases]]"]),
        (
            '[sample]\nn = 2\nseed = "a"\n"fluid.beta" = { uniform = [20, 200] }\n',
            ["seed must be an integer"],
        ),
        ('[grid]\n"fluid.beta" = [20.0]\n[run]\nt_end = "8"\n', ["t_end"]),
    ],
)
def test_wrong_types_in_the_sweep_file_are_femehls_errors(tmp_path, capsys, body, words):
    f = _sweep_file(tmp_path, body)
    assert main(["sweep", str(f)]) == 2  # a bare TypeError/AttributeError would raise here
    err = capsys.readouterr().err
    assert err.startswith("femehl: error:") and str(f) in err
    for w in words:
        assert w in err, err
    assert not (tmp_path / "out").exists()


# ---- 2. run options checked before the cluster; failed cases exit non-zero ------------------
@pytest.mark.parametrize(
    "run,words",
    [
        ({"t_end": -1.0}, "t_end"),
        ({"store_every": 1.5}, "store_every"),
        ({"tol": 2.0}, "tol"),
        ({"method": "fx"}, "unknown method 'fx'"),
        ({"mesh": "coarse", "dt": 0.05, "max_wall": 10.0}, "automatic mode only"),
        ({"mesh": "coarse", "dt": 0.05, "meshh": 3}, "meshh"),
        ({"mesh": "coarse", "dt": 0.05, "overwrite": True}, "the sweep sets these itself"),
    ],
)
def test_bad_run_options_are_refused_before_the_cluster_starts(tmp_path, monkeypatch, run, words):
    from femehl.studies import sweeps as sw

    def no_cluster(*a, **k):
        raise AssertionError("the cluster was started for a sweep whose cases cannot run")

    monkeypatch.setattr(sw, "_client", no_cluster)
    cases = [{"fluid.beta": 50.0}, {"fluid.beta": 200.0}]
    with pytest.raises(sw.SweepError, match="2 of 2 cases cannot run") as info:
        sw.sweep(None, cases=cases, run=run, out=tmp_path / "out", progress=False)
    assert words in str(info.value) and "fluid.beta = 50.0" in str(info.value)
    assert not (tmp_path / "out").exists()  # nothing written


def test_cli_all_bad_cases_exit_2_naming_them(tmp_path, capsys, monkeypatch):
    from femehl.studies import sweeps as sw

    monkeypatch.setattr(sw, "_client", lambda *a, **k: pytest.fail("cluster started"))
    body = '[[cases]]\n"fluid.beta" = 50.0\n[[cases]]\n"fluid.beta" = 200.0\n[run]\nt_end = -2.0\n'
    assert main(["sweep", str(_sweep_file(tmp_path, body))]) == 2
    err = capsys.readouterr().err
    assert "2 of 2 cases cannot run" in err and "fluid.beta = 200.0" in err and "t_end" in err


def test_cli_failed_cases_exit_3_naming_them_and_the_others_stay(tmp_path, capsys, scheduler):
    """One case runs, one fails on its worker (its mesh file is missing): exit 3, the failed
    case named with its error and the command to retry it, the finished case written."""
    missing = tmp_path / "no-such-mesh.msh"
    body = (
        f'[sweep]\nout = "OUT"\n[[cases]]\n"fluid.beta" = 50.0\n[[cases]]\n"fluid.beta" = 60.0\n'
        f'"run.mesh" = "{missing}"\n' + RUN_TOML
    )
    f = _sweep_file(tmp_path, body)
    assert main(["sweep", str(f), "--scheduler", scheduler, "--quiet"]) == 3
    cap = capsys.readouterr()
    assert "1 of 2 cases did not finish" in cap.err and "fluid.beta = 60.0" in cap.err
    assert "no-such-mesh" in cap.err and "--retry-failed" in cap.err
    from femehl.studies import sweeps as sw

    table = sw.read_results(tmp_path / "out")
    st = table.drop_duplicates("case").set_index("fluid.beta")["status"]
    assert st[50.0] == "done" and st[60.0] == "failed"
    done = table[table["fluid.beta"] == 50.0]
    assert np.all(np.isfinite(done["load"])) and len(done) == 2  # t = 0 and 0.1 stored


# ---- 3. workers = 0 -----------------------------------------------------------------------
def test_workers_zero_is_refused_everywhere(tmp_path, capsys, monkeypatch):
    from femehl.studies import sweeps as sw

    monkeypatch.setattr(sw, "_client", lambda *a, **k: pytest.fail("cluster started"))
    with pytest.raises(sw.SweepError, match="workers must be a positive integer") as info:
        sw.sweep(None, cases=[{"fluid.beta": 50.0}], run=RUN, out=tmp_path / "a", workers=0, progress=False)
    assert "leave it out for one per core" in str(info.value)
    body = '[sweep]\nout = "OUT"\n[grid]\n"fluid.beta" = [50.0]\n' + RUN_TOML
    f = _sweep_file(tmp_path, body)
    assert main(["sweep", str(f), "--workers", "0"]) == 2
    assert "got 0 (int): give e.g. workers = 2 (--workers 2)" in capsys.readouterr().err
    f2 = _sweep_file(tmp_path, body + "[cluster]\nworkers = 0\n", "s2.toml")
    assert main(["sweep", str(f2)]) == 2
    assert (
        "[cluster] workers must be a positive integer (local worker processes), got 0"
        in capsys.readouterr().err
    )
    assert not (tmp_path / "out").exists() and not (tmp_path / "a").exists()


# ---- 4. a grid too large to expand --------------------------------------------------------
def test_a_huge_grid_is_refused_before_it_is_expanded():
    from femehl.studies import sweeps as sw

    grid = {n: {"linspace": [1.0, 2.0], "num": 10_000} for n in ("fluid.beta", "domain.L")}
    t0 = time.perf_counter()
    with pytest.raises(sw.SweepError) as info:
        sw.plan_sweep(None, grid, run=RUN)
    assert time.perf_counter() - t0 < 2.0  # counted, not expanded
    msg = str(info.value)
    assert "100,000,000 cases" in msg and f"{sw.MAX_CASES:,}" in msg
    assert "split it into several sweeps" in msg and "max_cases" in msg
    with pytest.raises(sw.SweepError, match="5 cases"):
        sw.plan_sweep(None, sample={"n": 5, "fluid.beta": {"uniform": [20, 200]}}, run=RUN, max_cases=4)
    assert len(sw.plan_sweep(None, {"fluid.beta": [20.0, 30.0, 40.0]}, run=RUN, max_cases=3).cases) == 3
    with pytest.raises(sw.SweepError, match="3 cases"):
        sw.plan_sweep(None, {"fluid.beta": [20.0, 30.0, 40.0]}, run=RUN, max_cases=2)


def test_max_cases_in_the_sweep_file(tmp_path, capsys):
    body = '[sweep]\nmax_cases = 2\n[grid]\n"fluid.beta" = [20.0, 30.0, 40.0]\n' + RUN_TOML
    assert main(["sweep", str(_sweep_file(tmp_path, body))]) == 2
    assert "more than the limit of 2" in capsys.readouterr().err


# ---- 5. Ctrl-C ----------------------------------------------------------------------------
def test_ctrl_c_says_what_finished_and_how_to_go_on(tmp_path, capsys, monkeypatch, scheduler):
    """Interrupted after the first case finished: exit 130, '1 of 3 cases finished', the
    command; running that command finishes the sweep without running the first again."""
    import distributed

    from femehl.studies import sweeps as sw

    real = distributed.as_completed

    def interrupted(futures):
        for fut in real(futures):
            yield fut
            raise KeyboardInterrupt

    body = '[sweep]\nout = "OUT"\n[grid]\n"fluid.beta" = [40.0, 50.0, 60.0]\n' + RUN_TOML
    f = _sweep_file(tmp_path, body)
    monkeypatch.setattr(distributed, "as_completed", interrupted)
    argv = ["sweep", str(f), "--scheduler", scheduler, "--quiet"]
    assert main(argv) == 130
    err = capsys.readouterr().err
    assert "nothing to resume" not in err
    said = re.search(r"interrupted; (\d) of 3 cases finished", err)
    assert said and int(said.group(1)) >= 1 and f"femehl sweep {f}" in err
    out = tmp_path / "out"
    _wait_idle(scheduler)  # a case still running on the worker finishes (and is kept)
    finished = [p for p in (out / "cases").glob("*/case.json")]
    assert len(finished) >= 1
    before = {p: p.read_bytes() for p in finished if json.loads(p.read_text())["status"] == "done"}
    table = sw.read_results(out)  # the table of what finished was written
    assert set(table.drop_duplicates("case")["status"]) <= {"done", "missing"}
    monkeypatch.setattr(distributed, "as_completed", real)
    command = err.strip().splitlines()[-1].split()
    assert command[:2] == ["femehl", "sweep"]
    assert main(command[1:]) == 0
    assert all(p.read_bytes() == b for p, b in before.items())  # not run again
    assert set(sw.read_results(out).drop_duplicates("case")["status"]) == {"done"}


def _wait_idle(address, timeout=60.0):
    from distributed import Client

    with Client(address, timeout="20s") as c:
        t0 = time.perf_counter()
        while any(c.processing().values()) and time.perf_counter() - t0 < timeout:
            time.sleep(0.2)


# ---- property: rerunning a sweep folder never loses or mixes --------------------------------
def _fake_runner(case, folder):
    """A case without the solver: summary.csv and case.json from its beta (values to check)."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    beta = case.params["fluid.beta"]
    (folder / "summary.csv").write_text(
        f"t,load,film_min\n0,{beta},{1 / beta}\n0.1,{2 * beta},{0.5 / beta}\n"
    )
    rec = {
        "key": case.key,
        "params": case.params,
        "status": "done",
        "error": None,
        "wall_s": 0.01,
        "rows": [],
    }
    (folder / "case.json").write_text(json.dumps(rec))
    return rec


def _tree(folder: pathlib.Path) -> dict:
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_rerunning_a_sweep_folder_never_loses_or_mixes(scheduler):
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    from femehl.studies import sweeps as sw

    betas = (40.0, 50.0, 60.0)
    plan0 = sw.plan_sweep(None, cases=[{"fluid.beta": b} for b in betas], run=RUN)
    state = st.fixed_dictionaries(
        {
            "done": st.sets(st.sampled_from(range(3))),
            "failed": st.sets(st.sampled_from(range(3))),
            "partial": st.sets(st.sampled_from(range(3))),
            "bad_json": st.sets(st.sampled_from(range(3))),
            "spec": st.sampled_from(["same", "absent", "damaged", "other"]),
            "results": st.sampled_from(["absent", "ok", "damaged"]),
            "overwrite": st.booleans(),
            "retry": st.booleans(),
        }
    )

    @settings(max_examples=18, deadline=None, suppress_health_check=list(HealthCheck))
    @given(state)
    def check(s):
        out = pathlib.Path(tempfile.mkdtemp(prefix="femehl-prop-"))
        try:
            plan = dataclasses.replace(plan0, out=out)
            cases = plan.cases
            (out / "cases").mkdir(parents=True)
            foreign = out / "cases" / ("f" * 16)  # another sweep's case: never touched
            foreign.mkdir()
            (foreign / "case.json").write_text('{"key": "ffff", "status": "done"}')
            for i, c in enumerate(cases):
                folder = out / "cases" / c.key
                if i in s["done"] or i in s["failed"]:
                    _fake_runner(c, folder)
                    if i in s["failed"] and i not in s["done"]:
                        rec = json.loads((folder / "case.json").read_text())
                        (folder / "case.json").write_text(
                            json.dumps({**rec, "status": "failed", "error": "X"})
                        )
                    if i in s["bad_json"]:
                        (folder / "case.json").write_text('{"key": "' + c.key[:5])  # truncated
                elif i in s["partial"]:  # an interrupted case: files, no case.json
                    folder.mkdir()
                    (folder / "summary.csv").write_text("t,load,film_min\n0,-999,-999\n")
            if s["spec"] == "same":
                (out / "sweep.json").write_text(json.dumps(plan.spec))
            elif s["spec"] == "damaged":
                (out / "sweep.json").write_text('{"names": [')
            elif s["spec"] == "other":
                (out / "sweep.json").write_text(json.dumps({**plan.spec, "cases": {"f" * 16: {}}}))
            if s["results"] == "damaged":
                (out / "results.parquet").write_bytes(b"PAR1 not really")
            elif s["results"] == "ok":
                (out / "results.parquet").write_bytes(b"stale")  # replaced by the rerun
            before = _tree(out)
            finished_ok = {
                c.key
                for i, c in enumerate(cases)
                if (i in s["done"] or (i in s["failed"] and not s["retry"])) and i not in s["bad_json"]
            }
            refused = s["spec"] in ("damaged", "other") and not s["overwrite"]
            try:
                table = sw.sweep(
                    plan=plan,
                    scheduler=scheduler,
                    runner=_fake_runner,
                    progress=False,
                    overwrite=s["overwrite"],
                    retry_failed=s["retry"],
                )
            except OutputError as exc:
                assert refused, exc
                assert _tree(out) == before  # a refusal changes nothing
                return
            assert not refused
            after = _tree(out)
            rel = pathlib.Path("cases")
            # the other sweep's case and every finished case of this one: byte for byte
            assert after[rel / ("f" * 16) / "case.json"] == before[rel / ("f" * 16) / "case.json"]
            for key in finished_ok:
                for name in ("case.json", "summary.csv"):
                    assert after[rel / key / name] == before[rel / key / name]
            # one entry per case of this sweep, each with its own values only
            assert sorted(table["case"].unique()) == sorted(c.key for c in cases)
            for c in cases:
                rows = table[table["case"] == c.key].sort_values("t")
                b = c.params["fluid.beta"]
                i = cases.index(c)
                if i in s["failed"] and i not in s["done"] and not s["retry"] and i not in s["bad_json"]:
                    # kept as recorded, with the rows its run wrote before failing (its own only)
                    assert set(rows["status"]) == {"failed"} and set(rows["load"]) <= {b, 2 * b}
                    continue
                assert list(rows["status"]) == ["done", "done"]
                assert np.allclose(rows["load"], [b, 2 * b]) and np.allclose(rows["t"], [0.0, 0.1])
            back = sw.read_results(out)
            assert back[["case", "t", "load"]].equals(table[["case", "t", "load"]])
        finally:
            shutil.rmtree(out, ignore_errors=True)

    check()


# ---- 6. output faults ---------------------------------------------------------------------
@pytest.mark.parametrize(
    "code,words",
    [(errno.EACCES, "make the folder writable"), (errno.ENOSPC, "free some space")],
)
def test_write_faults_are_output_errors_and_keep_the_old_picture(copy_of, capsys, monkeypatch, code, words):
    from matplotlib.figure import Figure

    old = copy_of / "history.png"
    kept = old.read_bytes()

    def fail(self, fname, *a, **k):
        pathlib.Path(fname).write_bytes(b"half a picture")  # a partial write, then the fault
        raise OSError(code, "simulated")

    monkeypatch.setattr(Figure, "savefig", fail)
    assert main(["plot", "history", str(copy_of)]) == 2
    err = capsys.readouterr().err
    assert "femehl: error: cannot write the picture" in err and words in err and str(copy_of) in err
    assert old.read_bytes() == kept  # the picture there before is untouched
    assert not list(copy_of.glob("*.tmp*"))  # no temporary file left


def test_out_in_a_folder_that_cannot_exist(copy_of, tmp_path, capsys):
    blocker = tmp_path / "a-file"
    blocker.write_text("x")
    assert main(["plot", "history", str(copy_of), "--out", str(blocker / "h.png")]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert main(["plot", "history", str(copy_of), "--out", str(blocker) + "/"]) == 2
    assert "cannot create the folder" in capsys.readouterr().err


@pytest.mark.parametrize(
    "damage,words",
    [
        (lambda f: (f / "summary.csv").write_bytes(b"\xff\xfe\x00garbage"), "not a femehl summary CSV"),
        (lambda f: (f / "summary.csv").write_text("t,load\n0,1\n0.1,1\n"), "has no column(s)"),
        (lambda f: (f / "summary.csv").unlink(), "holds no femehl run"),
    ],
)
def test_a_damaged_run_folder_is_an_output_error(copy_of, capsys, damage, words):
    damage(copy_of)
    assert main(["plot", "history", str(copy_of)]) == 2
    assert words in capsys.readouterr().err


def test_a_corrupt_field_file_is_named(copy_of, capsys):
    last = sorted(copy_of.glob("fields_*.vtu"))[-1]
    data = last.read_bytes()
    i = data.find(b"<AppendedData")
    i = i if i > 0 else len(data) // 2
    last.write_bytes(data[:i] + b"<broken" + data[i + 200 :])  # complete ends, damaged inside
    assert main(["plot", "maps", str(copy_of)]) == 2
    err = capsys.readouterr().err
    assert last.name in err and "damaged" in err


def test_sweep_plot_of_damaged_or_missing_folders(tmp_path, capsys):
    pytest.importorskip("pyarrow")
    assert main(["sweep", "plot", str(tmp_path / "nope")]) == 2
    assert "is not a folder" in capsys.readouterr().err
    (tmp_path / "results.parquet").write_bytes(b"PAR1 damaged")
    assert main(["sweep", "plot", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "cannot read" in err and "rerun the sweep" in err


def test_a_sweep_out_that_is_a_file(tmp_path):
    from femehl.studies import sweeps as sw

    pytest.importorskip("distributed")
    (tmp_path / "f").write_text("mine")
    with pytest.raises(OutputError, match="is a file"):
        sw.sweep(None, cases=[{"fluid.beta": 50.0}], run=RUN, out=tmp_path / "f", progress=False)
    assert (tmp_path / "f").read_text() == "mine"


# ---- 7. --out a folder --------------------------------------------------------------------
def test_out_names_a_folder_or_a_file(copy_of, tmp_path, capsys):
    d = tmp_path / "figs"
    d.mkdir()
    assert main(["plot", "history", str(copy_of), "--out", str(d)]) == 0
    assert (d / "history.png").stat().st_size > 10_000 and not (tmp_path / "figs.png").exists()
    assert main(["plot", "maps", str(copy_of), "--t", "0.4", "--out", str(tmp_path / "new") + "/"]) == 0
    assert (tmp_path / "new" / "maps_t0.4.png").is_file()
    assert main(["plot", "animation", str(copy_of), "--out", str(d)]) == 0
    assert (d / "animation.gif").is_file()
    assert main(["plot", "history", str(copy_of), "--out", str(tmp_path / "h")]) == 0
    assert (tmp_path / "h.png").is_file()  # a file name without suffix: .png
    capsys.readouterr()
    summary = (copy_of / "summary.csv").read_bytes()
    assert main(["plot", "history", str(copy_of), "--out", str(copy_of / "summary.csv")]) == 2
    assert "cannot write a '.csv' file" in capsys.readouterr().err
    assert (copy_of / "summary.csv").read_bytes() == summary  # never drawn over
    assert main(["plot", "animation", str(copy_of), "--out", str(tmp_path / "a.png")]) == 2
    assert ".gif" in capsys.readouterr().err


# ---- 8. a damaged last frame --------------------------------------------------------------
def test_a_truncated_last_frame_is_said_not_silently_skipped(copy_of, capsys):
    files = sorted(copy_of.glob("fields_*.vtu"))
    last = files[-1]
    last.write_bytes(last.read_bytes()[:5000])  # a run stopped while writing it
    assert main(["plot", "maps", str(copy_of)]) == 0
    err = capsys.readouterr().err
    assert last.name in err and "damaged" in err
    assert "maps at t = 0.6 " in err and files[-2].name in err  # the time drawn instead, and why
    assert main(["plot", "animation", str(copy_of), "--out", str(copy_of / "a.gif")]) == 0
    assert last.name in capsys.readouterr().err
    for f in files[:-1]:  # every frame damaged: refused, naming them
        f.write_bytes(f.read_bytes()[:100])
    assert main(["plot", "maps", str(copy_of)]) == 2
    assert "no readable field file" in capsys.readouterr().err


# ---- 9. --t between stored times ----------------------------------------------------------
def test_t_takes_the_nearest_stored_time_and_says_so(copy_of, capsys):
    """Stored times 0, 0.2, 0.6, 0.8 (as an adaptive run's irregular ones): t = 0.45 was
    refused (more than half the smallest gap from every stored time); now 0.6 is drawn."""
    (copy_of / "fields_000002.vtu").unlink()  # t = 0.4
    assert main(["plot", "maps", str(copy_of), "--t", "0.45"]) == 0
    err = capsys.readouterr().err
    assert "maps at t = 0.6 (nearest stored to 0.45)" in err
    assert (copy_of / "maps_t0.6.png").is_file()
    assert main(["plot", "centreline", str(copy_of), "--t", "0.05"]) == 0
    assert "centreline at t = 0 (nearest stored to 0.05)" in capsys.readouterr().err
    assert (copy_of / "centreline_t0.png").is_file()
    assert main(["plot", "maps", str(copy_of), "--t", "0.2"]) == 0
    assert "nearest" not in capsys.readouterr().err  # a stored time: nothing to say
    for t in ("0.9", "-0.1", "nan"):
        assert main(["plot", "maps", str(copy_of), "--t", t]) == 2
        err = capsys.readouterr().err
        assert "from 0 to 0.8" in err and "give --t in that range" in err


def test_read_snapshot_nearest_without_the_cli(run_folder):
    from femehl.output.snapshot import read_snapshot

    assert read_snapshot(run_folder, 0.29).t == pytest.approx(0.2)
    assert read_snapshot(run_folder, 0.31).t == pytest.approx(0.4)
    with pytest.raises(OutputError, match="from 0 to 0.8"):
        read_snapshot(run_folder, 0.81)


# ---- 10. the import graph of femehl.output ---------------------------------------------------
def _imports(path: pathlib.Path) -> set[str]:
    """The femehl.output modules a module imports (anywhere in it, also inside functions)."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            if node.module:
                out.add(node.module.split(".")[0])
            else:
                out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("femehl.output."):
            out.add(node.module.split(".")[2])
    return out


def test_no_import_circle_in_femehl_output():
    folder = ROOT / "femehl" / "output"
    mods = {p.stem: p for p in folder.glob("*.py")}
    graph = {m: _imports(p) & set(mods) for m, p in mods.items()}
    assert "snapshot" not in graph["series"]  # the circle that was there

    def reach(start):
        seen, todo = set(), [start]
        while todo:
            for n in graph[todo.pop()]:
                if n not in seen:
                    seen.add(n)
                    todo.append(n)
        return seen

    circles = sorted(m for m in graph if m in reach(m))
    assert not circles, {m: graph[m] for m in circles}
    import importlib

    mirror, series, snapshot = (
        importlib.import_module(f"femehl.output.{m}") for m in ("mirror", "series", "snapshot")
    )
    # moved, not copied: one function, reachable under its old name
    assert snapshot.mirror_half is mirror.mirror_half and series.mirror_half is mirror.mirror_half
