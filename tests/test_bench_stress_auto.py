"""``benchmarks/stress_auto.py``: a capped case keeps the levels it finished.

The driver kills a worker at the cap and reads femehl's per-level log lines (the format of
``femehl.accuracy.auto``'s "auto: level ..." message) from what the worker wrote to stderr.  Here a
worker that finishes two levels and then sleeps past a 3 s cap, so the record must name
exactly those two levels.
"""

import importlib.util
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def bench():
    sys.path.insert(0, str(ROOT / "benchmarks"))
    spec = importlib.util.spec_from_file_location(
        "femehl_bench_stress_auto", ROOT / "benchmarks" / "stress_auto.py"
    )
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_levels_are_read_from_the_log(bench, caplog):
    """The parser reads the lines a real automatic run logs: one per level, with its cells."""
    import logging

    import femehl
    from femehl.problem.line import LineScene

    with caplog.at_level(logging.INFO, logger="femehl"):
        res = femehl.solve(LineScene(), t_end=0.5, tol=1e-4, store_every=0)
    cells = res.info["auto"]["elements"]
    assert len(cells) >= 2
    assert [n for _, n in bench._finished_levels(caplog.text)] == cells
    assert bench._finished_levels(caplog.text.encode()) == bench._finished_levels(caplog.text)
    assert bench._finished_levels(None) == []


def test_capped_record_names_finished_levels(bench, monkeypatch):
    """A worker killed at the cap: status "capped" and the two levels it had logged."""
    script = (
        "import sys, time; "
        "sys.stderr.write('auto: level 4 (192 cells, time tolerance 0.02): 10 steps, 0.1 s\\n'); "
        "sys.stderr.write('auto: level 2 (788 cells, time tolerance 0.005): 20 steps, 0.5 s\\n'); "
        "sys.stderr.flush(); time.sleep(60)"
    )
    monkeypatch.setattr(bench.sys, "executable", sys.executable)
    real_run = bench.subprocess.run

    def run(cmd, **kw):  # the worker command replaced by the script above
        return real_run([sys.executable, "-c", script], **kw)

    monkeypatch.setattr(bench.subprocess, "run", run)
    rec = bench._run_case(dict(beta=2.0, h0=0.1, T=1.0), cap=3.0)
    assert rec["status"] == "capped at 3 s"
    assert rec["levels_done"] == [[4.0, 192], [2.0, 788]]
