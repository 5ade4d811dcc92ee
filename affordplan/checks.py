"""Argument checks shared by the library's entry points.

Each check raises :class:`affordplan.errors.InputError` naming the setting, so a caller's typo or NaN stops at
the boundary with a message that says which setting and what it got.
"""

from __future__ import annotations

import math
from numbers import Integral, Real

import numpy as np

from affordplan.errors import InputError


def is_whole(value: object) -> bool:
    """Whether ``value`` is an integer (Python or numpy), and not a ``bool``."""
    return isinstance(value, Integral) and not isinstance(value, bool)


def is_finite(value: object) -> bool:
    """Whether ``value`` is a finite real number (Python or numpy), and not a ``bool``."""
    try:
        return isinstance(value, Real) and not isinstance(value, bool) and math.isfinite(value)
    except OverflowError:  # an integer beyond a float's range
        return False


def require_whole(label: str, value: object, least: int) -> None:
    """Raise :class:`InputError` unless ``value`` is a whole number >= ``least``; ``label`` names the setting."""
    if not is_whole(value) or value < least:
        raise InputError(f"{label} must be a whole number >= {least}, got {describe(value)}")


def require_probability(label: str, value: object) -> None:
    """Raise :class:`InputError` unless ``value`` is a finite number in [0, 1]; ``label`` names the setting."""
    if not is_finite(value) or not 0.0 <= value <= 1.0:
        raise InputError(f"{label} is a probability in [0, 1], got {describe(value)}")


def describe(value: object, limit: int = 60) -> str:
    """A short description of ``value`` for an error message: its repr cut to ``limit`` characters (never an
    unbounded value formatted into a message), containers by type and length, huge integers by digit count."""
    if isinstance(value, (list, tuple, dict, set)) and len(value) > 8:
        return f"a {type(value).__name__} of {len(value)} items"
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**30:
        return f"an integer of {len(str(abs(value)))} digits"
    try:
        text = repr(value)
    except Exception:  # a hostile __repr__
        text = f"<{type(value).__name__}>"
    return text if len(text) <= limit else text[:limit - 3] + "..."


def as_finite(label: str, value: object, low: float = -math.inf, high: float = math.inf) -> float:
    """``value`` as a float, or :class:`InputError`: a finite real number in [``low``, ``high``]; booleans, strings
    and integers beyond a float's range are refused."""
    ok = is_whole(value) or (isinstance(value, Real) and not isinstance(value, bool))
    try:
        number = float(value) if ok else math.nan
    except (OverflowError, TypeError, ValueError):
        number = math.nan
    if not math.isfinite(number) or not low <= number <= high:
        bounds = "" if (low, high) == (-math.inf, math.inf) else f" in [{low:g}, {high:g}]"
        raise InputError(f"{label} must be a finite number{bounds}, got {describe(value)}")
    return number


def as_vector(label: str, value: object, n: int, bound: float = math.inf) -> np.ndarray:
    """``value`` as a float array of shape ``(n,)``, or :class:`InputError`: ``n`` finite real numbers of magnitude
    at most ``bound`` (a list, tuple or array of numbers; no strings, booleans or nested lists)."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
        raise InputError(f"{label} must be {n} finite numbers, got {describe(value)}")
    try:
        items = list(np.asarray(value, dtype=object).reshape(-1)) if isinstance(value, np.ndarray) else list(value)
    except (TypeError, ValueError):
        raise InputError(f"{label} must be {n} finite numbers, got {describe(value)}") from None
    if len(items) != n or any(isinstance(v, (bool, np.bool_)) for v in items):
        raise InputError(f"{label} must be {n} finite numbers, got {describe(value)}")
    out = np.array([as_finite(f"{label}[{i}]", v) for i, v in enumerate(items)], dtype=float)
    if np.any(np.abs(out) > bound):
        raise InputError(f"{label} must be {n} numbers of magnitude at most {bound:g}, got {describe(value)}")
    return out


def as_whole(label: str, value: object, least: int = 0, most: int | None = None) -> int:
    """``value`` as an int, or :class:`InputError`: a whole number (not a bool) in [``least``, ``most``]."""
    if not is_whole(value) or value < least or (most is not None and value > most):
        upper = "" if most is None else f" and <= {most}"
        raise InputError(f"{label} must be a whole number >= {least}{upper}, got {describe(value)}")
    return int(value)


def as_seed(label: str, value: object) -> int:
    """A random seed: a whole number in [0, 2**32)."""
    return as_whole(label, value, 0, 2**32 - 1)
