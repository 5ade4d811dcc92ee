"""Scene generation (affordplan.sim.scene): the MJCF of a table-top scene parses for either pusher, the object is one
free body with the object's mass and inertia, collision filtering keeps the finger off the table, poses are written
into a free joint exactly."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import affordplan as ap
from affordplan.geometry import make_pose
from affordplan.sim import scene


def _collide(m: mujoco.MjModel, a: str, b: str) -> bool:
    ga, gb = m.geom(a), m.geom(b)
    return bool((ga.contype[0] & gb.conaffinity[0]) or (gb.contype[0] & ga.conaffinity[0]))


@pytest.mark.parametrize("pusher", scene.PUSHERS)
def test_the_scene_parses_with_the_object_obstacles_cameras_and_pusher(mug, pusher):
    walls = (ap.Box(center=(0.6, -0.21), size=(0.02, 0.3, 0.1)), ap.Box(center=(0.6, 0.21), size=(0.02, 0.3, 0.1)))
    m = mujoco.MjModel.from_xml_string(scene.build_mjcf(mug, walls, pusher=pusher))
    body = m.body(scene.OBJECT_BODY)
    assert m.body_jntnum[body.id] == 1 and m.jnt_type[m.body_jntadr[body.id]] == mujoco.mjtJoint.mjJNT_FREE
    assert body.mass[0] == pytest.approx(mug.mass, rel=1e-5)
    assert sorted(body.inertia) == pytest.approx(sorted(np.linalg.eigvalsh(mug.inertia)), rel=1e-4)  # the solid's
    parts = [g for g in range(m.ngeom) if m.geom_bodyid[g] == body.id]
    assert len(parts) == len(mug.parts) and all(m.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH for g in parts)
    assert [m.geom(f"obstacle{i}").id >= 0 for i in range(2)] == [True, True]
    assert {m.camera(i).name for i in range(m.ncam)} == {"overview", "wide", "top"}
    assert m.opt.timestep == 0.002 and m.nu == (3 if pusher == "finger" else 7)


def test_collisions_keep_the_finger_off_the_table_but_not_off_the_object_or_the_walls(cube):
    wall = ap.Box(center=(0.6, 0.0), size=(0.02, 0.3, 0.1))
    m = mujoco.MjModel.from_xml_string(scene.build_mjcf(cube, (wall,), pusher="finger"))
    assert _collide(m, "table", "object_part0") and _collide(m, "obstacle0", "object_part0")
    assert _collide(m, "finger_tip", "object_part0") and _collide(m, "finger_tip", "obstacle0")
    assert not _collide(m, "finger_tip", "table")  # its targets are clamped above it instead


def test_an_unknown_pusher_is_refused(cube):
    with pytest.raises(ValueError, match="unknown pusher 'gripper'"):
        scene.build_mjcf(cube, pusher="gripper")


def test_a_pose_written_into_the_free_joint_is_the_body_s_pose(cube):
    m = mujoco.MjModel.from_xml_string(scene.build_mjcf(cube))
    d = mujoco.MjData(m)
    T = make_pose(np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]), (0.55, -0.1, 0.05))
    body = m.body(scene.OBJECT_BODY).id
    scene.set_free_pose(d, int(m.jnt_qposadr[m.body_jntadr[body]]), T)
    mujoco.mj_kinematics(m, d)
    assert d.xpos[body] == pytest.approx(T[:3, 3]) and d.xmat[body].reshape(3, 3) == pytest.approx(T[:3, :3])


def test_the_top_camera_looks_straight_down_at_the_table(cube):
    m = mujoco.MjModel.from_xml_string(scene.build_mjcf(cube))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    cam = m.camera("top").id
    looking = -d.cam_xmat[cam].reshape(3, 3)[:, 2]  # a MuJoCo camera looks along its -z
    assert looking == pytest.approx([0.0, 0.0, -1.0], abs=1e-6)
