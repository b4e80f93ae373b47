"""``femehl run`` options: refused when they do not apply or are out of range, before anything
is written; exit codes 0 / 2 / 130; Ctrl-C prints the command that resumes."""

from __future__ import annotations

import hashlib
import pathlib
import shlex

import pytest

import femehl
import femehl.output.run
import femehl.solver.loop
from femehl.cli import main, resume_command
from femehl.errors import SceneError
from femehl.output._validation import (
    check_count,
    check_divisions,
    check_method_flags,
    check_run_options,
)

BASE = ["run", "--mesh", "coarse", "--dt", "0.02", "--quiet"]


def _snapshot(folder):
    folder = pathlib.Path(folder)
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in folder.iterdir() if p.is_file()}


def _rows(folder):
    return (pathlib.Path(folder) / "summary.csv").read_text().splitlines()


@pytest.mark.parametrize(
    "args, words",
    [
        (["--method", "fd", "--mesh", "coarse"], ["--mesh", "--method fe"]),
        (["--dr", "0.1"], ["--dr", "--method fd"]),
        (["--dtheta-divisions", "12"], ["--dtheta-divisions", "--method fd"]),
        (["--method", "fd", "--scheme", "bdf2"], ["--scheme"]),
        (["--method", "fd", "--dtheta-divisions", "0"], ["--dtheta-divisions", ">= 2"]),
        (["--method", "fd", "--dtheta-divisions", "-4"], ["--dtheta-divisions", ">= 2"]),
        (["--method", "fd", "--dr", "0"], ["--dr", "> 0"]),
        (["--mesh", "coarse", "--store-every", "-1"], ["store_every", ">= 0"]),
        (["--mesh", "coarse", "--dt", "0"], ["dt must be > 0"]),
        (["--mesh", "coarse", "--t-end", "nan"], ["t_end must be finite"]),
        (["--mesh", "coarse", "--t-end", "inf"], ["t_end must be finite"]),
        (["--mesh", "coarse", "--resume", "--overwrite"], ["--resume", "--overwrite"]),
        (["--n-elements", "10"], ["--n-elements"]),
    ],
)
def test_bad_options_exit_2_and_write_nothing(tmp_path, capsys, args, words):
    out = tmp_path / "o"
    rc = main(["run", "--t-end", "0.04", "--quiet", *args, "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2, err
    for w in words:
        assert w in err
    assert not out.exists()


def test_fd_accepts_scheme_euler(tmp_path):
    out = tmp_path / "o"
    assert (
        main(
            [
                "run",
                "--method",
                "fd",
                "--scheme",
                "euler",
                "--dr",
                "0.2",
                "--dtheta-divisions",
                "8",
                "--t-end",
                "0.04",
                "--dt",
                "0.02",
                "--out",
                str(out),
                "--quiet",
            ]
        )
        == 0
    )
    assert len(_rows(out)) == 1 + 3


def test_scene_file_options_of_the_other_method_are_refused(tmp_path, capsys):
    f = tmp_path / "s.toml"
    f.write_text('[run]\nmethod = "fd"\nmesh = "coarse"\n')
    assert main(["run", str(f), "--t-end", "0.04", "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert "mesh" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_regression_bad_store_every_keeps_the_run_and_resume_goes_on(tmp_path, capsys):
    """``--store-every -1`` on a run folder used to wipe its summary.csv; --resume then said done."""
    out = str(tmp_path / "o")
    assert main(BASE + ["--t-end", "0.04", "--out", out]) == 0
    before, rows = _snapshot(out), _rows(out)
    for bad in (
        ["--store-every", "-1"],
        ["--store-every", "-1", "--resume"],
        ["--store-every", "-1", "--overwrite"],
        ["--t-end", "nan", "--resume"],
    ):
        assert main(BASE + ["--t-end", "0.08", "--out", out, *bad]) == 2
        assert _snapshot(out) == before
    capsys.readouterr()
    assert main(BASE + ["--t-end", "0.08", "--out", out, "--resume"]) == 0
    new = _rows(out)
    assert new[: len(rows)] == rows and len(new) == len(rows) + 2


def test_existing_run_needs_overwrite_or_resume(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(BASE + ["--t-end", "0.04", "--out", str(out)]) == 0
    (out / "notes.txt").write_text("mine")
    before = _snapshot(out)
    capsys.readouterr()
    assert main(BASE + ["--t-end", "0.02", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert str(out) in err and "--overwrite" in err and "--resume" in err
    assert _snapshot(out) == before
    assert main(BASE + ["--t-end", "0.02", "--out", str(out), "--overwrite"]) == 0
    assert len(_rows(out)) == 1 + 2 and (out / "notes.txt").read_text() == "mine"


def test_ctrl_c_exits_130_and_prints_the_resume_command(tmp_path, capsys, monkeypatch):
    real = femehl.solver.loop.make_stepper

    def make(*a, **k):
        stepper = real(*a, **k)
        orig, calls = stepper.step, [0]

        def step(*sa, **sk):
            calls[0] += 1
            if calls[0] > 2:
                raise KeyboardInterrupt
            return orig(*sa, **sk)

        stepper.step = step
        return stepper

    monkeypatch.setattr(femehl.solver.loop, "make_stepper", make)
    out = tmp_path / "o"
    argv = BASE + ["--t-end", "0.1", "--out", str(out)]
    assert main(argv) == 130
    err = capsys.readouterr().err
    line = next(ln.strip() for ln in err.splitlines() if ln.strip().startswith("femehl run"))
    assert line.endswith(f"--resume --out {shlex.quote(str(out))}")
    assert len(_rows(out)) == 1 + 3  # t = 0, 0.02, 0.04
    monkeypatch.undo()
    assert main(shlex.split(line)[1:]) == 0
    assert len(_rows(out)) == 1 + 6


def test_resume_command():
    argv = ["run", "s.toml", "--overwrite", "--out=a b", "--dt", "0.1"]
    assert resume_command(argv, "a b") == "femehl run s.toml --dt 0.1 --resume --out 'a b'"
    assert resume_command(["run", "--out", "x", "--resume"], "x") == "femehl run --resume --out x"


# ---- validators ------------------------------------------------------------------------------
@pytest.mark.parametrize("value", [-1, 1.0, True, "3", None])
def test_check_count_refuses(value):
    with pytest.raises(SceneError, match="integer >= 0"):
        check_count("store_every", value)


def test_validators_return_values_and_keep_inputs():
    assert check_divisions(12) == 12
    assert check_run_options(0.1, 0.02, 2, None)[3:] == (2, 2)
    given = {"mesh": None, "dr": 0.1, "scheme": "euler"}
    copy = dict(given)
    check_method_flags("fd", given)
    assert given == copy
    with pytest.raises(SceneError, match="--dr"):
        check_method_flags("fe", given)
    assert given == copy
