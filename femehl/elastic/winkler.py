"""Winkler foundation: ``w = -p / k``, local (every operator sparse)."""

from __future__ import annotations

from dataclasses import dataclass

from femehl.elastic.base import register_substrate
from femehl.elastic.contact import overlap_contact
from femehl.validation import check_positive

__all__ = ["Winkler"]


@register_substrate
@dataclass(frozen=True)
class Winkler:
    """Winkler foundation: ``w = -p / k`` (local, diagonal)."""

    k: float = 1.0
    kind = "winkler"
    #: every operator is sparse (no dense influence matrix):
    #: see :data:`femehl.accuracy.auto.LOCAL_MAX_ELEMENTS`
    local = True

    def __post_init__(self):
        object.__setattr__(self, "k", check_positive("Winkler stiffness k", self.k))

    def compliance_operator(self, disc):
        return (disc.average() / self.k).tocsr()

    def deflection_rows(self, disc, points):
        return (disc.pressure_rows(points) / self.k).tocsr()

    def dry_contact(self, shape):
        """The geometric overlap, ``F = k int (delta - s)+ dA`` (no lateral spreading)."""
        return overlap_contact(shape, self.k, "the Winkler foundation")
