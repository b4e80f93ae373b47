"""The documentation site's sources hang together (no Sphinx build: that is ``.ci/run``'s).

Every example has a sphinx-gallery title, every page of a toctree exists, every file a
page includes exists and still holds the text its ``start-after`` / ``end-before``
options cut at (README or design-note headings renamed would otherwise break the build).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

try:
    import tomllib
except ModuleNotFoundError:  # Python < 3.11
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))


def _pages() -> list[Path]:
    generated = ("_build", "auto_examples", "_ext")
    return sorted(
        p
        for p in [*DOCS.rglob("*.md"), *DOCS.rglob("*.rst")]
        if not any(part in generated for part in p.relative_to(DOCS).parts)
        and p.name != "sg_execution_times.rst"
    )


def _toctree_entries(page: Path) -> list[str]:
    text = page.read_text()
    if page.suffix == ".md":
        blocks = re.findall(r"```\{toctree\}\n(.*?)```", text, flags=re.S)
    else:
        blocks = re.findall(r"\.\. toctree::\n((?:[ \t]+.*\n|\n)*)", text)
    entries = []
    for block in blocks:
        for line in block.splitlines():
            line = line.strip()
            if line and not line.startswith(":"):
                entries.append(line)
    return entries


def _includes(page: Path) -> list[tuple[str, dict[str, str]]]:
    """(target, options) of every MyST ``{include}`` / ``{literalinclude}`` of a page."""
    out = []
    for m in re.finditer(r"```\{(?:literal)?include\} (\S+)\n(.*?)```", page.read_text(), flags=re.S):
        opts = dict(re.findall(r"^:([\w-]+): (.*)$", m.group(2), flags=re.M))
        out.append((m.group(1), {k: v.strip().strip('"') for k, v in opts.items()}))
    return out


def test_pages_found():
    names = {p.relative_to(DOCS).as_posix() for p in _pages()}
    assert {"index.md", "design.md", "scene.md", "accuracy.md", "api/index.rst"} <= names


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.name)
def test_example_has_gallery_title(example):
    doc = ast.get_docstring(ast.parse(example.read_text()), clean=False)
    assert doc, f"{example.name}: no module docstring"
    lines = doc.splitlines()
    assert len(lines) >= 2 and lines[0].strip(), f"{example.name}: the docstring must start with a title"
    assert re.fullmatch(r"=+", lines[1].strip()), f"{example.name}: the title must be underlined with ==="
    assert len(lines[1].strip()) >= len(lines[0].strip()), f"{example.name}: title underline too short"


def test_every_toctree_entry_exists():
    entries = 0
    for page in _pages():
        for entry in _toctree_entries(page):
            entries += 1
            target = (page.parent / entry).resolve()
            if target.relative_to(DOCS.resolve()).parts[0] == "auto_examples":
                assert entry.endswith("auto_examples/index"), entry  # the generated gallery
                continue
            found = [target.with_suffix(s) for s in (".md", ".rst") if target.with_suffix(s).exists()]
            assert found, f"{page.relative_to(ROOT)}: toctree entry {entry!r} has no page"
    assert entries >= 10


def test_every_page_is_in_a_toctree():
    listed = {"index"}
    for page in _pages():
        for entry in _toctree_entries(page):
            listed.add((page.parent / entry).resolve().relative_to(DOCS.resolve()).as_posix())
    for page in _pages():
        name = page.relative_to(DOCS).with_suffix("").as_posix()
        assert name in listed, f"docs/{page.relative_to(DOCS)} is in no toctree"


def test_every_include_exists_and_its_markers_match():
    n = 0
    for page in _pages():
        for target, opts in _includes(page):
            n += 1
            path = (page.parent / target).resolve()
            assert path.is_file(), f"{page.relative_to(ROOT)}: includes missing {target}"
            text = path.read_text()
            start = 0
            if "start-after" in opts:
                marker = opts["start-after"].replace('\\"', '"')
                assert marker in text, f"{page.relative_to(ROOT)}: {target} lost {marker!r}"
                start = text.index(marker) + len(marker)
            if "end-before" in opts:
                marker = opts["end-before"].replace('\\"', '"')
                assert marker in text[start:], f"{page.relative_to(ROOT)}: {target} lost {marker!r}"
    assert n >= 10


def test_gallery_runs_existing_examples():
    # read, not imported: the helper module needs Sphinx, which the test extra lacks
    tree = ast.parse((DOCS / "_ext" / "femehl_docs.py").read_text())
    (GALLERY_EXECUTED,) = (
        ast.literal_eval(node.value)
        for node in tree.body
        if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", None) == "GALLERY_EXECUTED"
    )
    names = {p.stem for p in EXAMPLES}
    assert set(GALLERY_EXECUTED) <= names
    assert not {"textured_sphere", "paper_figures"} & set(GALLERY_EXECUTED)  # 40 and 15 minutes


def test_docs_extra_and_ci_build():
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    docs = {re.split(r"[<>=!~ ;\[]", d, maxsplit=1)[0].lower() for d in extras["docs"]}
    assert {"sphinx", "numpydoc", "sphinx-gallery", "myst-parser"} <= docs
    ci = (ROOT / ".ci" / "run").read_text()
    assert 'python -m pip install -q -e ".[test]" && python -m pytest -q' in ci
    assert "-W" in ci and "sphinx" in ci and "plot_gallery=0" in ci
