"""Elastic layer of finite thickness on a rigid base: ``w = -c int p(x') g(|x - x'|) dA'``.

In femehl's normalization (Eq. 10b; :mod:`femehl.elastic.halfspace`) the half space has
the kernel ``c / r``, ``c = 2 (1 - nu)``.  A layer of normalized thickness ``h`` (in units
of the horizontal length ``sqrt(R h_inf)``, like x and y), bonded to a rigid base
(``bonded=True``) or resting on it without friction (``bonded=False``), multiplies the
half space's Fourier transform by ``K(k h)``, so its kernel is

    g(r) = c int_0^inf K(k h) J0(k r) dk = c [1/r - R(r)],   R(r) = Rh(r/h) / h,

    bonded:        K(t) = [2 kappa sinh 2t - 4t] / [2 kappa cosh 2t + 1 + kappa^2 + 4t^2],
                   kappa = 3 - 4 nu;
    frictionless:  K(t) = [cosh 2t - 1] / [sinh 2t + 2t]

(:mod:`femehl.elastic.layer_kernel`: the equations, their limits, the table of ``Rh`` and the
references).  ``g`` decays like ``exp(-y r/h)`` (``y = 0.739`` bonded at nu = 1/2), so
beyond about 40 h a load is not felt.  Limits: ``h -> inf`` is the half space,
``h -> 0`` the Winkler foundation ``k = (1 - nu) / (2 pi (1 - 2 nu) h)`` (bonded,
nu < 1/2; :func:`femehl.elastic.layer_kernel.winkler_limit`) or, bonded and incompressible, the
thin layer ``w = (4 pi h^3 / 3) lap p``.

The operator (FE and FD): the exact ``1/r`` integral of the discretized pressure over
each element minus the integral of ``R`` (:meth:`femehl.discretize.fe_disk.FEDisc.radial_kernel`):
sparse for a thin layer (pairs beyond the cut-off are zero), dense otherwise.  The fast
hierarchical operator (``operator="fast"``) is the half space's only; line contact takes
local substrates only.  Its dry contact (:meth:`Layer.dry_contact`) bounds depth and
extent from the half space and the geometric overlap.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femehl.elastic.base import register_substrate
from femehl.elastic.contact import DryContact, elastic_contact
from femehl.errors import SceneError
from femehl.validation import check_finite, check_positive

__all__ = ["Layer"]


@register_substrate
@dataclass(frozen=True)
class Layer:
    """Elastic layer of thickness ``thickness`` on a rigid base (normalized units).

    Parameters
    ----------
    thickness : float
        Layer thickness h, in the units of x and y (``sqrt(R h_inf)``; > 0).
    nu : float, default: 0.5
        Poisson ratio, in (-1, 0.5].
    bonded : bool, default: True
        The layer is bonded to the base (True) or slides on it without friction (False).
    """

    thickness: float
    nu: float = 0.5
    bonded: bool = True
    kind = "layer"
    #: the FE elastic operators this substrate builds (not the hierarchical "fast" one)
    operators = ("dense",)

    def __post_init__(self):
        h = check_positive(
            "layer thickness", self.thickness, "Give the thickness in the units of x and y, e.g. Layer(0.5)."
        )
        object.__setattr__(self, "thickness", h)
        nu = check_finite("Poisson ratio nu", self.nu)
        if not (-1.0 < nu <= 0.5):
            raise SceneError(f"Poisson ratio nu must lie in (-1, 0.5], got {nu}.")
        object.__setattr__(self, "nu", nu)
        if not isinstance(self.bonded, (bool, np.bool_)):
            raise SceneError(
                f"Layer bonded must be True (bonded to the rigid base) or False (frictionless base), "
                f"got {self.bonded!r}."
            )
        object.__setattr__(self, "bonded", bool(self.bonded))

    @property
    def compliance(self) -> float:
        """The half space's factor ``c = 2 (1 - nu)`` (the layer's short-wave limit)."""
        return 2.0 * (1.0 - self.nu)

    @property
    def kernel(self):
        """The radial kernel ``g / c = 1/r - R(r)`` (:class:`femehl.elastic.layer_kernel.LayerKernel`)."""
        from femehl.elastic.layer_kernel import LayerKernel

        return LayerKernel(self.thickness, self.nu, self.bonded)

    def _primitive(self, disc, name):
        f = getattr(disc, name, None)
        if f is None:
            raise SceneError(
                f"the {getattr(disc, 'method', type(disc).__name__)!r} discretization has no "
                "radial-kernel operator, so it cannot model an elastic layer: use method='fe'."
            )
        return f

    def compliance_operator(self, disc):
        C = self._primitive(disc, "radial_kernel")(self.kernel)
        C *= self.compliance
        return C

    def deflection_rows(self, disc, points):
        return self._primitive(disc, "radial_kernel_rows")(self.kernel, points) * self.compliance

    def dry_contact(self, shape):
        """Bounds that hold at any thickness: a layer is stiffer than the half space of its
        ``compliance`` (so that half space's depth under a load is the deeper) and spreads
        less than the geometric overlap (its thin limit): depth from the half space, extent
        from the overlap."""
        half = elastic_contact(shape, self.compliance, "the layer")
        return DryContact(shape.overlap_axes, half.load, "the layer")
