"""Paths to skill calls (planner.chain): pushes that track a path, turns split into spins, short strides."""

import math

import numpy as np
import pytest

from planner import chain
from primitives import params as skill_params


def test_chained_calls_track_the_path():
    path = np.array([[0.4, 0.0, 0.0], [0.5, 0.0, math.radians(60)], [0.5, 0.1, math.radians(60)]])
    from planner.motion import interpolate_path

    calls = chain.path_to_calls(interpolate_path(path), goal_yaw=math.radians(-30))
    x, y, yaw = 0.4, 0.0, 0.0
    for skill, params, after in calls:
        if skill == "push":
            assert math.hypot(after[0] - x, after[1] - y) <= skill_params.PUSH_STEP + 0.011
            assert after[2] == yaw
        else:
            assert (after[0], after[1]) == (x, y)
            assert math.radians(15) - 1e-9 <= abs(params["angle"]) <= math.radians(45) + 1e-9
        x, y, yaw = after
    assert math.hypot(x - 0.5, y - 0.1) < 0.01 and abs(yaw - math.radians(-30)) <= chain.YAW_DEADBAND


def test_turns_are_split_into_the_spins_rated_likeliest():
    deg = math.radians

    def rate(angle):  # a policy that spins 35 deg well, 15-25 deg badly, and clockwise worse
        return (0.9 if abs(abs(angle) - deg(35)) < deg(1) else 0.3) * (1.0 if angle > 0 else 0.5)

    assert np.allclose(chain.spins_for(deg(70)), [deg(45), deg(25)])  # unrated: the largest first
    assert np.allclose(chain.spins_for(deg(70), rate), [deg(35), deg(35)])  # 0.81 beats 0.3 for 45 + 25
    assert np.allclose(chain.spins_for(deg(30), rate), [deg(35)])  # within the 5 deg slack
    assert np.allclose(chain.spins_for(deg(-70), rate), [deg(-35), deg(-35)])
    assert chain.spins_for(deg(8), rate) == []  # inside the dead band
    flat = chain.spins_for(deg(60), lambda a: 0.5)  # no preference: the fewest spins
    assert len(flat) == 2 and sum(flat) == pytest.approx(deg(60), abs=deg(5.01))
    for turn in np.radians([12, 20, 44, 50, 100, 170, -130]):  # every split sums to the turn within the slack
        spins = chain.spins_for(turn, rate)
        assert all(deg(15) - 1e-9 <= abs(a) <= deg(45) + 1e-9 for a in spins)
        assert abs(sum(spins) - turn) <= chain.SPIN_SLACK + 1e-9


def test_a_short_last_stride_is_two_full_pushes_in_a_v():
    """Pushes move at least PUSH_STEP: 3.5 cm to go is two 5 cm pushes whose sum is the stride, on the free side."""
    path = np.array([[0.6, 0.0, 0.3], [0.635, 0.0, 0.3]])
    step = skill_params.PUSH_STEP

    def legs(calls):
        pts = [(0.6, 0.0)] + [c[2][:2] for c in calls]
        return [math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(pts, pts[1:])], pts

    calls = chain.path_to_calls(path)
    lengths, pts = legs(calls)
    assert [c[0] for c in calls] == ["push", "push"] and np.allclose(lengths, step)
    assert np.allclose(pts[-1], (0.635, 0.0)) and pts[1][1] > 0  # left first
    assert all(after[2] == 0.3 for _, _, after in calls)  # pushes do not turn

    right = chain.path_to_calls(path, is_free=lambda x, y, yaw: y <= 0.001)  # nothing free on the left
    lengths, pts = legs(right)
    assert np.allclose(lengths, step) and pts[1][1] < 0 and np.allclose(pts[-1], (0.635, 0.0))

    boxed_in = chain.path_to_calls(path, is_free=lambda x, y, yaw: abs(y) < 0.001)  # a 2 mm corridor
    assert len(boxed_in) == 1 and math.isclose(boxed_in[0][1]["direction"], 0.0, abs_tol=1e-12)
    long = chain.path_to_calls(np.array([[0.6, 0.0, 0.0], [0.65, 0.0, 0.0], [0.67, 0.0, 0.0]]))  # 5 cm, then 2 cm
    assert len(long) == 3 and long[0][1]["direction"] == 0.0 and np.allclose(long[0][2][:2], (0.65, 0.0))
    assert np.allclose(long[-1][2][:2], (0.67, 0.0))  # the last 2 cm as a V
    # a lone stride under MIN_PUSH is still pushed (a goal asked to within less), one of floating-point dust is not
    lone = chain.path_to_calls(np.array([[0.6, 0.0, 0.0], [0.61, 0.0, 0.0]]))
    assert [c[0] for c in lone] == ["push", "push"] and np.allclose(lone[-1][2][:2], (0.61, 0.0))
    assert chain.path_to_calls(np.array([[0.6, 0.0, 0.0], [0.6 + 1e-12, 0.0, 0.0]])) == []
