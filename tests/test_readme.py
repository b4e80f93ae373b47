"""The README's Python blocks run as written (docs that run) and print what they claim."""

from __future__ import annotations

import itertools
import pathlib
import re

import pytest

import femehl

README = pathlib.Path(__file__).resolve().parents[1] / "README.md"


def python_blocks():
    return re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)


def test_every_readme_python_block_is_collected():
    """The parametrized test below runs every ```python block: a fence the pattern misses
    (or a README without blocks) would otherwise drop tests silently."""
    blocks = python_blocks()
    assert len(blocks) >= 2
    assert len(blocks) == README.read_text().count("```python")
    for i, b in enumerate(blocks):
        compile(b, f"README block {i}", "exec")


def _floats(line):
    return [float(v) for v in line.split()]


@pytest.mark.parametrize("index", range(len(python_blocks())))
def test_readme_block_runs(index, tmp_path, monkeypatch, capsys, paper_reference):
    monkeypatch.chdir(tmp_path)
    namespace = {"femehl": femehl}  # blocks after the first omit the import
    exec(compile(python_blocks()[index], f"README block {index}", "exec"), namespace)
    out = capsys.readouterr().out.splitlines()
    if index == 0:
        assert (tmp_path / "femehl-out" / "readme" / "fields.pvd").exists()
        ref1, ref5 = paper_reference[1.0], paper_reference[5.0]
        # FE, medium mesh, Euler, dt = 0.01, to t = 5 (benchmarks/accuracy_results.md, run
        # "FE euler medium dt=0.01"): load at t = 1 is 0.33 % low (measured 0.47412), the
        # minimum film at t = 5 0.59 % (measured 0.026315); tolerances about 2x those.
        load1, film_min5 = _floats(out[0])
        assert load1 == pytest.approx(ref1["load"], rel=0.007)
        assert film_min5 == pytest.approx(ref5["film_min"], rel=0.012)
        assert load1 == pytest.approx(namespace["res"].value_at("load", 1.0), rel=1e-12)
        # the printed FD load at t = 1 (dr = 0.05, dtheta = pi/24, dt = 0.01): measured
        # 0.4755, 0.03 % off the reference; the FD's first-order error in dr passes through
        # zero near this grid (0.12 % at dr = 0.033, 0.20 % at dr = 0.025 with dtheta = pi/24;
        # accuracy_results.md), so the tolerance is the error size of its neighbour grid
        assert _floats(out[1])[0] == pytest.approx(ref1["load"], rel=0.002)
        # the generator: one line per step from t = 0 to 0.5; the load grows as the sphere
        # indents and the film thins overall (it first rises ~1 % as the surface deflects)
        rows = [_floats(line) for line in out[2:-1]]
        t, load, film_min = (list(col) for col in zip(*rows, strict=True))
        assert t[0] == pytest.approx(0.0) and t[-1] == pytest.approx(0.5) and len(t) == 51
        assert all(b > a for a, b in itertools.pairwise(t))
        assert all(b > a for a, b in itertools.pairwise(load))
        assert film_min[-1] < 0.7 * film_min[0]
        # automatic to tol = 3e-2: the estimate is within tol, and the minimum film at
        # t = 0.5 agrees with the medium/Euler run within tol + that run's ~1 % time error
        cells, err = _floats(out[-1])
        auto = namespace["auto"]
        assert cells == auto.info["auto"]["elements"][-1] and 0.0 < err <= 3e-2
        assert auto.value_at("film_min", 0.5) == pytest.approx(
            namespace["res"].value_at("film_min", 0.5), rel=0.04
        )
    elif "cavitation=" in python_blocks()[index]:
        # the cavitation block: half-Sommerfeld reports the clipped load (above the
        # full-Sommerfeld one, whose sub-ambient lobe it drops) and a cavitated area; the
        # Reynolds condition a cavitated area and a positive full-film source; JFO below
        (hs_load, hs_full, hs_area), (re_area, re_source) = _floats(out[0]), _floats(out[1])
        assert hs_load > 1.02 * hs_full and hs_area > 1.0
        assert re_area > 1.0 and re_source > 0.0
        # JFO: a cavity, the liquid balance to the solver's tolerance, a filling in [0, 1]
        jfo_area, imbalance, theta_min = _floats(out[2])
        assert jfo_area > 1.0 and imbalance < 1e-7 and 0.0 <= theta_min < 1.0
    elif "femehl.Layer(thickness" in python_blocks()[index]:
        # the coated contact: a layer as thick as the contact is stiffer than the half space,
        # so the same indentation carries more load (same mesh, dt and horizon)
        load, film_center = _floats(out[0])
        half = femehl.solve(femehl.presets.paper_sphere(), t_end=0.5, dt=0.05, mesh="coarse")
        assert load > 1.05 * half.load[-1] and film_center > 0
    elif "Viscoelastic(" in python_blocks()[index]:
        # the viscoelastic block at t = 2 (V = tanh 1, still accelerating, so the steady
        # balance f V = D_film + P does not hold yet: it is tested at steady sliding in
        # tests/test_viscoelastic.py): friction, film dissipation and the rubber's hysteresis
        # are positive, the hysteresis a sizeable part (tau = 0.3 is near the peak, De ~ 1)
        f, d_film, p_rubber = _floats(out[0])
        assert f > 0 and d_film > 0 and p_rubber > 0.1 * d_film
    else:
        # the Scene built field by field is the paper case of the first block
        assert namespace["scene"] == femehl.presets.paper_sphere()
