"""What closed-loop execution learns from failures: which calls failed, and where rolls failed.

A failure is remembered by its (resting state, skill, parameter bucket relative to the object)
(:func:`failure_key`): pushes in 45 deg sectors of the object's frame, spins by their sense, rolls by their
target. A call that failed :data:`FAILURES_TO_AVOID` times is avoided by the plans that follow, and a place
where rolls failed :data:`ROLL_SPOT_FAILURES` times is not rolled at again (:meth:`FailureMemory.spoiled`).
The planner (:class:`planner.plan.Planner`) holds one memory; execution records into a fork of it, so a plan's
own planner never changes.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from affordplan.geometry import wrap_angle
from affordplan.objects.model import ObjectModel

FAILURES_TO_AVOID = 2  # a (state, skill, parameter) that failed this often is avoided
# A place where rolls failed this often (any target; within ROLL_SPOT_RADIUS metres) is not rolled at again:
# some spots defeat every roll (the arm cannot reach round the object there), and trying each target in
# turn at the same spot spent whole executions.
ROLL_SPOT_FAILURES = 2
ROLL_SPOT_RADIUS = 0.04  # metres


def failure_key(obj: ObjectModel, skill: str, params: dict, T_world_object: np.ndarray) -> tuple:
    """What a failure is remembered by: (state, skill, parameter bucket relative to the object)."""
    state, _, _, yaw = obj.planar_pose(T_world_object)
    if skill == "push":
        return state, skill, int(round(wrap_angle(params["direction"] - yaw) / (math.pi / 4))) % 8
    if skill == "spin":
        return state, skill, int(math.copysign(1, params["angle"]))
    return state, skill, params["target"]


@dataclass
class FailureMemory:
    """Failed calls of one object, counted by :func:`failure_key`, and the places (x, y, metres) of failed rolls."""

    obj: ObjectModel
    failures: Counter = field(default_factory=Counter)
    roll_spots: list[tuple[float, float]] = field(default_factory=list)

    def record(self, skill: str, params: dict, T_world_object: np.ndarray) -> int:
        """Remember a failed call at the object's pose ``T_world_object``; returns how often it has failed."""
        key = failure_key(self.obj, skill, params, T_world_object)
        self.failures[key] += 1
        if skill == "roll":
            self.roll_spots.append((float(T_world_object[0, 3]), float(T_world_object[1, 3])))
        return self.failures[key]

    def count(self, skill: str, params: dict, T_world_object: np.ndarray) -> int:
        """How often this (state, skill, parameter bucket) has failed."""
        return self.failures[failure_key(self.obj, skill, params, T_world_object)]

    def avoided(self, skill: str, params: dict, T_world_object: np.ndarray) -> bool:
        """Whether this call failed :data:`FAILURES_TO_AVOID` times."""
        return self.count(skill, params, T_world_object) >= FAILURES_TO_AVOID

    def spoiled(self, x: float, y: float) -> bool:
        """Whether rolls failed :data:`ROLL_SPOT_FAILURES` times within :data:`ROLL_SPOT_RADIUS` of (x, y)."""
        near = sum(math.hypot(x - fx, y - fy) <= ROLL_SPOT_RADIUS for fx, fy in self.roll_spots)
        return near >= ROLL_SPOT_FAILURES

    def copy(self) -> FailureMemory:
        """A memory with this one's failures, recording apart from it."""
        return FailureMemory(self.obj, Counter(self.failures), list(self.roll_spots))

    def __bool__(self) -> bool:
        return bool(self.failures)
