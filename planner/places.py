"""Where on the table the planner puts the object: the free part of a goal's region, a free yaw, the nearest free
place, and room to roll.

Each search is a small grid or ring search over the footprint checkers of the object's resting states
(:mod:`planner.motion`); what the planner has learned from failures (spots where rolls failed, pushes it avoids) is
passed in by the caller, so a :class:`Places` holds geometry only and is shared by a planner's forks.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from affordplan.errors import GoalError, PlanningError
from affordplan.geometry import wrap_angle
from affordplan.goal import Goal
from affordplan.objects.model import ObjectModel
from affordplan.world import Box, Workspace
from planner.motion import FootprintChecker
from planner.predict import state_pose

# A goal is a region: where its exact point is not free, the plan aims at the nearest free placement (rings of
# GOAL_AIM_RING metres, turns of GOAL_AIM_YAW_STEP radians) within GOAL_AIM_SHARE of its tolerances.
GOAL_AIM_SHARE = 0.6
GOAL_AIM_RING = 0.002
GOAL_AIM_YAW_STEP = math.radians(2.5)
FREE_YAW_STEPS = np.radians([0.0] + [sign * a for a in range(5, 180, 5) for sign in (1, -1)] + [180.0])
FREE_SEARCH_SLACK = 0.02  # metres past the nearest free position that nearest_free looks for a better one


def disc(radius: float, n: int) -> np.ndarray:
    """A regular ``n``-gon of circumradius ``radius`` metres about the origin, (n, 2)."""
    a = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return radius * np.stack([np.cos(a), np.sin(a)], axis=1)


def grid_argmin(workspace: Workspace, cost: Callable[[float, float], float], ok: Callable[[float, float], bool],
                step: float = 0.01) -> tuple[float, float] | None:
    """The point of a ``step`` (metres) grid over ``workspace`` with the lowest ``cost`` among those where ``ok``
    holds (the first on a tie, x then y ascending; ``ok``, the costly test, only where the cost would win);
    ``None`` where it holds nowhere."""
    best, best_cost = None, math.inf
    for px in np.arange(workspace.x[0], workspace.x[1] + 1e-9, step):
        for py in np.arange(workspace.y[0], workspace.y[1] + 1e-9, step):
            c = cost(float(px), float(py))
            if c < best_cost and ok(float(px), float(py)):
                best, best_cost = (float(px), float(py)), c
    return best


class Places:
    """The planner's place searches for one object among obstacles.

    Args:
        obj: the object.
        checkers: one footprint checker per resting state (inflated footprints; :func:`planner.plan.make_checkers`).
        workspace: where grid searches look (world frame, metres).
        obstacles: the boxes (for the room a roll needs).
        radius: each resting state's inflated footprint's circumscribed radius, metres.
        clearance: metres the footprints were inflated by.
        roll_margin: metres around a roll spot kept clear for the displacement a roll causes.
        reach: metres from the arm's base within which spins are placed with room to drift; ``None``: anywhere.
    """

    def __init__(self, obj: ObjectModel, checkers: dict[int, FootprintChecker], workspace: Workspace,
                 obstacles: tuple[Box, ...], radius: dict[int, float], clearance: float, roll_margin: float,
                 reach: float | None):
        self.obj = obj
        self.checkers = checkers
        self.workspace = workspace
        self.obstacles = tuple(obstacles)
        self.radius = radius
        self.clearance = clearance
        self.roll_margin = roll_margin
        self.reach = reach

    def aim(self, goal: Goal, state: int) -> Goal:
        """The point of the goal's region the plan aims at: the goal itself where the object fits there, else the
        free placement nearest it within the region (a goal is its tolerance disc and yaw interval, not a point).

        Aims stay inside ``GOAL_AIM_SHARE`` of the tolerances, so the drift of the last primitive still leaves the
        object in the region. Raises :class:`GoalError` when no part of the region is free.
        """
        checker = self.checkers[state]
        free_yaw = goal.yaw_free(self.obj, state)
        if free_yaw:  # the yaws free_yaw will try to place the object at the goal
            yaws = [(0.0, float(a)) for a in FREE_YAW_STEPS]
        else:  # the goal's yaw, the yaws its state's symmetry makes equal to it, then turns within the interval
            period = goal.period(self.obj, state)
            turns = [0.0] + [s * a for a in np.arange(GOAL_AIM_YAW_STEP, GOAL_AIM_SHARE * goal.yaw_tol + 1e-9,
                                                        GOAL_AIM_YAW_STEP) for s in (1.0, -1.0)]
            yaws = [(abs(d), goal.yaw + d + k * period) for d in turns
                    for k in range(int(round(2.0 * math.pi / period)))]
        reach = GOAL_AIM_SHARE * goal.xy_tol
        spots = [(0.0, *goal.xy)]
        for r in np.arange(GOAL_AIM_RING, reach + 1e-9, GOAL_AIM_RING):
            n = max(8, int(2 * math.pi * r / GOAL_AIM_RING))
            spots += [(float(r), goal.xy[0] + r * math.cos(a), goal.xy[1] + r * math.sin(a))
                      for a in np.linspace(-math.pi, math.pi, n, endpoint=False)]
        best = None
        for r, x, y in spots:
            if best is not None and r > best[0]:
                break
            for turn, a in sorted(yaws):
                if self.workspace.contains((x, y)) and checker.is_free(x, y, a):
                    if best is None or (r, turn) < best[:2]:
                        best = (r, turn, x, y, a)
                    break
        if best is None:
            why = checker.why_not_free(*goal.xy, yaws[0][1])
            raise GoalError(f"goal xy={goal.xy} is not reachable by the object in resting state {state}: no free "
                            f"placement within {100 * reach:.1f} cm of it ({why})")
        r, turn, x, y, a = best
        if r == 0.0 and turn == 0.0:
            return goal
        return replace(goal, xy=(float(x), float(y)), yaw=None if free_yaw else float(wrap_angle(a)),
                       xy_tol=goal.xy_tol - r, yaw_tol=goal.yaw_tol - turn)

    def free_yaw(self, state: int, xy, prefer: float) -> float:
        """The yaw nearest ``prefer`` (5 deg steps either way, all round) at which ``state`` is free at ``xy``.

        All round: an object near the arm's reach may be free at a few yaws only (the goal check found one).
        """
        checker = self.checkers[state]
        for d in FREE_YAW_STEPS:
            if checker.is_free(xy[0], xy[1], prefer + d):
                return float(wrap_angle(prefer + d))
        raise PlanningError(f"no free orientation of resting state {state} at {tuple(np.round(xy, 3))}")

    def nearest_free(self, state: int, cur, toward,
                     avoided: Callable[[str, dict, np.ndarray], bool]) -> tuple[float, float]:
        """Where to push an object that is not free at ``cur`` (x, y, yaw), at its yaw: of the free positions
        (5 mm rings) at most ``FREE_SEARCH_SLACK`` farther than the nearest, one the push to which is not avoided
        (``avoided(skill, params, T)``, the planner's rule: no room for the
        fingertip, or failed twice), and of those the one nearest ``toward``
        (x, y: where the segment goes). A die pressed against a block, its goal along the block, was pushed off
        it on the side nearest by a hair, away from the goal and out of the arm's reach."""
        T = state_pose(self.obj, state, *cur)
        found: list[tuple[bool, float, float, float]] = []  # (avoided, distance to toward, x, y)
        first = None
        for r in np.arange(0.005, 0.3, 0.005):
            if first is not None and r > first + FREE_SEARCH_SLACK:
                break
            for a in np.linspace(-math.pi, math.pi, max(8, int(2 * math.pi * r / 0.005)), endpoint=False):
                px, py = cur[0] + r * math.cos(a), cur[1] + r * math.sin(a)
                if self.checkers[state].is_free(px, py, cur[2]):
                    first = r if first is None else first
                    found.append((avoided("push", {"direction": float(a)}, T),
                                  math.hypot(px - toward[0], py - toward[1]), float(px), float(py)))
        if not found:
            raise PlanningError(f"the object is stuck at {tuple(np.round(cur[:2], 3))}: no free position nearby")
        _, _, px, py = min(found)
        return px, py

    def roll_spot(self, a: int, b: int, cur, goal: Goal, late: bool = False,
                  spoiled: Callable[[float, float], bool] = lambda x, y: False) -> tuple[float, float]:
        """Nearest place, to the object (``cur``: x, y, yaw) or with ``late`` to the goal, where a roll from
        state ``a`` to ``b`` has room.

        The room is a disc around the object, clear of obstacles. A disc inside the workspace is preferred
        (rolls near its edge drift out of it); where no such spot exists (a big object among obstacles),
        the disc may reach over the edge while the object's own footprint stays inside.
        """
        r = max(self.radius[a], self.radius[b]) + self.roll_margin
        shape = disc(r, 16)
        ws = self.workspace
        grown = Workspace(x=(ws.x[0] - r, ws.x[1] + r), y=(ws.y[0] - r, ws.y[1] + r))
        near = (goal.xy[0], goal.xy[1], cur[2]) if late else cur
        for room in (FootprintChecker(shape, self.obstacles, ws), FootprintChecker(shape, self.obstacles, grown)):
            spot = self._nearest_room(room, a, near, goal, spoiled)
            if spot is not None:
                return spot
        raise PlanningError(f"no room anywhere in the workspace to roll from state {a} to state {b}")

    def _nearest_room(self, room: FootprintChecker, a: int, cur, goal: Goal,
                      spoiled: Callable[[float, float], bool]) -> tuple[float, float] | None:
        """Where to roll: the object's own place when it has room, else the free spot (1 cm grid) nearest the
        object and then the goal."""
        if room.is_free(cur[0], cur[1], 0.0) and self.checkers[a].is_free(*cur) and not spoiled(*cur[:2]):
            return float(cur[0]), float(cur[1])
        return grid_argmin(self.workspace,
                            lambda px, py: math.hypot(px - cur[0], py - cur[1])
                            + 0.5 * math.hypot(px - goal.xy[0], py - goal.xy[1]),
                            lambda px, py: room.is_free(px, py, 0.0) and self.checkers[a].is_free(px, py, cur[2])
                            and not spoiled(px, py))
