"""Redraw the README's pictures: ``python docs/images/make_pictures.py``.

The README's main job, ``femehl run`` (the paper case, beta = 200, h0 = 0.1, to t = 5,
automatically to 1 %: a few minutes), into a temporary run folder; its ``history.png``
(with the estimated error as a band) and ``maps.png`` are copied here as
``paper_history.png`` and ``paper_maps.png``; the maps of the same case with the Reynolds
cavitation condition (medium mesh, BDF2, dt = 0.01) as ``paper_maps_cavitation.png``;
and the time to draw each again from the folder (``femehl plot``) is printed.
"""

from __future__ import annotations

import shutil
import tempfile
import time
from pathlib import Path

import femehl
from femehl.output import plots
from femehl.run import run_to_folder

HERE = Path(__file__).resolve().parent


def main():
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "paper_sphere"
        run_to_folder(femehl.presets.paper_sphere(), folder, t_end=5.0, log=print)
        for name in ("history", "maps"):
            t0 = time.perf_counter()
            path = plots.FOLDER_PLOTS[name](folder)
            print(f"{name}: {time.perf_counter() - t0:.2f} s")
            shutil.copyfile(path, HERE / f"paper_{name}.png")
        # the same case with the Reynolds cavitation condition (medium mesh, BDF2, dt = 0.01)
        import dataclasses

        sc = femehl.presets.paper_sphere()
        cav = dataclasses.replace(sc, fluid=femehl.Fluid(sc.fluid.beta, cavitation="reynolds"))
        res = femehl.solve(
            cav, t_end=5.0, dt=0.01, mesh="medium", scheme="bdf2", estimate=False, store_every=100
        )
        res.save(Path(tmp) / "cavitation")
        path = plots.FOLDER_PLOTS["maps"](Path(tmp) / "cavitation")
        shutil.copyfile(path, HERE / "paper_maps_cavitation.png")


if __name__ == "__main__":
    main()
