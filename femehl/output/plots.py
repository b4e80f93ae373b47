"""Centreline profiles and a quick-look picture of the fields (matplotlib, Agg)."""

from __future__ import annotations

import pathlib

import numpy as np

__all__ = ["centreline_png", "profile_times", "quicklook_png"]


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _save(plt, fig, path, dpi):
    fig.tight_layout()
    path = pathlib.Path(path)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def profile_times(result, wanted=(0.5, 0.8, 1.0, 1.5, 2.0, 5.0)):
    """Times to plot: the paper's figure times that the run reached, plus its end."""
    ts = result.stored_times
    if ts.size == 0:
        return []
    out = [t for t in wanted if ts[0] < t <= ts[-1] + 1e-9]
    if not out or abs(out[-1] - ts[-1]) > 1e-9:
        out.append(float(ts[-1]))
    return out


def centreline_png(results, path, times=None, labels=None, L=None):
    """Pressure and film thickness along y = 0 (x from -L to L) at several times.

    ``results`` is one Result or a list of them (e.g. FE and FD on one plot).
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
    xh = np.linspace(-1, 1, 201)
    ax1.plot(xh, 2 / np.pi**2 * np.sqrt(1 - xh**2), color="k", lw=0.8, alpha=0.5, label="Hertz")
    ax1.set_ylabel("pressure p")
    ax2.set_ylabel("film thickness d")
    ax2.set_xlabel("x (sliding toward +x; exit at x < 0)")
    ax2.set_yscale("log")
    ax1.legend(fontsize=7, ncol=2)
    ax1.set_title("centreline y = 0")
    return _save(plt, fig, path, dpi=110)


def quicklook_png(result, path, t=None):
    """Pressure and film maps at time ``t`` (default: the last stored state)."""
    plt = _plt()
    state = result.state_at(result.stored_times[-1] if t is None else t)
    L = result.scene.domain.L
    n = 201
    xs = np.linspace(-L, L, n)
    ys = np.linspace(-L, L, n)
    X, Y = np.meshgrid(xs, ys)
    pts = np.column_stack([X.ravel(), Y.ravel()])
    inside = np.hypot(pts[:, 0], pts[:, 1]) <= L
    P = np.full(pts.shape[0], np.nan)
    D = np.full(pts.shape[0], np.nan)
    P[inside] = result.disc.pressure_at(state.p, pts[inside])
    D[inside] = result.disc.film_at(state.d, pts[inside])
    fig, axs = plt.subplots(1, 2, figsize=(10, 4.4))
    for ax, F, name, cmap in ((axs[0], P, "pressure p", "viridis"), (axs[1], D, "film d", "magma")):
        F = F.reshape(n, n)
        if name.startswith("film"):
            F = np.where(np.abs(X) ** 2 + np.abs(Y) ** 2 <= 1.6**2, F, np.nan)
        im = ax.pcolormesh(X, Y, F, shading="auto", cmap=cmap)
        fig.colorbar(im, ax=ax, shrink=0.85)
        ax.set_aspect("equal")
        ax.set_title(f"{name} at t = {state.t:g}")
        ax.set_xlabel("x")
    return _save(plt, fig, path, dpi=100)


def line_png(result, path):
    """p(x) and d(x) at a few stored times of a line-contact run."""
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
    sc = result.scene
    fig.suptitle(f"cylinder on Winkler foundation: k = {sc.k:g}, beta = {sc.beta:g}")
    return _save(plt, fig, path, 110)


#: the figures of a run folder, by the dimension of the discretization: (file name, drawer)
FIGURES = {
    1: (("line.png", line_png),),
    2: (("centreline.png", centreline_png), ("fields.png", quicklook_png)),
}


def draw_figures(result, folder):
    """Draw the figures of ``result`` into ``folder``; returns their paths."""
    out = []
    for name, draw in FIGURES[result.disc.dimension]:
        draw(result, pathlib.Path(folder) / name)
        out.append(pathlib.Path(folder) / name)
    return out
