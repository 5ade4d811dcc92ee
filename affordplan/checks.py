"""Argument checks shared by the library's entry points.

Each check raises :class:`affordplan.errors.InputError` naming the setting, so a caller's typo or NaN stops at
the boundary with a message that says which setting and what it got.
"""

from __future__ import annotations

import math
from numbers import Integral, Real

from affordplan.errors import InputError


def is_whole(value: object) -> bool:
    """Whether ``value`` is an integer (Python or numpy), and not a ``bool``."""
    return isinstance(value, Integral) and not isinstance(value, bool)


def is_finite(value: object) -> bool:
    """Whether ``value`` is a finite real number (Python or numpy), and not a ``bool``."""
    return isinstance(value, Real) and not isinstance(value, bool) and math.isfinite(value)


def require_whole(label: str, value: object, least: int) -> None:
    """Raise :class:`InputError` unless ``value`` is a whole number >= ``least``; ``label`` names the setting."""
    if not is_whole(value) or value < least:
        raise InputError(f"{label} must be a whole number >= {least}, got {value!r}")


def require_probability(label: str, value: object) -> None:
    """Raise :class:`InputError` unless ``value`` is a finite number in [0, 1]; ``label`` names the setting."""
    if not is_finite(value) or not 0.0 <= value <= 1.0:
        raise InputError(f"{label} is a probability in [0, 1], got {value!r}")
