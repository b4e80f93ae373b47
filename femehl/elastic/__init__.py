"""Substrates: each one owns its elastic operator for any discretization.

Convention: the surface deflection is ``w = -C p`` on the discretization's film points
(``w < 0`` under positive pressure, so the film is ``d = h - w = h + C p``).  A substrate
is a frozen dataclass with two methods, written against the primitives every
discretization offers (:mod:`femehl.discretize`):

``compliance_operator(disc)``
    ``C`` (film points x pressure unknowns): a dense ndarray for a non-local substrate,
    a scipy sparse matrix for a local one (then no dense matrix is built anywhere).
``deflection_rows(disc, points)``
    The rows of ``C`` at arbitrary points (the origin for the central film, nodes for
    the film check).

The primitives are ``disc.boussinesq()`` / ``disc.boussinesq_rows(points)`` (exact
integral of ``1/|x - x'|`` of the discretized unit pressure, mirror image included for a
half domain), ``disc.average()`` (the pressure's value on the film points),
``disc.pressure_rows(points)`` and, for a radial kernel ``singular/r - R(r)`` with R smooth
(an elastic layer, :class:`Layer`), ``disc.radial_kernel(kernel)`` /
``disc.radial_kernel_rows(kernel, points)``.  A new substrate is one module defining such a class; no
solver file changes; decorated with :func:`register_substrate` its ``kind`` also names
it in TOML scene files (``[substrate] kind = "..."``).
"""

from femehl.elastic.base import SUBSTRATES, Substrate, register_substrate
from femehl.elastic.halfspace import HalfSpace
from femehl.elastic.layer import Layer
from femehl.elastic.rigid import Rigid
from femehl.elastic.viscoelastic import Viscoelastic
from femehl.elastic.winkler import Winkler

__all__ = [
    "Substrate",
    "SUBSTRATES",
    "register_substrate",
    "HalfSpace",
    "Layer",
    "Winkler",
    "Rigid",
    "Viscoelastic",
]
