"""The pushers (affordplan.sim.pushers) driven directly on a scene's model: the finger parks under the table and
teleports, the arm homes pointing down, transits at the safe height, checks the way down, and snapshots its own
state."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from affordplan.sim import arm, scene
from affordplan.sim.pushers import ArmPusher, FingerPusher
from affordplan.sim.simulator import CHUNK_STEPS

SAFE = 0.4  # metres: the safe height the tests give the arm (above its home pose's tip)


def _scene(obj, pusher: str):
    m = mujoco.MjModel.from_xml_string(scene.build_mjcf(obj, pusher=pusher))
    d = mujoco.MjData(m)
    body = m.body(scene.OBJECT_BODY).id
    T = obj.resting_states[0].pose((0.5, 0.0), 0.0)  # the cube's faces at x = 0.45 and 0.55, its top at 0.1
    scene.set_free_pose(d, int(m.jnt_qposadr[m.body_jntadr[body]]), T)
    return m, d


def _arm(obj) -> tuple[ArmPusher, mujoco.MjModel, mujoco.MjData]:
    m, d = _scene(obj, "arm")
    pusher = ArmPusher(m, d, arm.ArmIK(), CHUNK_STEPS * m.opt.timestep, lambda: SAFE)
    pusher.home()
    return pusher, m, d


def test_the_finger_parks_under_the_table_and_teleports_to_its_targets(cube):
    m, d = _scene(cube, "finger")
    finger = FingerPusher(m, d)
    finger.home()
    assert finger.tip() == pytest.approx(scene.PARK_POSITION) and finger.tip()[2] < 0  # out of view
    target = np.array([0.42, 0.03, 0.05])
    finger.go_to(target, servo=lambda *a: pytest.fail("the finger needs no physics to move"))
    assert finger.tip() == pytest.approx(target) and finger.target() == pytest.approx(target)
    assert np.all(d.qvel[finger._qvel] == 0.0)  # at rest there
    finger.command(target + [0.01, 0.0, 0.0])
    assert finger.target() == pytest.approx(target + [0.01, 0.0, 0.0])
    assert finger.tilt() == 0.0 and finger.can_descend_to(target) and finger.state() == ()


def test_the_arm_homes_at_rest_pointing_down_with_its_target_on_the_tip(cube):
    pusher, m, d = _arm(cube)
    assert pusher.q == pytest.approx(arm.HOME)
    assert pusher.tilt() < np.radians(5.0)  # pointing down
    assert pusher.target() == pytest.approx(pusher.tip())
    assert np.all(d.qvel[pusher._qvel] == 0.0)
    assert np.all(pusher.contact_force() == 0.0)  # touching nothing


def test_the_arm_transits_up_to_the_safe_height_across_and_down(cube):
    pusher, _, _ = _arm(cube)
    start = pusher.target()
    legs = []
    pusher.go_to(np.array([0.42, 0.05, 0.05]), servo=lambda a, b, t: legs.append((a.copy(), b.copy(), t)))
    assert start[2] < SAFE
    ends = np.array([b for _, b, _ in legs])
    assert ends == pytest.approx(np.array([[start[0], start[1], SAFE], [0.42, 0.05, SAFE], [0.42, 0.05, 0.05]]))
    assert legs[0][0] == pytest.approx(start) and all(np.array_equal(legs[k][1], legs[k + 1][0]) for k in range(2))
    for a, b, t in legs:
        assert t == pytest.approx(max(np.linalg.norm(b - a) / pusher.transit_speed, CHUNK_STEPS * 0.002))
    rises = []
    pusher._target = np.array([0.42, 0.05, 0.05])
    pusher.leave(servo=lambda a, b, t: rises.append(b.copy()))
    assert len(rises) == 1 and rises[0] == pytest.approx([0.42, 0.05, SAFE])  # straight up, then it holds


def test_the_arm_may_come_down_beside_the_cube_but_not_onto_it(cube):
    pusher, _, _ = _arm(cube)
    beside = np.array([0.45 - arm.TIP_RADIUS - 0.001, 0.0, 0.05])  # touching the -x face
    assert pusher.can_descend_to(beside)
    assert not pusher.can_descend_to(np.array([0.5, 0.0, 0.05]))  # the cube's top is in the way
    assert not pusher.can_descend_to(np.array([0.45 + 0.5 * arm.TIP_RADIUS, 0.0, 0.05]))  # the tip overlaps its edge


def test_the_arm_s_own_state_restores_exactly(cube):
    pusher, _, _ = _arm(cube)
    saved = pusher.state()
    pusher.command(pusher.tip() + [0.02, 0.0, -0.02])  # moves the target and the IK's configuration
    assert not np.allclose(pusher.target(), saved[0]) and not np.allclose(pusher.ik.q, saved[2])
    pusher.restore(saved)
    target, offset, q = pusher.state()
    assert np.array_equal(target, saved[0]) and np.array_equal(offset, saved[1]) and np.array_equal(q, saved[2])
