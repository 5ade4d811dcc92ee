"""Goals: errors, and yaws compared modulo the resting state's symmetry."""

import math

import numpy as np
import pytest

import affordplan as ap
from affordplan.errors import GoalError
from affordplan.geometry import wrap_period


def test_wrap_period_wraps_into_half_a_period_either_way():
    assert wrap_period(math.radians(100), math.radians(90)) == pytest.approx(math.radians(10))
    assert wrap_period(math.radians(-50), math.radians(90)) == pytest.approx(math.radians(40))
    assert wrap_period(math.radians(190), 2 * math.pi) == pytest.approx(math.radians(-170))
    assert wrap_period(0.0, math.radians(11.25)) == 0.0


def test_a_cube_turned_a_quarter_meets_the_goal_unless_markings_matter():
    cube = ap.load_object("cube")
    T = cube.resting_states[0].pose((0.6, 0.0), math.radians(93.0))
    symmetric = ap.Goal(xy=(0.6, 0.0), yaw=0.0, resting_state=0)
    d, yaw_err, state_ok = symmetric.errors(cube, T)
    assert d == pytest.approx(0.0, abs=1e-9) and state_ok
    assert math.degrees(yaw_err) == pytest.approx(3.0, abs=1e-6)
    assert symmetric.reached(cube, T)
    labelled = ap.Goal(xy=(0.6, 0.0), yaw=0.0, resting_state=0, yaw_symmetric=False)
    assert math.degrees(labelled.errors(cube, T)[1]) == pytest.approx(93.0, abs=1e-6)
    assert not labelled.reached(cube, T)


def test_yaw_near_and_yaw_free():
    cube, box, planter = ap.load_object("cube"), ap.load_object("lunch_box"), ap.load_object("planter_1")
    goal = ap.Goal(xy=(0.6, 0.0), yaw=math.radians(10.0))
    # of 10 + k 90 deg, the one nearest 170 deg is 190 deg; for the lunch box (180 deg) it is 190 deg too
    assert math.degrees(goal.yaw_near(cube, 0, math.radians(170.0))) == pytest.approx(190.0)
    assert math.degrees(goal.yaw_near(box, 0, math.radians(95.0))) == pytest.approx(10.0)
    assert math.degrees(goal.yaw_near(box, 0, math.radians(105.0))) == pytest.approx(190.0)
    assert not goal.yaw_free(cube, 0)
    upright = next(i for i in range(len(planter.resting_states)) if planter.yaw_period(i) < math.radians(15))
    assert goal.yaw_free(planter, upright) and not goal.yaw_free(planter, 0)
    assert ap.Goal(xy=(0.6, 0.0)).yaw_free(cube, 0) and ap.Goal(xy=(0.6, 0.0)).yaw_near(cube, 0, 1.0) is None
    assert not ap.Goal(xy=(0.6, 0.0), yaw=0.0, yaw_symmetric=False).yaw_free(planter, upright)


def test_yaw_symmetric_must_be_a_bool():
    with pytest.raises(GoalError, match="yaw_symmetric must be True or False"):
        ap.Goal(xy=(0.6, 0.0), yaw=0.0, yaw_symmetric="yes")
    assert ap.Goal(xy=(0.6, 0.0), yaw_symmetric=np.bool_(False)).yaw_symmetric is False


def test_from_degrees_is_the_goal_in_radians():
    assert ap.Goal.from_degrees((0.6, 0.0), 90.0, 1, xy_tol=0.02, yaw_tol_deg=10.0) == ap.Goal(
        xy=(0.6, 0.0), yaw=math.radians(90.0), resting_state=1, xy_tol=0.02, yaw_tol=math.radians(10.0))
    assert ap.Goal.from_degrees([0.6, -0.1]) == ap.Goal(xy=(0.6, -0.1))  # no yaw; 15 deg tolerance, as Goal's
    assert ap.Goal.from_degrees((0.6, 0.0), -30, yaw_symmetric=False) == ap.Goal(
        xy=(0.6, 0.0), yaw=math.radians(-30.0), yaw_symmetric=False)


@pytest.mark.parametrize("kwargs, words", [
    ({"yaw_deg": True}, "yaw_deg"), ({"yaw_deg": float("nan")}, "yaw_deg"), ({"yaw_deg": "90"}, "yaw_deg"),
    ({"yaw_tol_deg": math.inf}, "yaw_tol_deg"), ({"yaw_tol_deg": 0.0}, "yaw_tol"), ({"xy_tol": -0.01}, "xy_tol"),
    ({"resting_state": 1.5}, "resting_state"), ({"yaw_symmetric": "no"}, "yaw_symmetric"),
])
def test_from_degrees_keeps_the_goal_checks(kwargs, words):
    with pytest.raises(GoalError, match=words):
        ap.Goal.from_degrees((0.6, 0.0), **kwargs)
    with pytest.raises(GoalError, match="xy"):
        ap.Goal.from_degrees((0.6, float("nan")))
