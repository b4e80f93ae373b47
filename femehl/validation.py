"""Validators of scalar input: small functions whose messages name the fix."""

from __future__ import annotations

import math
import numbers

import numpy as np

from .errors import SceneError

__all__ = ["check_finite", "check_positive"]


def _short(value) -> str:
    r = repr(value)
    return r if len(r) <= 40 else r[:37] + "..."


def check_finite(name: str, value, hint: str = "") -> float:
    """Return ``value`` as a float, or raise SceneError if it is not a finite real number.

    Strings, booleans, complex numbers and other non-real types are refused
    (a "1" in a scene is a typo, not a number).
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise SceneError(f"{name} must be a real number, got {_short(value)} "
                         f"({type(value).__name__}). {hint}".strip())
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        raise SceneError(f"{name} must be a finite number, got {_short(value)}. {hint}".strip()) from None
    if not math.isfinite(v):
        raise SceneError(f"{name} must be finite, got {v}. {hint}".strip())
    return v


def check_positive(name: str, value, hint: str = "") -> float:
    """Return ``value`` as a float, or raise SceneError if it is not finite and > 0."""
    v = check_finite(name, value, hint)
    if v <= 0.0:
        raise SceneError(f"{name} must be > 0, got {v}. {hint}".strip())
    return v
