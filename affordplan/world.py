"""The table-top world: workspace bounds and box obstacles.

World frame: z up, table top at z = 0, the arm's base at the origin. Objects live in the
:class:`Workspace` (x in [0.3, 0.75] m, |y| <= 0.3 m by default).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from affordplan.checks import as_vector
from affordplan.errors import InputError

WORLD_BOUND = 10.0  # metres: no coordinate or length of the table-top world is larger


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

    def corners_xy(self) -> np.ndarray:
        """(4, 2) footprint corners on the table, counter-clockwise."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        hx, hy = 0.5 * self.size[0], 0.5 * self.size[1]
        local = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
        return local @ np.array([[c, s], [-s, c]]) + np.array(self.center)
