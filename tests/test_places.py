"""The planner's place searches (planner.places): free yaws and places, room to roll and to turn, goal regions."""

import math

import numpy as np
import pytest

import affordplan as ap
from affordplan.errors import GoalError
from planner.places import Places
from planner.plan import ARM_REACH, CLEARANCE, inflated_footprints, make_checkers

BLOCK = ap.Box(center=(0.55, 0.0), size=(0.1, 0.1, 0.1))


def places_for(obj, obstacles=(), reach=ARM_REACH):
    footprints = inflated_footprints(obj, CLEARANCE)
    checkers = make_checkers(footprints, obstacles, ap.Workspace(), reach)
    radius = {i: float(np.max(np.linalg.norm(fp, axis=1))) for i, fp in footprints.items()}
    return Places(obj, checkers, ap.Workspace(), tuple(obstacles), radius, CLEARANCE, 0.04, reach)


@pytest.fixture(scope="module")
def cube():
    return ap.load_object("cube")


def test_a_free_yaw_is_the_nearest_turn_that_fits(cube):
    places = places_for(cube, (BLOCK,))
    assert places.free_yaw(0, (0.5, 0.2), 0.3) == pytest.approx(0.3)  # open: as preferred
    x = 0.55 - 0.05 - 0.0725  # the cube's inflated half-width at yaw 0 just clears the block's face
    yaw = places.free_yaw(0, (x, 0.0), math.pi / 4)  # turned 45 deg its corner would hit the block
    assert abs(yaw - math.pi / 4) > 0 and places.checkers[0].is_free(x, 0.0, yaw)


def test_the_nearest_free_place_skips_pushes_the_planner_avoids(cube):
    places = places_for(cube, (BLOCK,))
    stuck = (0.55, 0.0, 0.0)  # inside the block
    free = places.nearest_free(0, stuck, (0.3, 0.0), avoided=lambda skill, params, T: False)
    assert places.checkers[0].is_free(*free, 0.0) and free[0] < 0.55  # towards where the segment goes
    westward = places.nearest_free(0, stuck, (0.3, 0.0),
                                   avoided=lambda skill, params, T: math.cos(params["direction"]) < 0)
    assert places.checkers[0].is_free(*westward, 0.0) and westward[0] >= 0.55 - 1e-9  # not pushed west


def test_a_roll_is_made_in_place_unless_the_spot_is_spoiled(cube):
    places = places_for(cube)
    goal = ap.Goal(xy=(0.65, 0.1))
    assert places.roll_spot(0, 1, (0.45, -0.1, 0.0), goal) == pytest.approx((0.45, -0.1))
    spot = places.roll_spot(0, 1, (0.45, -0.1, 0.0), goal, spoiled=lambda x, y: math.dist((x, y), (0.45, -0.1)) < 0.05)
    assert math.dist(spot, (0.45, -0.1)) >= 0.05
    late = places.roll_spot(0, 1, (0.45, -0.1, 0.0), goal, late=True)  # near the goal, where the roll has room
    assert math.dist(late, goal.xy) < 0.05 and late[0] > 0.55


def test_a_goal_in_a_block_is_moved_to_the_free_part_of_its_region_or_refused(cube):
    places = places_for(cube, (BLOCK,))
    edge = 0.55 - 0.05 - 0.0725
    goal = ap.Goal(xy=(edge + 0.01, 0.0), yaw=0.0, xy_tol=0.03)
    aim = places.aim(goal, 0)
    assert places.checkers[0].is_free(*aim.xy, aim.yaw) and math.dist(aim.xy, goal.xy) <= 0.6 * goal.xy_tol
    assert aim.xy_tol == pytest.approx(goal.xy_tol - math.dist(aim.xy, goal.xy))
    with pytest.raises(GoalError, match="no free placement"):
        places.aim(ap.Goal(xy=(0.55, 0.0), yaw=0.0), 0)
    open_goal = ap.Goal(xy=(0.5, 0.2), yaw=0.0)
    assert places.aim(open_goal, 0) is open_goal
