"""Small input validators shared by the scene, indenter and mesh modules.

Each validator takes a *name* (how the value is called in the error message), the
value and, optionally, a *hint* (what to do about a bad value), and either returns
the value converted (a float, a checked array) or raises
:class:`~femehl.errors.SceneError` naming the value, what is wrong and the fix.
Inputs are never mutated: arrays are copied before they are changed.

This module imports nothing from the rest of femehl but :mod:`femehl.errors`, so
:mod:`femehl.problem.scene` and :mod:`femehl.problem.indenters` can both use it without an import
cycle.  ``femehl.problem.scene.check_finite`` / ``check_positive`` re-export the functions.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from femehl.errors import SceneError

__all__ = [
    "call_time_function",
    "check_finite",
    "check_in_range",
    "check_int",
    "check_nonnegative",
    "check_positive",
    "check_shape_values",
    "short",
]


def short(value, width: int = 40) -> str:
    """``repr(value)``, cut to ``width`` characters (for error messages)."""
    r = repr(value)
    return r if len(r) <= width else r[: width - 3] + "..."


_short = short  # the historic name in femehl.problem.scene


def _join(message: str, hint: str) -> str:
    return f"{message} {hint}".strip()


def check_finite(name: str, value, hint: str = "") -> float:
    """Return ``value`` as a float, or raise SceneError if it is not a finite real number.

    Strings, booleans, complex numbers and other non-real types are refused
    (a "1" in a scene is a typo, not a number).
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise SceneError(
            _join(f"{name} must be a real number, got {short(value)} ({type(value).__name__}).", hint)
        )
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        raise SceneError(_join(f"{name} must be a finite number, got {short(value)}.", hint)) from None
    if not math.isfinite(v):
        raise SceneError(_join(f"{name} must be finite, got {v}.", hint))
    return v


def check_positive(name: str, value, hint: str = "") -> float:
    """Return ``value`` as a float, or raise SceneError if it is not finite and > 0."""
    v = check_finite(name, value, hint)
    if v <= 0.0:
        raise SceneError(_join(f"{name} must be > 0, got {v}.", hint))
    return v


def check_nonnegative(name: str, value, hint: str = "") -> float:
    """Return ``value`` as a float, or raise SceneError if it is not finite and >= 0."""
    v = check_finite(name, value, hint)
    if v < 0.0:
        raise SceneError(_join(f"{name} must be >= 0, got {v:g}.", hint))
    return v


def check_int(name: str, value, minimum: int | None = None, hint: str = "", error=SceneError) -> int:
    """Return ``value`` as an int, or raise ``error`` if it is not an integer >= ``minimum``.

    Booleans and floats (even 3.0) are refused: a count is written as an integer.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise error(_join(f"{name} must be an integer, got {short(value)} ({type(value).__name__}).", hint))
    v = int(value)
    if minimum is not None and v < minimum:
        raise error(_join(f"{name} must be an integer >= {minimum}, got {v}.", hint))
    return v


def check_shape_values(what: str, values, shape: tuple, hint: str = "") -> np.ndarray:
    """Check what a user function returned on points of array shape ``shape``.

    Returns a new float array of that shape (a scalar is broadcast); raises
    SceneError for complex values, non-numbers, the wrong shape, NaN or inf.
    """
    a = np.asarray(values)
    if np.iscomplexobj(a):
        raise SceneError(
            _join(
                f"{what} returned complex values (e.g. {complex(a.ravel()[0]):.3g}): "
                "a gap is a real number; return the real part or fix the formula "
                "(a square root of a negative number?).",
                hint,
            )
        )
    try:
        a = np.array(a, dtype=float)  # a copy: the caller's array is never touched
    except (TypeError, ValueError):
        raise SceneError(
            _join(f"{what} must return real numbers, got {type(values).__name__}.", hint)
        ) from None
    if a.shape != tuple(shape):
        if a.ndim != 0:
            raise SceneError(
                _join(
                    f"{what} returned shape {a.shape} for inputs of shape "
                    f"{tuple(shape)}: return one value per point (vectorize with numpy).",
                    hint,
                )
            )
        a = np.full(shape, float(a))
    return a


def call_time_function(history: str, symbol: str, f, t: float, hint: str = "") -> float:
    """``f(t)`` as a finite float; an exception of ``f`` becomes a SceneError naming the history and t.

    ``history`` names the function in words (``"the gap history hc(t)"``), ``symbol``
    in the formula (``"hc"``: a bad value is reported as ``hc(t=0.5) must be finite``).
    """
    t = float(t)
    try:
        v = f(t)
    except SceneError:
        raise
    except Exception as exc:  # noqa: BLE001 - the user's code: say which history failed, and when
        raise SceneError(
            f"{history} raised {type(exc).__name__} at t = {t:g} ({exc}): fix the "
            "function so that it returns a finite number at every time of the run."
        ) from None
    return check_finite(f"{symbol}(t={t:g})", v, hint)


def check_in_range(name: str, value, low: float, high: float, *, open_low=False, open_high=False) -> float:
    """``value`` as a float if it is a finite real number (:func:`check_finite`) in the
    interval from ``low`` to ``high`` (ends open as told), else SceneError naming it."""
    interval = f"{'(' if open_low else '['}{low:g}, {high:g}{')' if open_high else ']'}"
    v = check_finite(name, value, f"It is a number in {interval}.")
    if not ((low < v if open_low else low <= v) and (v < high if open_high else v <= high)):
        raise SceneError(f"{name} must be a number in {interval}, got {value!r}.")
    return v


def check_operator_tol(value) -> float:
    """The fast elastic operator's relative error: a number in [1e-12, 0.1)."""
    return check_in_range("operator_tol", value, 1e-12, 0.1, open_high=True)


def check_chebyshev_order(value) -> int:
    """Chebyshev points per axis of the fast operator (an experiment's override): 2..16."""
    p = check_int("the Chebyshev order p", value, 2, "It is in [2, 16].")
    if p > 16:
        raise SceneError(f"the Chebyshev order p must be an integer in [2, 16], got {value!r}.")
    return p


def check_svd_ratio(value) -> float:
    """Truncation of the fast operator's couplings, relative to operator_tol: in (0, 1000]."""
    return check_in_range("svd_ratio", value, 0.0, 1e3, open_low=True)


def check_admissibility(value) -> float:
    """Admissibility of the fast operator's far blocks (an experiment's override): in [0.5, 10]."""
    return check_in_range("the admissibility eta", value, 0.5, 10.0)
