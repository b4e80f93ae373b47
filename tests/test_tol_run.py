"""``tol`` reaches the command line, scene files and run folders (adaptive time steps)."""

from __future__ import annotations

import csv

import numpy as np

from femehl.cli import main
from femehl.problem.scenefile import load_scene_file


def _times(folder):
    with open(folder / "summary.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    return np.array([float(r[0]) for r in rows[1:]])


def test_cli_tol_runs_adaptive_steps_and_resumes(tmp_path):
    out = tmp_path / "run"
    args = ["run", "--mesh", "coarse", "--step-tol", "0.02", "--quiet", "--out", str(out)]
    assert main([*args, "--t-end", "1.2"]) == 0
    t = _times(out)
    steps = np.diff(t)
    assert t[-1] == 1.2 and np.all(steps > 0)
    assert steps.max() > 2 * steps.min()  # the steps adapt
    assert np.any(np.isclose(t, 1.0))  # the end of the ramp is a breakpoint: landed on
    assert main([*args, "--t-end", "1.6", "--resume"]) == 0
    t2 = _times(out)
    assert np.array_equal(t2[: t.size], t) and t2[-1] == 1.6 and np.all(np.diff(t2) > 0)


def test_cli_refuses_a_tol_that_is_not_a_relative_error(tmp_path, capsys):
    for bad in ("0", "-1", "0.7", "nan"):
        assert main(["run", "--tol", bad, "--out", str(tmp_path / "x"), "--quiet"]) == 2
        assert "tol" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


def test_scene_file_run_tol(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text('[fluid]\nbeta = 200.0\n[run]\nstep_tol = 0.02\nt_end = 0.5\nmesh = "coarse"\n')
    _, run = load_scene_file(path)
    assert run["step_tol"] == 0.02
    out = tmp_path / "o"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    t = _times(out)
    assert t[-1] == 0.5 and np.ptp(np.diff(t)) > 0


def test_scene_file_tol_without_a_mesh_is_automatic(tmp_path):
    """``[run] tol`` and no mesh/dt: the file's tol is the accuracy of an automatic run."""
    import json

    path = tmp_path / "s.toml"
    path.write_text("[fluid]\nbeta = 200.0\n[run]\ntol = 0.05\nt_end = 0.2\n")
    out = tmp_path / "o"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    chosen = json.loads((out / "auto.json").read_text())
    assert chosen["tol"] == 0.05 and chosen["reached"] and chosen["total"] <= 0.05
