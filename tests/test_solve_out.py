"""``femehl.solve(..., out=folder)`` writes the run folder through the one loop
(docs/design.md section 8): the same files as ``run_to_folder``, the estimate's columns."""

from __future__ import annotations

import csv
import json

import pytest

import femehl
from femehl.api import run_to_folder

SC = femehl.presets.paper_sphere()


def _rows(folder):
    with open(folder / "summary.csv", newline="") as fh:
        return list(csv.reader(fh))


def _names(folder):
    return sorted(p.name for p in folder.iterdir())


def test_solve_out_writes_what_run_to_folder_writes(tmp_path):
    opts = dict(t_end=0.2, tol=5e-2, linear_solver="lu")
    a = femehl.solve(SC, out=tmp_path / "a", store_every=10, **opts)
    b = run_to_folder(SC, tmp_path / "b", **opts)
    assert _names(tmp_path / "a") == _names(tmp_path / "b")
    assert _rows(tmp_path / "a") == _rows(tmp_path / "b")
    chosen = [json.loads((tmp_path / f / "auto.json").read_text()) for f in "ab"]
    a_chose, b_chose = ({k: v for k, v in c.items() if "wall" not in k} for c in chosen)  # wall times differ
    assert a_chose == b_chose
    assert a.estimate.how == b.estimate.how == "companion"
    assert a.estimate.levels[1] == 2.0 * a.estimate.levels[0]  # its companions, twice as coarse
    assert "err_load" in _rows(tmp_path / "a")[0]


def test_expert_solve_out_writes_its_companions_estimate(tmp_path):
    res = femehl.solve(SC, t_end=0.1, mesh="medium", dt=0.02, out=tmp_path, linear_solver="lu")
    assert res.estimate.how == "companion" and res.estimate.ratio > 1
    rows = _rows(tmp_path)
    header = rows[0]
    for q in ("load", "film_center", "film_min"):
        assert {f"err_{q}", f"err_{q}_space", f"err_{q}_time"} <= set(header)
    space = header.index("err_film_min_space")
    assert [float(r[space]) for r in rows[1:]] == [
        float(f"{res.uncertainty('film_min', float(r[0]))['space']:.4g}") for r in rows[1:]
    ]
    time, total = header.index("err_film_min_time"), header.index("err_film_min")
    for r in rows[2:]:  # fixed steps: the time part from the companion at 2 dt, and the total
        assert float(r[time]) > 0.0
        assert float(r[total]) == pytest.approx(float(r[space]) + float(r[time]), rel=1e-3, abs=1e-7)
    assert len(rows) - 1 == len(res.t)


def test_folder_options_need_out():
    import pytest

    with pytest.raises(femehl.SceneError, match="out="):
        femehl.solve(SC, t_end=0.02, dt=0.01, mesh="coarse", resume=True)
