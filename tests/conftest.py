"""Shared fixtures: the paper case, its reference values, quick run parameters, output folder.

The reference values are femehl's independent reference for the paper case (beta = 200,
h0 = 0.1): Richardson extrapolation of FE BDF2 in dt and in mesh size, uncertainty
<= 0.3 % (benchmarks/accuracy_results.md, "Reference"; docs/design.md, section 7).
Tests compare with them at a tolerance taken from the measured discretization error of
the configuration they run (the "Runs" table of the same file), not with a wide window.
"""

from __future__ import annotations

import pytest

import femehl

#: t -> {quantity: reference value} for the paper case.
PAPER_REFERENCE = {
    1.0: {"load": 0.47567, "film_center": 0.05570, "film_min": 0.04999},
    5.0: {"load": 0.45215, "film_center": 0.04112, "film_min": 0.02647},
}


@pytest.fixture(scope="session")
def paper_reference():
    """``paper_reference[t][quantity]``: the reference values above (t = 1 and 5)."""
    return PAPER_REFERENCE


@pytest.fixture
def paper_scene():
    """The paper's sphere case, ``femehl.problem.presets.paper_sphere()`` (beta = 200, h0 = 0.1, L = 2)."""
    return femehl.presets.paper_sphere()


@pytest.fixture(scope="session")
def quick_fe():
    """Keyword arguments of a quick FE run: coarse mesh, dt = 0.02, only the first and
    last states stored.  Add ``t_end``."""
    return dict(mesh="coarse", dt=0.02, store_every=0)


@pytest.fixture
def out_dir(tmp_path):
    """A fresh, not yet existing output folder under pytest's tmp_path."""
    return tmp_path / "out"
