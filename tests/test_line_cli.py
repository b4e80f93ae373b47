"""Line contact in TOML scene files and through ``femehl run`` (femehl.problem.scenefile, femehl.cli)."""

from __future__ import annotations

import csv
import pathlib

import numpy as np
import pytest

from femehl.api import solve_line
from femehl.cli import main
from femehl.errors import SceneFileError
from femehl.output.table import COLUMNS, ERROR_COLUMNS
from femehl.problem.line import LineScene
from femehl.problem.scene import Motion, RampHold, TanhStart
from femehl.problem.scenefile import load_scene_file
from femehl.solver.energetics import FRICTION_COLUMNS

ROOT = pathlib.Path(__file__).resolve().parents[1]
TOML = ROOT / "examples" / "cylinder_winkler.toml"


def test_toml_gives_the_example_scene():
    scene, run = load_scene_file(TOML)
    # examples/cylinder_winkler.py main() defaults
    expected = LineScene(
        k=1.0, beta=10.0, L=2.0, motion=Motion(gap=RampHold(0.1, -0.5, 1.0), velocity=TanhStart(1.0, 1.0))
    )
    assert scene.default_method == "line"
    assert scene == expected
    assert run == {"n_elements": 400, "dt": 0.05, "t_end": 15.0, "store_every": 10}


def test_cli_runs_line_contact(tmp_path, capsys):
    out = tmp_path / "out"
    rc = main(["run", str(TOML), "--t-end", "2", "--dt", "0.05", "--out", str(out), "--quiet"])
    assert rc == 0
    cap = capsys.readouterr()
    text = cap.out + cap.err  # the run's report goes to stderr, the figures to stdout
    assert "elasticity=winkler" in text and "sliding=True" in text and "squeeze=True" in text
    assert "t = 1:" in text and "t = 2:" in text
    assert (out / "line.png").stat().st_size > 0
    assert (out / "fields.pvd").is_file() and (out / "checkpoint.npz").is_file()  # a run folder
    with open(out / "summary.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    # the expert run's space estimate (a companion on 200 elements) is appended at the end
    assert tuple(rows[0]) == COLUMNS + FRICTION_COLUMNS + ERROR_COLUMNS
    assert all(r[len(COLUMNS) + 1] for r in rows[1:])  # err_load_space is filled
    data = np.array([r[: len(COLUMNS)] for r in rows[1:]], dtype=float)
    ref = solve_line(load_scene_file(TOML)[0], 2.0, 0.05, n_elements=400)
    assert data.shape[0] == ref.info["steps"] + 1 == 41
    col = {c: data[:, i] for i, c in enumerate(COLUMNS)}
    np.testing.assert_allclose(col["t"], ref.t, rtol=0, atol=1e-12)
    # SummaryWriter writes 10 significant digits: the CSV is solve_line's load so rounded
    rounded = np.array([float(f"{v:.10g}") for v in ref.load])
    np.testing.assert_allclose(col["load"], rounded, rtol=0, atol=1e-12)
    np.testing.assert_allclose(col["load"], ref.load, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(col["film_min"], ref.film_min, rtol=1e-9, atol=1e-12)
    assert np.all(col["film_min_y"] == 0) and np.all(col["p_max_y"] == 0)


def _write(tmp_path, text, name="bad.toml"):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


SCENE = """
[indenter]
kind = "cylinder"
[substrate]
{substrate}
[fluid]
beta = 10.0
[motion.gap]
kind = "ramp_hold"
h0 = 0.1
h_end = -0.5
t1 = 1.0
[run]
{run}
"""


def test_cylinder_on_halfspace_is_refused(tmp_path, capsys):
    f = _write(tmp_path, SCENE.format(substrate='kind = "halfspace"\nnu = 0.5', run="dt = 0.1"))
    with pytest.raises(SceneFileError, match="Winkler"):
        load_scene_file(f)
    assert main(["run", f, "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert "Winkler" in capsys.readouterr().err


def test_unknown_run_key_is_refused(tmp_path, capsys):
    f = _write(tmp_path, SCENE.format(substrate='kind = "winkler"\nk = 1.0', run='mesh = "coarse"'))
    assert main(["run", f, "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "mesh" in err and "n_elements" in err


@pytest.mark.parametrize(
    "extra", [["--mesh", "coarse"], ["--dr", "0.1"], ["--dtheta-divisions", "8"], ["--method", "fe"]]
)
def test_2d_options_are_refused(tmp_path, capsys, extra):
    rc = main(["run", str(TOML), "--t-end", "0.1", "--out", str(tmp_path / "o"), "--quiet"] + extra)
    assert rc == 2
    err = capsys.readouterr().err
    assert "line contact" in err


def test_radius_other_than_one_is_refused(tmp_path):
    text = SCENE.format(substrate='kind = "winkler"\nk = 1.0', run="").replace(
        'kind = "cylinder"', 'kind = "cylinder"\nR = 2.0'
    )
    with pytest.raises(SceneFileError, match="R must be 1"):
        load_scene_file(_write(tmp_path, text))
    text1 = text.replace("R = 2.0", "R = 1.0")
    assert load_scene_file(_write(tmp_path, text1, "ok.toml"))[0].default_method == "line"


def test_line_method_and_imposed_load(tmp_path):
    text = SCENE.format(substrate='kind = "winkler"\nk = 2.0', run='method = "line"\ngrading = "uniform"')
    text = text.replace("[motion.gap]", "[motion]\nload = 0.5\n[motion.gap]")
    scene, run = load_scene_file(_write(tmp_path, text))
    assert scene.substrate.k == 2.0 and scene.motion.load_controlled and scene.motion.F(3.0) == 0.5
    assert run == {"grading": "uniform"}
    bad = text.replace('method = "line"', 'method = "fe"')
    with pytest.raises(SceneFileError, match="line"):
        load_scene_file(_write(tmp_path, bad, "bad2.toml"))
