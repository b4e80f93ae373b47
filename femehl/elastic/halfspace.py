"""Elastic half space: Boussinesq, ``w = -2 (1 - nu) int p(x') / |x - x'| dA'``.

In the paper's normalization (Eq. 10b) the incompressible half space (nu = 1/2) has unit
factor; a compressible one multiplies the integral by ``2 (1 - nu)`` (the plane-strain
modulus ``E/(1 - nu^2) = 2 G/(1 - nu)`` in place of ``4 G``).  The operator is dense.
"""

from __future__ import annotations

from dataclasses import dataclass

from femehl.elastic.base import register_substrate
from femehl.elastic.contact import elastic_contact
from femehl.errors import SceneError
from femehl.validation import check_finite

__all__ = ["HalfSpace"]


@register_substrate
@dataclass(frozen=True)
class HalfSpace:
    """Elastic half space (Boussinesq, Eq. 3 / 10b).  ``compliance = 2 (1 - nu)``."""

    nu: float = 0.5
    kind = "halfspace"

    def __post_init__(self):
        nu = check_finite("Poisson ratio nu", self.nu)
        object.__setattr__(self, "nu", nu)
        if not (-1.0 < nu <= 0.5):
            raise SceneError(f"Poisson ratio nu must lie in (-1, 0.5], got {nu}.")

    @property
    def compliance(self) -> float:
        """Factor multiplying the normalized Boussinesq integral (1 for nu = 0.5)."""
        return 2.0 * (1.0 - self.nu)

    def compliance_operator(self, disc):
        C = disc.boussinesq()
        if self.compliance != 1.0:
            C *= self.compliance
        return C

    def deflection_rows(self, disc, points):
        return self.compliance * disc.boussinesq_rows(points)

    def dry_contact(self, shape):
        """Hertz / Sneddon (:func:`femehl.elastic.contact.elastic_contact`)."""
        return elastic_contact(shape, self.compliance)
