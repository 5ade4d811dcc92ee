"""Physics guards fire on each kind of fault, and not on a sane state."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import affordplan as ap
from affordplan.sim.guards import GuardLimits, PhysicsGuard
from affordplan.sim.scene import OBJECT_BODY


@pytest.fixture()
def guarded(cube):
    sim = ap.Simulator(cube)
    sim.reset()
    body = sim.model.body(OBJECT_BODY).id
    guard = PhysicsGuard(sim.model, sim.data, body, cube.hull.vertices, sim.workspace)
    guard.arm()
    return sim, guard


def test_sane_resting_state_passes(guarded):
    sim, guard = guarded
    assert guard.check() is None


def test_nan_state(guarded):
    sim, guard = guarded
    sim.data.qvel[2] = np.nan
    assert guard.check() == "nan"


def test_left_workspace(guarded):
    sim, guard = guarded
    sim.data.qpos[0] = 1.2
    assert guard.check() == "left_workspace"


def test_absurd_speed(guarded):
    sim, guard = guarded
    sim.data.qvel[3] = 100.0  # rad/s
    assert guard.check() == "speed"


def test_sunk_into_table(guarded):
    sim, guard = guarded
    sim.data.qpos[2] = 0.03  # the cube's half-height is 5 cm: 2 cm under the table
    mujoco.mj_kinematics(sim.model, sim.data)
    assert guard.check() == "sank"


def test_unstable_warning(guarded):
    sim, guard = guarded
    sim.data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number += 1
    assert guard.check() == "unstable"


def test_execute_reports_the_guard(cube):
    """An object dropped from inside the table is thrown out: the primitive is marked invalid."""
    sim = ap.Simulator(cube)
    T = sim.reset()
    T[2, 3] = -0.02
    sim.set_object_pose(T, settle=False)
    out = sim.execute(T[:3, 3] + np.array([-0.05, 0.0, 0.07]), (1.0, 0.0, 0.0))
    assert not out.valid
    assert out.invalid_reason in {"sank", "speed", "unstable"}


def test_off_table_after_settling(guarded):
    sim, guard = guarded
    assert guard.check_rest() is None  # resting on the table
    sim.data.qpos[2] += 0.05  # hanging 5 cm up (on the pusher, or on an obstacle)
    mujoco.mj_forward(sim.model, sim.data)
    assert guard.check_rest() == "off_table"
    assert guard.check() is None  # mid-primitive, being lifted is not a fault by itself


def test_a_faulty_start_is_never_a_valid_sample(cube):
    sim = ap.Simulator(cube)
    T = sim.reset()
    sim.data.qpos[2] -= 0.03  # sunk 3 cm into the table before the primitive starts
    mujoco.mj_forward(sim.model, sim.data)
    out = sim.execute(T[:3, 3] - np.array([0.05, 0.0, 0.0]), (1.0, 0.0, 0.0))
    assert not out.valid and out.invalid_reason == "sank"


def test_an_object_caught_mid_motion_is_left_at_rest(cube):
    """A guard firing mid-push voids the sample, but the object comes to rest before the next primitive.

    With a speed bound of 5 cm/s, the push trips ``"speed"`` while the cube slides. Left as it was, the
    cube would carry that speed (or a transient 6 mm impact) into the next primitive, whose start check
    would refuse it.
    """
    sim = ap.Simulator(cube, guard_limits=GuardLimits(max_linear_speed=0.05))
    T = sim.reset()
    out = sim.execute(T[:3, 3] + np.array([-0.05, 0.0, -0.02]), (1.0, 0.0, 0.0), normal=(-1.0, 0.0, 0.0))
    assert not out.valid and out.invalid_reason == "speed"
    moved = out.pose_after[:3, 3] - out.pose_before[:3, 3]
    assert 0.0005 < moved[0] < 0.09  # it was pushed along +x before the guard stopped the push
    v = sim.data.qvel[:6]
    assert np.linalg.norm(v[:3]) < 0.01 and np.linalg.norm(v[3:]) < 0.1  # at rest now
    assert sim.object_pose()[2, 3] == pytest.approx(T[2, 3], abs=0.002)  # on the table, as before
