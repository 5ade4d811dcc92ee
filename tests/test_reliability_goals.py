"""Bad goals and starts raise GoalError; unplannable problems raise PlanningError naming why.

Everything goes through the public ``affordplan.plan``. A stand-in predictor (a fixed success
probability) replaces the learned success models, so these tests check the checks, not the skills.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import affordplan as ap
from affordplan.errors import AffordplanError, GoalError, InputError, PlanningError

WALL_WITH_GAP = (ap.Box(center=(0.6, -0.2), size=(0.02, 0.2, 0.1)), ap.Box(center=(0.6, 0.2), size=(0.02, 0.2, 0.1)))
START = {"resting_state": 0, "xy": (0.45, 0.0), "yaw": 0.0}


class FixedPredictor:
    """Every skill call succeeds with probability ``p`` (no networks)."""

    def __init__(self, p: float = 0.8):
        self.p = p

    def p_success(self, skill, params, T):
        return self.p

    def p_success_many(self, queries):
        return np.full(len(queries), self.p)


@pytest.fixture(scope="module")
def cube():
    return ap.load_object("cube")


def plan(obj, goal, **kwargs):
    kwargs.setdefault("start", START)
    kwargs.setdefault("predictor", FixedPredictor())
    return ap.plan(obj, goal, **kwargs)


def test_a_good_problem_plans(cube):
    """The baseline the other cases break: the same call with a free goal succeeds."""
    result = plan(cube, ap.Goal(xy=(0.69, 0.0), yaw=0.0), obstacles=WALL_WITH_GAP)
    assert result.steps and ap.Goal(xy=(0.69, 0.0), yaw=0.0).reached(cube, result.steps[-1].expected_pose)


# ---------------------------------------------------------------- goals
def test_goal_inside_an_obstacle(cube):
    with pytest.raises(GoalError, match=r"goal xy=\(0.6, 0.2\) is not reachable .*overlaps obstacle 1"):
        plan(cube, ap.Goal(xy=(0.6, 0.2)), obstacles=WALL_WITH_GAP)


@pytest.mark.parametrize("xy", [(0.95, 0.0), (0.5, -0.5), (0.0, 0.0), (1e6, 1e6)])
def test_goal_outside_the_workspace(cube, xy):
    with pytest.raises(GoalError, match="outside the workspace"):
        plan(cube, ap.Goal(xy=xy))


@pytest.mark.parametrize("kwargs", [
    dict(xy=(math.nan, 0.0)), dict(xy=(0.5, math.inf)), dict(xy=(0.5,)), dict(xy=(0.5, 0.0, 0.0)),
    dict(xy="here"), dict(xy=None),
    dict(xy=(0.5, 0.0), yaw=math.nan), dict(xy=(0.5, 0.0), xy_tol=math.nan), dict(xy=(0.5, 0.0), yaw_tol=-1.0),
])
def test_nan_or_malformed_goal(kwargs):
    with pytest.raises(GoalError, match="goal"):
        ap.Goal(**kwargs)


def test_a_goal_that_is_not_a_goal(cube):
    with pytest.raises(GoalError, match="goal must be an affordplan.Goal"):
        plan(cube, (0.6, 0.0))


@pytest.mark.parametrize("state", [6, 99, -1])
def test_goal_in_an_unknown_resting_state(cube, state):
    with pytest.raises(GoalError, match=f"goal resting_state {state} does not exist: cube has 6"):
        plan(cube, ap.Goal(xy=(0.55, 0.0), resting_state=state))


def test_goal_resting_state_that_is_not_an_index():
    with pytest.raises(GoalError, match="resting_state must be an integer"):
        ap.Goal(xy=(0.55, 0.0), resting_state=1.5)


# ---------------------------------------------------------------- starts
def test_start_in_collision(cube):
    start = {"resting_state": 0, "xy": (0.6, 0.2), "yaw": 0.0}  # inside the wall
    with pytest.raises(GoalError, match="the start pose is in collision: .*overlaps obstacle 1"):
        plan(cube, ap.Goal(xy=(0.45, 0.0)), start=start, obstacles=WALL_WITH_GAP)


def test_start_in_collision_with_the_greedy_baseline_too(cube):
    start = {"resting_state": 0, "xy": (0.6, 0.2), "yaw": 0.0}
    with pytest.raises(GoalError, match="in collision"):
        plan(cube, ap.Goal(xy=(0.45, 0.0)), start=start, obstacles=WALL_WITH_GAP, planner="greedy")


def test_start_in_collision_given_as_a_pose(cube):
    T = cube.resting_states[0].pose((0.6, -0.2), 0.3)
    with pytest.raises(GoalError, match="in collision"):
        plan(cube, ap.Goal(xy=(0.45, 0.0)), start=T, obstacles=WALL_WITH_GAP)


def test_start_outside_the_workspace(cube):
    with pytest.raises(GoalError, match="start .* is outside the workspace"):
        plan(cube, ap.Goal(xy=(0.45, 0.0)), start={"resting_state": 0, "xy": (1.2, 0.0), "yaw": 0.0})


def test_start_in_an_unknown_resting_state(cube):
    with pytest.raises(GoalError, match="start resting_state 7 does not exist"):
        plan(cube, ap.Goal(xy=(0.45, 0.0)), start={"resting_state": 7, "xy": (0.5, 0.0)})


@pytest.mark.parametrize("start", [
    {"resting_state": 0, "xy": (math.nan, 0.0)}, {"resting_state": 0, "xy": (0.5, 0.0), "yaw": math.inf},
    {"resting_state": "top", "xy": (0.5, 0.0)}, {"xy": (0.5, 0.0), "colour": "red"},
    np.full((4, 4), np.nan), np.zeros((4, 4)), "anywhere",
])
def test_malformed_start(cube, start):
    with pytest.raises(InputError, match="start"):
        plan(cube, ap.Goal(xy=(0.45, 0.0)), start=start)


def test_start_close_to_an_obstacle_but_clear_of_it_plans(cube):
    """Within the fingertip clearance of the wall but not touching it: legal, the plan pushes it clear."""
    wall = (ap.Box(center=(0.5, 0.085), size=(0.3, 0.02, 0.1)),)  # its face 1.5 cm from the cube's side
    result = plan(cube, ap.Goal(xy=(0.62, -0.05)), start={"resting_state": 0, "xy": (0.5, 0.0), "yaw": 0.0},
                  obstacles=wall)
    first = result.steps[0]
    assert first.skill == "push" and math.sin(first.params["direction"]) < 0  # away from the wall


# ---------------------------------------------------------------- no plan within the budget
def test_goal_walled_in(cube):
    """The goal is free, but four walls close it in: no path exists."""
    pen = (ap.Box(center=(0.43, 0.1), size=(0.02, 0.26, 0.1)), ap.Box(center=(0.67, 0.1), size=(0.02, 0.26, 0.1)),
           ap.Box(center=(0.55, -0.02), size=(0.26, 0.02, 0.1)), ap.Box(center=(0.55, 0.22), size=(0.26, 0.02, 0.1)))
    with pytest.raises(PlanningError, match=r"no collision-free path from .* within .* s \(OMPL: "):
        plan(cube, ap.Goal(xy=(0.55, 0.1)), start={"resting_state": 0, "xy": (0.35, -0.2)}, obstacles=pen,
             time_limit=0.5)


def test_budget_too_small(cube):
    with pytest.raises(PlanningError, match=r"within 1e-06 s|ran out of its"):
        plan(cube, ap.Goal(xy=(0.69, 0.0), yaw=0.0), obstacles=WALL_WITH_GAP, time_limit=1e-6)


def test_no_room_to_roll(cube):
    """A face change is asked for, but obstacles leave no spot where the cube can tip over."""
    posts = tuple(ap.Box(center=(x, y), size=(0.02, 0.02, 0.1))
                  for x in np.arange(0.3, 0.76, 0.09) for y in np.arange(-0.3, 0.31, 0.09)
                  if math.hypot(x - 0.48, y - 0.03) > 0.06)
    with pytest.raises(PlanningError, match="no room anywhere in the workspace to roll from state 0"):
        plan(cube, ap.Goal(xy=(0.48, 0.03), resting_state=1), start={"resting_state": 0, "xy": (0.48, 0.03)},
             obstacles=posts)


@pytest.mark.parametrize("time_limit", [0.0, -1.0, math.nan, "5"])
def test_bad_budget(cube, time_limit):
    with pytest.raises(InputError, match="time_limit"):
        plan(cube, ap.Goal(xy=(0.6, 0.0)), time_limit=time_limit)


def test_every_failure_is_one_catchable_type(cube):
    for call in (lambda: plan(cube, ap.Goal(xy=(0.95, 0.0))), lambda: ap.Goal(xy=(math.nan, 0.0)),
                 lambda: plan(cube, ap.Goal(xy=(0.6, 0.0)), planner="magic"), lambda: ap.plan("cube", None)):
        with pytest.raises(AffordplanError):
            call()
