"""Nothing an earlier run wrote is lost or mixed with another run; user files are never deleted.

Every test compares file bytes (sha256) before and after.  Runs are kept cheap: the paper
sphere on the coarse mesh to t <= 0.1.
"""

from __future__ import annotations

import csv
import hashlib
import json
import math
import pathlib
import shutil
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import femehl
import femehl.output.run
import femehl.solver.loop
from femehl.api import run_to_folder
from femehl.errors import CheckpointError, OutputError, SceneError
from femehl.output import checkpoint, write_all
from femehl.output.series import scan_series

SC = femehl.presets.paper_sphere()
RUN = {"mesh": "coarse", "dt": 0.02, "store_every": 1}
USER = b"my notes, not femehl's\n"


def _run(folder, t_end=0.04, **kw):
    return run_to_folder(SC, folder, t_end=t_end, **dict(RUN, **kw))


def _snapshot(folder) -> dict:
    folder = pathlib.Path(folder)
    if not folder.is_dir():
        return {}
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in folder.iterdir() if p.is_file()}


def _times(folder) -> list:
    root = ET.parse(pathlib.Path(folder) / "fields.pvd").getroot()
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def _rows(folder) -> list:
    with open(pathlib.Path(folder) / "summary.csv", newline="") as fh:
        return list(csv.reader(fh))


_TEMPLATE = {}


def _template(tmp_path_factory) -> pathlib.Path:
    """One finished run (to t = 0.04), made once and copied for each test."""
    if "run" not in _TEMPLATE:
        folder = tmp_path_factory.mktemp("template") / "run"
        _run(folder)
        (folder / "summary_si.csv").write_text("t_s\n0\n")
        _TEMPLATE["run"] = folder
    return _TEMPLATE["run"]


@pytest.fixture
def old_run(tmp_path, tmp_path_factory):
    folder = tmp_path / "out"
    shutil.copytree(_template(tmp_path_factory), folder)
    return folder


# ---- a folder that holds a run ---------------------------------------------------------------
def test_a_run_is_refused_in_a_folder_holding_another(old_run):
    before = _snapshot(old_run)
    with pytest.raises(OutputError) as info:
        _run(old_run)
    msg = str(info.value)
    assert str(old_run) in msg and "--overwrite" in msg and "--resume" in msg and "--out" in msg
    assert _snapshot(old_run) == before


def test_overwrite_removes_only_femehls_files(old_run):
    (old_run / "notes.txt").write_bytes(USER)
    (old_run / "fields_mine.vtu.bak").write_bytes(USER)
    assert len(list(old_run.glob("fields_*.vtu"))) == 3
    _run(old_run, t_end=0.02, store_every=2, overwrite=True)
    assert (old_run / "notes.txt").read_bytes() == USER
    assert (old_run / "fields_mine.vtu.bak").read_bytes() == USER
    assert not (old_run / "summary_si.csv").exists()  # the old run's, gone
    assert sorted(p.name for p in old_run.glob("fields_*.vtu")) == [f for _, f in _times(old_run)]
    assert [t for t, _ in _times(old_run)] == pytest.approx([0.0, 0.02])
    assert len(_rows(old_run)) == 1 + 2


def test_a_folder_with_user_files_only_is_used(tmp_path):
    (tmp_path / "notes.txt").write_bytes(USER)
    _run(tmp_path, t_end=0.02)
    assert (tmp_path / "notes.txt").read_bytes() == USER
    assert (tmp_path / "summary.csv").is_file()


@pytest.mark.parametrize(
    "bad",
    [
        {"store_every": -1},
        {"checkpoint_every": -1},
        {"store_every": 1.5},
        {"t_end": math.nan},
        {"dt": 0.0},
        {"mesh": "no-such-mesh"},
        {"colour": "red"},
        {"resume": True, "overwrite": True},
        {"method": "nope"},
        {"progress": "yes"},
    ],
)
@pytest.mark.parametrize("mode", [{}, {"resume": True}, {"overwrite": True}])
def test_bad_options_touch_nothing(old_run, bad, mode):
    """Regression: ``--store-every -1`` on a run folder used to wipe its summary.csv."""
    before = _snapshot(old_run)
    kw = dict(mode, **bad)
    with pytest.raises((SceneError, OutputError, femehl.MeshError)):
        _run(old_run, t_end=kw.pop("t_end", 0.08), **kw)
    assert _snapshot(old_run) == before


def test_bad_options_create_no_folder(tmp_path):
    with pytest.raises(SceneError):
        _run(tmp_path / "new", store_every=-1)
    assert not (tmp_path / "new").exists()


# ---- resume ----------------------------------------------------------------------------------
@pytest.mark.parametrize("index", ["missing", "damaged", "a directory"])
def test_resume_never_overwrites_field_files(old_run, index):
    pvd = old_run / "fields.pvd"
    if index == "missing":
        pvd.unlink()
    elif index == "damaged":
        pvd.write_bytes(pvd.read_bytes()[:90])
    else:
        pvd.unlink()
        pvd.mkdir()
        before = _snapshot(old_run)
        with pytest.raises(OutputError, match="fields.pvd"):
            _run(old_run, t_end=0.08, resume=True)
        assert _snapshot(old_run) == before
        return
    vtus = {p.name: p.read_bytes() for p in old_run.glob("fields_*.vtu")}
    _run(old_run, t_end=0.08, resume=True)
    assert {n: (old_run / n).read_bytes() for n in vtus} == vtus
    entries = _times(old_run)
    assert [t for t, _ in entries] == pytest.approx([0.0, 0.02, 0.04, 0.06, 0.08])
    assert [f for _, f in entries] == [f"fields_{k:06d}.vtu" for k in range(5)]
    assert [float(r[0]) for r in _rows(old_run)[1:]] == pytest.approx([0.02 * k for k in range(5)])


def test_resume_numbers_after_the_highest_file(old_run):
    """A stray higher-numbered series file (of unknown time) is kept and not reused."""
    (old_run / "fields_000007.vtu").write_bytes(USER)
    _run(old_run, t_end=0.06, resume=True)
    assert (old_run / "fields_000007.vtu").read_bytes() == USER
    assert [f for _, f in _times(old_run)][-1] == "fields_000008.vtu"
    assert [n for n, _, t in scan_series(old_run) if t is None] == [7]


def _damage(folder: pathlib.Path, how: str) -> str:
    npz, js = folder / "checkpoint.npz", folder / "checkpoint.json"
    if how == "truncated npz":
        npz.write_bytes(npz.read_bytes()[:200])
    elif how == "garbage npz":
        npz.write_bytes(b"PK\x03\x04" + b"\x00" * 64)
    elif how == "not a zip":
        npz.write_bytes(USER)
    elif how == "missing key":
        with np.load(npz) as z:
            a = {k: z[k] for k in z.files if k != "d"}
        np.savez(npz, **a)
    elif how == "wrong size":
        with np.load(npz) as z:
            a = {k: z[k] for k in z.files}
        a["p"] = a["p"][:-3]
        np.savez(npz, **a)
    elif how == "json list":
        js.write_text("[1, 2]")
        return js.name
    elif how == "json missing keys":
        js.write_text(json.dumps({"format": 1}))
        return js.name
    elif how == "json garbage":
        js.write_text("{not json")
        return js.name
    elif how == "json missing":
        js.unlink()
        return js.name
    return npz.name


DAMAGE = [
    "truncated npz",
    "garbage npz",
    "not a zip",
    "missing key",
    "wrong size",
    "json list",
    "json missing keys",
    "json garbage",
    "json missing",
]


@pytest.mark.parametrize("how", DAMAGE)
def test_a_damaged_checkpoint_is_named_and_nothing_is_touched(old_run, how):
    name = _damage(old_run, how)
    before = _snapshot(old_run)
    with pytest.raises(CheckpointError) as info:
        _run(old_run, t_end=0.08, resume=True)
    msg = str(info.value)
    assert name in msg and "--overwrite" in msg
    assert _snapshot(old_run) == before


def test_load_checkpoint_checks_sizes(old_run):
    stepper = femehl.make_stepper(SC, "fe", mesh="coarse")
    assert checkpoint.load_checkpoint(old_run, reference=stepper.initial_state()).t == pytest.approx(0.04)
    _damage(old_run, "wrong size")
    with pytest.raises(CheckpointError, match="shape"):
        checkpoint.load_checkpoint(old_run, reference=stepper.initial_state())


# ---- folder faults ---------------------------------------------------------------------------
def test_output_path_is_a_file(tmp_path):
    f = tmp_path / "afile"
    f.write_bytes(USER)
    with pytest.raises(OutputError, match="is a file") as info:
        _run(f)
    assert str(f) in str(info.value) and "--out" in str(info.value)
    with pytest.raises(OutputError, match="is a file"):
        _run(f / "sub" / "deeper")
    assert f.read_bytes() == USER


def test_output_path_not_writable(tmp_path, monkeypatch):
    import femehl.output.folder as fo

    monkeypatch.setattr(fo, "_writable", lambda p: False)
    with pytest.raises(OutputError, match="not writable") as info:
        _run(tmp_path / "x")
    assert str(tmp_path) in str(info.value)
    assert not (tmp_path / "x").exists()


def test_result_save_checks_the_folder(tmp_path):
    res = femehl.solve(SC, "fe", mesh="coarse", t_end=0.02, dt=0.02)
    f = tmp_path / "afile"
    f.write_bytes(USER)
    with pytest.raises(OutputError, match="is a file"):
        res.save(f)
    assert f.read_bytes() == USER
    res.save(tmp_path / "r")
    before = _snapshot(tmp_path / "r")
    with pytest.raises(OutputError, match="already holds a run"):
        res.save(tmp_path / "r")
    assert _snapshot(tmp_path / "r") == before
    (tmp_path / "r" / "fields_000009.vtu").write_bytes(USER)  # a stale file of that run
    (tmp_path / "r" / "notes.txt").write_bytes(USER)
    write_all(res, tmp_path / "r", overwrite=True)
    assert not (tmp_path / "r" / "fields_000009.vtu").exists()
    assert (tmp_path / "r" / "notes.txt").read_bytes() == USER


def test_a_write_failure_names_the_folder_and_keeps_the_last_checkpoint(tmp_path, monkeypatch):
    from femehl.output.table import SummaryWriter

    real, calls = SummaryWriter.write, [0]

    def write(self, state):
        calls[0] += 1
        if calls[0] > 3:
            raise OSError(28, "No space left on device")
        return real(self, state)

    monkeypatch.setattr(SummaryWriter, "write", write)
    with pytest.raises(OutputError) as info:
        _run(tmp_path, t_end=0.1)
    assert str(tmp_path) in str(info.value) and "resume" in str(info.value)
    assert "No space left" in str(info.value)
    assert checkpoint.load_checkpoint(tmp_path).t == pytest.approx(0.04)  # the last state written


# ---- Ctrl-C ----------------------------------------------------------------------------------
def interrupting(after: int):
    """A make_stepper whose stepper raises KeyboardInterrupt in its step number ``after + 1``."""
    real = femehl.solver.loop.make_stepper

    def make(*a, **k):
        stepper = real(*a, **k)
        orig, calls = stepper.step, [0]

        def step(*sa, **sk):
            calls[0] += 1
            if calls[0] > after:
                raise KeyboardInterrupt
            return orig(*sa, **sk)

        stepper.step = step
        return stepper

    return make


def test_interrupt_leaves_readable_output_and_resumes(tmp_path, monkeypatch):
    out = tmp_path / "o"
    monkeypatch.setattr(femehl.solver.loop, "make_stepper", interrupting(3))
    with pytest.raises(KeyboardInterrupt) as info:
        run_to_folder(SC, out, t_end=0.1, mesh="coarse", dt=0.02, store_every=2, checkpoint_every=10)
    assert info.value.result.t[-1] == pytest.approx(0.06)
    rows = _rows(out)
    assert [float(r[0]) for r in rows[1:]] == pytest.approx([0.0, 0.02, 0.04, 0.06])
    assert [t for t, _ in _times(out)] == pytest.approx([0.0, 0.04, 0.06])  # last state written
    assert checkpoint.load_checkpoint(out).t == pytest.approx(0.06)  # the last good state
    monkeypatch.undo()
    run_to_folder(SC, out, t_end=0.1, mesh="coarse", dt=0.02, store_every=2, resume=True)
    full = tmp_path / "full"
    run_to_folder(SC, full, t_end=0.1, mesh="coarse", dt=0.02, store_every=2)
    a, b = _rows(out), _rows(full)
    assert [r[0] for r in a] == [r[0] for r in b]
    _same_rows(a, b)


def _same_rows(a, b):
    """The rows of two summaries agree to 1e-6; the friction columns, sums of terms of both
    signs that cancel to ~1e-4 of the load during a pure indentation (no sliding: 3e-6
    here), to 1e-6 of the largest load (their rounding measured 5e-11 apart)."""
    from femehl.solver.energetics import FRICTION_COLUMNS, SIDE_COLUMNS

    x, y = np.array(a[1:], float), np.array(b[1:], float)
    fric = np.isin(a[0], FRICTION_COLUMNS + SIDE_COLUMNS)
    np.testing.assert_allclose(x[:, ~fric], y[:, ~fric], rtol=1e-6, atol=1e-12)
    scale = 1e-6 * np.max(np.abs(y[:, a[0].index("load")]))
    np.testing.assert_allclose(x[:, fric], y[:, fric], rtol=0.0, atol=scale)


# ---- folder states x actions -----------------------------------------------------------------
STATES = ["empty", "missing", "run", "damaged checkpoint", "damaged index", "missing index", "user only"]
ACTIONS = ["new", "overwrite", "resume"]


def _make_state(folder: pathlib.Path, state: str, stray: bool, template: pathlib.Path):
    if state == "missing":
        return
    if state in ("empty", "user only"):
        folder.mkdir()
    else:
        shutil.copytree(template, folder)
    if state == "damaged checkpoint":
        _damage(folder, "truncated npz")
    elif state == "damaged index":
        (folder / "fields.pvd").write_text("<VTKFile><Collection><DataSet timestep=")
    elif state == "missing index":
        (folder / "fields.pvd").unlink()
    if stray or state == "user only":
        (folder / "notes.txt").write_bytes(USER)
        (folder / "fields.csv").write_bytes(USER)


def _read(folder):
    return {n: (folder / n).read_bytes() for n in _snapshot(folder)}


@settings(max_examples=14, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(state=st.sampled_from(STATES), action=st.sampled_from(ACTIONS), stray=st.booleans())
def test_no_earlier_data_is_lost(tmp_path_factory, state, action, stray):
    folder = tmp_path_factory.mktemp("case") / "out"
    _make_state(folder, state, stray, _template(tmp_path_factory))
    before = _read(folder) if folder.is_dir() else {}
    user = {n: b for n, b in before.items() if b == USER}
    held_run = any(n not in user for n in before)
    kw = {"overwrite": action == "overwrite", "resume": action == "resume"}
    try:
        _run(folder, t_end=0.08 if action == "resume" else 0.02, **kw)
        error = None
    except (OutputError, SceneError) as exc:
        error = exc
    after = _read(folder) if folder.is_dir() else {}
    assert {n: after.get(n) for n in user} == user  # user files: never touched
    if error is not None:
        assert after == before  # refused: nothing touched
    expect_refusal = (action == "new" and held_run) or (
        action == "resume" and state in ("empty", "missing", "user only", "damaged checkpoint")
    )
    assert (error is not None) == expect_refusal, error
    if error is not None or action == "overwrite":
        if action == "overwrite":  # the old run's files are gone
            assert "summary_si.csv" not in after
            assert sorted(n for n in after if n.startswith("fields_") and n.endswith(".vtu")) == [
                f for _, f in _times(folder)
            ]
        return
    if action == "resume":
        for n, b in before.items():
            if n.endswith(".vtu") or n == "summary_si.csv":
                assert after[n] == b, n  # field files never rewritten
        assert after["summary.csv"].startswith(before["summary.csv"])  # rows appended
        assert [t for t, _ in _times(folder)] == pytest.approx([0.0, 0.02, 0.04, 0.06, 0.08])
