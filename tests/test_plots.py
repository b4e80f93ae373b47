"""The pictures of a run (history, contact maps, animation), ``femehl plot``, and the
mirrored full-disk series.

The figures are checked through their matplotlib objects (axes, scales, norms, markers),
not pixels; the mirrored series against the computed half (twice the cells, nodes on
y = 0 shared, pressure integral equal to the run's load).
"""

from __future__ import annotations

import math
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.colors as mcolors  # noqa: E402
import meshio  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import femehl  # noqa: E402
from femehl.cli import main  # noqa: E402
from femehl.errors import OutputError  # noqa: E402
from femehl.output import plots  # noqa: E402
from femehl.output.snapshot import mirror_half, read_snapshot, snapshot  # noqa: E402
from femehl.output.table import read_summary  # noqa: E402


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The paper case on the coarse mesh to t = 2.4 (indentation, then sliding), saved."""
    folder = tmp_path_factory.mktemp("run")
    res = femehl.solve(
        femehl.presets.paper_sphere(),
        t_end=2.4,
        dt=0.04,
        mesh="coarse",
        scheme="bdf2",
        estimate=False,
        store_every=5,
    )
    res.save(folder)
    return res, folder


# ---- history ---------------------------------------------------------------------------
def _table(t, **cols):
    base = {k: np.ones_like(t) for k in ("load", "film_center", "film_min", "p_max", "hc", "V")}
    base.update(cols)
    return {"t": t, **base}


def test_phases_of_the_paper_case_shape():
    """Approach (V = 0, hc falling), sliding start-up, then everything constant: steady."""
    t = np.linspace(0, 6, 601)
    hc = np.where(t < 1, 0.1 - 1.1 * t, -1.0)
    V = np.clip(t - 1, 0, 1)
    film = np.where(t < 4, 0.1 - 0.015 * t, 0.04)
    ph = plots.phases(_table(t, hc=hc, V=V, film_center=film, film_min=0.5 * film, load=1 + 0 * t))
    assert [p[0] for p in ph] == ["indentation", "start-up", "steady"]
    assert ph[0][1:] == pytest.approx((0.0, 1.01), abs=0.011)  # sliding from the first V > 0
    # steady from the first stored time with the film within 1 % of 0.04: 0.1 - 0.015 t <= 0.0404
    assert ph[2][1] == pytest.approx((0.1 - 0.0404) / 0.015, abs=0.011)
    assert ph[2][2] == 6.0


def test_phases_without_sliding_and_unsteady():
    t = np.linspace(0, 3, 301)
    ph = plots.phases(_table(t, hc=-t, V=0 * t, film_center=1 / (1 + t), film_min=1 / (1 + t)))
    assert [p[0] for p in ph] == ["indentation"]  # never steady: no steady phase
    drift = plots.phases(_table(t, V=np.clip(t, 0, 1), film_min=1 + 0.1 * t))
    assert [p[0] for p in drift] == ["start-up"]  # V > 0 from t = 0.01; the film keeps drifting


def test_history_figure_axes_and_error_band(run):
    res, folder = run
    table = read_summary(folder / "summary.csv")
    assert table["t"].size == res.nsteps + 1
    table = dict(table, err_film_min=np.full(table["t"].size, 0.05))
    fig = plots.history_figure(table)
    axes = fig.get_axes()
    assert len(axes) == 6  # load, peak pressure, hc with V on a twin axis, films, friction
    load_ax, p_ax, hc_ax, film_ax, f_ax, v_ax = axes
    assert film_ax.get_yscale() == "log"
    assert np.allclose(f_ax.get_lines()[0].get_ydata(), res.friction)
    assert np.allclose(load_ax.get_lines()[0].get_ydata(), res.load)
    assert np.allclose(v_ax.get_lines()[0].get_ydata(), res.V)
    # the band: (1 -+ 5 %) of the minimum film, as a filled polygon on the film axis
    bands = [c for c in film_ax.collections if "estimated error" in str(c.get_label())]
    assert len(bands) == 1
    ys = np.concatenate([p.vertices[:, 1] for p in bands[0].get_paths()])
    assert ys.min() == pytest.approx(0.95 * res.film_min.min(), rel=1e-6)
    names = [t.get_text() for t in load_ax.texts]
    assert names == ["indentation", "start-up"]
    matplotlib.pyplot.close(fig)


# ---- maps ------------------------------------------------------------------------------
def test_maps_figure_shows_the_physics(run):
    res, folder = run
    snap = snapshot(res.disc, res.final)
    assert snap.mirrored and snap.triangles.shape[0] == 2 * res.disc.nelements
    fig = plots.maps_figure(snap)
    film_ax, film_bar, p_ax, p_bar = (
        fig.get_axes()[0],
        fig.get_axes()[2],
        fig.get_axes()[1],
        fig.get_axes()[3],
    )
    film_im = film_ax.collections[0]
    assert isinstance(film_im.norm, mcolors.LogNorm)
    assert film_im.norm.vmin == pytest.approx(snap.film.min())  # the whole film range starts at its minimum
    assert film_im.norm.vmax == pytest.approx(plots.FILM_DECADES * snap.film.min())
    p_im = p_ax.collections[0]
    assert isinstance(p_im.norm, mcolors.TwoSlopeNorm) and p_im.norm.vcenter == 0.0
    assert p_im.norm.vmin < 0  # the sliding contact has its sub-ambient exit region
    a = plots.contact_radius(snap)
    W = min(snap.L, plots.WINDOW * a)
    assert film_ax.get_xlim() == pytest.approx((-W, W))
    # the minimum film, marked where the run found it (and at its mirror image)
    mark = [ln for ln in film_ax.get_lines() if "minimum film" in ln.get_label()][0]
    assert mark.get_xdata()[0] == pytest.approx(res.final.film_min_at[0])
    assert sorted(mark.get_ydata()) == pytest.approx(
        sorted([res.final.film_min_at[1], -res.final.film_min_at[1]])
    )
    assert any("p = 0" in ln.get_label() for ln in p_ax.get_lines())
    assert film_bar.get_ylabel().startswith("film") and p_bar.get_ylabel().startswith("pressure")
    matplotlib.pyplot.close(fig)


def test_contact_radius_of_hertz_like_pressure():
    """p = sqrt(1 - r^2) on a disk of radius 2: p > 5 % of the peak out to r = sqrt(1 - 0.05^2)."""
    from femehl.output.snapshot import Snapshot

    r, th = np.meshgrid(np.linspace(0, 2, 201), np.linspace(0, 2 * math.pi, 181))
    pts = np.column_stack([(r * np.cos(th)).ravel(), (r * np.sin(th)).ravel()])
    p = np.sqrt(np.clip(1 - np.hypot(pts[:, 0], pts[:, 1]) ** 2, 0, None))
    snap = Snapshot(0.0, pts, np.zeros((0, 3), int), p, p, True, 0.0, (0.0, 0.0), False, 2.0)
    assert plots.contact_radius(snap) == pytest.approx(math.sqrt(1 - 0.05**2), abs=0.01)


def test_read_snapshot_is_the_state(run):
    """The maps a folder gives back are the run's: same fields and minimum film."""
    res, folder = run
    a = snapshot(res.disc, res.final)
    b = read_snapshot(folder)
    assert b.t == pytest.approx(res.final.t)
    assert np.allclose(a.points, b.points) and np.array_equal(a.triangles, b.triangles)
    assert np.allclose(a.pressure, b.pressure) and np.allclose(a.film, b.film)
    assert b.film_min == pytest.approx(res.final.film_min) and b.mirrored


# ---- the mirrored series ---------------------------------------------------------------
def test_mirrored_series_merges_the_mirror_line(run):
    """Twice the cells, each node on y = 0 once, and the pressure integral over the full
    disk is the run's load (P1 integrated exactly: the mean of the vertices times the area)."""
    pv = pytest.importorskip("pyvista")
    res, folder = run
    last = sorted(folder.glob("fields_*.vtu"))[-1]
    m = meshio.read(last)
    n = res.disc.nnodes
    on_line = np.count_nonzero(np.abs(res.disc.nodes[:, 1]) <= 1e-12)
    assert m.cells[0].data.shape[0] == 2 * res.disc.nelements
    assert m.points.shape[0] == 2 * n - on_line
    assert np.unique(np.round(m.points[:, :2], 12), axis=0).shape[0] == m.points.shape[0]
    tri = m.points[m.cells[0].data][:, :, :2]
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    cross = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    assert np.all(np.sign(cross) == np.sign(cross[0]))  # images keep the orientation
    load = np.sum(0.5 * np.abs(cross) * m.point_data["pressure"][m.cells[0].data].mean(axis=1))
    assert load == pytest.approx(res.final.load, rel=1e-9)
    grid = pv.read(last)
    assert grid.n_cells == 2 * res.disc.nelements
    assert int(grid.field_data["MirroredHalfDisk"][0]) == 1
    assert float(grid.field_data["TimeValue"][0]) == pytest.approx(res.final.t)


def test_mirror_half_of_a_square():
    """Two triangles on [0, 1] x [0, 1]: the nodes on y = 0 are shared by the images."""
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    cells = [("triangle", np.array([[0, 1, 2], [0, 2, 3]]))]
    full, fc, src = mirror_half(pts, cells)
    assert full.shape[0] == 6 and np.array_equal(src, [0, 1, 2, 3, 2, 3])
    assert np.allclose(full[4:, 1], -1.0)
    assert np.array_equal(fc[0][1][2:], [[4, 1, 0], [5, 4, 0]])


def test_full_disk_run_is_written_as_computed(tmp_path):
    sc = femehl.presets.paper_sphere()
    res = femehl.solve(sc, t_end=0.1, dt=0.05, mesh="coarse", half=False, estimate=False)
    res.save(tmp_path)
    grid = meshio.read(sorted(tmp_path.glob("fields_*.vtu"))[-1])
    assert grid.cells[0].data.shape[0] == res.disc.nelements
    assert read_snapshot(tmp_path).mirrored is False


# ---- femehl plot -----------------------------------------------------------------------
def test_cli_plot_commands(run, tmp_path, capsys):
    res, folder = run
    assert main(["plot", "history", str(folder), "--out", str(tmp_path / "h.png")]) == 0
    assert main(["plot", "maps", str(folder), "--t", "1.2", "--out", str(tmp_path / "m.png")]) == 0
    assert main(["plot", "animation", str(folder), "--out", str(tmp_path / "a.gif"), "--fps", "4"]) == 0
    for name in ("h.png", "m.png", "a.gif"):
        assert (tmp_path / name).stat().st_size > 10_000
    from PIL import Image

    frames = len(list(folder.glob("fields_*.vtu")))
    assert Image.open(tmp_path / "a.gif").n_frames == frames
    # the figure sizes the code sets (inches x dpi): history 7.5 x 9 at 100, maps 11 x 4.8 at 100
    assert Image.open(tmp_path / "h.png").size == (750, 1125)  # five panels (the friction force the fifth)
    assert Image.open(tmp_path / "m.png").size == (1100, 480)
    assert "femehl: wrote" in capsys.readouterr().out


def test_cli_plot_maps_default_name_in_the_folder(run):
    res, folder = run
    assert main(["plot", "maps", str(folder), "--t", "1.2"]) == 0
    assert (folder / "maps_t1.2.png").stat().st_size > 10_000


@pytest.mark.parametrize(
    "argv,words",
    [
        (["plot", "maps", "{f}", "--t", "9"], "no stored fields at t = 9"),
        (["plot", "history", "{f}", "--t", "1"], "--t applies to femehl plot maps and centreline only"),
        (["plot", "animation", "{f}", "--fps", "0"], "fps must be"),
        (["plot", "history", "{missing}"], "is not a folder"),
        (["plot", "maps", "{empty}"], "holds no femehl run"),
    ],
)
def test_cli_plot_bad_input(run, tmp_path, capsys, argv, words):
    _, folder = run
    (tmp_path / "empty").mkdir()
    fill = {"f": str(folder), "missing": str(tmp_path / "nope"), "empty": str(tmp_path / "empty")}
    assert main([a.format(**fill) for a in argv]) == 2
    assert words in capsys.readouterr().err


def test_maps_of_a_run_without_series(tmp_path):
    from femehl.api import run_to_folder

    sc = femehl.presets.paper_sphere()

    run_to_folder(sc, tmp_path / "r", mesh="coarse", t_end=0.1, dt=0.05, store_every=0, log=lambda *a: None)
    with pytest.raises(OutputError, match="store-every"):
        plots.plot_maps(tmp_path / "r")


def test_line_contact_history_and_no_maps(tmp_path):
    """A line-contact run draws its history; maps of a 1-D run are refused, naming why."""
    from femehl.api import run_to_folder
    from femehl.problem.scenefile import load_scene_file

    scene, _ = load_scene_file(pathlib.Path(__file__).parents[1] / "examples" / "cylinder_winkler.toml")
    run_to_folder(scene, tmp_path, t_end=0.2, dt=0.05, n_elements=200, store_every=2, log=lambda *a: None)
    assert (tmp_path / "history.png").stat().st_size > 10_000
    with pytest.raises(OutputError, match="line-contact run has no maps"):
        plots.plot_maps(tmp_path)
    with pytest.raises(OutputError, match="maps and the centreline need a 2-D mesh"):
        plots.plot_centreline(tmp_path)


def test_cli_animate_needs_stored_fields(tmp_path, capsys):
    argv = ["run", "--mesh", "coarse", "--dt", "0.1", "--t-end", "0.2", "--store-every", "0", "--animate"]
    assert main([*argv, "--out", str(tmp_path / "r"), "--quiet"]) == 2
    assert "drop --store-every 0" in capsys.readouterr().err
    assert not (tmp_path / "r").exists()  # refused before anything is written


def test_cli_run_animate(tmp_path):
    argv = ["run", "--mesh", "coarse", "--dt", "0.1", "--t-end", "0.4", "--store-every", "2", "--animate"]
    assert main([*argv, "--out", str(tmp_path), "--quiet"]) == 0
    from PIL import Image

    assert Image.open(tmp_path / "animation.gif").n_frames == 3  # t = 0, 0.2, 0.4


# ---- the centreline and the cavitated interval ------------------------------------------
def test_cavitated_intervals_between_samples():
    x = np.arange(10.0)
    flag = np.array([1, 1, 0, 0, 1, 1, 1, 0, 0, 1], dtype=float)
    assert plots.cavitated_intervals(x, flag) == [(0.0, 1.5), (3.5, 6.5), (8.5, 9.0)]
    assert plots.cavitated_intervals(x, np.zeros(10)) == []
    assert plots.cavitated_intervals(x, np.r_[np.nan, 0.8, np.full(8, np.nan)]) == [(0.5, 1.5)]


def _span(patch):
    """The x extent of an axvspan (a Rectangle in recent matplotlib, a Polygon before)."""
    if hasattr(patch, "get_width"):
        return patch.get_x(), patch.get_x() + patch.get_width()
    x = np.asarray(patch.get_xy())[:, 0]
    return x.min(), x.max()


@pytest.mark.parametrize("condition", ["reynolds", "half-sommerfeld"])
def test_centreline_shades_where_the_film_cavitates(tmp_path, condition):
    """The one-time centreline (``femehl plot centreline``) shades the cavitated interval(s)
    with a legend entry: it covers the flagged nodes on y = 0 and stops before the first
    unflagged one, and the pressure there is 0 (held, or clipped)."""
    import dataclasses

    sc = femehl.presets.paper_sphere()
    sc = dataclasses.replace(sc, fluid=femehl.Fluid(200.0, cavitation=condition))
    res = femehl.solve(sc, t_end=2.5, dt=0.05, mesh="coarse", estimate=False, store_every=25)
    res.save(tmp_path)  # centreline.png of several times, the last one's interval shaded
    assert (tmp_path / "centreline.png").stat().st_size > 10_000
    assert main(["plot", "centreline", str(tmp_path), "--t", "2.5"]) == 0
    assert (tmp_path / "centreline_t2.5.png").stat().st_size > 10_000
    snap = read_snapshot(tmp_path)
    fig = plots.centreline_figure(snap)
    ax_p, ax_d = fig.get_axes()
    label = {"reynolds": "cavitated (p held at 0)", "half-sommerfeld": "cavitated (p < 0 clipped)"}[condition]
    assert label in ax_p.get_legend_handles_labels()[1]
    spans = [_span(p) for p in ax_p.patches]
    assert spans and len(spans) == len(ax_d.patches)
    on_line = np.abs(snap.points[:, 1]) < 1e-12
    xs, flags = snap.points[on_line, 0], snap.cavitated[on_line]
    order = np.argsort(xs)
    xs, flags = xs[order], flags[order]
    for a, b in spans:
        inside = (xs > a) & (xs < b)
        assert inside.any() and np.all(flags[inside] == 1.0)
        assert np.all(np.abs(snap.pressure[on_line][order][inside]) <= 3e-3 * snap.pressure.max())
        left, right = xs[xs < a], xs[xs > b]  # the neighbours outside are not cavitated
        assert left.size == 0 or flags[xs == left.max()][0] == 0.0
        assert right.size == 0 or flags[xs == right.min()][0] == 0.0
    assert any(b < 0 for _, b in spans)  # behind the contact (the exit side)
    matplotlib.pyplot.close(fig)


def test_centreline_of_a_full_sommerfeld_run_shades_nothing(run):
    _, folder = run
    fig = plots.centreline_figure(read_snapshot(folder, 1.2))
    assert not fig.get_axes()[0].patches
    assert not any("cavitated" in lab for lab in fig.get_axes()[0].get_legend_handles_labels()[1])
    assert fig.get_axes()[1].get_yscale() == "log"
    matplotlib.pyplot.close(fig)


def test_line_contact_shades_the_cavitated_interval():
    """line.png of a line-contact run with the Reynolds condition: the held nodes of the
    last state as one interval from the cavitation point to the outlet."""
    from femehl.problem.line import LineScene
    from femehl.problem.scene import Constant, Motion

    sc = LineScene(
        k=1e9,
        beta=10.0,
        motion=Motion(gap=Constant(0.2), velocity=Constant(1.0)),
        L=2.0,
        cavitation="reynolds",
    )
    res = femehl.solve(sc, t_end=2.0, dt=0.05, n_elements=100, estimate=False, linear_solver="lu")
    fig = plots.line_figure(res)
    ax = fig.get_axes()[0]
    assert any(lab.startswith("cavitated (p held at 0)") for lab in ax.get_legend_handles_labels()[1])
    ((a, b),) = [_span(p) for p in ax.patches]
    x = res.disc.x
    held = x[res.disc.expand((res.final.own["p_aux"] < 0).astype(float)) > 0]  # p_aux: free nodes
    assert a <= held.min() and held.max() <= b
    assert b - a == pytest.approx(res.final.info["cavitated_area"], abs=2 * np.diff(x).max())
    matplotlib.pyplot.close(fig)
