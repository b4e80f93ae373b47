"""What the Stribeck benchmarks (``stribeck.py``, ``stribeck_pdms.py``) report of a curve."""

from __future__ import annotations

import json
import pathlib
import shutil

HERE = pathlib.Path(__file__).resolve().parent


def case_walls(out, name: str) -> dict:
    """Each case's wall time [s] by its swept value ``name`` (the sweep's ``case.json`` files)."""
    recs = [json.loads((c / "case.json").read_text()) for c in sorted((out / "cases").iterdir())]
    return {float(r["params"][name]): r.get("wall_s", float("nan")) for r in recs}


def summary(curve, wall: float, walls, mu_b: float, unit: str = "") -> list[str]:
    """The table's bullet lines: the wall time and the cost per point, the statuses and the
    steady points, the regimes, the friction coefficient at both ends and its minimum."""
    n, walls = len(curve), sorted(walls)
    regimes = {r: int((curve["regime"] == r).sum()) for r in ("boundary", "mixed", "full film")}
    statuses = {k: int(v) for k, v in curve["status"].value_counts().items()}
    mu = curve["friction_coefficient"]
    i = int(mu.idxmin())
    return [
        f"- wall time {wall:.0f} s for {n} points; {sum(walls):.0f} s of runs, "
        f"{walls[len(walls) // 2]:.3g} s per point (median), {walls[-1]:.3g} s at most",
        f"- statuses: {statuses}; steady at t_end: {int(curve['steady'].sum())} of {n}",
        f"- regimes: {regimes}",
        f"- friction coefficient: {mu.iloc[0]:.4f} at the lowest speed (mu_b = {mu_b}), minimum "
        f"{mu.iloc[i]:.4f} at {curve['speed'].iloc[i]:.3g}{unit} ({curve['regime'].iloc[i]}), "
        f"{mu.iloc[-1]:.4f} at the highest",
    ]


def finish(lines: list[str], name: str, out) -> None:
    """Point to the picture ``name.png``, write ``name.md`` here, print its head, and remove
    the sweep's temporary folder ``out``."""
    lines = [*lines, "", f"The picture: `{name}.png` beside this table.", ""]
    (HERE / f"{name}.md").write_text("\n".join(lines))
    print("\n".join(lines[:14]))
    shutil.rmtree(out, ignore_errors=True)
