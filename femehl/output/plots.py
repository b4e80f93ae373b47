"""The pictures of a run (matplotlib, Agg): history, contact maps, centreline, animation.

* :func:`history_figure` (``history.png``): load, peak pressure, hc and V, central and
  minimum film (log axis) against t, the phases of the run shaded (indentation: no
  sliding yet; start-up: sliding, not yet steady; steady: every headline quantity within
  :data:`STEADY_TOL` of its final value), the estimated error as a band where the run
  carries one;
* :func:`maps_figure` (``maps.png``): film on a logarithmic colour scale and pressure on a
  scale centred at p = 0 (sub-ambient blue) with the p = 0 contour, over a window of
  :data:`WINDOW` contact radii (the contact: where p > 5 % of its peak), the minimum film
  marked, the cavitated region hatched (a run with a cavitation condition); a half-disk
  run is shown mirrored (the whole contact);
* :func:`centreline_png` (``centreline.png``): p and d along y = 0 at several times, the
  cavitated interval(s) of the last one shaded (a run with a cavitation condition);
* :func:`centreline_figure` (``femehl plot centreline RUN --t T``,
  ``centreline_tT.png``): p and d along y = 0 at one stored time, the cavitated
  interval(s) shaded: the nodes held at p = 0 (Reynolds) or clipped (half-Sommerfeld);
* :func:`animation_file`: the maps and the centreline, one frame per stored time (GIF
  through matplotlib's Pillow writer), on request only (0.16 s a frame on the coarse
  mesh, more on finer ones).

Every ``*_figure`` returns the matplotlib Figure (tests check its axes); ``*_png`` save it.
The pictures of a run folder are drawn from its files (``summary.csv``, ``fields_*.vtu``),
so ``femehl plot`` redraws them for any stored time without the run in memory.
"""

from __future__ import annotations

import logging
import pathlib

import numpy as np

__all__ = [
    "animation_file",
    "cavitated_intervals",
    "centreline_figure",
    "centreline_png",
    "plot_centreline",
    "history_figure",
    "history_png",
    "maps_figure",
    "maps_png",
    "phases",
    "plot_animation",
    "plot_history",
    "plot_maps",
    "profile_times",
    "result_table",
]

#: a quantity is steady when it stays within this fraction of its final value
STEADY_TOL = 0.01
#: ... for at least this fraction of the run's duration
STEADY_SPAN = 0.1
#: the maps show this many contact radii around the origin
WINDOW = 2.5
#: the film map's colour scale spans from the thinnest film to this many times it
FILM_DECADES = 10.0

logger = logging.getLogger("femehl")


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _save(plt, fig, path, dpi):
    """Save ``fig`` to ``path`` (atomically: a failed write leaves the file there untouched);
    a fault (unwritable folder, full disk) is an :class:`~femehl.errors.OutputError`."""
    from femehl.output._files import write_atomic

    path = pathlib.Path(path)
    try:
        fig.tight_layout()
        fmt = path.suffix[1:].lower() or None
        return write_atomic(path, lambda tmp: fig.savefig(tmp, dpi=dpi, format=fmt), "write the picture")
    finally:
        plt.close(fig)


def figure_suffixes() -> frozenset:
    """The file suffixes matplotlib can write a figure to (``.png``, ``.pdf``, ``.svg``, ...)."""
    from matplotlib.backend_bases import FigureCanvasBase

    return frozenset("." + k for k in FigureCanvasBase.get_supported_filetypes())


def _out(out, folder, name):
    """The file ``--out`` names for the picture ``name`` (see :func:`femehl.output._files.out_path`)."""
    from femehl.output._files import out_path

    suffixes = {".gif"} if name.endswith(".gif") else figure_suffixes()
    return out_path(out, folder, name, suffixes)


def profile_times(result, wanted=(0.5, 0.8, 1.0, 1.5, 2.0, 5.0)):
    """Times to plot: the paper's figure times that the run reached, plus its end."""
    ts = result.stored_times
    if ts.size == 0:
        return []
    out = [t for t in wanted if ts[0] < t <= ts[-1] + 1e-9]
    if not out or abs(out[-1] - ts[-1]) > 1e-9:
        out.append(float(ts[-1]))
    return out


#: shading of the cavitated interval(s) on the centreline
_CAV_SHADE = {"color": "0.8", "alpha": 0.6, "lw": 0, "zorder": 0}


def _cavitation_label(clipped: bool) -> str:
    return "cavitated (p < 0 clipped)" if clipped else "cavitated (p held at 0)"


def cavitation_label(snap) -> str:
    """The legend entry of the cavitated region of a Snapshot."""
    return _cavitation_label(snap.clipped)


def cavitated_intervals(x, flag) -> list[tuple[float, float]]:
    """The intervals ``(a, b)`` of sorted samples ``x`` where ``flag > 0.5`` (NaN: outside),
    their ends halfway between the last sample in and the first out."""
    x = np.asarray(x, dtype=float)
    on = np.nan_to_num(np.asarray(flag, dtype=float), nan=0.0) > 0.5
    if not on.any():
        return []
    edges = np.flatnonzero(np.diff(on.astype(np.int8)))
    starts = [0, *(edges[~on[edges]] + 1)] if on[0] else list(edges[~on[edges]] + 1)
    ends = [*(edges[on[edges]]), x.size - 1] if on[-1] else list(edges[on[edges]])
    mid = 0.5 * (x[:-1] + x[1:])
    return [
        (float(x[0] if a == 0 else mid[a - 1]), float(x[-1] if b == x.size - 1 else mid[b]))
        for a, b in zip(starts, ends, strict=True)
    ]


def _shade_cavitated(axes, snap, x, cav):
    """Shade the intervals of ``cav`` (centreline samples of ``snap.cavitated``) on ``axes``;
    the first axis gets the legend entry.  Returns the intervals."""
    spans = cavitated_intervals(x, cav)
    for k, (a, b) in enumerate(spans):
        for j, ax in enumerate(axes):
            ax.axvspan(a, b, label=cavitation_label(snap) if k == 0 and j == 0 else None, **_CAV_SHADE)
    return spans


def centreline_png(results, path, times=None, labels=None, L=None):
    """Pressure and film thickness along y = 0 (x from -L to L) at several times.

    ``results`` is one Result or a list of them (e.g. FE and FD on one plot).  With a
    cavitation condition the cavitated interval(s) of the first result at the last time
    are shaded.
    """
    plt = _plt()
    if not isinstance(results, (list, tuple)):
        results = [results]
    labels = labels or [r.method.upper() for r in results]
    L = L or results[0].scene.domain.L
    times = times or profile_times(results[0])
    x = np.linspace(-L, L, 801)
    pts = np.column_stack([x, np.zeros_like(x)])
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.5, 7), sharex=True)
    styles = ["-", "--", ":", "-."]
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, (res, lab) in enumerate(zip(results, labels, strict=True)):
        for i, t in enumerate(times):
            kw = {"color": colors[i % len(colors)], "ls": styles[k % len(styles)]}
            ax1.plot(x, res.pressure_at(pts, t), label=f"{lab} t={t:g}", **kw)
            ax2.plot(x, res.film_at(pts, t), **kw)
    first = results[0]
    if getattr(first.scene, "cavitation", None) is not None and first.states:
        from femehl.output.snapshot import snapshot

        snap = snapshot(first.disc, first.state_at(times[-1]))
        if snap.cavitated is not None:
            xs, _, _, cav = _centreline(snap)
            spans = cavitated_intervals(xs, cav)
            for k, (a, b) in enumerate(spans):
                for ax in (ax1, ax2):
                    lab = f"{cavitation_label(snap)}, t={snap.t:g}" if k == 0 and ax is ax1 else None
                    ax.axvspan(a, b, label=lab, **_CAV_SHADE)
    xh = np.linspace(-1, 1, 201)
    ax1.plot(xh, 2 / np.pi**2 * np.sqrt(1 - xh**2), color="k", lw=0.8, alpha=0.5, label="Hertz")
    ax1.set_ylabel("pressure p")
    ax2.set_ylabel("film thickness d")
    ax2.set_xlabel("x (sliding toward +x; exit at x < 0)")
    ax2.set_yscale("log")
    ax1.legend(fontsize=7, ncol=2)
    ax1.set_title("centreline y = 0")
    return _save(plt, fig, path, dpi=110)


def result_table(result) -> dict:
    """The summary columns of a Result (as in ``summary.csv``), with its error estimate.

    The ``err_<name>`` columns (relative, :data:`~femehl.output.table.ERROR_COLUMNS`) are
    the estimate interpolated to the steps; absent when the result carries none.
    """
    table = {k: np.asarray(v, dtype=float) for k, v in result.summary().items()}
    est = getattr(result, "estimate", None)
    if est is not None:
        ts = np.asarray(est["t"], dtype=float)
        for q in ("load", "film_center", "film_min"):
            if q in est and est[q].get("total") is not None:
                table[f"err_{q}"] = np.interp(table["t"], ts, est[q]["total"], left=np.nan, right=np.nan)
    return table


def _plateau(t, q, tol):
    """Earliest time from which ``q`` stays within ``tol`` (absolute) of its final value, or None."""
    q = np.asarray(q, dtype=float)
    off = np.flatnonzero(~(np.abs(q - q[-1]) <= tol))
    if off.size == 0:
        return float(t[0])
    return float(t[off[-1] + 1]) if off[-1] + 1 < t.size else None


def phases(table: dict) -> list[tuple[str, float, float]]:
    """The phases of a run from its summary columns: ``[(name, t_start, t_end)]``.

    *indentation*: before the indenter slides (V = 0), if hc or the load changes there;
    *start-up*: sliding (or, without sliding, approaching) until steady; *steady*: from
    the first time after which V, hc, the load and the central and minimum film all stay
    within :data:`STEADY_TOL` of their final values (hc relative to the central film),
    if that lasts at least :data:`STEADY_SPAN` of the run.
    """
    t = np.asarray(table["t"], dtype=float)
    if t.size < 2:
        return []
    V, hc = np.asarray(table["V"], dtype=float), np.asarray(table["hc"], dtype=float)
    film = np.asarray(table["film_center"], dtype=float)
    sliding = np.abs(V) > 1e-12 * max(1.0, float(np.max(np.abs(V))))
    t_slide = float(t[np.argmax(sliding)]) if sliding.any() else None
    rel = [(table[q], STEADY_TOL * abs(float(table[q][-1]))) for q in ("load", "film_center", "film_min")]
    # hc on the film's scale: the indenter is still if it moves less than 1 % of the film
    checks = [*rel, (hc, STEADY_TOL * abs(film[-1]))] + ([(V, 1e-9 * abs(V[-1]))] if sliding.any() else [])
    starts = [_plateau(t, q, tol) for q, tol in checks]
    t_steady = None if any(s is None for s in starts) else max(starts)
    if t_steady is not None and t[-1] - t_steady < STEADY_SPAN * (t[-1] - t[0]):
        t_steady = None  # a few last steps within 1 %: drifting slowly, not steady
    end = float(t[-1])
    out = []
    before = t <= (t_slide if t_slide is not None else end)
    load = np.asarray(table["load"], dtype=float)
    moving = np.ptp(hc[before]) > STEADY_TOL * abs(film[-1]) or np.ptp(load[before]) > STEADY_TOL * max(
        float(np.max(np.abs(load))), 1e-300
    )
    if (t_slide is None or t_slide > t[0]) and moving:
        first = t_slide if t_slide is not None else (t_steady if t_steady is not None else end)
        out.append(("indentation", float(t[0]), first))
    if t_slide is not None:
        out.append(("start-up", t_slide, t_steady if t_steady is not None else end))
    if t_steady is not None:
        out.append(("steady", t_steady, end))
    return [ph for ph in out if ph[2] > ph[1]]


_PHASE_COLOURS = {"indentation": "#dde6f5", "start-up": "#f7e6cf", "steady": "#ddf0dd"}


def history_figure(table: dict, title: str = ""):
    """Load, peak pressure, hc and V, central and minimum film, and the friction force with
    its parts where the table has them, against t (a Figure).

    ``table``: summary columns (:func:`result_table`, or
    :func:`~femehl.output.table.read_summary` of a run folder's ``summary.csv``).
    """
    plt = _plt()
    t = np.asarray(table["t"], dtype=float)
    friction = "friction" in table and np.any(np.isfinite(np.asarray(table["friction"], dtype=float)))
    rows = 5 if friction else 4
    fig, axs = plt.subplots(rows, 1, figsize=(7.5, 2.25 * rows), sharex=True)
    ax_load, ax_p, ax_hc, ax_film = axs[:4]

    def band(ax, name, color, label):
        v = np.asarray(table[name], dtype=float)
        ax.plot(t, v, color=color, label=label)
        e = table.get(f"err_{name}")
        if e is not None and np.any(np.isfinite(e)):
            e = np.where(np.isfinite(e), np.abs(e), np.nan)
            ax.fill_between(
                t,
                v * (1 - e),
                v * (1 + e),
                color=color,
                alpha=0.25,
                lw=0,
                label=f"{label} +- estimated error",
            )

    band(ax_load, "load", "C0", "load")
    ax_load.set_ylabel("load F")
    ax_p.plot(t, table["p_max"], color="C3")
    ax_p.set_ylabel("peak pressure")
    ax_hc.plot(t, table["hc"], color="C2", label="hc (indenter height)")
    ax_hc.set_ylabel("hc")
    ax_v = ax_hc.twinx()
    ax_v.plot(t, table["V"], color="C4", ls="--", label="V (the surfaces' speeds, summed)")
    ax_v.set_ylabel("V")
    lines = ax_hc.get_lines() + ax_v.get_lines()
    ax_hc.legend(lines, [ln.get_label() for ln in lines], fontsize=7, loc="best")
    band(ax_film, "film_center", "C0", "central film")
    band(ax_film, "film_min", "C1", "minimum film")
    if np.all(np.asarray(table["film_min"]) > 0):
        ax_film.set_yscale("log")
    ax_film.set_ylabel("film thickness")
    ax_film.legend(fontsize=7, loc="best")
    if friction:
        ax_f = axs[4]
        ax_f.plot(t, table["friction"], color="k", label="friction")
        for name, label, style in (
            ("shear_couette", "Couette shear", "--"),
            ("shear_poiseuille", "Poiseuille shear", ":"),
            ("pressure_drag", "pressure on the indenter", "-."),
        ):
            if name in table:
                ax_f.plot(t, table[name], ls=style, lw=1.0, label=label)
        ax_f.set_ylabel("friction force")
        ax_f.legend(fontsize=7, loc="best")
    axs[-1].set_xlabel("t")
    for name, a, b in phases(table):
        for ax in axs:
            ax.axvspan(a, b, color=_PHASE_COLOURS[name], zorder=0, lw=0)
        ax_load.text(
            0.5 * (a + b), 1.02, name, transform=ax_load.get_xaxis_transform(), ha="center", fontsize=8
        )
    ax_load.legend(fontsize=7, loc="lower right")
    for ax in axs:
        ax.grid(alpha=0.3)
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def history_png(table: dict, path, title: str = ""):
    """:func:`history_figure` saved to ``path``."""
    return _save(_plt(), history_figure(table, title), path, dpi=100)


def contact_radius(snap) -> float | None:
    """Largest distance from the origin where the pressure exceeds 5 % of its peak."""
    p = snap.pressure
    top = float(np.max(p)) if p.size else 0.0
    if not np.isfinite(top) or top <= 0.0:
        return None
    r = np.hypot(snap.points[:, 0], snap.points[:, 1])
    return float(np.max(r[p > 0.05 * top]))


def _window(snap) -> float:
    a = contact_radius(snap)
    return snap.L if a is None else float(min(snap.L, max(WINDOW * a, 4.0 * _mesh_size(snap))))


def _mesh_size(snap) -> float:
    e = snap.points[snap.triangles[:, 1]] - snap.points[snap.triangles[:, 0]]
    return float(np.median(np.hypot(e[:, 0], e[:, 1])))


def maps_figure(snap, title: str = ""):
    """Film (log scale) and pressure (centred at 0, with the p = 0 contour) maps of a Snapshot."""
    import matplotlib.colors as mcolors
    import matplotlib.tri as mtri

    plt = _plt()
    tri = mtri.Triangulation(snap.points[:, 0], snap.points[:, 1], snap.triangles)
    W = _window(snap)
    fig, (ax_d, ax_p) = plt.subplots(1, 2, figsize=(11, 4.8))
    # film: logarithmic, limited to the values inside the window
    cen = snap.points[snap.triangles].mean(axis=1)
    inside = np.max(np.abs(cen), axis=1) <= W
    d = snap.film
    d_in = d[inside] if not snap.film_on_points else d[np.max(np.abs(snap.points), axis=1) <= W]
    pos = d_in[d_in > 0]
    if pos.size and np.all(np.isfinite(pos)):  # a decade above the thinnest film: the contact's detail
        vmin = float(pos.min())
        norm = mcolors.LogNorm(vmin=vmin, vmax=float(min(max(pos.max(), vmin * 1.0001), FILM_DECADES * vmin)))
    else:
        norm = None
    if snap.film_on_points:
        im = ax_d.tripcolor(
            tri, np.maximum(d, pos.min() if pos.size else 1e-300), shading="gouraud", cmap="magma", norm=norm
        )
    else:
        im = ax_d.tripcolor(
            tri, facecolors=np.maximum(d, pos.min() if pos.size else 1e-300), cmap="magma", norm=norm
        )
    fig.colorbar(im, ax=ax_d, shrink=0.85, extend="max", label="film thickness d (log scale)")
    # pressure: diverging around p = 0, so the sub-ambient region shows
    p = snap.pressure
    top = float(np.nanmax(np.abs(p))) or 1.0
    lo = float(np.nanmin(p))
    pnorm = mcolors.TwoSlopeNorm(
        vcenter=0.0, vmin=min(lo, -1e-6 * top), vmax=max(float(np.nanmax(p)), 1e-6 * top)
    )
    im = ax_p.tripcolor(tri, p, shading="gouraud", cmap="RdBu_r", norm=pnorm)
    fig.colorbar(im, ax=ax_p, shrink=0.85, label="pressure p (blue: below ambient)")
    a = contact_radius(snap)
    if lo < 0.0 < float(np.nanmax(p)) and a is not None and snap.cavitated is None:
        # p = 0 where it bounds the loaded region (within 1.25 contact radii: farther out p is ~0
        # everywhere and its sign is noise); with cavitation p >= 0 and the hatch shows p = 0
        near = mtri.Triangulation(snap.points[:, 0], snap.points[:, 1], snap.triangles)
        near.set_mask(np.hypot(cen[:, 0], cen[:, 1]) > 1.25 * a)
        ax_p.tricontour(near, p, levels=[0.0], colors="k", linewidths=0.8)
        ax_p.plot([], [], color="k", lw=0.8, label="p = 0")
    if snap.cavitated is not None and np.any(snap.cavitated > 0.5):
        # a cavitation condition: hatch where the pressure is held at 0
        ax_p.tricontourf(tri, snap.cavitated, levels=[0.5, 1.5], colors="none", hatches=["////"])
        import matplotlib.patches as mpatches

        label = "cavitated (p < 0 clipped)" if snap.clipped else "cavitated (p = 0)"
        ax_p.add_patch(mpatches.Rectangle((0, 0), 0, 0, fill=False, hatch="////", label=label))
    x0, y0 = snap.film_min_at
    xs, ys = ([x0, x0], [y0, -y0]) if snap.mirrored and abs(y0) > 0 else ([x0], [y0])
    for ax in (ax_d, ax_p):
        ax.plot(
            xs, ys, marker="x", color="c", ms=9, mew=2, ls="none", label=f"minimum film {snap.film_min:.4g}"
        )
        ax.set_xlim(-W, W)
        ax.set_ylim(-W, W)
        ax.set_aspect("equal")
        ax.set_xlabel("x (sliding toward +x)")
        ax.set_ylabel("y")
        ax.legend(fontsize=7, loc="upper right")
    mirrored = " (half disk, mirrored)" if snap.mirrored else ""
    ax_d.set_title(f"film d at t = {snap.t:g}{mirrored}", fontsize=10)
    ax_p.set_title(f"pressure p at t = {snap.t:g}", fontsize=10)
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def maps_png(snap, path, title: str = ""):
    """:func:`maps_figure` saved to ``path``."""
    return _save(_plt(), maps_figure(snap, title), path, dpi=100)


def _centreline(snap, n=401):
    """x, p(x, 0), d(x, 0) and the cavitated flag (linear; None without a cavitation
    condition) of a Snapshot (linear interpolation; film per triangle)."""
    import matplotlib.tri as mtri

    tri = mtri.Triangulation(snap.points[:, 0], snap.points[:, 1], snap.triangles)
    x = np.linspace(-snap.L, snap.L, n) * (1 - 1e-9)
    y = np.full_like(x, 1e-12 * snap.L)
    p = mtri.LinearTriInterpolator(tri, snap.pressure)(x, y).filled(np.nan)
    if snap.film_on_points:
        d = mtri.LinearTriInterpolator(tri, snap.film)(x, y).filled(np.nan)
    else:
        k = tri.get_trifinder()(x, y)
        d = np.where(k >= 0, snap.film[np.maximum(k, 0)], np.nan)
    cav = None
    if snap.cavitated is not None:
        cav = mtri.LinearTriInterpolator(tri, snap.cavitated)(x, y).filled(np.nan)
    return x, p, d, cav


def centreline_figure(snap, title: str = ""):
    """Pressure and film along y = 0 at the Snapshot's time (a Figure), the cavitated
    interval(s) shaded with a legend entry (a run with a cavitation condition)."""
    plt = _plt()
    x, p, d, cav = _centreline(snap)
    fig, (ax_p, ax_d) = plt.subplots(2, 1, figsize=(7.5, 6.5), sharex=True)
    if cav is not None:
        _shade_cavitated((ax_p, ax_d), snap, x, cav)
    ax_p.plot(x, p, color="C0", label="pressure p")
    ax_p.axhline(0.0, color="k", lw=0.6)
    ax_d.plot(x, d, color="C1", label="film d")
    if np.all(d[np.isfinite(d)] > 0):
        ax_d.set_yscale("log")
    ax_p.set_ylabel("pressure p")
    ax_d.set_ylabel("film thickness d")
    ax_d.set_xlabel("x (sliding toward +x; exit at x < 0)")
    ax_p.set_title(f"centreline y = 0 at t = {snap.t:g}", fontsize=10)
    for ax in (ax_p, ax_d):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right")
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def centreline_name(t: float) -> str:
    """The file name of the one-time centreline at a stored time."""
    return f"centreline_t{t:g}.png"


def plot_centreline(folder, t=None, out=None):
    """``centreline_tT.png`` of a run folder: p and d along y = 0 at the stored time
    nearest ``t`` (default: the last), the cavitated interval(s) shaded."""
    from femehl.output.snapshot import read_snapshot

    _out(out, folder, "centreline.png")  # a bad --out is refused before anything is read
    snap = read_snapshot(folder, t, what="centreline")
    path = _out(out, folder, centreline_name(snap.t))
    return _save(_plt(), centreline_figure(snap, title=_title_of(folder)), path, dpi=100)


def animation_file(snaps, path, fps: int = 8, title: str = ""):
    """The film and pressure maps and the centreline, one frame per Snapshot (GIF).

    ``snaps``: a list of Snapshots, or a callable ``k -> Snapshot`` with ``len`` given as
    ``(callable, count)`` to read frames lazily.  Written through matplotlib's Pillow writer
    to ``path`` (``.gif``).
    """
    import matplotlib.animation as manim
    import matplotlib.colors as mcolors
    import matplotlib.tri as mtri

    plt = _plt()
    from femehl.errors import OutputError

    get, count = snaps if isinstance(snaps, tuple) else ((lambda k: snaps[k]), len(snaps))
    if count < 1:
        raise OutputError("an animation needs at least one stored time: the run stored no fields.")
    last = get(count - 1)
    W = _window(last)
    tri = mtri.Triangulation(last.points[:, 0], last.points[:, 1], last.triangles)
    fig, (ax_d, ax_p, ax_c) = plt.subplots(1, 3, figsize=(14, 4.4))
    pos = last.film[last.film > 0]
    dnorm = mcolors.LogNorm(vmin=float(pos.min()), vmax=FILM_DECADES * float(pos.min())) if pos.size else None
    top = float(np.nanmax(np.abs(last.pressure))) or 1.0
    pnorm = mcolors.TwoSlopeNorm(vcenter=0.0, vmin=-0.5 * top, vmax=1.2 * top)
    writer = manim.PillowWriter(fps=int(fps))
    path = pathlib.Path(path)
    from femehl.output._files import write_atomic

    def frames(tmp):
        _animate(writer, fig, tmp, get, count, last, (ax_d, ax_p, ax_c), tri, dnorm, pnorm, W, top, title)

    try:
        return write_atomic(path, frames, "write the animation")
    finally:
        plt.close(fig)


def _animate(writer, fig, path, get, count, last, axes, tri, dnorm, pnorm, W, top, title):
    """The frames of :func:`animation_file`, grabbed into ``writer`` saving to ``path``."""
    ax_d, ax_p, ax_c = axes
    with writer.saving(fig, str(path), dpi=80):
        for k in range(count):
            s = get(k) if k < count - 1 else last
            for ax in (ax_d, ax_p, ax_c):
                ax.clear()
            kw = {"shading": "gouraud"} if s.film_on_points else {}
            if s.film_on_points:
                ax_d.tripcolor(tri, np.maximum(s.film, 1e-300), cmap="magma", norm=dnorm, **kw)
            else:
                ax_d.tripcolor(tri, facecolors=np.maximum(s.film, 1e-300), cmap="magma", norm=dnorm)
            ax_p.tripcolor(tri, s.pressure, shading="gouraud", cmap="RdBu_r", norm=pnorm)
            for ax, name in ((ax_d, "film d (log)"), (ax_p, "pressure p")):
                ax.set_xlim(-W, W)
                ax.set_ylim(-W, W)
                ax.set_aspect("equal")
                ax.set_title(f"{name}, t = {s.t:.3g}", fontsize=9)
            x, p, d, _ = _centreline(s)
            ax_c.plot(x, p, color="C0", label="p")
            ax_c.plot(x, d, color="C1", label="d")
            ax_c.set_xlim(-W, W)
            ax_c.set_ylim(min(-0.4 * top, 1.1 * float(np.nanmin(p))), 1.2 * top)
            ax_c.set_title("centreline y = 0", fontsize=9)
            ax_c.legend(fontsize=7, loc="upper right")
            if title:
                fig.suptitle(title, fontsize=10)
            writer.grab_frame()


def line_png(result, path):
    """p(x) and d(x) at a few stored times of a line-contact run (:func:`line_figure`)."""
    return _save(_plt(), line_figure(result), path, 110)


def line_figure(result):
    """p(x) and d(x) at a few stored times of a line-contact run, the cavitated interval(s)
    of the last one shaded (a run with a cavitation condition)."""
    from femehl.output.series import cavitated_nodes

    plt = _plt()
    states = list(result.states[:: max(1, len(result.states) // 6)])
    if states[-1] is not result.final:
        states.append(result.final)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 7), sharex=True)
    for s in states:
        last = s is result.final
        kw = {"lw": 2 if last else 0.8, "alpha": 1.0 if last else 0.6, "label": f"t = {s.t:.3g}"}
        ax1.plot(result.disc.x, s.p, **kw)
        ax2.plot(result.disc.xc, s.d, **kw)
    ax1.set_ylabel("p")
    ax2.set_ylabel("d")
    ax2.set_xlabel("x  (cylinder slides toward +x)")
    ax1.legend(fontsize=7, ncol=2)
    cav = cavitated_nodes(result.disc, result.final)
    if cav is not None:
        spans = cavitated_intervals(result.disc.x, cav)
        from femehl.problem.cavitation import clips_pressure

        label = _cavitation_label(clips_pressure(result.scene))
        for k, (a, b) in enumerate(spans):
            for ax in (ax1, ax2):
                lab = f"{label}, t = {result.final.t:.3g}" if k == 0 and ax is ax1 else None
                ax.axvspan(a, b, label=lab, **_CAV_SHADE)
    ax1.legend(fontsize=7, ncol=2)
    sc = result.scene
    fig.suptitle(f"{type(sc.indenter).__name__} on {sc.substrate!r}, beta = {sc.fluid.beta:g}", fontsize=9)
    return fig


def _history(result, path):
    """A run folder's history from its summary.csv (the whole run, also when resumed), else
    from the Result."""
    from femehl.output.table import read_summary

    csv = pathlib.Path(path).parent / "summary.csv"
    table = read_summary(csv) if csv.is_file() else result_table(result)
    return history_png(table, path, title=_title(result))


def _maps(result, path):
    from femehl.output.snapshot import snapshot

    return maps_png(snapshot(result.disc, result.final), path, title=_title(result))


def _title(result) -> str:
    info = getattr(result, "info", {}) or {}
    bits = [getattr(result, "method", "") or "", info.get("mesh", "")]
    if info.get("elements"):
        bits.append(f"{info['elements']} elements")
    return ", ".join(str(b) for b in bits if b)


#: the figures of a run folder, by the dimension of the discretization: (file name, drawer)
FIGURES = {
    1: (("line.png", line_png), ("history.png", _history)),
    2: (("centreline.png", centreline_png), ("maps.png", _maps), ("history.png", _history)),
}


def draw_figures(result, folder, skip=()):
    """Draw the figures of ``result`` into ``folder`` (those named in ``skip`` left out);
    returns their paths."""
    out = []
    for name, draw in FIGURES[result.disc.dimension]:
        if name in skip:
            continue
        draw(result, pathlib.Path(folder) / name)
        out.append(pathlib.Path(folder) / name)
    return out


# ---- pictures of a run folder (``femehl plot``) -------------------------------------------
def _title_of(folder) -> str:
    return f"run folder {pathlib.Path(folder).resolve().name}"


def plot_history(folder, out=None):
    """``history.png`` of a run folder from its ``summary.csv`` (``out``: another file)."""
    from femehl.errors import OutputError
    from femehl.output.snapshot import check_run_folder
    from femehl.output.table import read_summary

    folder = check_run_folder(folder)
    path = _out(out, folder, "history.png")
    table = read_summary(folder / "summary.csv")
    missing = [c for c in ("load", "p_max", "hc", "V", "film_center", "film_min") if c not in table]
    if missing:
        raise OutputError(
            f"{folder}/summary.csv has no column(s) {', '.join(missing)}: it is damaged or not "
            "femehl's; rerun the case (femehl run --overwrite) to write it again."
        )
    if table["t"].size < 2:
        raise OutputError(f"{folder}/summary.csv has fewer than two steps: nothing to plot yet.")
    return history_png(table, path, title=_title_of(folder))


def maps_name(t: float | None) -> str:
    """The file name of the maps at a stored time (``maps.png`` for the last)."""
    return "maps.png" if t is None else f"maps_t{t:g}.png"


def plot_maps(folder, t=None, out=None):
    """The contact maps of a run folder at the stored time nearest ``t`` (default: the last)."""
    from femehl.output.snapshot import read_snapshot

    _out(out, folder, "maps.png")  # a bad --out is refused before anything is read
    snap = read_snapshot(folder, t, what="maps")
    path = _out(out, folder, maps_name(None if t is None else snap.t))
    return maps_png(snap, path, title=_title_of(folder))


def plot_animation(folder, out=None, fps: int = 8):
    """``animation.gif`` of a run folder: one frame per stored field file."""
    from femehl.errors import OutputError
    from femehl.output.snapshot import damaged_files, read_snapshot, stored_times

    if isinstance(fps, bool) or not isinstance(fps, int) or not 1 <= fps <= 60:
        raise OutputError(f"fps must be an integer from 1 to 60, got {fps!r}.")
    from femehl.output.table import read_summary

    path = _out(out, folder, "animation.gif")
    read_snapshot(folder, report=False)  # a run folder with a readable series (else OutputError)
    damaged = damaged_files(folder)
    if damaged:
        logger.warning(
            "femehl: %s damaged (incomplete) and left out of the animation; it shows the %d readable times",
            ", ".join(damaged),
            len(stored_times(folder)),
        )
    times = [t for t, _ in stored_times(folder)]
    table = read_summary(pathlib.Path(folder) / "summary.csv")
    frames = (lambda k: read_snapshot(folder, times[k], summary=table, report=False), len(times))
    return animation_file(frames, path, fps=fps, title=_title_of(folder))


#: ``femehl plot WHAT FOLDER``: the drawers of a run folder's pictures
FOLDER_PLOTS = {
    "history": plot_history,
    "maps": plot_maps,
    "centreline": plot_centreline,
    "animation": plot_animation,
}
#: the pictures of one stored time (``femehl plot ... --t``)
TIMED_PLOTS = ("maps", "centreline")
