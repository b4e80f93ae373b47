"""Property: whatever state a run folder is in (a finished automatic or expert run, a run cut
short, a damaged checkpoint or series index, a file of the user's), running into it again,
resuming or overwriting never loses or mixes what was written before, and ends in femehl's
own message (an exit status), never a bare traceback."""

from __future__ import annotations

import hashlib
import pathlib
import shutil

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from femehl.cli import EXIT_BAD_INPUT, EXIT_DONE, main
from femehl.output.table import read_summary

EXPERT = ["--mesh", "coarse", "--dt", "0.02", "--quiet", "--store-every", "2"]
AUTO = ["--tol", "0.05", "--quiet"]


def _digest(folder: pathlib.Path) -> dict:
    files = (p for p in sorted(folder.iterdir()) if p.is_file())
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in files}


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """Finished runs to copy: expert and automatic, to t = 0.2."""
    root = tmp_path_factory.mktemp("made")
    out = {}
    for name, flags in (("expert", EXPERT), ("auto", AUTO)):
        folder = root / name
        assert main(["run", *flags, "--t-end", "0.2", "--out", str(folder)]) == EXIT_DONE
        out[name] = folder
    return out


def _damage(folder: pathlib.Path, how: str) -> None:
    if how == "cut":  # a run cut short: its last rows and checkpoint as if stopped earlier
        return
    if how == "checkpoint":
        p = folder / "checkpoint.npz"
        p.write_bytes(p.read_bytes()[: len(p.read_bytes()) // 3])
    elif how == "index":
        p = folder / "fields.pvd"
        p.write_text(p.read_text()[:40])
    elif how == "user_file":
        (folder / "notes.txt").write_text("my notes")


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    kind=st.sampled_from(["expert", "auto"]),
    damage=st.sampled_from(["none", "checkpoint", "index", "user_file"]),
    action=st.sampled_from(["again", "resume", "resume_longer", "overwrite"]),
)
def test_nothing_written_before_is_lost(made, tmp_path_factory, kind, damage, action):
    folder = tmp_path_factory.mktemp("state") / "run"
    shutil.copytree(made[kind], folder)
    (folder / "notes.txt").write_text("my notes")  # a file of the user's, always there
    _damage(folder, damage)
    before = _digest(folder)
    rows_before = read_summary(folder / "summary.csv")
    flags = EXPERT if kind == "expert" else AUTO
    args = {
        "again": ["--t-end", "0.2"],
        "resume": ["--t-end", "0.2", "--resume"],
        "resume_longer": ["--t-end", "0.26", "--resume"],
        "overwrite": ["--t-end", "0.2", "--overwrite"],
    }[action]
    code = main(["run", *flags, *args, "--out", str(folder)])  # femehl's message, or done
    assert code in (EXIT_DONE, EXIT_BAD_INPUT)
    after = _digest(folder)
    assert (folder / "notes.txt").read_text() == "my notes"  # never touched
    if code == EXIT_BAD_INPUT or action == "again" or (action == "resume" and damage != "checkpoint"):
        # refused (or nothing to do): every byte as it was
        assert after == before
        return
    rows = read_summary(folder / "summary.csv")
    if action == "overwrite":  # a fresh run of the same scene: the same answer to the
        # iterative linear solver's tolerance (two identical runs differ by up to 3.6e-5 in
        # the load: the recycled Krylov space is the process's); a different run would not
        assert rows["t"][-1] == pytest.approx(0.2)
        assert rows["load"][-1] == pytest.approx(rows_before["load"][-1], rel=1e-4)
        return
    # resumed to a later time: the rows written before are kept, the new ones follow
    n = rows_before["t"].size
    assert rows["t"][-1] == pytest.approx(0.26)
    assert rows["t"][:n].tolist() == rows_before["t"].tolist()
    assert rows["load"][:n].tolist() == rows_before["load"].tolist()
