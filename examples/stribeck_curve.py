"""A Stribeck curve: from boundary through mixed to full-film lubrication
=========================================================================

A rigid cylinder slides over a rough, lubricated soft substrate (a Winkler foundation, line
contact, normalized units) under a constant load. The two surfaces' combined roughness
(rms ``sigma``) meets through Greenwood-Tripp asperities (``femehl.Roughness``): where the
film thins to the roughness they carry part of the load, with a boundary friction
coefficient ``mu_b``.

:func:`femehl.studies.stribeck.stribeck` runs the scene's steady state at several speeds as
a Dask sweep (one folder per speed; run it again and the finished speeds are reused) and
writes the curve: the friction coefficient, the central film over the roughness and the
asperities' share of the load against the speed, the regimes shaded. At low speed the
asperities carry nearly everything and the friction coefficient is about ``mu_b``; it falls
through the mixed regime, and at high speed the full film's viscous shear makes it rise
again.

Run::

    python examples/stribeck_curve.py

Output: ``stribeck.png`` and ``stribeck.csv`` in ``femehl-out/stribeck_curve`` (the
command line does the same for a scene file: ``femehl stribeck SCENE.toml --speeds LO HI``).
"""

from __future__ import annotations

from pathlib import Path

from femehl.studies.stribeck import stribeck

MU_B = 0.1  # the asperities' boundary friction coefficient

#: the scene's tables, as in a TOML scene file; the speed factor s divides beta
SCENE = {
    "indenter": {"kind": "cylinder"},
    "substrate": {"kind": "winkler", "k": 1.0},
    "fluid": {"beta": 200.0},
    # sigma over h_inf, the asperity stiffness over p0, and aspect = sqrt(h_inf/R), which
    # turns mu_b into femehl's friction unit
    "roughness": {"sigma": 0.05, "stiffness": 2.0, "friction": MU_B, "aspect": 0.05},
    "motion": {
        "velocity": 1.0,
        "gap": {"kind": "constant", "value": 0.2},
        "load": {"kind": "table", "times": [0.0, 1.0], "values": [0.0, 0.5]},  # ramped, then held
    },
    "domain": {"L": 2.5},
    "run": {"t_end": 20.0},  # 20 length units of sliding: steady at every speed here
}


def main(out=None, speeds=(1e-3, 1e2), num: int = 11, workers: int = 2):
    """The curve at ``num`` speed factors from ``speeds[0]`` to ``speeds[1]`` (a table)."""
    out = Path(out) if out is not None else Path("femehl-out") / "stribeck_curve"
    curve = stribeck(SCENE, speeds, num, out=out, workers=workers, progress=False)
    print(curve[["speed", "friction_coefficient", "film_over_sigma", "asperity_share", "regime"]].to_string())
    print(f"wrote {curve.attrs['png']} and {curve.attrs['csv']}")
    return curve


if __name__ == "__main__":
    main()
