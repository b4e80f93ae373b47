"""Output a user opens (CSV, VTU/PVD series, PNG) and the command line."""

from __future__ import annotations

import csv
import math
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

import femehl
from femehl.api import run_to_folder
from femehl.cli import main
from femehl.output import COLUMNS
from femehl.solver.energetics import FRICTION_COLUMNS, SIDE_COLUMNS


def _sources(points, n):
    """For each written point, the computed node (one of the first ``n``) it mirrors."""
    from scipy.spatial import cKDTree

    tree = cKDTree(points[:n, :2])
    img = points[n:, :2] * np.array([1.0, -1.0])
    dist, k = tree.query(img)
    assert np.all(dist < 1e-12) and np.all(points[n:, 1] < 0)
    return np.concatenate([np.arange(n), k])


def _read_csv(path):
    with open(path) as fh:
        rows = list(csv.reader(fh))
    return rows[0], np.array(rows[1:], dtype=float)


@pytest.mark.parametrize(
    "method,opts", [("fe", dict(mesh="coarse")), ("fd", dict(dr=0.1, dtheta=math.pi / 12))]
)
def test_run_writes_readable_series(tmp_path, method, opts):
    """Every stored state is a .vtu meshio reads back with the fields it had; the .pvd
    lists them with their times; the CSV has one row per step and matches the Result."""
    sc = femehl.presets.paper_sphere()
    res = run_to_folder(
        sc, tmp_path, method=method, t_end=0.3, dt=0.05, store_every=2, log=lambda *a: None, **opts
    )
    head, data = _read_csv(tmp_path / "summary.csv")
    # fe: the friction from dp/dx per element, and across the motion on a disk
    assert tuple(head) == COLUMNS + (FRICTION_COLUMNS + SIDE_COLUMNS if method == "fe" else ())
    assert data.shape[0] == res.nsteps + 1 == 7
    assert np.allclose(data[:, head.index("load")], res.load, rtol=1e-9, atol=1e-12)
    root = ET.parse(tmp_path / "fields.pvd").getroot()
    sets = root.findall("./Collection/DataSet")
    times = [float(s.get("timestep")) for s in sets]
    assert np.allclose(times, [0.0, 0.1, 0.2, 0.3])
    for s, t in zip(sets, times, strict=True):
        m = meshio.read(tmp_path / s.get("file"))
        st = res.state_at(t)
        # the half disk is written mirrored: the computed nodes first, then the images of
        # those off y = 0, each carrying the value of its source node (x, -y)
        n = st.p.size
        src = _sources(m.points, n)
        assert np.allclose(m.point_data["pressure"], st.p[src])
        if method == "fd":
            assert np.allclose(m.point_data["film"], st.d[src])
        else:
            assert np.allclose(m.cell_data["film"][0], np.concatenate([st.d, st.d]))
    for png in ("centreline.png", "maps.png", "history.png"):
        assert (tmp_path / png).stat().st_size > 10_000


def test_series_readable_by_pyvista(tmp_path):
    """ParaView/pyvista open the .pvd index (pyvista is optional: skipped if absent)."""
    pv = pytest.importorskip("pyvista")
    sc = femehl.presets.paper_sphere()
    run_to_folder(
        sc, tmp_path, method="fe", mesh="coarse", t_end=0.2, dt=0.1, store_every=1, log=lambda *a: None
    )
    reader = pv.get_reader(str(tmp_path / "fields.pvd"))
    assert np.allclose(reader.time_values, [0.0, 0.1, 0.2])
    reader.set_active_time_value(0.2)
    mesh = reader.read()[0]
    assert "pressure" in mesh.point_data and "film" in mesh.cell_data
    assert float(np.max(mesh.point_data["pressure"])) > 0.0


def test_cli_default_scene_short(tmp_path, capsys):
    """`femehl run` on the built-in scene (shortened) prints the figures it wrote."""
    rc = main(
        ["run", "--t-end", "0.2", "--dt", "0.05", "--mesh", "coarse", "--out", str(tmp_path), "--quiet"]
    )
    assert rc == 0
    cap = capsys.readouterr()
    # sliding starts at t = 1: a run to t = 0.2 has no Couette term (the run's report: stderr)
    assert "terms: squeeze=True, sliding=False, elasticity=halfspace" in cap.err
    assert "femehl: done in" in cap.out and "t = 0.2: load" in cap.out
    assert (tmp_path / "summary.csv").exists() and (tmp_path / "fields.pvd").exists()


def test_cli_scene_file_and_fd(tmp_path, capsys):
    """The commented example scene file runs, with --method fd overriding [run]."""
    rc = main(
        [
            "run",
            "examples/paper_sphere.toml",
            "--method",
            "fd",
            "--dr",
            "0.1",
            "--dtheta-divisions",
            "12",
            "--t-end",
            "0.1",
            "--dt",
            "0.05",
            "--out",
            str(tmp_path),
            "--quiet",
        ]
    )
    assert rc == 0
    head, data = _read_csv(tmp_path / "summary.csv")
    assert data.shape[0] == 3


def test_cli_bad_input_exit_code(tmp_path, capsys):
    rc = main(["run", str(tmp_path / "missing.toml"), "--out", str(tmp_path)])
    assert rc == 2
    assert "does not exist" in capsys.readouterr().err
    bad = tmp_path / "bad.toml"
    bad.write_text("[fluid]\nbeta = -1\n")
    assert main(["run", str(bad), "--out", str(tmp_path)]) == 2
    assert "beta must be > 0" in capsys.readouterr().err


def test_user_mesh_file(tmp_path):
    """Any mesh meshio reads is accepted (here a .vtu of the coarse ladder mesh)."""
    from femehl.discretize.mesh import load_mesh

    dm = load_mesh("coarse")
    path = tmp_path / "mine.vtu"
    meshio.write(path, meshio.Mesh(dm.mesh.p.T, [("triangle", dm.mesh.t.T)]))
    sc = femehl.presets.paper_sphere()
    a = femehl.solve(sc, "fe", mesh=str(path), t_end=0.2, dt=0.1, store_every=0)
    b = femehl.solve(sc, "fe", mesh="coarse", t_end=0.2, dt=0.1, store_every=0)
    assert np.allclose(a.load, b.load, rtol=1e-10)


def test_result_interpolation_in_time():
    """pressure_at between stored times is the linear blend of the two neighbours."""
    sc = femehl.presets.paper_sphere()
    r = femehl.solve(sc, "fe", mesh="coarse", t_end=0.4, dt=0.1)
    pts = np.array([[0.0, 0.0], [0.3, -0.2], [5.0, 0.0]])
    mid = r.pressure_at(pts, 0.25)
    lo, hi = r.pressure_at(pts, 0.2), r.pressure_at(pts, 0.3)
    assert np.allclose(mid, 0.5 * (lo + hi))
    assert mid[2] == 0.0  # outside the domain: p = 0
    assert np.isclose(r.pressure_at(pts[:2] * [1, -1], 0.3)[1], hi[1])  # mirror symmetry
    with pytest.raises(femehl.SceneError, match="outside the stored times"):
        r.pressure_at(pts, 0.5)
    with pytest.raises(femehl.SceneError, match=r"shape \(n, 2\)"):
        r.pressure_at(np.zeros((3, 3)), 0.1)
