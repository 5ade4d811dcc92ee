"""Turning an object's SE(2) path into skill calls: pushes of at most 5 cm and spins of 15-45 deg.

A push moves the object without turning it (direction: world heading, radians); a spin turns it in
place. The path is walked in 5 cm strides: before each stride, the yaw the path has reached there is
caught up with spins (when it is more than ``YAW_DEADBAND`` off), then a push covers the stride. At
the end, spins bring the object to the goal yaw.
"""

from __future__ import annotations

import math

import numpy as np

from affordplan.geometry import wrap_angle
from primitives.params import PUSH_STEP, SPIN_MAX, SPIN_MIN

YAW_DEADBAND = math.radians(10.0)  # smaller yaw errors are left alone (goal tolerance: 15 deg)
MIN_PUSH = 0.015  # metres: shorter strides are not pushed (goal tolerance: 3 cm)


def spins_for(dyaw: float) -> list[float]:
    """Signed spin angles (each 15-45 deg) that turn by ``dyaw`` (radians) to within the dead band."""
    out = []
    rest = wrap_angle(dyaw)
    while abs(rest) > YAW_DEADBAND:
        a = math.copysign(min(max(abs(rest), SPIN_MIN), SPIN_MAX), rest)
        out.append(a)
        rest -= a
    return out


Call = tuple[str, dict, tuple[float, float, float]]  # (skill, params, (x, y, yaw) after)


def path_to_calls(path: np.ndarray, goal_yaw: float | None = None) -> list[Call]:
    """``(skill, params, (x, y, yaw) after)`` calls that track ``path`` ((m, 3) x, y, yaw; metres, radians)."""
    path = np.asarray(path, dtype=float)
    x, y, yaw = path[0]
    calls: list[Call] = []
    i = 0
    last = len(path) - 1
    while i < last:
        d = np.hypot(path[i + 1:, 0] - x, path[i + 1:, 1] - y)
        beyond = np.flatnonzero(d >= PUSH_STEP)
        j = i + 1 + int(beyond[0]) if len(beyond) else last
        tx, ty, tyaw = path[j]
        for a in spins_for(tyaw - yaw):
            yaw = wrap_angle(yaw + a)
            calls.append(("spin", {"angle": a}, (x, y, yaw)))
        stride = math.hypot(tx - x, ty - y)
        if stride >= MIN_PUSH or (j == last and stride > 0.0 and not calls):
            direction = math.atan2(ty - y, tx - x)
            x, y = tx, ty
            calls.append(("push", {"direction": direction}, (x, y, yaw)))
        i = j
    if goal_yaw is not None:
        for a in spins_for(goal_yaw - yaw):
            yaw = wrap_angle(yaw + a)
            calls.append(("spin", {"angle": a}, (x, y, yaw)))
    return calls
