"""Tests of femehl.discretize.mesh: the mesh ladder, graded_disk, load_mesh and its checks."""

from __future__ import annotations

import itertools
import math

import meshio
import numpy as np
import pytest
import skfem

from femehl.discretize import mesh as fm
from femehl.discretize.mesh import LADDER, DiskMesh, areas, centroids, graded_disk, ladder_path, load_mesh
from femehl.errors import MeshError

NAMES = ["coarse", "medium", "fine", "xfine"]


def signed_areas(p, t):
    x, y = p[0, t], p[1, t]
    return 0.5 * ((x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]))


def boundary_nodes(t):
    """Nodes on edges used by exactly one triangle (independent of skfem)."""
    e = np.sort(np.hstack([t[[0, 1]], t[[1, 2]], t[[2, 0]]]), axis=0)
    u, c = np.unique(e, axis=1, return_counts=True)
    return np.unique(u[:, c == 1])


@pytest.fixture(scope="module")
def ladder():
    return {(n, h): load_mesh(n, half=h) for n in NAMES for h in (True, False)}


@pytest.fixture(scope="module")
def coarse_full(ladder):
    return ladder["coarse", False]


# ---------------------------------------------------------------------------
# the ladder


def test_ladder_names():
    assert list(LADDER) == NAMES
    for n in NAMES:
        assert ladder_path(n).name == f"half_{n}.msh"
        assert ladder_path(n, half=False).name == f"full_{n}.msh"
        assert ladder_path(n).is_file() and ladder_path(n, half=False).is_file()


@pytest.mark.parametrize("half", [True, False])
@pytest.mark.parametrize("name", NAMES)
def test_ladder_loads(ladder, name, half):
    dm = ladder[name, half]
    assert isinstance(dm, DiskMesh)
    assert dm.half is half and dm.L == 2.0 and dm.name == name
    p, t = dm.mesh.p, dm.mesh.t
    # counterclockwise, from node coordinates
    assert np.all(signed_areas(p, t) > 0)
    np.testing.assert_allclose(areas(dm), signed_areas(p, t))
    # area: the inscribed polygon loses at most ~ h^2 / (6 L^2) (h = boundary chord <= h_far)
    A0 = math.pi * 4 / (2 if half else 1)
    rel = (areas(dm).sum() - A0) / A0
    tol = max(1e-3, 2 * LADDER[name]["h_far"] ** 2 / (6 * 4))
    assert -tol <= rel <= 0
    # boundary exactly on r = L or y = 0
    b = boundary_nodes(t)
    r = np.hypot(p[0, b], p[1, b])
    on = np.abs(r - 2) <= 1e-14
    if half:
        on |= p[1, b] == 0.0
        assert p[1].min() == 0.0
    else:
        assert p[1].min() < -1.9
    assert on.all()
    assert np.hypot(p[0], p[1]).max() == pytest.approx(2, rel=1e-14)
    # the origin is a node; no unused nodes
    assert np.any(np.hypot(p[0], p[1]) == 0)
    assert np.unique(t).size == p.shape[1]
    assert centroids(dm).shape == (t.shape[1], 2)


@pytest.mark.parametrize("half", [True, False])
def test_ladder_counts_double(ladder, half):
    ne = np.array([ladder[n, half].mesh.t.shape[1] for n in NAMES])
    ratios = ne[1:] / ne[:-1]
    assert np.all((ratios > 1.8) & (ratios < 2.3)), ratios
    if half:
        for n, lo, hi in zip(NAMES, (1000, 2500, 6000, 12000), (1500, 3500, 8000, 16000), strict=True):
            assert lo <= ladder[n, True].mesh.t.shape[1] <= hi
    # sizes: every rung divides all three by the same factor ~ sqrt(2)
    for a, b in itertools.pairwise(NAMES):
        for k in ("h_far", "h_contact", "h_edge"):
            assert LADDER[a][k] / LADDER[b][k] == pytest.approx(fm.LADDER_RATIO, rel=1e-4)
    assert 1.35 < fm.LADDER_RATIO < 1.5


@pytest.mark.parametrize("name", NAMES)
def test_grading(ladder, name):
    for half in (True, False):
        dm = ladder[name, half]
        r = np.hypot(*centroids(dm).T)
        a = areas(dm)
        h_edge = math.sqrt(a[(r > 0.8) & (r < 1.2)].mean())
        h_far = math.sqrt(a[(r > 1.6) & (r < 2.0)].mean())
        assert h_far > 3 * h_edge


# ---------------------------------------------------------------------------
# graded_disk


def test_graded_disk_reproducible_and_exact():
    kw = dict(L=1.5, h_far=0.3, h_contact=0.12, h_edge=0.06)
    a, b = graded_disk(**kw), graded_disk(**kw)
    assert np.array_equal(a.mesh.p, b.mesh.p) and np.array_equal(a.mesh.t, b.mesh.t)
    assert a.half and a.L == 1.5 and a.name == "generated"
    p = a.mesh.p
    bn = boundary_nodes(a.mesh.t)
    on_arc = np.abs(np.hypot(p[0, bn], p[1, bn]) - 1.5) <= 4 * 2.3e-16 * 1.5
    assert np.all(on_arc | (p[1, bn] == 0))
    f = graded_disk(half=False, **kw)
    assert not f.half and f.mesh.p[1].min() < -1.4


def test_ladder_name_with_other_L():
    dm = load_mesh("coarse", L=3.0)
    assert dm.L == 3.0 and dm.half and dm.name == "coarse"
    assert np.hypot(*dm.mesh.p).max() == pytest.approx(3.0, rel=1e-14)
    assert areas(dm).sum() == pytest.approx(math.pi * 9 / 2, rel=2e-2)
    # same sizes in normalized units, not a scaled copy: more elements than at L = 2
    assert dm.mesh.t.shape[1] > load_mesh("coarse").mesh.t.shape[1]


def test_graded_disk_bad_sizes():
    with pytest.raises(MeshError, match="positive"):
        graded_disk(h_edge=0.0)
    with pytest.raises(MeshError, match="r_in < r_out"):
        graded_disk(r_edge=(1.2, 0.8))


def test_ladder_path_generates_and_caches(tmp_path, monkeypatch):
    monkeypatch.setattr(fm, "_MESHES_DIR", tmp_path / "no_meshes_folder")
    monkeypatch.setattr(fm, "_USER_CACHE", tmp_path / "cache")
    p = ladder_path("coarse")
    assert p.parent == tmp_path / "cache" and p.name.startswith("half_coarse-")
    assert ladder_path("coarse") == p  # cached
    dm = load_mesh("coarse")
    assert dm.mesh.t.shape[1] == meshio.read(p).cells_dict["triangle"].shape[0]
    # with a writable meshes folder the file goes there, under its ladder name
    (tmp_path / "meshes").mkdir()
    monkeypatch.setattr(fm, "_MESHES_DIR", tmp_path / "meshes")
    assert ladder_path("coarse", half=False) == tmp_path / "meshes" / "full_coarse.msh"


# ---------------------------------------------------------------------------
# load_mesh of other inputs


@pytest.mark.parametrize("half", [True, False])
def test_vtu_round_trip(ladder, tmp_path, half):
    dm = ladder["coarse", half]
    path = tmp_path / "disk.vtu"
    meshio.write(path, meshio.Mesh(dm.mesh.p.T, [("triangle", dm.mesh.t.T)]))
    back = load_mesh(path)
    assert back.half is half  # detected from the nodes
    assert back.name == str(path)
    assert back.mesh.p.shape == dm.mesh.p.shape and back.mesh.t.shape == dm.mesh.t.shape
    assert np.array_equal(back.mesh.t, dm.mesh.t)
    assert load_mesh(str(path)).mesh.t.shape == dm.mesh.t.shape


def test_meshio_file_with_z_and_unused_nodes_and_lines(coarse_full, tmp_path):
    p, t = coarse_full.mesh.p, coarse_full.mesh.t
    pts = np.vstack([np.c_[p.T, np.zeros(p.shape[1])], [[9.0, 9.0, 0.0]]])  # unused node
    cells = [("line", np.array([[0, 1]])), ("triangle", t.T[:, ::-1])]  # clockwise
    path = tmp_path / "disk.vtu"
    meshio.write(path, meshio.Mesh(pts, cells))
    dm = load_mesh(path)
    assert not dm.half
    assert dm.mesh.p.shape == p.shape
    assert np.all(signed_areas(dm.mesh.p, dm.mesh.t) > 0)


def test_meshtri_and_diskmesh(coarse_full):
    m = coarse_full.mesh
    # a MeshTri with skfem's default sort_t=True: mixed orientation
    sorted_m = skfem.MeshTri(m.p.copy(), m.t.copy())
    dm = load_mesh(sorted_m)
    assert np.all(signed_areas(dm.mesh.p, dm.mesh.t) > 0)
    assert dm.name == "<MeshTri>" and not dm.half
    # a DiskMesh that passes unchanged is returned as is
    assert load_mesh(coarse_full) is coarse_full
    with pytest.raises(MeshError, match="pass a ladder name"):
        load_mesh(42)


def test_input_meshtri_not_mutated(coarse_full):
    p = coarse_full.mesh.p.copy()
    t = coarse_full.mesh.t.copy()
    t[[1, 2], ::2] = t[[2, 1], ::2]  # every other triangle clockwise: must be reoriented
    b = boundary_nodes(t)
    p[:, b] *= 1 + 1e-12  # off the circle by round-off: must be snapped
    m = skfem.MeshTri(p, t, sort_t=False)
    p0, t0 = m.p.copy(), m.t.copy()
    dm = load_mesh(m)
    assert np.array_equal(m.p, p0) and np.array_equal(m.t, t0)
    assert np.all(signed_areas(dm.mesh.p, dm.mesh.t) > 0)
    assert np.abs(np.hypot(*dm.mesh.p[:, b]) - 2).max() <= 1e-15


# ---------------------------------------------------------------------------
# errors: type and the fix in the message


def test_error_nonexistent_file(tmp_path):
    with pytest.raises(MeshError, match="does not exist.*ladder name"):
        load_mesh(tmp_path / "nope.msh")
    with pytest.raises(MeshError, match="does not exist.*coarse"):
        load_mesh("coarsest")


@pytest.mark.parametrize("suffix", [".msh", ".vtu", ".txt"])
def test_error_garbage_file(tmp_path, suffix, capsys):
    path = tmp_path / f"garbage{suffix}"
    path.write_text("this is not a mesh\n1 2 3\n")
    with pytest.raises(MeshError, match=r"is not a mesh meshio can read.*meshio reads.*\.msh"):
        load_mesh(path)
    out = capsys.readouterr()
    assert out.out == "" and out.err == ""  # meshio's chatter is captured


def test_reading_a_mesh_leaves_sys_streams_alone(ladder, tmp_path, monkeypatch):
    """A mesh read in one thread (a sweep's case) must not swap sys.stdout/stderr for the
    process: the main thread's messages printed meanwhile would go into the swapped stream."""
    import sys

    from meshio import _helpers

    streams = sys.stdout, sys.stderr
    seen = []
    real = _helpers.reader_map["gmsh"]

    def reader(path):
        seen.append((sys.stdout, sys.stderr))
        return real(path)

    monkeypatch.setitem(_helpers.reader_map, "gmsh", reader)
    fm.load_mesh(ladder_path("coarse"))
    assert seen and all(s[0] is streams[0] and s[1] is streams[1] for s in seen)


def test_error_quads_only(tmp_path):
    pts = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    path = tmp_path / "quads.vtu"
    meshio.write(path, meshio.Mesh(pts, [("quad", np.array([[0, 1, 2, 3]]))]))
    with pytest.raises(MeshError, match=r"no triangle cells \(found: quad\).*2-D triangulation"):
        load_mesh(path)


def test_error_square():
    sq = skfem.MeshTri.init_sqsymmetric().refined(2)
    m = skfem.MeshTri(sq.p * 4 - 2, sq.t)
    with pytest.raises(MeshError, match="does not cover the disk"):
        load_mesh(m)


def test_error_hole(coarse_full):
    m = coarse_full.mesh
    keep = np.hypot(*centroids(coarse_full).T) > 0.3
    with pytest.raises(MeshError, match=r"1 hole.*remesh the disk without holes"):
        load_mesh(skfem.MeshTri(m.p, m.t[:, keep], sort_t=False))


def test_error_radius(coarse_full):
    m = coarse_full.mesh
    with pytest.raises(MeshError, match=r"mesh radius R = 1 != L = 2; pass L=1 or scale"):
        load_mesh(skfem.MeshTri(m.p / 2, m.t, sort_t=False), L=2.0)
    assert load_mesh(skfem.MeshTri(m.p / 2, m.t, sort_t=False), L=1.0).L == 1.0


def test_error_nan(coarse_full):
    p = coarse_full.mesh.p.copy()
    p[0, 5] = np.nan
    with pytest.raises(MeshError, match="non-finite.*fix the coordinates"):
        load_mesh(skfem.MeshTri(p, coarse_full.mesh.t, sort_t=False))


def test_error_degenerate(coarse_full):
    p, t = coarse_full.mesh.p.copy(), coarse_full.mesh.t
    p[:, t[2, 100]] = p[:, t[0, 100]]
    with pytest.raises(MeshError, match="degenerate.*remesh"):
        load_mesh(skfem.MeshTri(p, t, sort_t=False))


def test_error_disconnected(coarse_full):
    p, t = coarse_full.mesh.p, coarse_full.mesh.t
    p2 = np.hstack([p, p + [[5.0], [0.0]]])
    t2 = np.hstack([t, t + p.shape[1]])
    with pytest.raises(MeshError, match="2 disconnected pieces.*one piece"):
        load_mesh(skfem.MeshTri(p2, t2, sort_t=False))


def test_error_half_mismatch(ladder):
    full, half = ladder["coarse", False], ladder["coarse", True]
    with pytest.raises(MeshError, match="pass half=False"):
        load_mesh(full.mesh, half=True)
    with pytest.raises(MeshError, match="does not cover.*pass half=True"):
        load_mesh(half.mesh, half=False)
