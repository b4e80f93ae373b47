"""The README's Python blocks run as written (docs that run)."""

from __future__ import annotations

import pathlib
import re

import pytest

README = pathlib.Path(__file__).resolve().parents[1] / "README.md"


def python_blocks():
    return re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)


def test_readme_has_python_examples():
    assert len(python_blocks()) >= 2


@pytest.mark.parametrize("index", range(len(python_blocks())))
def test_readme_block_runs(index, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    import femehl

    namespace = {"femehl": femehl}  # blocks after the first omit the import
    exec(compile(python_blocks()[index], f"README block {index}", "exec"), namespace)
    if index == 0:
        assert (tmp_path / "femehl-out" / "readme" / "fields.pvd").exists()
        res = namespace["res"]
        assert 0.42 < res.value_at("load", 1.0) < 0.52
