"""The table-top world: workspace bounds and box obstacles.

World frame: z up, table top at z = 0, the arm's base at the origin. Objects live in the
:class:`Workspace` (x in [0.3, 0.75] m, |y| <= 0.3 m by default).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from affordplan.checks import as_finite, as_vector, describe
from affordplan.errors import InputError

WORLD_BOUND = 10.0  # metres: no coordinate or length of the table-top world is larger
BOX_FIELDS = ("center", "size", "yaw", "yaw_deg")  # a box as a dict (scene files, affordplan.plan's obstacles)


def _finite(values, name: str, n: int) -> tuple[float, ...]:
    return tuple(float(v) for v in as_vector(name, values, n, WORLD_BOUND))


@dataclass(frozen=True)
class Workspace:
    """Axis-aligned region of the table where objects live, metres."""

    x: tuple[float, float] = (0.3, 0.75)
    y: tuple[float, float] = (-0.3, 0.3)

    def contains(self, xy, margin: float = 0.0) -> bool:
        """Whether ``xy`` lies inside the region grown by ``margin`` metres."""
        return (self.x[0] - margin <= xy[0] <= self.x[1] + margin
                and self.y[0] - margin <= xy[1] <= self.y[1] + margin)

    @property
    def center(self) -> tuple[float, float]:
        return (0.5 * (self.x[0] + self.x[1]), 0.5 * (self.y[0] + self.y[1]))


@dataclass(frozen=True)
class Box:
    """A box obstacle standing on the table.

    Args:
        center: (x, y) of the box's centre on the table, metres.
        size: full side lengths (sx, sy, sz), metres; it spans z in [0, sz].
        yaw: rotation about the world z axis, radians.
    """

    center: tuple[float, float]
    size: tuple[float, float, float]
    yaw: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "center", _finite(self.center, "Box.center", 2))
        object.__setattr__(self, "size", _finite(self.size, "Box.size", 3))
        object.__setattr__(self, "yaw", _finite([self.yaw], "Box.yaw", 1)[0])
        if min(self.size) <= 0:
            raise InputError(f"Box.size must be positive, got {self.size}")

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], name: str = "obstacle") -> Box:
        """The box a dict describes, as scene files write them: ``{"center": [x, y], "size": [sx, sy, sz]}`` (metres)
        and optionally ``"yaw"`` (radians) or ``"yaw_deg"`` (degrees), not both.

        Raises :class:`InputError` naming the field (``name`` prefixes it: ``obstacles[1].size must be positive``)
        for a missing, unknown or malformed one.
        """
        if not isinstance(d, Mapping):
            raise InputError(f"{name} must be a mapping of fields {list(BOX_FIELDS)}, got {type(d).__name__}")
        unknown = sorted(str(k) for k in d if k not in BOX_FIELDS)
        if unknown:
            raise InputError(f"{name}: unknown field(s) {str(unknown)[:200]}; expected some of {list(BOX_FIELDS)}")
        for key in ("center", "size"):
            if key not in d:
                raise InputError(f"{name}: missing field '{key}' (metres)")
        center = _box_numbers(d["center"], 2, f"{name}.center", "metres")
        size = _box_numbers(d["size"], 3, f"{name}.size", "metres: sx, sy, sz")
        if min(size) <= 0:
            raise InputError(f"{name}.size must be positive, got {list(size)}")
        if "yaw" in d and "yaw_deg" in d:
            raise InputError(f"{name}: give yaw (radians) or yaw_deg (degrees), not both")
        if "yaw_deg" in d:
            yaw = math.radians(as_finite(f"{name}.yaw_deg", d["yaw_deg"]))
        else:
            yaw = as_finite(f"{name}.yaw", d.get("yaw", 0.0))
        return cls(center=(center[0], center[1]), size=(size[0], size[1], size[2]), yaw=yaw)

    def as_dict(self) -> dict[str, Any]:
        """``{"center": [x, y], "size": [sx, sy, sz], "yaw": rad}``: what :meth:`from_dict` reads."""
        return {"center": list(self.center), "size": list(self.size), "yaw": self.yaw}

    def corners_xy(self) -> np.ndarray:
        """(4, 2) footprint corners on the table, counter-clockwise."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        hx, hy = 0.5 * self.size[0], 0.5 * self.size[1]
        local = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
        return local @ np.array([[c, s], [-s, c]]) + np.array(self.center)


def _box_numbers(value: Any, n: int, name: str, unit: str) -> tuple[float, ...]:
    """``n`` finite numbers of magnitude at most ``WORLD_BOUND`` (a list, tuple or array), or :class:`InputError`."""
    if isinstance(value, np.ndarray):
        value = value.tolist() if value.ndim == 1 else value
    if not isinstance(value, (list, tuple)) or len(value) != n:
        raise InputError(f"{name} must be a list of {n} numbers ({unit}), got {describe(value)}")
    numbers = tuple(as_finite(f"{name}[{i}]", v) for i, v in enumerate(value))
    if any(abs(v) > WORLD_BOUND for v in numbers):
        raise InputError(f"{name} must be numbers of magnitude at most {WORLD_BOUND:g} metres, got {describe(value)}")
    return numbers


def as_box(value: Box | Mapping[str, Any], name: str = "obstacle") -> Box:
    """``value`` itself when it is a :class:`Box`, the box a dict describes (:meth:`Box.from_dict`, the scene-file
    form), else :class:`InputError`; ``name`` names it in messages."""
    if isinstance(value, Box):
        return value
    if isinstance(value, Mapping):
        return Box.from_dict(value, name)
    raise InputError(f"{name} must be an affordplan.Box or a dict with center, size and yaw (or yaw_deg), "
                     f"got {describe(value)}")
