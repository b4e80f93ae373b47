"""femehl.studies.stribeck: the plan of speeds, bad input, the steadiness of a case.

The curves themselves are checked where they are run: the rough line's in
tests/test_examples.py (``check_stribeck_curve``), the PDMS ball's in
benchmarks/stribeck_pdms.md.
"""

from __future__ import annotations

import csv
import pathlib

import numpy as np
import pandas as pd
import pytest

from femehl.cli import main as cli_main
from femehl.problem.scenefile import tomllib
from femehl.studies.stribeck import STEADY_CHANGE, StribeckError, _history, _steady, plan_stribeck

SI = {
    "si": {"R": 0.01, "G": 1e5, "eta": 1.0, "V_ss": 0.01, "h_inf": 1e-4, "h0": 1e-5, "load": 0.05},
    "run": {"t_end": 3.0},
}


def test_the_speeds_of_an_si_scene_are_its_sliding_speed(tmp_path):
    plan, name = plan_stribeck(SI, (1e-3, 1e-1), 3, out=tmp_path / "s")
    assert name == "si.V_ss"
    assert [c.params[name] for c in plan.cases] == pytest.approx([1e-3, 1e-2, 1e-1], rel=1e-12)


def test_the_cases_keep_no_field_series_unless_asked(tmp_path):
    plan, _ = plan_stribeck(SI, (1e-3, 1e-1), 2, out=tmp_path / "a")
    assert all(c.options.get("store_every") == 0 for c in plan.cases)
    plan, _ = plan_stribeck(
        {**SI, "run": {"t_end": 3.0, "store_every": 5}}, (1e-3, 1e-1), 2, out=tmp_path / "b"
    )
    assert all(c.options.get("store_every") == 5 for c in plan.cases)


def test_the_speeds_of_a_normalized_scene_divide_its_beta(tmp_path):
    scene = pathlib.Path(__file__).resolve().parents[1] / "examples" / "cylinder_winkler.toml"
    beta = tomllib.loads(scene.read_text())["fluid"]["beta"]
    plan, name = plan_stribeck(scene, (0.1, 10.0), 3, out=tmp_path / "s")
    assert name == "fluid.beta"
    assert [c.params[name] for c in plan.cases] == pytest.approx([10 * beta, beta, beta / 10], rel=1e-12)


@pytest.mark.parametrize(
    "speeds, num, match",
    [
        ((1.0,), 3, "two numbers"),
        (("a", 2.0), 3, "two numbers"),
        ((2.0, 1.0), 3, "0 < LO < HI"),
        ((0.0, 1.0), 3, "0 < LO < HI"),
        ((1.0, float("inf")), 3, "0 < LO < HI"),
        ((1.0, 2.0), 1, "num"),
        ((1.0, 2.0), True, "num"),
        ((1.0, 2.0), 2.5, "num"),
    ],
)
def test_bad_speeds_are_refused_with_the_fix(speeds, num, match, tmp_path):
    with pytest.raises(StribeckError, match=match):
        plan_stribeck(SI, speeds, num, out=tmp_path / "s")


def test_a_missing_or_broken_scene_file(tmp_path):
    with pytest.raises(StribeckError, match="does not exist"):
        plan_stribeck(tmp_path / "nope.toml", (1.0, 2.0))
    bad = tmp_path / "bad.toml"
    bad.write_text("[si\nR = ")
    with pytest.raises(StribeckError, match="cannot read"):
        plan_stribeck(bad, (1.0, 2.0))


def test_the_command_refuses_bad_speeds_before_anything_runs(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text("[fluid]\nbeta = 20.0\n")
    rc = cli_main(["stribeck", str(scene), "--speeds", "2", "1", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "0 < LO < HI" in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_a_case_is_steady_by_its_whole_history(tmp_path):
    """The sweep's table keeps a case's stored times only (a fast case may store a few: here
    t = 0, 2, 8); steadiness reads every step of its summary.csv (the friction settles by
    t = 6, so it changed by 0.08 % over the last fifth, against 8 % since the stored t = 2)."""
    t = np.linspace(0.0, 8.0, 81)
    friction = 0.3 * (1.0 - 0.6 * np.exp(-t))
    with open(tmp_path / "summary.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["t", "friction"])
        w.writerows(zip(t, friction, strict=True))
    sparse = pd.DataFrame({"t": t[[0, 20, 80]], "friction": friction[[0, 20, 80]]})
    assert not _steady(_history(tmp_path / "missing", sparse))  # the table's rows alone
    assert _steady(_history(tmp_path, sparse))
    assert abs(friction[-1] / friction[64] - 1.0) < 0.1 * STEADY_CHANGE
