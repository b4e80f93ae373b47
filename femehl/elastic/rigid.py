"""Rigid substrate: ``w = 0``; the step is the rigid Reynolds problem."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from femehl.elastic.base import register_substrate
from femehl.elastic.contact import overlap_contact

__all__ = ["Rigid"]


@register_substrate
@dataclass(frozen=True)
class Rigid:
    """Rigid substrate: w = 0, no elastic operator at all."""

    kind = "rigid"
    #: every operator is sparse (none at all): see :data:`femehl.accuracy.auto.LOCAL_MAX_ELEMENTS`
    local = True
    #: the pressure follows the motion at once (algebraic in hc'): the load jumps where hc'
    #: does (t = 0, breakpoints), which the adaptive steps do not count as a time error
    instant = True

    def compliance_operator(self, disc):
        return sp.csr_matrix((disc.film_points.shape[0], disc.n))

    def deflection_rows(self, disc, points):
        return sp.csr_matrix((np.asarray(points).reshape(-1, 2).shape[0], disc.n))

    def dry_contact(self, shape):
        """Never indented under a load; an imposed gap overlaps the shape geometrically."""
        return overlap_contact(shape, None, "a rigid substrate")
