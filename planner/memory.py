"""What closed-loop execution learns from failures: which calls failed, and where rolls failed.

A failure is remembered by its (resting state, skill, parameter bucket relative to the object)
(:func:`failure_key`): pushes in 45 deg sectors of the object's frame, spins by their sense, rolls by their
target. A call that failed :data:`FAILURES_TO_AVOID` times is avoided by the plans that follow (a push only within
:data:`PUSH_FAILURE_RADIUS` of where it failed), and a place where rolls failed :data:`ROLL_SPOT_FAILURES` times is
not rolled at again (:meth:`FailureMemory.spoiled`).

Push failures are local: a push is made by a fingertip on a cloud, and one that fails where the object lies (against
a wall, on a handle) says little about the same push a few centimetres on. Until 0.24 a push direction that had
failed twice anywhere was avoided for the rest of the execution, and plans went round it with detours of 35-85 deg;
on the plan bench's 400 tasks, not going round pushes that failed twice at all reached 0.815 against 0.785 (13 of the
14 outcomes that differed), but repeats a push that fails where it stands for the whole budget.
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
PUSH_FAILURE_RADIUS = 0.03  # metres: a push's failures count against it within this distance of where they happened


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
    push_spots: list[tuple[tuple, float, float]] = field(default_factory=list)  # (failure key, x, y) of failed pushes

    def record(self, skill: str, params: dict, T_world_object: np.ndarray) -> int:
        """Remember a failed call at the object's pose ``T_world_object``; returns how often it has failed."""
        key = failure_key(self.obj, skill, params, T_world_object)
        self.failures[key] += 1
        x, y = float(T_world_object[0, 3]), float(T_world_object[1, 3])
        if skill == "roll":
            self.roll_spots.append((x, y))
        if skill == "push":
            self.push_spots.append((key, x, y))
        return self.count(skill, params, T_world_object)

    def count(self, skill: str, params: dict, T_world_object: np.ndarray) -> int:
        """How often this (state, skill, parameter bucket) has failed; for a push, within
        :data:`PUSH_FAILURE_RADIUS` of the object's position in ``T_world_object``."""
        key = failure_key(self.obj, skill, params, T_world_object)
        if skill != "push":
            return self.failures[key]
        x, y = float(T_world_object[0, 3]), float(T_world_object[1, 3])
        return sum(k == key and math.hypot(x - fx, y - fy) <= PUSH_FAILURE_RADIUS for k, fx, fy in self.push_spots)

    def avoided(self, skill: str, params: dict, T_world_object: np.ndarray) -> bool:
        """Whether this call failed :data:`FAILURES_TO_AVOID` times (a push: near here, :meth:`count`)."""
        return self.count(skill, params, T_world_object) >= FAILURES_TO_AVOID

    def spoiled(self, x: float, y: float) -> bool:
        """Whether rolls failed :data:`ROLL_SPOT_FAILURES` times within :data:`ROLL_SPOT_RADIUS` of (x, y)."""
        near = sum(math.hypot(x - fx, y - fy) <= ROLL_SPOT_RADIUS for fx, fy in self.roll_spots)
        return near >= ROLL_SPOT_FAILURES

    def copy(self) -> FailureMemory:
        """A memory with this one's failures, recording apart from it."""
        return FailureMemory(self.obj, Counter(self.failures), list(self.roll_spots), list(self.push_spots))

    def __bool__(self) -> bool:
        return bool(self.failures)
