"""Regenerate the mesh ladder: meshes/half_<name>.msh and meshes/full_<name>.msh.

Usage (from anywhere)::

    python meshes/make_ladder.py

For every name in ``femehl.discretize.mesh.LADDER`` (coarse, medium, fine, xfine) this
meshes the half disk ``y >= 0`` and the full disk of radius ``L = 2`` with
``graded_disk(L=2.0, half=..., **LADDER[name])`` (gmsh, deterministic), writes
them as gmsh 4.1 binary files with meshio, reads each file back through
``load_mesh`` to check it, and prints a table of node and element counts, the
shortest and longest edge, and the smallest angle.  A file larger than
``MAX_BYTES`` is not kept (none is, at present: the largest is about 1.2 MB).
"""

from __future__ import annotations

import pathlib
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # the repository root, for an uninstalled femehl

from femehl.discretize.mesh import LADDER, _write_msh, graded_disk, load_mesh  # noqa: E402

MAX_BYTES = 3_000_000


def quality(p: np.ndarray, t: np.ndarray) -> tuple[float, float, float]:
    """Shortest edge, longest edge and smallest angle (degrees) of a triangulation."""
    e = [p[:, t[(k + 1) % 3]] - p[:, t[k]] for k in range(3)]
    lengths = np.array([np.hypot(*v) for v in e])
    angles = []
    for k in range(3):  # angle at node k between the edges k -> k+1 and k -> k-1
        u, w = e[k], -e[(k + 2) % 3]
        c = (u * w).sum(axis=0) / (lengths[k] * lengths[(k + 2) % 3])
        angles.append(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))
    return float(lengths.min()), float(lengths.max()), float(np.min(angles))


def main() -> int:
    t_start = time.perf_counter()
    header = (
        f"{'name':<7} {'domain':<6} {'nodes':>6} {'elements':>8} {'min h':>7} "
        f"{'max h':>7} {'min angle':>9} {'size':>9} {'time':>6}"
    )
    print(header)
    print("-" * len(header))
    for name, sizes in LADDER.items():
        for half in (True, False):
            kind = "half" if half else "full"
            path = HERE / f"{kind}_{name}.msh"
            t0 = time.perf_counter()
            dm = graded_disk(L=2.0, half=half, name=name, **sizes)
            _write_msh(dm, path)
            nbytes = path.stat().st_size
            if nbytes > MAX_BYTES:
                path.unlink()
                mb, cap = nbytes / 1e6, MAX_BYTES / 1e6
                print(f"{name:<7} {kind:<6} skipped: {mb:.1f} MB > {cap:.0f} MB")
                continue
            back = load_mesh(path, L=2.0, half=half)
            assert back.mesh.p.shape == dm.mesh.p.shape
            assert np.array_equal(back.mesh.t, dm.mesh.t)
            hmin, hmax, amin = quality(dm.mesh.p, dm.mesh.t)
            print(
                f"{name:<7} {kind:<6} {dm.mesh.p.shape[1]:>6} {dm.mesh.t.shape[1]:>8} "
                f"{hmin:>7.4f} {hmax:>7.4f} {amin:>8.1f}° {nbytes / 1e3:>7.0f}kB "
                f"{time.perf_counter() - t0:>5.1f}s"
            )
    print(f"total {time.perf_counter() - t_start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
