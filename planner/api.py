"""``affordplan.plan``: from an object, a start and a goal to an executable plan."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from affordplan.errors import GoalError, InputError
from affordplan.goal import Goal
from affordplan.objects.model import ObjectModel
from affordplan.world import Box, Workspace
from planner.plan import Plan, Planner
from planner.predict import Predictor

PLANNERS = ("affordplan", "greedy")


def start_pose(obj: ObjectModel, start) -> np.ndarray:
    """The 4x4 world pose of ``start``: a dict ``{"resting_state", "xy", "yaw"}`` or a 4x4 pose."""
    if start is None:
        start = {}
    if isinstance(start, dict):
        unknown = set(start) - {"resting_state", "xy", "yaw"}
        if unknown:
            raise InputError(f"start takes resting_state, xy and yaw; got {sorted(unknown)}")
        state = start.get("resting_state", 0)
        n = len(obj.resting_states)
        if not isinstance(state, (int, np.integer)) or not 0 <= state < n:
            raise InputError(f"start resting_state must be an index in [0, {n}), got {state!r}")
        xy = np.asarray(start.get("xy", Workspace().center), dtype=float)
        yaw = start.get("yaw", 0.0)
        if xy.shape != (2,) or not np.all(np.isfinite(xy)) or not math.isfinite(yaw):
            raise InputError(f"start xy must be 2 finite numbers and yaw finite, got {start!r}")
        return obj.resting_states[int(state)].pose(xy, float(yaw))
    T = np.asarray(start, dtype=float)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise InputError("start must be a dict or a finite 4x4 pose")
    return T


def plan(obj: ObjectModel, goal: Goal, *, start=None, obstacles: Sequence[Box] = (), time_limit: float = 5.0,
         planner: str = "affordplan", seed: int = 0, predictor: Predictor | None = None,
         workspace: Workspace = Workspace()) -> Plan:
    """Plan to bring ``obj`` from ``start`` to ``goal`` among ``obstacles`` (see :class:`planner.plan.Planner`).

    ``planner="greedy"`` returns the reactive baseline: a plan without steps whose ``execute`` picks
    every call on the spot (:func:`planner.execute.execute_greedy`).
    """
    if planner not in PLANNERS:
        raise InputError(f"planner must be one of {PLANNERS}, got {planner!r}")
    if not isinstance(goal, Goal):
        raise GoalError(f"goal must be an affordplan.Goal, got {type(goal).__name__}")
    if not (isinstance(time_limit, (int, float)) and math.isfinite(time_limit) and time_limit > 0):
        raise InputError(f"time_limit must be a positive number of seconds, got {time_limit!r}")
    T0 = start_pose(obj, start)
    p = Planner(obj, obstacles, workspace, predictor=predictor, time_limit=time_limit, seed=seed)
    if planner == "greedy":
        p.check_goal(goal, obj.classify(T0))
        return Plan(steps=[], p_success=float("nan"), planning_time=0.0, route=[], goal=goal, start_pose=T0,
                    planner=p, kind="greedy")
    state, x, y, yaw = obj.planar_pose(T0)
    why = p.checkers[state].why_not_free(x, y, yaw)
    if why is not None:
        raise InputError(f"the start pose collides or leaves the workspace: {why}")
    return p.plan(T0, goal)
