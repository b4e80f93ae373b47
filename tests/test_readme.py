"""The README's Python blocks run as pasted and print what they claim.

Every ```python block of the README, and of the documentation pages its longer examples
moved to (``docs/getting_started.md``, ``docs/scene.md``), runs alone: in an empty
namespace (nothing injected, so each block imports what it uses), in a fresh temporary
folder.  What a block prints is checked against independent expectations where that is
cheap: the paper case's reference values (``paper_reference`` in ``conftest.py``, from
refined runs, not from the code under test) and physical bounds.
"""

from __future__ import annotations

import itertools
import pathlib
import re

import pytest

import femehl

ROOT = pathlib.Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
PAGES = [README, ROOT / "docs" / "getting_started.md", ROOT / "docs" / "scene.md"]
MAX_LINES = 230


def python_blocks(page: pathlib.Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", page.read_text(), flags=re.S)


BLOCKS = [(page, i) for page in PAGES for i in range(len(python_blocks(page)))]


def _id(block):
    page, i = block
    return f"{page.stem}-{i}"


def test_readme_is_short():
    n = len(README.read_text().splitlines())
    assert n <= MAX_LINES, f"README.md has {n} lines; keep it at most {MAX_LINES} (move detail to docs/)"


def test_readme_keeps_the_two_set_up_commands():
    text = README.read_text()
    assert "    python -m pip install -e . && femehl run\n" in text
    assert '    python -m pip install -e ".[test]" && python -m pytest -q\n' in text
    # each stated time in one sentence of its own, easy to find and re-measure
    assert len(re.findall(r"^Time: .* on 2 cores\.$", text, flags=re.M)) == 2


def test_readme_links_exist():
    text = README.read_text()
    links = re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text)
    local = [link for link in links if "://" not in link]
    assert len(local) >= 10
    for link in local:
        assert (ROOT / link).exists(), f"README links to missing {link}"


def test_every_python_block_is_collected():
    """The parametrized test below runs every ```python block: a fence the pattern misses
    (or a README without blocks) would otherwise drop tests silently.  Each block is
    self-contained: its first statement is an import."""
    assert len(python_blocks(README)) >= 5
    for page in PAGES:
        blocks = python_blocks(page)
        assert len(blocks) == page.read_text().count("```python"), page.name
        for i, b in enumerate(blocks):
            compile(b, f"{page.name} block {i}", "exec")
            first = next(line for line in b.splitlines() if line.strip() and not line.startswith("#"))
            assert first.startswith(("import ", "from ")), f"{page.name} block {i} starts with {first!r}"


def _value(line: str) -> float:
    """The number after the last colon of a ``label: value`` line."""
    return float(line.rsplit(":", 1)[1])


def _floats(line):
    return [float(v) for v in line.split()]


def _run(block, tmp_path, monkeypatch, capsys):
    page, index = block
    code = python_blocks(page)[index]
    if "import pyvista" in code:
        pytest.importorskip("pyvista")  # installed with the test extra
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}  # empty: the block imports what it uses
    exec(compile(code, f"{page.name} block {index}", "exec"), namespace)
    return code, namespace, capsys.readouterr().out.splitlines()


@pytest.mark.parametrize("block", [b for b in BLOCKS if b[0] == README], ids=_id)
def test_readme_block_runs(block, tmp_path, monkeypatch, capsys, paper_reference):
    code, ns, out = _run(block, tmp_path, monkeypatch, capsys)
    ref1, ref5 = paper_reference[1.0], paper_reference[5.0]
    if "import pyvista" in code:
        # the series read back: the film in the file is the result's, the half disk mirrored
        res = ns["res"]
        film_min, mirrored = _value(out[0]), _value(out[1])
        assert (tmp_path / "femehl-out" / "view" / "fields.pvd").exists()
        assert film_min == pytest.approx(res.film_min[-1], rel=1e-9)
        assert res.info["half"] and mirrored == 1
        assert set(ns["grid"].cell_data) >= {"film", "deflection", "gap"}
        assert "pressure" in ns["grid"].point_data
        # t = 2, in the sliding start-up: thinner than at the end of the indentation, still
        # thicker than the steady film at t = 5
        assert ref5["film_min"] < film_min < ref1["film_min"]
    elif "femehl.Shape(" in code:
        # the function and its sampled height map give the same contact (bilinear
        # interpolation on a 0.02 grid: gap error ~1e-4 against an indentation of 1);
        # the ripple only adds gap, so the load is below the smooth sphere's, by less
        # than the ripple's 0.1 peak could take away
        (shape_name, shape_load), (map_name, map_load) = ((ln.split()[0], _value(ln)) for ln in out)
        assert (shape_name, map_name) == ("Shape", "HeightMap")
        assert map_load == pytest.approx(shape_load, rel=5e-3)
        assert 0.85 * ref1["load"] < shape_load < ref1["load"]
    elif "femehl.Scene(" in code:
        # the Scene built field by field is the paper case
        assert out == ["the paper's case: True"]
        assert ns["scene"] == femehl.presets.paper_sphere()
    elif "tol=" in code:
        # automatic to tol = 2e-2: the estimate is within tol, and so is the true error of
        # the load at t = 1 against the refined reference
        cells, load1, err = (_value(line) for line in out)
        res = ns["res"]
        assert cells == res.info["auto"]["elements"][-1] and res.info["auto"]["reached"]
        assert 0.0 < err <= 2e-2
        assert load1 == pytest.approx(ref1["load"], rel=2e-2)
        assert load1 == pytest.approx(res.value_at("load", 1.0), rel=1e-12)
    else:
        # the whole paper case, coarse mesh, BDF2, dt = 0.02: on the mesh ladder
        # (docs/validation/index.md, coarse at dt = 0.01) the load at t = 1 is 0.04 % low and
        # the minimum film at t = 5 1.8 % low; tolerances above those
        assert "paper_sphere()" in code and 'mesh="coarse"' in code
        load1, film_min5 = _value(out[0]), _value(out[1])
        assert load1 == pytest.approx(ref1["load"], rel=2e-3)
        assert film_min5 == pytest.approx(ref5["film_min"], rel=3e-2)
        assert load1 == pytest.approx(ns["res"].value_at("load", 1.0), rel=1e-12)


@pytest.mark.parametrize("block", [b for b in BLOCKS if b[0] != README], ids=_id)
def test_docs_block_runs(block, tmp_path, monkeypatch, capsys, paper_reference):
    """The examples that moved from the README to the documentation pages."""
    code, ns, out = _run(block, tmp_path, monkeypatch, capsys)
    if "femehl.steps(" in code:
        assert (tmp_path / "femehl-out" / "readme" / "fields.pvd").exists()
        ref1, ref5 = paper_reference[1.0], paper_reference[5.0]
        # FE, medium mesh, Euler, dt = 0.01, to t = 5 (benchmarks/accuracy_results.md, run
        # "FE euler medium dt=0.01"): load at t = 1 is 0.33 % low (measured 0.47412), the
        # minimum film at t = 5 0.59 % (measured 0.026315); tolerances about 2x those.
        load1, film_min5 = _floats(out[0])
        assert load1 == pytest.approx(ref1["load"], rel=0.007)
        assert film_min5 == pytest.approx(ref5["film_min"], rel=0.012)
        assert load1 == pytest.approx(ns["res"].value_at("load", 1.0), rel=1e-12)
        # the printed FD load at t = 1 (dr = 0.05, dtheta = pi/24, dt = 0.01): measured
        # 0.4755, 0.03 % off the reference; the FD's first-order error in dr passes through
        # zero near this grid (0.12 % at dr = 0.033, 0.20 % at dr = 0.025 with dtheta = pi/24;
        # accuracy_results.md), so the tolerance is the error size of its neighbour grid
        assert _floats(out[1])[0] == pytest.approx(ref1["load"], rel=0.002)
        # the generator: one line per step from t = 0 to 0.5; the load grows as the sphere
        # indents and the film thins overall (it first rises ~1 % as the surface deflects)
        rows = [_floats(line) for line in out[2:]]
        t, load, film_min = (list(col) for col in zip(*rows, strict=True))
        assert t[0] == pytest.approx(0.0) and t[-1] == pytest.approx(0.5) and len(t) == 51
        assert all(b > a for a, b in itertools.pairwise(t))
        assert all(b > a for a, b in itertools.pairwise(load))
        assert film_min[-1] < 0.7 * film_min[0]
    elif "cavitation=" in code:
        # the cavitation block: half-Sommerfeld reports the clipped load (above the
        # full-Sommerfeld one, whose sub-ambient lobe it drops) and a cavitated area; the
        # Reynolds condition a cavitated area and a positive full-film source; JFO below
        (hs_load, hs_full, hs_area), (re_area, re_source) = _floats(out[0]), _floats(out[1])
        assert hs_load > 1.02 * hs_full and hs_area > 1.0
        assert re_area > 1.0 and re_source > 0.0
        # JFO: a cavity, the liquid balance to the solver's tolerance, a filling in [0, 1]
        jfo_area, imbalance, theta_min = _floats(out[2])
        assert jfo_area > 1.0 and imbalance < 1e-7 and 0.0 <= theta_min < 1.0
    elif "femehl.Layer(thickness" in code:
        # the coated contact: a layer as thick as the contact is stiffer than the half space,
        # so the same indentation carries more load (same mesh, dt and horizon)
        load, film_center = _floats(out[0])
        half = femehl.solve(femehl.presets.paper_sphere(), t_end=0.5, dt=0.05, mesh="coarse")
        assert load > 1.05 * half.load[-1] and film_center > 0
    elif "Viscoelastic(" in code:
        # the viscoelastic block at t = 2 (V = tanh 1, still accelerating, so the steady
        # balance f V = D_film + P does not hold yet: it is tested at steady sliding in
        # tests/test_viscoelastic.py): friction, film dissipation and the rubber's hysteresis
        # are positive, the hysteresis a sizeable part (tau = 0.3 is near the peak, De ~ 1)
        f, d_film, p_rubber = _floats(out[0])
        assert f > 0 and d_film > 0 and p_rubber > 0.1 * d_film
    else:
        pytest.fail(f"{_id(block)}: a block with no check; add one here")
