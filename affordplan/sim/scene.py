"""MJCF for a table-top scene, generated in code (no asset files).

The scene holds a table plane, the object as one free body whose geoms are its convex parts (mesh
vertices inlined; the inertia is the true solid's, not the parts' sum), box obstacles, and the
pusher. Options and contact parameters are the ones measured here (docs/guide.md) to give stable contacts.

Collision filtering (contype / conaffinity): the table collides with the object only; the finger
collides with the object and obstacles but not the table (its targets are clamped above it).
"""

from __future__ import annotations

import mujoco
import numpy as np

from affordplan.objects.model import ObjectModel
from affordplan.sim.mjcf import floats as _floats
from affordplan.sim.mjcf import obstacle_geom_xml
from affordplan.world import Box

OBJECT_BODY = "object"
FINGER_BODY = "finger"
FINGER_RADIUS = 0.008  # metres
FINGER_LENGTH = 0.08  # metres, cylinder part of the capsule above the tip
PARK_POSITION = (0.5, 0.0, -0.3)  # where the finger waits: under the table (it does not collide with it), out of view

# Sliding friction of the table (MuJoCo takes the larger of two geoms' values, so this is the
# object-table friction). At 0.5 a 10 cm cube pushed horizontally at its top edge slides instead of
# tipping (tipping needs mu > half-width / height = 0.5): no roll of a cube or box is possible. At 0.8
# (a rubber mat, wood on wood) it tips; pushes low on the object still slide.
TABLE_FRICTION = 0.8
OBJECT_CONTACT = 'condim="6" friction="0.5 0.005 0.002" solref="0.005 1" solimp="0.95 0.99 0.001"'


def set_free_pose(data: mujoco.MjData, qpos_adr: int, T_world_object: np.ndarray) -> None:
    """Write a 4x4 world pose into a free joint's ``qpos`` (position, then the rotation as a quaternion)."""
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(T_world_object[:3, :3]).reshape(-1))
    data.qpos[qpos_adr:qpos_adr + 3] = T_world_object[:3, 3]
    data.qpos[qpos_adr + 3:qpos_adr + 7] = quat


def _object_xml(obj: ObjectModel) -> tuple[str, str]:
    assets = []
    geoms = []
    for i, part in enumerate(obj.parts):
        assets.append(f'<mesh name="part{i}" vertex="{_floats(part.vertices)}"/>')
        geoms.append(
            f'<geom name="object_part{i}" type="mesh" mesh="part{i}" contype="1" conaffinity="3" '
            f'group="1" rgba="0.85 0.55 0.2 1" {OBJECT_CONTACT}/>'
        )
    I = obj.inertia
    full = _floats([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])
    body = (
        f'<body name="{OBJECT_BODY}" pos="0.5 0 0.2">\n'
        f'  <freejoint name="object_joint"/>\n'
        f'  <inertial pos="0 0 0" mass="{obj.mass:.6g}" fullinertia="{full}"/>\n  '
        + "\n  ".join(geoms)
        + "\n</body>"
    )
    return "\n".join(assets), body


def _look_at(pos, target) -> str:
    """MJCF ``xyaxes`` of a camera at ``pos`` looking at ``target`` with world z up in the image."""
    forward = np.asarray(target, dtype=float) - np.asarray(pos, dtype=float)
    forward /= np.linalg.norm(forward)
    x = np.cross(forward, [0.0, 0.0, 1.0])
    if np.linalg.norm(x) < 1e-6:  # looking straight down: image up is world +x
        x = np.array([0.0, -1.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(x, forward)
    return _floats(np.concatenate([x, y]))


FINGER_KP = 2000.0  # N/m, position gain of each finger axis
FINGER_KV = 40.0  # N s/m
FINGER_MAX_FORCE = 10.0  # N per axis: enough to slide, tip and roll these objects (<= 0.5 kg), no more


def _finger_xml() -> str:
    """A fingertip on three slide joints (world x, y, z) with force-limited position actuators."""
    slide = 'type="slide" armature="0.01" damping="0" limited="false"'
    return f"""
<body name="{FINGER_BODY}" pos="0 0 0" gravcomp="1">
  <joint name="finger_x" axis="1 0 0" {slide}/>
  <joint name="finger_y" axis="0 1 0" {slide}/>
  <joint name="finger_z" axis="0 0 1" {slide}/>
  <geom name="finger_tip" type="capsule" fromto="0 0 0 0 0 {FINGER_LENGTH}" size="{FINGER_RADIUS}"
        mass="0.05" contype="2" conaffinity="0" friction="0.5 0.005 0.002" rgba="0.2 0.2 0.25 1"/>
</body>"""


def _finger_actuators_xml() -> str:
    return "\n".join(
        f'<position name="finger_{a}" joint="finger_{a}" kp="{FINGER_KP}" kv="{FINGER_KV}" '
        f'forcelimited="true" forcerange="{-FINGER_MAX_FORCE} {FINGER_MAX_FORCE}"/>'
        for a in "xyz"
    )


PUSHERS = ("finger", "arm")


def build_mjcf(obj: ObjectModel, obstacles: tuple[Box, ...] = (), pusher: str = "finger") -> str:
    """MJCF text of the scene.

    ``pusher``: ``"finger"`` (a force-limited fingertip on three slide joints) or ``"arm"`` (the 7-DOF arm of
    :mod:`affordplan.sim.arm`, base at the world origin).
    """
    if pusher not in PUSHERS:
        raise ValueError(f"unknown pusher {pusher!r}")
    from affordplan.sim.arm import arm_actuator_xml, arm_body_xml

    assets, body = _object_xml(obj)
    if pusher == "finger":
        pusher_xml = _finger_xml()
        extra = f"<actuator>{_finger_actuators_xml()}</actuator>"
    else:
        pusher_xml = arm_body_xml()
        extra = f"<actuator>{arm_actuator_xml()}</actuator>"
    obstacles_xml = "\n".join(obstacle_geom_xml(i, b) for i, b in enumerate(obstacles))
    return f"""<mujoco model="affordplan">
<compiler angle="radian"/>
<option timestep="0.002" integrator="implicitfast" cone="elliptic" impratio="10"/>
<visual>
  <global offwidth="1280" offheight="960"/>
  <quality shadowsize="2048"/>
</visual>
<asset>
  <texture name="grid" type="2d" builtin="checker" rgb1="0.82 0.8 0.76" rgb2="0.76 0.74 0.7"
           width="512" height="512"/>
  <material name="table" texture="grid" texrepeat="8 8" reflectance="0.05"/>
  {assets}
</asset>
<worldbody>
  <light pos="0.5 -0.6 1.5" dir="0 0.4 -1" diffuse="0.8 0.8 0.8" castshadow="true"/>
  <light pos="0.3 0.6 1.2" dir="0 -0.3 -1" diffuse="0.4 0.4 0.4" castshadow="false"/>
  <camera name="overview" pos="0.82 -0.38 0.36" xyaxes="{_look_at((0.82, -0.38, 0.36), (0.52, 0.0, 0.03))}"/>
  <camera name="wide" pos="1.05 -0.7 0.55" xyaxes="{_look_at((1.05, -0.7, 0.55), (0.4, 0.0, 0.15))}"/>
  <camera name="top" pos="0.52 0 1.3" xyaxes="{_look_at((0.52, 0.0, 1.3), (0.52, 0.0, 0.0))}"/>
  <geom name="table" type="plane" size="1.5 1.5 0.05" material="table" contype="1" conaffinity="1"
        friction="{TABLE_FRICTION} 0.005 0.002"/>
  {obstacles_xml}
  {body}
  {pusher_xml}
</worldbody>
{extra}
</mujoco>
"""
