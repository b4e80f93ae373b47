"""The examples a user copies run (short horizons) and give one physically checked number.

Each example module in ``examples/`` has ``main(out=..., t_end=..., mesh=...) -> dict``;
its TOML twin (where the shape is expressible in a scene file) describes the same scene.
Wall times at these horizons (coarse mesh): ``pytest --durations=0`` lists them.
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

from femehl.cli import main as cli_main
from femehl.problem.scene import Dimensional
from femehl.problem.scenefile import load_scene_file

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
HERTZ_LOAD = 4.0 / (3.0 * math.pi)


def load_example(name):
    spec = importlib.util.spec_from_file_location(f"example_{name}", EXAMPLES / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def check_load_controlled(mod, tmp_path):
    """Constant load F = 4/(3 pi): the load equals F to 1e-9 at every step, and the sphere
    sinks toward the Hertz depth hc = -1 from above (hc ~ -0.946 at t = 1)."""
    o = mod.main(out=tmp_path, t_end=1.0, mesh="coarse", dt=0.02)
    res = o["result"]
    assert np.max(np.abs(res.load[1:] - HERTZ_LOAD)) <= 1e-9 * HERTZ_LOAD
    assert abs(o["load"] - o["F"]) <= 1e-9 * o["F"]
    assert -1.0 < o["hc"] < -0.9 and o["hc_hertz"] == pytest.approx(-1.0)


def check_ellipsoid_sliding(mod, tmp_path):
    """Rx < Ry: at the end of indentation the contact is long across the sliding direction
    (pressure at (0, 0.7) ~ 40x that at (0.7, 0)); once sliding, the minimum film sits at
    the exit, x < 0."""
    o = mod.main(out=tmp_path, t_end=2.0, mesh="coarse", dt=0.02)
    res = o["result"]
    p_across, p_along = res.pressure_at([[0.0, 0.7], [0.7, 0.0]], 1.0)
    assert p_across > 10.0 * p_along
    assert o["film_min_at"][0] < -0.1 and 0.0 < o["film_min"] < o["film_center"]


def check_custom_shape(mod, tmp_path):
    """The rippled sphere is not symmetric in y: full disk.  Its ripple lowers the load at the
    end of indentation by ~6 % below the smooth sphere's (0.4757)."""
    o = mod.main(out=tmp_path, t_end=1.0, mesh="coarse", dt=0.02)
    assert o["half"] is False
    # reference 0.44556: FE BDF2, dt = 0.01, fine full disk (coarse and medium give 0.44546
    # and 0.44549, so mesh error <= 0.03 %).  This run (coarse, Euler, dt = 0.02) measured
    # 0.44243, -0.70 %: Euler's time error at dt = 0.02, as for the sphere (-0.65 %,
    # benchmarks/accuracy_results.md); tolerance 1.5 %, about 2x
    assert o["load"] == pytest.approx(0.44556, rel=0.015)


def check_textured_sphere(mod, tmp_path):
    """The dimpled sphere on a small mesh (4k elements instead of 200k) through the indentation
    and the start of sliding, with the fast operator forced: load and films equal those of
    the dense operator on the same mesh to 1e-6 (the fast operator's stated accuracy)."""
    fast = mod.main(out=tmp_path, t_end=1.2, elements=4000, dt=0.02, operator="fast")
    dense = mod.main(out=tmp_path / "dense", t_end=1.2, elements=4000, dt=0.02, operator="dense")
    assert fast["operator"] == "fast" and dense["operator"] == "dense" and fast["half"] is False
    assert 3000 <= fast["elements"] <= 5000
    for q in ("load", "film_center", "film_min"):
        assert fast[q] == pytest.approx(dense[q], rel=1e-6), q


def check_cylinder_winkler(mod, tmp_path):
    """Line contact on a Winkler foundation: the long-time state matches the exact steady
    solution (quadrature and shooting)."""
    o = mod.main(t_end=15.0, dt=0.2, n_elements=200, outdir=tmp_path, verbose=False)
    assert o["load_error"] < 1e-3 and o["film_error"] < 2e-2


def check_paper_figures(mod, tmp_path):
    """Figs. 5-7 with both solvers, shortened to the indentation (t <= 1, coarse grids, same
    dt): FE and FD loads agree within 2 % at t = 0.5 and 1 (the FD at dr = 0.05 is first
    order; its load changes by 0.15 % from dr = 0.05 to 0.025), and the three figures exist."""
    summary = mod.main(
        out=tmp_path, t_end=1.0, dt=0.05, mesh="coarse", fd_dr=0.05, fd_divisions=12, log=lambda *a: None
    )
    for t in (0.5, 1.0):
        fe, fd = summary[t]["load"]
        assert abs(fe - fd) < 0.02 * fd, (t, fe, fd)
    assert (tmp_path / "fig5.png").exists() and (tmp_path / "fig6.png").exists()


def check_rubber_slider(mod, tmp_path):
    """Three speeds (shortened to t = 6, V = 1 - 1e-4): the rubber's hysteresis is largest at
    De ~ 1, the middle speed (elastic in both limits), and the two dissipations add up to
    the friction work (steady sliding, femehl.solver.energetics) to 1e-3."""
    rows = mod.main(out=tmp_path, speeds=(1e-3, 1e-2, 1e-1), t_end=6.0, dt=0.05)
    rubber = [r["mu_rubber"] for r in rows]
    assert rubber[1] > max(rubber[0], rubber[2]) and min(rubber) > 0  # the peak near De = 1
    for r in rows:
        assert r["mu_rubber"] + r["mu_film"] == pytest.approx(r["mu"], rel=1e-3)
    assert (tmp_path / "friction_speed.png").exists() and (tmp_path / "V_1e-02" / "summary.csv").exists()


def check_rolling_traction(mod, tmp_path):
    """Pure rolling at three relaxation times and sliding at one: every run's friction within
    1e-4 of the steady solution computed without time stepping (measured <= 3.1e-5, the
    400-element mesh's spatial error); the rolling resistance peaks at the middle Deborah
    number (2 here, 0.2 and 60 on either side); no Couette shear in rolling, and sliding
    adds it (0.28 of the friction's 0.44 at SRR = 2)."""
    o = mod.main(out=tmp_path, taus=(0.1, 1.0, 30.0), srrs=(0.0, 2.0))
    rows = o["rolling"] + o["traction"]
    for r in rows:
        assert r["friction"] == pytest.approx(r["friction_reference"], rel=1e-4)
    f = [r["friction"] for r in o["rolling"]]
    assert f[1] > 1.5 * max(f[0], f[2])
    roll, slide = o["traction"]
    assert roll["couette"] == 0.0 and slide["couette"] > 0.5 * slide["friction"] > 0
    assert (tmp_path / "rolling_traction.png").exists()


def check_stribeck_curve(mod, tmp_path):
    """Four speeds over four decades (a local Dask cluster): every point steady; from boundary
    (the asperities carry all but 4e-5 of the load, so the friction coefficient is their
    mu_b = 0.1: 0.10004 measured) through mixed to full film, the film rising and the
    asperities' share falling with the speed; the friction coefficient's minimum inside."""
    curve = mod.main(out=tmp_path, speeds=(1e-2, 1e2), num=4, workers=1)
    assert list(curve["status"]) == ["done"] * 4 and curve["steady"].all()
    share, film = curve["asperity_share"].to_numpy(), curve["film_center"].to_numpy()
    assert np.all(np.diff(share) < 0) and np.all(np.diff(film) > 0)
    assert list(curve["regime"])[0] == "boundary" and list(curve["regime"])[-1] == "full film"
    mu = curve["friction_coefficient"].to_numpy()
    assert mu[0] == pytest.approx(mod.MU_B, rel=1e-3)
    assert mu.argmin() in (1, 2) and mu.min() < 0.5 * mod.MU_B
    assert (tmp_path / "stribeck.png").is_file() and (tmp_path / "stribeck.csv").is_file()


def check_ball_drop(mod, tmp_path):
    """One approach speed, dt = 0.004: the ball bounces (0 < e < 1; e = 0.765 at dt = 0.002,
    unchanged to 3 digits at 0.001), never touches the gel, and the energy budget closes to
    BDF2's time error (2.4e-4 measured at dt = 0.002, second order)."""
    (row,) = mod.main(out=tmp_path, speeds=(0.05,), dt=0.004)
    assert 0.7 < row["restitution"] < 0.8 and row["film_min_um"] > 0
    assert row["energy_drift"] < 4e-3 and row["indentation_um"] > 50


def check_coated_contact(mod, tmp_path):
    """Under the same load, a coating as thick as the contact (h = 1) is stiffer than the
    half space: shallower indentation (hc -0.44 against -0.96 at t = 5) and a thinner
    film; shortened here to t = 2 (sliding started)."""
    half, coat = mod.main(out=tmp_path, thicknesses=(1.0,), t_end=2.0)
    assert half["thickness"] is None and coat["thickness"] == 1.0
    assert coat["hc"] > 0.7 * half["hc"] and coat["film_min"] < half["film_min"]


CHECKS = {
    "coated_contact": check_coated_contact,
    "ball_drop": check_ball_drop,
    "rubber_slider": check_rubber_slider,
    "rolling_traction": check_rolling_traction,
    "stribeck_curve": check_stribeck_curve,
    "load_controlled": check_load_controlled,
    "ellipsoid_sliding": check_ellipsoid_sliding,
    "custom_shape": check_custom_shape,
    "cylinder_winkler": check_cylinder_winkler,
    "textured_sphere": check_textured_sphere,
    "paper_figures": check_paper_figures,
}
WRITES_RUN_FOLDER = {"load_controlled", "ellipsoid_sliding", "custom_shape", "textured_sphere"}


@pytest.mark.parametrize("name", sorted(CHECKS))
def test_example_runs(name, tmp_path, capsys):
    mod = load_example(name)
    CHECKS[name](mod, tmp_path)
    if name in WRITES_RUN_FOLDER:
        out = capsys.readouterr().out
        assert "load" in out and "central film" in out and "minimum film" in out
        assert (tmp_path / "summary.csv").exists()


@pytest.mark.parametrize("name", ["load_controlled", "ellipsoid_sliding", "coated_contact"])
def test_toml_twin_is_the_same_scene(name, tmp_path):
    sc, run = load_scene_file(EXAMPLES / f"{name}.toml")
    assert sc == load_example(name).scene()
    assert run["method"] == "fe" and run["mesh"] == "coarse"
    # (dt = 0.05 is too coarse for the first step of a suddenly applied Hertz load: rupture)
    rc = cli_main(
        [
            "run",
            str(EXAMPLES / f"{name}.toml"),
            "--t-end",
            "0.1",
            "--dt",
            "0.02",
            "--out",
            str(tmp_path),
            "--quiet",
        ]
    )
    assert rc == 0 and (tmp_path / "summary.csv").exists()


def test_ball_drop_toml_is_the_example():
    """The SI scene file states the example's U = 0.05 m/s case (free indenter, no sliding)."""
    sc, run = load_scene_file(EXAMPLES / "ball_drop.toml")
    py, _dim = load_example("ball_drop").scene(0.05)
    assert sc.fluid == py.fluid and sc.domain == py.domain and sc.substrate == py.substrate
    assert sc.motion.velocity(2.0) == 0.0 and sc.motion.hc(0.0) == pytest.approx(py.motion.hc(0.0))
    for q in ("mass", "hc_dot0"):
        assert getattr(sc.motion, q) == pytest.approx(getattr(py.motion, q), rel=1e-9)
    assert sc.motion.applied_force(0.0) == pytest.approx(py.motion.applied_force(0.0), rel=1e-9)
    assert run["_dimensional"].V_ss == 0.05


def test_sphere_si_toml():
    sc, run = load_scene_file(EXAMPLES / "sphere_si.toml")
    dim = run.pop("_dimensional")
    assert dim == Dimensional(R=0.01, G=1e5, eta=1.0, V_ss=0.01, h_inf=1e-4, nu=0.5)
    assert sc == dim.scene(h0=1e-5)
    assert sc.fluid.beta == pytest.approx(dim.beta)
