"""Mesh input that cannot work is refused with a MeshError naming the cause and the fix.

Directories, missing and unreadable files, files meshio cannot read, meshes whose dense
elastic operator would not fit in memory, and gmsh sizes that would make millions of
elements (refused before gmsh runs).
"""

from __future__ import annotations

import math
import os
import shutil

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import femehl.discretize.mesh as M
from femehl.discretize.mesh import (
    LADDER,
    MAX_GMSH_ELEMENTS,
    check_mesh_memory,
    dense_bytes,
    estimate_elements,
    graded_disk,
    load_mesh,
    machine_memory,
    operator_bytes,
)
from femehl.errors import MeshError
from femehl.problem.scenefile import load_scene_file


# ---- 3. paths: directory, missing, unreadable, not a mesh ---------------------------------
def test_directory_is_reported_as_directory(tmp_path):
    with pytest.raises(MeshError, match=rf"mesh path '{tmp_path}' is a directory, not a mesh file"):
        load_mesh(tmp_path)
    with pytest.raises(MeshError, match="is a directory"):
        load_mesh(str(tmp_path))


def test_missing_file_is_reported_as_missing(tmp_path):
    with pytest.raises(MeshError, match=r"nope\.msh' does not exist; pass an existing mesh file"):
        load_mesh(tmp_path / "nope.msh")
    with pytest.raises(
        MeshError, match=r"'corse' does not exist \(did you mean the ladder mesh 'coarse'\?\)"
    ):
        load_mesh("corse")


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root reads every file")
def test_unreadable_file(tmp_path):
    p = tmp_path / "locked.msh"
    shutil.copy(M.ladder_path("coarse"), p)
    p.chmod(0)
    try:
        with pytest.raises(MeshError, match="is not readable"):
            load_mesh(p)
    finally:
        p.chmod(0o600)


@pytest.mark.parametrize(
    "suffix,data",
    [
        (".msh", b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\ngarbage"),
        (".msh", b""),
        (".vtu", b"<VTKFile><broken"),
        (".xdmf", b"\x00\x01\x02\xff" * 50),
        (".stl", b"solid x\n facet normal nonsense"),
        (".weird", b"1 2 3\n"),
        ("", b"no suffix at all"),
    ],
)
def test_garbage_file_is_not_a_mesh_meshio_can_read(tmp_path, capsys, suffix, data):
    p = tmp_path / f"bad{suffix}"
    p.write_bytes(data)
    with pytest.raises(MeshError, match=r"is not a mesh meshio can read.*meshio reads"):
        load_mesh(p)
    out = capsys.readouterr()
    assert out.out == "" and out.err == ""


@settings(max_examples=25, deadline=None)
@given(data=st.binary(max_size=300), suffix=st.sampled_from([".msh", ".vtk", ".vtu", ".obj", ".off"]))
def test_random_bytes_give_mesh_error_only(tmp_path_factory, data, suffix):
    p = tmp_path_factory.mktemp("m") / f"r{suffix}"
    p.write_bytes(data)
    with pytest.raises(MeshError):
        load_mesh(p)


# ---- 2e. memory of the dense elastic operator --------------------------------------------
def test_machine_memory_reads_sysconf_and_falls_back(monkeypatch):
    n = machine_memory()
    assert n is None or n > 2**20

    def broken(name):
        raise ValueError(name)

    monkeypatch.setattr(M.os, "sysconf", broken)
    assert machine_memory() is None
    check_mesh_memory(10**6, 10**6, "huge")  # unknown memory: no refusal (graceful)


def test_operator_estimate_is_elements_times_free_nodes_times_8():
    assert operator_bytes(1000, 500) == 4_000_000
    # + two float64 film products and a float32 (default) or float64 (lu) LU of 500 x 500
    assert dense_bytes(1000, 500) == 4_000_000 + 20 * 250_000
    assert dense_bytes(1000, 500, lu_itemsize=8) == 4_000_000 + 24 * 250_000


def test_memory_check_names_estimate_and_machine_memory():
    with pytest.raises(
        MeshError,
        match=r"mesh big: 100000 elements and about 50000 free nodes need a dense "
        r"elastic operator of 40 GB.*about 90 GB with the film products and the LU, "
        r"more than 80% of this machine's 16 GB",
    ):
        check_mesh_memory(100_000, 50_000, "big", memory=16 * 10**9)
    check_mesh_memory(1000, 500, "small", memory=16 * 10**9)


def test_dense_count_is_what_a_sliding_run_holds():
    """The count of dense_bytes is the operator and film products the stepper formed
    (both terms: the surface slides), plus the default solver's single-precision LU."""
    import femehl

    scene = femehl.presets.paper_sphere()
    res = femehl.solve(scene, t_end=1.2, dt=0.1, mesh="coarse", operator="dense", estimate=False)
    ne, n = res.info["elements"], res.info["unknowns"]
    assert res.info["couette_assembled"] and res.info["squeeze_assembled"]
    assert res.info["operator_bytes"] + 4 * n * n == dense_bytes(ne, n)


def test_a_refresh_frees_the_old_lu_before_forming_the_new_matrix(monkeypatch):
    """One LU at a time: when the solver forms the next matrix, no earlier LU is alive.
    (A reference the solver kept to the old factor held one n x n array more at the dense
    path's peak: 1.515 against 1.377 GB over the whole paper case on 11,450 elements.)"""
    import weakref

    import femehl
    from femehl.solver import linsolve

    lus, alive = [], []
    factorize = linsolve.StepOperator.factorize

    def spy(self, dtype, t):
        alive.append(sum(r() is not None for r in lus))
        lu = factorize(self, dtype, t)
        lus.append(weakref.ref(lu))
        return lu

    monkeypatch.setattr(linsolve.StepOperator, "factorize", spy)
    scene = femehl.presets.paper_sphere()
    femehl.solve(scene, t_end=1.5, dt=0.1, mesh="coarse", operator="dense", estimate=False, refactor_after=1)
    assert len(alive) >= 3  # refreshed several times
    assert alive == [0] * len(alive)


def test_the_lu_solver_needs_a_double_precision_lu(monkeypatch):
    """A machine where the default solver's run fits and linear_solver='lu''s does not."""
    import femehl

    dm = load_mesh("coarse")
    scene = femehl.presets.paper_sphere()
    probe = femehl.solve(scene, t_end=0.1, dt=0.1, mesh=dm, operator="dense", estimate=False)
    ne, n = probe.info["elements"], probe.info["unknowns"]
    between = (dense_bytes(ne, n) + dense_bytes(ne, n, lu_itemsize=8)) / 2 / M.MEMORY_FRACTION
    monkeypatch.setattr(M, "machine_memory", lambda: int(between))
    monkeypatch.setattr(M, "FAST_BYTES_PER_ELEMENT", 1)  # not the check under test here
    femehl.solve(scene, t_end=0.1, dt=0.1, mesh=dm, operator="dense", estimate=False)
    with pytest.raises(MeshError, match=r"with the film products and the LU"):
        femehl.solve(scene, t_end=0.1, dt=0.1, mesh=dm, operator="dense", linear_solver="lu", estimate=False)


def test_loading_a_mesh_too_big_for_the_machine_is_refused(monkeypatch, tmp_path):
    medium = load_mesh("medium")  # loaded before the machine "shrinks"
    p = tmp_path / "copy.msh"
    shutil.copy(M.ladder_path("medium"), p)
    monkeypatch.setattr(M, "machine_memory", lambda: 10**8)  # a 100 MB machine
    with pytest.raises(MeshError, match=r"mesh medium: 2982 elements .*of this machine's 0\.1 GB"):
        load_mesh("medium")
    with pytest.raises(MeshError, match=rf"mesh {p}: 2982 elements"):
        load_mesh(p)
    with pytest.raises(MeshError, match=r"mesh <MeshTri>: 2982 elements"):
        load_mesh(medium.mesh)
    with pytest.raises(MeshError, match=r"mesh medium: 2982 elements"):
        load_mesh(medium)
    dm = load_mesh("coarse")  # 1468 x ~770 x 8 + 20 x 770^2 = 21 MB < 80 MB: fits
    assert dm.mesh.t.shape[1] == 1468


def test_graded_disk_memory_refused_before_gmsh(monkeypatch):
    def no_gmsh(*a, **k):
        raise AssertionError("gmsh must not run")

    monkeypatch.setattr(M, "_gmsh_disk", no_gmsh)
    monkeypatch.setattr(M, "machine_memory", lambda: 5 * 10**8)
    with pytest.raises(MeshError, match=r"graded_disk\(L=2, \.\.\.\) \(estimated\).*0\.5 GB"):
        graded_disk(**LADDER["xfine"], half=False)


# ---- 2e. gmsh sizes that would make millions of elements ----------------------------------
@pytest.mark.parametrize(
    "sizes",
    [
        {"h_far": 1e-4, "h_contact": 1e-4, "h_edge": 1e-4},
        {"h_far": 0.25, "h_contact": 0.05, "h_edge": 1e-9},
        {"h_far": 1e-3, "h_contact": 1e-3, "h_edge": 1e-3},
    ],
)
def test_too_many_elements_refused_before_gmsh(monkeypatch, sizes):
    def no_gmsh(*a, **k):
        raise AssertionError("gmsh must not run")

    monkeypatch.setattr(M, "_gmsh_disk", no_gmsh)
    with pytest.raises(
        MeshError,
        match=r"would make about [0-9.e+]+ elements, more than 2e\+06.*larger "
        r"mesh sizes",
    ):
        graded_disk(L=2.0, **sizes)


@pytest.mark.parametrize("name", list(LADDER))
def test_element_estimate_matches_the_ladder(name):
    """The estimate is within 20 % of gmsh's count (the ladder files)."""
    kw = LADDER[name]
    h = M._size_function(2.0, kw["h_far"], kw["h_contact"], kw["h_edge"], kw["r_contact"], kw["r_edge"])
    est = estimate_elements(2.0, True, h)
    real = load_mesh(name).mesh.t.shape[1]
    assert abs(est - real) / real < 0.2


@settings(max_examples=30, deadline=None)
@given(scale=st.floats(0.05, 20.0), half=st.booleans())
def test_element_estimate_scales_as_one_over_size_squared(scale, half):
    """h(r) is homogeneous of degree one in the sizes: s times the sizes, 1/s^2 the elements."""
    kw = LADDER["coarse"]
    h1 = M._size_function(2.0, kw["h_far"], kw["h_contact"], kw["h_edge"], kw["r_contact"], kw["r_edge"])
    hs = M._size_function(
        2.0, scale * kw["h_far"], scale * kw["h_contact"], scale * kw["h_edge"], kw["r_contact"], kw["r_edge"]
    )
    e1, es = estimate_elements(2.0, half, h1), estimate_elements(2.0, half, hs)
    assert es == pytest.approx(e1 / scale**2, rel=1e-9)


@settings(max_examples=30, deadline=None)
@given(log_h=st.floats(-12.0, math.log10(0.002)))
def test_any_tiny_size_is_refused_quickly(log_h):
    def no_gmsh(*a, **k):
        raise AssertionError("gmsh must not run")

    h = 10.0**log_h
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(M, "_gmsh_disk", no_gmsh)
        with pytest.raises(MeshError, match="more than 2e"):
            graded_disk(L=2.0, h_far=h, h_contact=h, h_edge=h)
    assert MAX_GMSH_ELEMENTS == 2_000_000


# ---- 4. a scene file's mesh path resolves against the scene file's folder -----------------
def test_scene_file_mesh_relative_to_scene_file(tmp_path, monkeypatch):
    sub = tmp_path / "case"
    (sub / "m").mkdir(parents=True)
    shutil.copy(M.ladder_path("coarse"), sub / "m" / "disk.msh")
    (sub / "s.toml").write_text('[run]\nmesh = "m/disk.msh"\n', encoding="utf-8")
    monkeypatch.chdir(tmp_path)  # not the scene file's folder
    _, run = load_scene_file("case/s.toml")
    dm = load_mesh(run["mesh"], L=2.0)
    assert dm.mesh.t.shape[1] == 1468 and dm.half
    (sub / "d.toml").write_text('[run]\nmesh = "m"\n', encoding="utf-8")
    _, run = load_scene_file(sub / "d.toml")
    with pytest.raises(MeshError, match="is a directory"):
        load_mesh(run["mesh"])


def test_load_mesh_never_mutates_its_input():
    dm = load_mesh("coarse")
    p0, t0 = dm.mesh.p.copy(), dm.mesh.t.copy()
    load_mesh(dm.mesh, L=2.0)
    assert np.array_equal(dm.mesh.p, p0) and np.array_equal(dm.mesh.t, t0)
