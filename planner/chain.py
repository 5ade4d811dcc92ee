"""Turning an object's SE(2) path into skill calls: pushes of at most 5 cm and spins of 15-45 deg.

A push moves the object without turning it (direction: world heading, radians); a spin turns it in
place. The path is walked in 5 cm strides: before each stride, the yaw the path has reached there is
caught up with spins (when it is more than ``YAW_DEADBAND`` off), then a push covers the stride. At
the end, spins bring the object to the goal yaw.

A push moves the object at least ``PUSH_STEP`` (its objective saturates there; the policies move it
5-9 cm), so a last stride shorter than that would overshoot the goal by the difference, and the
closed loop would push back and forth across it. A short last stride is therefore covered by two
full pushes in a V, turned by ``+-acos(stride / (2 PUSH_STEP))`` from it (their sum is the stride),
on the side where the V's apex is free (``is_free``), else by the one short push.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from affordplan.geometry import wrap_angle
from primitives.params import PUSH_STEP, SPIN_MAX, SPIN_MIN

YAW_DEADBAND = math.radians(10.0)  # smaller yaw errors are left alone (goal tolerance: 15 deg)
MIN_PUSH = 0.015  # metres: shorter strides are not pushed (goal tolerance: 3 cm) ...
MIN_STRIDE = 0.001  # ... unless the path has nothing else to do (a goal asked to within less); none below this
SPIN_SLACK = math.radians(5.0)  # a rated split of a turn may sum to this much more or less (spins_for)


def spins_for(dyaw: float, rate: Callable[[float], float] | None = None) -> list[float]:
    """Signed spin angles (each 15-45 deg) that turn by ``dyaw`` (radians) to within the dead band.

    Without ``rate``: the largest spins first. With ``rate(angle)`` (the predicted success of one spin by
    ``angle`` in this state), the likeliest split: ``n`` equal spins whose sum is within ``SPIN_SLACK`` of
    ``dyaw``, maximising ``rate(angle) ** n`` (on a tie, fewer spins, then the sum nearer ``dyaw``). The
    policies spin some angles far better than others (0.11's spin, rated over held-out objects: ~0.4 at
    15 deg, ~0.9 at 35 deg), so asking for 25 deg rather than 20 deg, or two spins of 35 deg rather than
    45 + 25, pays.
    """
    rest = wrap_angle(dyaw)
    if abs(rest) <= YAW_DEADBAND:
        return []
    if rate is not None:
        best, best_p = None, -1.0
        for n in range(1, int(math.ceil((abs(rest) + SPIN_SLACK) / SPIN_MIN)) + 1):
            for slack in (0.0, -SPIN_SLACK / 2, SPIN_SLACK / 2, -SPIN_SLACK, SPIN_SLACK):  # ties: the exact turn
                a = (abs(rest) + slack) / n
                if SPIN_MIN - 1e-9 <= a <= SPIN_MAX + 1e-9 and abs(abs(rest) + slack) > 1e-9:
                    p = rate(math.copysign(a, rest)) ** n
                    if p > best_p + 1e-9:
                        best, best_p = [math.copysign(a, rest)] * n, p
        if best is not None:
            return best
    out = []
    while abs(rest) > YAW_DEADBAND:
        a = math.copysign(min(max(abs(rest), SPIN_MIN), SPIN_MAX), rest)
        out.append(a)
        rest -= a
    return out


Call = tuple[str, dict, tuple[float, float, float]]  # (skill, params, (x, y, yaw) after)


def v_pushes(x: float, y: float, tx: float, ty: float, yaw: float,
             is_free: Callable[[float, float, float], bool] | None = None) -> list[Call] | None:
    """Two full pushes from ``(x, y)`` whose sum ends at ``(tx, ty)`` (a stride shorter than ``PUSH_STEP``).

    The V's apex goes on the first side where ``is_free(x, y, yaw)`` holds there and halfway to it on both
    legs (left first); ``None`` where neither side is free.
    """
    stride = math.hypot(tx - x, ty - y)
    heading = math.atan2(ty - y, tx - x)
    half = math.acos(min(1.0, stride / (2.0 * PUSH_STEP)))
    for sign in (1.0, -1.0):
        first = heading + sign * half
        ax, ay = x + PUSH_STEP * math.cos(first), y + PUSH_STEP * math.sin(first)
        probes = ((ax, ay), ((x + ax) / 2, (y + ay) / 2), ((ax + tx) / 2, (ay + ty) / 2))
        if is_free is None or all(is_free(px, py, yaw) for px, py in probes):
            second = math.atan2(ty - ay, tx - ax)
            return [("push", {"direction": float(wrap_angle(first))}, (ax, ay, yaw)),
                    ("push", {"direction": float(wrap_angle(second))}, (tx, ty, yaw))]
    return None


def path_to_calls(path: np.ndarray, goal_yaw: float | None = None,
                  is_free: Callable[[float, float, float], bool] | None = None,
                  spin_rate: Callable[[float], float] | None = None) -> list[Call]:
    """``(skill, params, (x, y, yaw) after)`` calls that track ``path`` ((m, 3) x, y, yaw; metres, radians).

    ``is_free(x, y, yaw)``: where the object may be (the footprint checker of its resting state); used to place
    the V of a short last stride (module docstring). Without it, the V goes left. ``spin_rate(angle)``: the
    predicted success of a spin in this state, to split turns (:func:`spins_for`).
    """
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
        for a in spins_for(tyaw - yaw, spin_rate):
            yaw = wrap_angle(yaw + a)
            calls.append(("spin", {"angle": a}, (x, y, yaw)))
        stride = math.hypot(tx - x, ty - y)
        if stride >= MIN_PUSH or (j == last and stride > MIN_STRIDE and not calls):
            v = v_pushes(x, y, tx, ty, yaw, is_free) if j == last and stride < PUSH_STEP - 1e-9 else None
            calls += v or [("push", {"direction": math.atan2(ty - y, tx - x)}, (tx, ty, yaw))]
            x, y = tx, ty
        i = j
    if goal_yaw is not None:
        for a in spins_for(goal_yaw - yaw, spin_rate):
            yaw = wrap_angle(yaw + a)
            calls.append(("spin", {"angle": a}, (x, y, yaw)))
    return calls
