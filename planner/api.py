"""``affordplan.plan``: from an object, a start and a goal to an executable plan."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any, Literal, get_args

import numpy as np

from affordplan.checks import as_finite, as_seed, as_vector, as_whole, describe
from affordplan.errors import GoalError, InputError
from affordplan.goal import Goal, StartLike
from affordplan.objects.model import ObjectModel
from affordplan.world import Box, Workspace, as_box
from planner.footprint import footprint
from planner.motion import FootprintChecker
from planner.plan import MAX_STRIDES, WORKSPACE_OVERHANG, Plan, Planner
from planner.predict import Predictor

PlannerName = Literal["affordplan", "greedy"]
PLANNERS: tuple[PlannerName, ...] = get_args(PlannerName)


START_TILT_MAX = math.radians(10.0)  # a start pose is this close to one of its resting states, or refused
START_HEIGHT_MAX = 0.01  # metres off the state's resting height (a pose floating above the table is refused)


def start_pose(obj: ObjectModel, start: StartLike) -> np.ndarray:
    """The 4x4 world pose of ``start``: a dict ``{"resting_state", "xy", "yaw"}`` or a 4x4 pose."""
    if start is None:
        start = {}
    if isinstance(start, dict):
        unknown = set(start) - {"resting_state", "xy", "yaw"}
        if unknown:
            raise InputError(f"start takes resting_state, xy and yaw; got {sorted(unknown)}")
        state = as_whole("start resting_state", start.get("resting_state", 0))
        n = len(obj.resting_states)
        if not 0 <= state < n:
            raise GoalError(f"start resting_state {state} does not exist: {obj.name} has {n} resting states "
                            f"(0..{n - 1})")
        xy = as_vector("start xy (metres)", start.get("xy", Workspace().center), 2)
        yaw = as_finite("start yaw (radians)", start.get("yaw", 0.0))
        return obj.resting_states[state].pose(xy, yaw)
    try:
        T = np.asarray(start, dtype=float)
    except (TypeError, ValueError):
        T = np.empty(0)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise InputError("start must be a dict or a finite 4x4 pose")
    R = T[:3, :3]
    if not (np.allclose(R.T @ R, np.eye(3), atol=1e-6) and np.linalg.det(R) > 0):
        raise InputError("start pose's upper-left 3x3 block must be a rotation matrix")
    return T


def check_start(obj: ObjectModel, T_start: np.ndarray, obstacles: Sequence[Box], workspace: Workspace) -> None:
    """Raise :class:`GoalError` when the object at ``T_start`` overlaps an obstacle or its centre is off
    the workspace.

    The object's own footprint is checked, not the one the planner inflates for the fingertip: a
    start closer to an obstacle than that clearance is legal (the plan then pushes it clear first).
    """
    state, x, y, yaw = obj.planar_pose(T_start)
    tilt = obj.tilt_from_state(T_start, state)
    if tilt > START_TILT_MAX:
        raise GoalError(f"the start pose is tipped {math.degrees(tilt):.0f} deg from every resting state; a start "
                        f"must rest on the table (at most {math.degrees(START_TILT_MAX):.0f} deg off)")
    height = float(T_start[2, 3]) - obj.resting_states[state].height
    if abs(height) > START_HEIGHT_MAX:
        raise GoalError(f"the start pose is {100 * height:+.1f} cm off the table's contact height; a start must rest "
                        f"on the table (within {100 * START_HEIGHT_MAX:.0f} cm)")
    if not workspace.contains((x, y)):
        raise GoalError(f"the start xy=({x:.3f}, {y:.3f}) is outside the workspace {workspace}")
    m = WORKSPACE_OVERHANG
    grown = Workspace((workspace.x[0] - m, workspace.x[1] + m), (workspace.y[0] - m, workspace.y[1] + m))
    why = FootprintChecker(footprint(obj, state), obstacles, grown).why_not_free(x, y, yaw)
    if why is not None:
        raise GoalError(f"the start pose is in collision: {why}")


def plan(obj: ObjectModel, goal: Goal, *, start: StartLike = None,
         obstacles: Iterable[Box | Mapping[str, Any]] = (), time_limit: float = 5.0,
         planner: PlannerName = "affordplan", seed: int = 0, predictor: Predictor | None = None,
         workspace: Workspace = Workspace(), max_strides: int = MAX_STRIDES) -> Plan:
    """Plan to bring ``obj`` from ``start`` to ``goal`` among ``obstacles`` (see :class:`planner.plan.Planner`).

    ``start``: a :class:`affordplan.goal.Start` dict ``{"resting_state": i, "xy": (x, y), "yaw": rad}`` (each key
    optional) or a 4x4 world pose. ``obstacles``: :class:`affordplan.Box` objects, or dicts in the scene-file form
    ``{"center": [x, y], "size": [sx, sy, sz], "yaw": rad}`` (or ``"yaw_deg"``; :meth:`affordplan.Box.from_dict`).

    ``planner="greedy"`` returns the reactive baseline: a plan without steps whose ``execute`` picks
    every call on the spot (:func:`planner.execute.execute_greedy`).

    ``max_strides``: the 5 cm strides one push call may make, correcting its course between strokes
    (:func:`planner.plan.merge_strides`); 1 makes every push one stroke, as until 0.24.

    Raises:
        GoalError: the goal is malformed, in an obstacle, off the workspace or in a resting state the
            object does not have; or the start is in collision, off the workspace or in a resting
            state the object does not have.
        InputError: a malformed start (NaN, wrong shape, unknown keys), obstacle, planner or time limit.
        PlanningError: no plan within ``time_limit``; the message names why (no collision-free path,
            no room to roll, no chain of rolls, out of time).
    """
    if not isinstance(obj, ObjectModel):
        raise InputError(f"obj must be an ObjectModel (see affordplan.load_object), got {type(obj).__name__}")
    if planner not in PLANNERS:
        raise InputError(f"planner must be one of {PLANNERS}, got {planner!r}")
    if not isinstance(goal, Goal):
        raise GoalError(f"goal must be an affordplan.Goal, got {type(goal).__name__}")
    time_limit = as_finite("time_limit (seconds)", time_limit, 0.0, 3600.0)
    if time_limit == 0.0:
        raise InputError("time_limit must be a positive number of seconds, got 0")
    seed = as_seed("seed", seed)
    if isinstance(obstacles, (str, bytes, Mapping)) or not hasattr(obstacles, "__iter__"):
        raise InputError(f"obstacles must be a sequence of affordplan.Box (or of box dicts), got "
                         f"{describe(obstacles)}")
    T0 = start_pose(obj, start)
    boxes = tuple(as_box(b, f"obstacles[{i}]") for i, b in enumerate(obstacles))
    p = Planner(obj, boxes, workspace, predictor=predictor, time_limit=time_limit, seed=seed, max_strides=max_strides)
    check_start(obj, T0, boxes, workspace)
    if planner == "greedy":
        p.check_goal(goal, obj.classify(T0))
        return Plan(steps=[], p_success=float("nan"), planning_time=0.0, route=[], goal=goal, start_pose=T0,
                    planner=p, kind="greedy")
    return p.plan(T0, goal)
