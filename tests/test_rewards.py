"""The seed's objectives pinned to hand-computed values at and around every threshold."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from primitives import rewards


def pose(rotvec_deg=(0.0, 0.0, 0.0), t=(0.5, 0.0, 0.05), base: np.ndarray | None = None) -> np.ndarray:
    """Pose whose rotation is ``Rot(rotvec) @ base`` (a world-frame rotation of ``base``)."""
    R = Rotation.from_rotvec(np.radians(rotvec_deg)).as_matrix()
    T = np.eye(4)
    T[:3, :3] = R if base is None else R @ base[:3, :3]
    T[:3, 3] = t
    return T


T0 = pose()


def axis_rot(angle_deg: float, tilt_from_horizontal_deg: float) -> np.ndarray:
    """Rotation vector (deg) of ``angle_deg`` about an axis tilted up from +x by the given angle."""
    a = math.radians(tilt_from_horizontal_deg)
    return angle_deg * np.array([math.cos(a), 0.0, math.sin(a)])


# ---------------------------------------------------------------- push
def test_push_at_exactly_5cm_without_rotation_is_zero_loss_and_success():
    T1 = pose(t=(0.53, 0.04, 0.05))  # |p| = 0.05
    assert rewards.push_loss(T0, T1) == pytest.approx(0.0, abs=1e-12)
    assert rewards.push_success(T0, T1)


def test_push_just_short_of_5cm_fails_and_costs_20_per_metre():
    T1 = pose(t=(0.549, 0.0, 0.05))
    assert rewards.push_loss(T0, T1) == pytest.approx(20 * 0.001)
    assert not rewards.push_success(T0, T1)


def test_push_saturates_beyond_5cm():
    assert rewards.push_loss(T0, pose(t=(0.6, 0.0, 0.05))) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("deg, ok", [(4.9, True), (5.1, False)])
def test_push_rotation_threshold_5deg(deg, ok):
    T1 = pose(rotvec_deg=(0, 0, deg), t=(0.56, 0.0, 0.05))
    assert rewards.push_success(T0, T1) is ok
    assert rewards.push_loss(T0, T1) == pytest.approx(deg / 180.0)


def test_push_loss_combines_both_terms():
    T1 = pose(rotvec_deg=(0, 0, 18.0), t=(0.52, 0.0, 0.05))  # 2 cm and 18 deg
    assert rewards.push_loss(T0, T1) == pytest.approx(20 * 0.03 + 0.1)


# ---------------------------------------------------------------- roll
@pytest.mark.parametrize("deg, ok", [(59.9, False), (60.0, True), (60.1, True), (90.0, True)])
def test_roll_angle_threshold_60deg(deg, ok):
    T1 = pose(rotvec_deg=(deg, 0, 0))
    assert rewards.roll_success(T0, T1) is ok
    assert rewards.roll_loss(T0, T1) == pytest.approx(max(1 - deg / 60.0, 0.0))


@pytest.mark.parametrize("tilt, ok", [(44.0, True), (45.0, True), (46.0, False)])
def test_roll_axis_within_45deg_of_flat(tilt, ok):
    T1 = pose(rotvec_deg=axis_rot(70.0, tilt))
    assert rewards.roll_success(T0, T1) is ok
    assert rewards.roll_loss(T0, T1) == pytest.approx(math.sin(math.radians(tilt)))


def test_roll_penalises_planar_travel_by_half():
    T1 = pose(rotvec_deg=(0, 90, 0), t=(0.56, 0.08, 0.05))  # 10 cm in the plane
    assert rewards.roll_loss(T0, T1) == pytest.approx(0.05)
    assert rewards.roll_success(T0, T1)


# ---------------------------------------------------------------- spin
@pytest.mark.parametrize("deg, ok", [(29.9, False), (30.0, True), (30.1, True), (-40.0, True)])
def test_spin_angle_threshold_30deg(deg, ok):
    T1 = pose(rotvec_deg=(0, 0, deg))
    assert rewards.spin_success(T0, T1) is ok
    assert rewards.spin_loss(T0, T1) == pytest.approx(max(1 - abs(deg) / 30.0, 0.0), abs=1e-12)


@pytest.mark.parametrize("tilt_from_vertical, ok", [(44.0, True), (45.0, True), (46.0, False)])
def test_spin_axis_within_45deg_of_vertical(tilt_from_vertical, ok):
    T1 = pose(rotvec_deg=axis_rot(40.0, 90.0 - tilt_from_vertical))
    assert rewards.spin_success(T0, T1) is ok
    assert rewards.spin_loss(T0, T1) == pytest.approx(1 - math.cos(math.radians(tilt_from_vertical)))


def test_spin_loss_terms_add_up():
    T1 = pose(rotvec_deg=(0, 0, 15.0), t=(0.52, 0.0, 0.05))  # half the angle, 2 cm of travel
    assert rewards.spin_loss(T0, T1) == pytest.approx(0.5 + 2.5 * 0.02)


def test_no_motion_takes_z_as_axis():
    m = rewards.motion(T0, T0)
    assert m.theta_deg == 0.0 and np.allclose(m.w, [0, 0, 1])
    assert rewards.spin_loss(T0, T0) == pytest.approx(1.0)
    assert rewards.roll_loss(T0, T0) == pytest.approx(2.0)


# --------------------------------------------- world axes on a rotated object
BASE = pose(rotvec_deg=(90.0, 0.0, 0.0), base=pose(rotvec_deg=(0.0, 0.0, 30.0)))  # lying, yawed


def test_rotation_about_world_x_of_a_rotated_object_is_a_roll():
    T1 = pose(rotvec_deg=(70.0, 0.0, 0.0), base=BASE)
    m = rewards.motion(BASE, T1)
    assert m.theta_deg == pytest.approx(70.0)
    assert np.allclose(np.abs(m.w), [1, 0, 0], atol=1e-9)  # the world axis, not the body axis
    assert rewards.roll_success(BASE, T1) and not rewards.spin_success(BASE, T1)
    assert rewards.roll_loss(BASE, T1) == pytest.approx(0.0, abs=1e-9)


def test_rotation_about_world_z_of_a_lying_object_is_a_spin():
    T1 = pose(rotvec_deg=(0.0, 0.0, 35.0), base=BASE)
    assert rewards.spin_success(BASE, T1) and not rewards.roll_success(BASE, T1)
    assert rewards.spin_loss(BASE, T1) == pytest.approx(0.0, abs=1e-9)


def test_reward_is_minus_loss():
    T1 = pose(rotvec_deg=(0, 0, 10.0), t=(0.52, 0.01, 0.05))
    for name, loss in rewards.LOSSES.items():
        assert rewards.reward(name, T0, T1) == -loss(T0, T1)


def test_bad_pose_raises():
    from affordplan.errors import InputError

    with pytest.raises(InputError):
        rewards.push_loss(np.full((4, 4), np.nan), T0)
    with pytest.raises(InputError):
        rewards.spin_success(np.eye(3), T0)


@pytest.mark.parametrize("asked, turned, ok", [(30.0, 38.0, True), (30.0, 41.0, False), (-45.0, -36.0, True),
                                               (175.0, -175.0, True), (-175.0, 178.0, True), (175.0, 160.0, False),
                                               (175.0, -5.0, False)])
def test_spin_by_an_angle_is_met_modulo_a_full_turn(asked, turned, ok):
    """Within 10 deg of the asked turn; an asked half turn met by turning just past it (the signed turn wraps)."""
    T1 = pose(rotvec_deg=(0.0, 0.0, turned))
    assert rewards.success("spin", T0, T1, {"angle": math.radians(asked)}) is ok
