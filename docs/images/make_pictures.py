"""Redraw the README's pictures: ``python docs/images/make_pictures.py``.

The README's main job, ``femehl run`` (the paper case, beta = 200, h0 = 0.1, to t = 5,
automatically to 1 %: a few minutes), into a temporary run folder; its ``history.png``
(with the estimated error as a band) and ``maps.png`` are copied here as
``paper_history.png`` and ``paper_maps.png``; the maps of the same case with the
mass-conserving JFO cavitation (medium mesh, BDF2, dt = 0.01) as
``paper_maps_cavitation.png``, and its centreline beside the full-Sommerfeld one (pressure,
film, film content) as ``paper_centreline_jfo.png``; and the time to draw each again from
the folder (``femehl plot``) is printed.  ``--cavitation`` redraws the cavitation pictures
only.
"""

from __future__ import annotations

import shutil
import tempfile
import time
from pathlib import Path

import femehl
from femehl.api import run_to_folder
from femehl.output import plots

HERE = Path(__file__).resolve().parent


def main(cavitation_only=False):
    with tempfile.TemporaryDirectory() as tmp:
        if not cavitation_only:
            folder = Path(tmp) / "paper_sphere"
            run_to_folder(femehl.presets.paper_sphere(), folder, t_end=5.0, log=print)
            for name in ("history", "maps"):
                t0 = time.perf_counter()
                path = plots.FOLDER_PLOTS[name](folder)
                print(f"{name}: {time.perf_counter() - t0:.2f} s")
                shutil.copyfile(path, HERE / f"paper_{name}.png")
        cavitation_pictures(Path(tmp))


def cavitation_pictures(tmp):
    """The paper case with JFO cavitation beside full Sommerfeld (medium, BDF2, dt = 0.01)."""
    import dataclasses

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    sc = femehl.presets.paper_sphere()
    runs = {}
    for label, cav in (("full Sommerfeld", None), ("JFO (mass-conserving)", "jfo")):
        s = dataclasses.replace(sc, fluid=femehl.Fluid(sc.fluid.beta, cavitation=cav))
        runs[label] = femehl.solve(
            s, t_end=5.0, dt=0.01, mesh="medium", scheme="bdf2", estimate=False, store_every=100
        )
    jfo = runs["JFO (mass-conserving)"]
    jfo.save(tmp / "paper_case_JFO")
    path = plots.FOLDER_PLOTS["maps"](tmp / "paper_case_JFO")
    shutil.copyfile(path, HERE / "paper_maps_cavitation.png")
    x = np.linspace(-2.0, 2.0, 801)
    pts = np.column_stack([x, np.zeros_like(x)])
    fig, (ax_p, ax_d, ax_t) = plt.subplots(1, 3, figsize=(13, 3.8))
    for (label, res), style in zip(runs.items(), ("-", "--"), strict=True):
        st = res.final
        ax_p.plot(x, res.pressure_at(pts, st.t), style, label=label)
        ax_d.plot(x, res.film_at(pts, st.t), style, label=label)
    st, disc = jfo.final, jfo.disc
    free = disc.free_index
    theta = np.ones(disc.nodes.shape[0])  # the nodes' filling 1 - v/dbar, on y = 0
    dbar = (disc.squeeze() @ st.d) / disc.node_weight[free]
    theta[free] = 1.0 - st.own["gas"] / dbar
    on = np.zeros(theta.size, dtype=bool)
    on[free] = np.abs(disc.nodes[free, 1]) < 1e-12
    order = np.argsort(disc.nodes[on, 0])
    ax_t.plot(disc.nodes[on, 0][order], theta[on][order], ".-", color="C1", ms=3)
    ax_p.axhline(0.0, color="0.6", lw=0.6)
    ax_p.set(xlabel="x (y = 0)", ylabel="pressure p", title="pressure at t = 5")
    ax_d.set(xlabel="x (y = 0)", ylabel="film d", yscale="log", ylim=(0.02, 3.0), title="film at t = 5")
    ax_t.set(xlabel="x (y = 0)", ylabel="film content theta", ylim=(0.0, 1.05), title="JFO film content")
    ax_p.legend(fontsize=8)
    fig.suptitle("paper case (beta = 200, medium mesh): sliding toward +x, the film ruptures at the exit")
    fig.tight_layout()
    fig.savefig(HERE / "paper_centreline_jfo.png", dpi=90)
    plt.close(fig)


if __name__ == "__main__":
    import sys

    main(cavitation_only="--cavitation" in sys.argv[1:])
