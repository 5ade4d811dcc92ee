"""The robot's constants (affordplan.robot) agree with the simulator and the planner that read them: the fingertip
radius is the MJCF fingertip's in both pusher scenes, the protocol's defaults are the simulator's and the documented
ones, the workspace lies within the fingertip's reach, one skill order everywhere."""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

import affordplan as ap
import primitives
from affordplan import robot
from affordplan.sim import arm, pushers, scene, sensor
from primitives import params


@pytest.fixture(scope="module")
def arm_model(cube) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(scene.build_mjcf(cube, pusher="arm"))


def test_the_arm_scene_s_fingertip_is_a_tip_radius_sphere_centred_on_the_fingertip_site(arm_model):
    m = arm_model
    tip = m.geom("fingertip_c")
    assert tip.type[0] == mujoco.mjtGeom.mjGEOM_CAPSULE and tip.size[0] == pytest.approx(robot.TIP_RADIUS)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    axis = d.geom_xmat[tip.id].reshape(3, 3)[:, 2]
    ends = [d.geom_xpos[tip.id] + s * tip.size[1] * axis for s in (-1.0, 1.0)]
    site = d.site_xpos[m.site(arm.FINGERTIP_SITE).id]
    assert min(np.linalg.norm(e - site) for e in ends) < 1e-9  # the site is the tip sphere's centre


def test_the_finger_scene_s_fingertip_has_the_same_radius(cube):
    m = mujoco.MjModel.from_xml_string(scene.build_mjcf(cube, pusher="finger"))
    assert m.geom("finger_tip").size[0] == pytest.approx(robot.TIP_RADIUS) == scene.FINGER_RADIUS
    assert pushers.FingerPusher.radius == pushers.ArmPusher.radius == robot.TIP_RADIUS
    assert arm.TIP_RADIUS is robot.TIP_RADIUS and arm.FINGERTIP_REACH is robot.FINGERTIP_REACH


def test_the_simulator_runs_the_protocol_s_defaults_and_they_are_the_documented_ones(cube):
    p = robot.Protocol()
    assert ap.Simulator(cube).protocol == p and ap.sim.Protocol is robot.Protocol
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.standoff = 0.1
    # affordplan.sim.simulator's account of a primitive: 4 cm out, 2 cm, 3 steps of motion * 3 cm over 0.5 s each,
    # back 2 cm, up 5 cm, settle for at most 2 s
    assert (p.standoff, p.mid_standoff) == (0.04, 0.02) and p.mid_standoff < p.standoff
    assert p.motion_steps * p.motion_step == pytest.approx(0.09)  # a unit motion moves the target 9 cm
    assert p.motion_step_time == 0.5 and p.retract_height == 0.05 and p.settle_time_max == 2.0
    assert p.approach_tilt_tolerance == pytest.approx(math.radians(5.0))
    assert p.standoff > robot.TIP_RADIUS  # the pre-contact point keeps the fingertip clear of the surface


def test_the_workspace_lies_within_the_fingertip_s_reach():
    ws = ap.Workspace()
    corners = [(x, y) for x in ws.x for y in ws.y]
    assert max(math.hypot(x, y) for x, y in corners) < robot.FINGERTIP_REACH


def test_one_skill_order_and_one_table_height_everywhere():
    assert robot.SKILLS == ("push", "roll", "spin")
    assert params.SKILLS is robot.SKILLS and primitives.SKILLS is robot.SKILLS
    assert sensor.TABLE_CONTACT_HEIGHT is robot.TABLE_CONTACT_HEIGHT
    assert 0.0 < robot.TABLE_CONTACT_HEIGHT < robot.TIP_RADIUS
