"""An automatic run's folder: resumed, extended, cut short by its budget, or out of disk, it
never loses what it wrote and never ends in a bare traceback."""

from __future__ import annotations

import errno
import json

import numpy as np
import pytest

import femehl
from femehl.api import run_to_folder
from femehl.errors import OutputError
from femehl.output.table import ERROR_COLUMNS, read_summary

SCENE = femehl.presets.paper_sphere()
RUN = dict(t_end=0.3, tol=5e-2, store_every=5)


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    folder = tmp_path_factory.mktemp("auto") / "run"
    run_to_folder(SCENE, folder, **RUN)
    return folder


def _copy(src, dst):
    import shutil

    shutil.copytree(src, dst)
    return dst


def test_resuming_a_finished_automatic_run_rewrites_nothing(finished, tmp_path):
    folder = _copy(finished, tmp_path / "run")
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    res = run_to_folder(SCENE, folder, resume=True, **RUN)
    assert res.info["nothing_to_do"]
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before


def test_an_automatic_run_extends_and_keeps_its_earlier_estimate(finished, tmp_path):
    folder = _copy(finished, tmp_path / "run")
    old = read_summary(folder / "summary.csv")
    res = run_to_folder(SCENE, folder, resume=True, **{**RUN, "t_end": 0.45})
    new = read_summary(folder / "summary.csv")
    n = old["t"].size
    assert new["t"][-1] == pytest.approx(0.45) and new["t"].size > n
    np.testing.assert_array_equal(new["t"][:n], old["t"])
    for c in ERROR_COLUMNS:  # the earlier part's estimate is the one it had
        np.testing.assert_array_equal(new[c][:n], old[c])
        assert np.all(np.isfinite(new[c][n:])), c  # and the new part has one
    assert res.info["auto"]["resumed"]
    # the extension is the same run as one made to 0.45 at once on that mesh: the load at
    # t = 0.45 within the estimate (the companion re-run gives it)
    assert res.uncertainty("load", 0.45)["total"] < RUN["tol"]
    assert not (folder / "summary_estimate_before_resume.csv").exists()


def test_a_run_on_adapted_meshes_extends_on_the_same_mesh(tmp_path):
    """To t = 1 at tol = 1e-2 the candidates are on meshes adapted to the level-2 first run,
    and the folder's plan keeps their sizes, so the extension
    to t = 1.3 goes on on the very same mesh (measured: 2,941 cells at level 1, 11 s)."""
    folder = tmp_path / "run"
    first = run_to_folder(SCENE, folder, t_end=1.0)
    assert first.info["auto"]["adapted_at"] == 2.0
    more = run_to_folder(SCENE, folder, t_end=1.3, resume=True)
    assert more.t[-1] == pytest.approx(1.3) and more.info["level"] == first.info["auto"]["levels"][-1]
    np.testing.assert_array_equal(more.disc.mesh.p, first.disc.mesh.p)
    assert more.uncertainty("film_min", 1.3)["total"] < 1e-2


def test_a_budget_spent_in_the_first_run_writes_it(tmp_path, monkeypatch):
    """The time budget stops the sequence after its first run (held in memory: the meshes
    would be adapted to it): that run is written into the folder, with its estimate."""
    import femehl.accuracy.auto as auto

    monkeypatch.setattr(auto, "predicted_wall", lambda runs, cells, level: 1e9)  # nothing more fits
    folder = tmp_path / "run"
    res = run_to_folder(SCENE, folder, t_end=1.0, tol=1e-2, max_wall=3600)
    assert len(res.info["auto"]["levels"]) == 1
    assert not res.info["auto"]["reached"]
    assert res.info["auto"]["stopped"] == "time budget"
    table = read_summary(folder / "summary.csv")
    assert table["t"][-1] == pytest.approx(1.0)
    np.testing.assert_allclose(table["load"], res.load, rtol=1e-9)
    assert json.loads((folder / "auto.json").read_text())["stopped"] == "time budget"


def test_a_full_disk_at_the_estimate_is_femehls_error(tmp_path, monkeypatch):
    import femehl.output.table as table

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(table, "add_error_columns", full)
    folder = tmp_path / "run"
    with pytest.raises(OutputError, match="No space left.*resume"):
        run_to_folder(SCENE, folder, **RUN)
    assert (folder / "summary.csv").is_file()  # what was written stays


def test_the_history_is_drawn_once_with_the_estimate(tmp_path, monkeypatch):
    """The answer's history.png is drawn once, after its estimate is in summary.csv (the
    run's writer leaves it to the folder's finish); a fault in the companions after the run
    ended still leaves a history.png of what was written."""
    import femehl.accuracy.auto as auto
    import femehl.output.plots as plots

    drawn = []
    draw = plots.history_png

    def counted(table, path, **kw):
        drawn.append(sorted(c for c in table if c.startswith("err_")))
        return draw(table, path, **kw)

    monkeypatch.setattr(plots, "history_png", counted)
    folder = tmp_path / "run"
    run_to_folder(SCENE, folder, **RUN)
    assert len(drawn) == 1 and drawn[0], drawn  # one drawing, with the error columns
    assert (folder / "history.png").stat().st_size > 10_000

    from femehl.accuracy import companions

    ways = [("serial", auto, "replays")]  # the companions replay after the run
    if companions.concurrent():  # ... or beside it
        ways.append(("auto", companions.Companions, "results"))
    for where, owner, name in ways:
        monkeypatch.setenv(companions.ENV, where)
        real, calls = getattr(owner, name), []

        def interrupted(*args, real=real, calls=calls, **kwargs):  # Ctrl-C in the candidate's companions
            calls.append(1)
            if len(calls) > 1:
                raise KeyboardInterrupt
            return real(*args, **kwargs)  # the first run's (in memory)

        drawn.clear()
        monkeypatch.setattr(owner, name, interrupted)
        folder = tmp_path / f"cut_{name}"
        with pytest.raises(KeyboardInterrupt):
            run_to_folder(SCENE, folder, **RUN)
        assert len(drawn) == 1 and not drawn[0] and (folder / "history.png").stat().st_size > 10_000
        monkeypatch.undo()
        monkeypatch.setattr(plots, "history_png", counted)
