"""Redraw the README's pictures: ``python docs/images/make_pictures.py``.

The README's main job, ``femehl run`` (the paper case, beta = 200, h0 = 0.1, to t = 5,
automatically to 1 %: a few minutes), into a temporary run folder; its ``history.png``
(with the estimated error as a band) and ``maps.png`` are copied here as
``paper_history.png`` and ``paper_maps.png``, and the time to draw each again from the
folder (``femehl plot``) is printed.
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


if __name__ == "__main__":
    main()
