"""SE(2) motion planning of a footprint among boxes: the fcl checker and OMPL's RRT-Connect."""

from __future__ import annotations

import math
import time

import fcl
import numpy as np
import pytest

import affordplan as ap
from affordplan.errors import GoalError, InputError, PlanningError
from affordplan.geometry import rot_z
from planner.footprint import footprint, inflate, place
from planner.motion import FootprintChecker, interpolate_path, path_length, plan_path

WORKSPACE = ap.Workspace()
GAP = 0.16  # metres between the two halves of the wall
WALL_X = 0.525
WALL = (
    ap.Box(center=(WALL_X, -(GAP / 2 + 0.11)), size=(0.03, 0.22, 0.1)),
    ap.Box(center=(WALL_X, GAP / 2 + 0.11), size=(0.03, 0.22, 0.1)),
)
START = (0.4, 0.2, 0.0)
GOAL = (0.65, 0.2, 1.0)


@pytest.fixture(scope="module")
def cube_footprint(cube) -> np.ndarray:
    return inflate(footprint(cube, 0), 0.01)  # a 12 cm square with rounded corners


@pytest.fixture(scope="module")
def wall_checker(cube_footprint) -> FootprintChecker:
    return FootprintChecker(cube_footprint, WALL, WORKSPACE)


def _sat_overlap(P: np.ndarray, Q: np.ndarray) -> bool:
    """Separating-axis test of two convex polygons (no fcl)."""
    for poly in (P, Q):
        e = np.roll(poly, -1, axis=0) - poly
        for n in np.column_stack([e[:, 1], -e[:, 0]]):
            a, b = P @ n, Q @ n
            if a.max() < b.min() or b.max() < a.min():
                return False
    return True


class _IndependentFcl:
    """A second fcl model of the scene: the footprint prism as a triangle BVH, boxes built from corners."""

    def __init__(self, polygon: np.ndarray, boxes):
        k = len(polygon)
        verts = np.vstack([np.column_stack([polygon, np.full(k, -0.05)]), np.column_stack([polygon, np.full(k, 0.05)])])
        tris = [[0, i + 1, i] for i in range(1, k - 1)] + [[k, k + i, k + i + 1] for i in range(1, k - 1)]
        for i in range(k):
            j = (i + 1) % k
            tris += [[i, j, k + j], [i, k + j, k + i]]
        bvh = fcl.BVHModel()
        bvh.beginModel(len(verts), len(tris))
        bvh.addSubModel(verts, np.array(tris))
        bvh.endModel()
        self.footprint = fcl.CollisionObject(bvh, fcl.Transform())
        self.boxes = []
        for box in boxes:
            corners = box.corners_xy()
            sx, sy = np.linalg.norm(corners[1] - corners[0]), np.linalg.norm(corners[2] - corners[1])
            yaw = math.atan2(*(corners[1] - corners[0])[::-1])
            T = fcl.Transform(rot_z(yaw), np.array([*corners.mean(axis=0), 0.0]))
            self.boxes.append(fcl.CollisionObject(fcl.Box(sx, sy, 1.0), T))

    def collides(self, x: float, y: float, yaw: float) -> bool:
        self.footprint.setTransform(fcl.Transform(rot_z(yaw), np.array([x, y, 0.0])))
        return any(fcl.collide(self.footprint, b, fcl.CollisionRequest(), fcl.CollisionResult()) for b in self.boxes)


def _independently_free(polygon: np.ndarray, boxes, independent: _IndependentFcl, pose) -> bool:
    placed = place(polygon, *pose)
    inside = (placed.min(axis=0) >= (WORKSPACE.x[0], WORKSPACE.y[0])).all() and (
        placed.max(axis=0) <= (WORKSPACE.x[1], WORKSPACE.y[1])).all()
    return inside and not independent.collides(*pose) and not any(
        _sat_overlap(placed, b.corners_xy()) for b in boxes)


def test_checker_sees_a_box_and_is_free_20cm_away(cube):
    fp = footprint(cube, 0)
    box = ap.Box(center=(0.5, 0.0), size=(0.04, 0.04, 0.1))
    checker = FootprintChecker(fp, [box], WORKSPACE)
    assert not checker.is_free(0.5, 0.0, 0.0)
    assert not checker.is_free(0.5, 0.06, 0.3)
    assert checker.is_free(0.5, 0.2, 0.0) and checker.is_free(0.65, 0.0, 1.0)
    assert checker.clearance(0.5, 0.2, 0.0) == pytest.approx(0.2 - 0.05 - 0.02, abs=1e-4)
    assert checker.clearance(0.5, 0.0, 0.0) == 0.0
    assert "obstacle 0" in checker.why_not_free(0.5, 0.0, 0.0)
    assert checker.why_not_free(0.5, 0.2, 0.0) is None
    assert not checker.is_free(float("nan"), 0.0, 0.0)


def test_checker_flags_workspace_exits(cube):
    checker = FootprintChecker(footprint(cube, 0), (), WORKSPACE)
    assert checker.is_free(0.36, 0.0, 0.0)
    assert not checker.is_free(0.34, 0.0, 0.0)  # the square's left side at x = 0.29
    assert checker.is_free(0.5, 0.25, 0.0) and not checker.is_free(0.5, 0.25, math.pi / 4)  # corner out
    assert "workspace" in checker.why_not_free(0.5, 0.29, 0.0)
    assert checker.clearance(0.5, 0.0, 0.0) == math.inf


def test_checker_keeps_the_footprint_within_the_arms_reach(cube):
    """With ``reach``, every vertex of the 10 cm square must lie within that distance of the base (origin)."""
    checker = FootprintChecker(footprint(cube, 0), (), WORKSPACE, reach=0.7)
    assert checker.is_free(0.64, 0.0, 0.0)  # far side at x = 0.69
    assert not checker.is_free(0.66, 0.0, 0.0)  # far side at x = 0.71
    assert not checker.is_free(0.635, 0.0, math.pi / 4)  # turned, a corner 7.1 cm out: at x = 0.706
    assert checker.is_free(0.62, 0.0, math.pi / 4)
    wide = FootprintChecker(footprint(cube, 0), (), ap.Workspace(x=(0.3, 0.9), y=(-0.5, 0.5)), reach=0.7)
    assert wide.is_free(0.45, 0.4, 0.0)  # the far corner (0.5, 0.45) is 0.673 m from the base
    assert not wide.is_free(0.5, 0.45, 0.0)  # the far corner (0.55, 0.5) is 0.743 m from it
    assert "within 0.7 m of the arm's base" in checker.why_not_free(0.66, 0.0, 0.0)
    assert FootprintChecker(footprint(cube, 0), (), WORKSPACE).is_free(0.66, 0.0, 0.0)  # no reach: no limit
    with pytest.raises(InputError):
        FootprintChecker(footprint(cube, 0), (), WORKSPACE, reach=-1.0)


def test_checker_agrees_with_a_separating_axis_test(pill_bottle):
    fp = inflate(footprint(pill_bottle, 0), 0.005)
    boxes = [ap.Box(center=(0.5, 0.0), size=(0.1, 0.03, 0.1), yaw=0.7),
             ap.Box(center=(0.65, 0.15), size=(0.05, 0.2, 0.1), yaw=-0.3)]
    checker = FootprintChecker(fp, boxes, WORKSPACE)
    rng = np.random.default_rng(0)
    hits = 0
    for x, y, yaw in rng.uniform((0.35, -0.25, -math.pi), (0.7, 0.25, math.pi), size=(400, 3)):
        expected = any(_sat_overlap(place(fp, x, y, yaw), b.corners_xy()) for b in boxes)
        assert bool(checker.colliding(x, y, yaw)) == expected
        hits += expected
    assert 50 < hits < 350  # both outcomes were exercised


@pytest.mark.parametrize("single_turn", [True, False])
def test_path_through_the_gap_is_free_everywhere(cube_footprint, wall_checker, single_turn):
    path = plan_path(wall_checker, START, GOAL, time_limit=1.0, seed=0, single_turn=single_turn)
    assert path.shape[1] == 3 and len(path) >= 2
    assert np.allclose(path[0], START)
    assert np.allclose(path[-1, :2], GOAL[:2])
    assert math.cos(path[-1, 2] - GOAL[2]) == pytest.approx(1.0)
    steps = np.diff(path, axis=0)
    assert np.hypot(steps[:, 0], steps[:, 1]).max() <= 0.01 + 1e-9
    assert np.abs(steps[:, 2]).max() <= math.radians(5) + 1e-9
    independent = _IndependentFcl(cube_footprint, WALL)
    dense = interpolate_path(path, max_step=0.002, max_turn=math.radians(1))
    assert all(_independently_free(cube_footprint, WALL, independent, pose) for pose in dense)
    crossing = dense[np.abs(dense[:, 0] - WALL_X) <= 0.015]
    assert len(crossing) and np.all(np.abs(crossing[:, 1]) < GAP / 2)
    assert path_length(path) > path_length(np.array([START, GOAL])) + 0.2  # the detour through the gap


def test_where_the_straight_way_is_free_the_path_is_straight_with_one_turn(cube_footprint):
    """Open table: one turn in place, then a straight line (the fewest spins); next to a block that leaves no room
    to turn at the start, straight first and the turn at the goal."""
    open_table = FootprintChecker(cube_footprint, (), WORKSPACE)
    start, goal = (0.4, -0.1, 0.2), (0.65, 0.1, 1.4)
    path = plan_path(open_table, start, goal, seed=0)
    turning = np.abs(np.diff(path[:, 2])) > 1e-9
    moving = np.hypot(*np.diff(path[:, :2], axis=0).T) > 1e-9
    assert not np.any(turning & moving)  # turns happen in place
    assert np.all(turning[:int(np.argmax(moving))]) and not np.any(turning[np.argmax(moving):])  # turn, then go
    assert path[-1, 2] == pytest.approx(1.4) and np.allclose(path[-1, :2], goal[:2])
    d = path[:, :2] - np.array(start[:2])
    u = np.subtract(goal[:2], start[:2]) / np.hypot(*np.subtract(goal[:2], start[:2]))
    assert np.abs(d[:, 0] * u[1] - d[:, 1] * u[0]).max() < 1e-9  # on the straight line

    # a block beside the start: the square cannot turn there by 45 deg, but can at the goal
    block = (ap.Box(center=(0.4, 0.0), size=(0.06, 0.06, 0.08)),)
    checker = FootprintChecker(cube_footprint, block, WORKSPACE)
    start, goal = (0.4, -0.095, 0.0), (0.65, -0.095, math.pi / 4)
    assert not checker.is_free(0.4, -0.095, math.pi / 4)
    path = plan_path(checker, start, goal, seed=0)
    turning = np.abs(np.diff(path[:, 2])) > 1e-9
    assert np.allclose(path[:, 1], -0.095) and not np.any(turning[:-9]) and np.all(turning[-9:])


def test_a_path_through_a_wide_gap_turns_once(cube_footprint):
    """The sampled way round a wall with a 30 cm gap keeps one yaw (the cube fits the gap at any), turning once,
    in place."""
    gap = 0.3
    wall = (ap.Box(center=(WALL_X, -(gap / 2 + 0.11)), size=(0.03, 0.22, 0.1)),
            ap.Box(center=(WALL_X, gap / 2 + 0.11), size=(0.03, 0.22, 0.1)))
    wall_checker = FootprintChecker(cube_footprint, wall, WORKSPACE)
    start, goal = (0.4, 0.15, 0.0), (0.65, 0.15, 1.0)
    path = plan_path(wall_checker, start, goal, seed=0)
    turning = np.abs(np.diff(path[:, 2])) > 1e-9
    moving = np.hypot(*np.diff(path[:, :2], axis=0).T) > 1e-9
    assert not np.any(turning & moving)
    changes = np.flatnonzero(np.diff(turning.astype(int)))
    assert len(changes) <= 2  # one contiguous turn, at the start or at the end
    assert path_length(path) > path_length(np.array([start, goal])) + 0.1  # still round through the gap
    free = plan_path(wall_checker, start, goal, seed=0, single_turn=False)
    assert np.abs(np.diff(free[:, 2])).sum() >= np.abs(np.diff(path[:, 2])).sum() - 1e-9


@pytest.mark.parametrize("single_turn", [True, False])
def test_same_seed_same_path(wall_checker, single_turn):
    a = plan_path(wall_checker, START, GOAL, seed=3, single_turn=single_turn)
    b = plan_path(wall_checker, START, GOAL, seed=3, single_turn=single_turn)
    assert np.array_equal(a, b)


class _SlowChecker(FootprintChecker):
    """The same scene, each state check slowed as on a loaded machine."""

    def is_free(self, x: float, y: float, yaw: float) -> bool:
        deadline = time.perf_counter() + 2e-5
        while time.perf_counter() < deadline:
            pass
        return super().is_free(x, y, yaw)


def test_a_slower_machine_gets_the_same_sampled_path(cube_footprint, wall_checker):
    """The SE(2) solve is bounded by iterations, not seconds: checks that take longer change nothing."""
    fast = plan_path(wall_checker, START, GOAL, seed=5, attempts=2, single_turn=False)
    slow = plan_path(_SlowChecker(cube_footprint, WALL, WORKSPACE), START, GOAL, seed=5, attempts=2,
                     single_turn=False)
    assert np.array_equal(fast, slow)


def test_an_iteration_budget_too_small_to_pass_the_gap_raises(wall_checker):
    with pytest.raises(PlanningError, match="2 x 3 RRT-Connect iterations"):
        plan_path(wall_checker, START, GOAL, seed=0, attempts=2, iterations=3, single_turn=False)


def test_restarts_keep_the_shortest_path(wall_checker):
    one = plan_path(wall_checker, START, GOAL, seed=4, single_turn=False)  # the sampled SE(2) way
    best = plan_path(wall_checker, START, GOAL, seed=4, attempts=3, single_turn=False)
    assert path_length(best) <= path_length(one) + 1e-9


def test_goal_in_an_obstacle_or_outside_raises_goal_error(wall_checker):
    with pytest.raises(GoalError, match="goal.*obstacle 1"):
        plan_path(wall_checker, START, (WALL_X, 0.2, 0.0))
    with pytest.raises(GoalError, match="start.*workspace"):
        plan_path(wall_checker, (0.31, 0.0, 0.0), GOAL)


def test_a_goal_walled_off_raises_planning_error_once_its_iterations_are_spent(cube_footprint):
    wall = [ap.Box(center=(WALL_X, 0.0), size=(0.03, 0.6, 0.1))]
    checker = FootprintChecker(cube_footprint, wall, WORKSPACE)
    with pytest.raises(PlanningError, match=r"no collision-free path .* 2 x 400 RRT-Connect iterations"):
        plan_path(checker, START, GOAL, attempts=2, iterations=400, time_limit=30.0)


def test_inputs_are_validated(wall_checker):
    with pytest.raises(InputError):
        plan_path(wall_checker, (np.nan, 0.2, 0.0), GOAL)
    with pytest.raises(InputError):
        plan_path(wall_checker, START, (0.65, 0.2))
    with pytest.raises(InputError):
        plan_path(wall_checker, START, GOAL, time_limit=float("nan"))
    with pytest.raises(InputError):
        plan_path(wall_checker, START, GOAL, seed=-1)
    with pytest.raises(InputError):
        plan_path(wall_checker, START, GOAL, iterations=0)
    with pytest.raises(InputError):
        FootprintChecker(np.array([[0.0, 0.0], [1.0, np.nan], [0.0, 1.0]]))


def test_interpolation_and_length():
    path = np.array([[0.4, 0.0, 3.0], [0.45, 0.0, -3.0]])  # the short way round crosses +-pi
    dense = interpolate_path(path)
    assert np.all(np.diff(dense[:, 2]) > 0) and dense[-1, 2] == pytest.approx(2 * math.pi - 3.0)
    assert path_length(path, yaw_weight=0.1) == pytest.approx(0.05 + 0.1 * (2 * math.pi - 6.0))
