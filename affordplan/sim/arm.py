"""A 7-DOF arm with the Franka Emika Panda's published kinematics, driven through mink IK.

Model: the Panda's joint frames, offsets and limits (as in its datasheet; the same frames as the
MuJoCo Menagerie model), with capsule links instead of meshes, a hand with two closed, lengthened
fingers (a pushing tool) and a fingertip capsule (radius 8 mm with an 8 cm shaft, the finger sim's) whose
tip sphere centre is the ``fingertip`` site.
The base stands on the table at the world origin.

Control: every 20 ms (50 Hz) mink solves one differential-IK step on an arm-only model (the arm,
the table and the obstacles, no object) for the fingertip target: a FrameTask on the fingertip site
(position, pointing down, yaw along the radial direction), a PostureTask toward the home posture, and
ConfigurationLimit, VelocityLimit and CollisionAvoidanceLimit (arm links vs table and obstacles).
The joint targets are interpolated every physics step without Python: each joint's position actuator
has an integrator activation (the target), and its control is the target's velocity over the chunk,
so the target moves linearly from one IK solution to the next (kp 20000, kv 200, torques capped at
the Panda's 87 / 12 N m). Those caps allow ~170 N at the fingertip, far above the training finger's 10 N
an axis, so :class:`affordplan.sim.pushers.ArmPusher` limits the contact force itself: the target gives way
along the force the arm feels beyond 15 N (an admittance), which keeps rolls from pressing objects into the
table.
"""

from __future__ import annotations

import math

import mink
import mujoco
import numpy as np

from affordplan.errors import ReachabilityError
from affordplan.robot import FINGERTIP_REACH, TIP_RADIUS  # noqa: F401 (re-exported)
from affordplan.world import Box

JOINTS = tuple(f"joint{i}" for i in range(1, 8))
JOINT_LIMITS = (
    (-2.8973, 2.8973), (-1.7628, 1.7628), (-2.8973, 2.8973), (-3.0718, -0.0698),
    (-2.8973, 2.8973), (-0.0175, 3.7525), (-2.8973, 2.8973),
)
VELOCITY_LIMITS = (2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61)  # rad/s
TORQUE_LIMITS = (87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0)  # N m
HOME = (0.0, -0.55, 0.0, -2.35, 0.0, 1.8, 0.785)  # fingertip above the near workspace, pointing down
KP, KV = 20000.0, 200.0
IK_DT = 0.02  # seconds: IK at 50 Hz
FINGERTIP_SITE = "fingertip"
# The fingers are 13 cm long (the Panda's are 5 cm): a pushing tool, so the hand stays above objects
# up to 12 cm tall while the fingertip pushes low on them.
FINGER_LENGTH = 0.132
HAND_TO_TIP = 0.058 + FINGER_LENGTH - TIP_RADIUS  # hand frame to the tip sphere centre, metres
# The tip is a capsule with this much round shaft above its sphere, as long as the training finger's capsule
# (scene.FINGER_LENGTH): with a 2 cm shaft the fingers' box met objects above it, and pushes and rolls that
# work with the finger failed with the arm (turned the object more, or lost it).
TIP_SHAFT = 0.08

ARM_BODIES = ("link1", "link2", "link3", "link4", "link5", "link6", "link7", "hand")
# Geoms kept clear of the table by the IK (the fingertip and fingers must reach it: they push).
TABLE_CLEAR_GEOMS = ("link1_c", "link2_c", "link3_c", "link4_c", "link5_c", "link6_c", "link7_c", "hand_c")
OBSTACLE_CLEAR_GEOMS = TABLE_CLEAR_GEOMS + ("fingers_c", "fingertip_c")

_ARM_GEOM = 'contype="2" conaffinity="1" group="1" rgba="0.92 0.92 0.94 1" friction="0.5 0.005 0.002"'


def _limits(i: int) -> str:
    lo, hi = JOINT_LIMITS[i]
    return f'range="{lo} {hi}"'


def arm_body_xml() -> str:
    """The arm's bodies (Panda frames), to put in ``<worldbody>``."""
    j = [_limits(i) for i in range(7)]
    return f"""
<body name="link0" pos="0 0 0">
  <geom name="link0_c" type="cylinder" size="0.07 0.07" pos="0 0 0.07" {_ARM_GEOM}/>
  <body name="link1" pos="0 0 0.333" gravcomp="1">
    <inertial pos="0 0 -0.05" mass="4.97" diaginertia="0.7 0.7 0.01"/>
    <joint name="joint1" axis="0 0 1" {j[0]} armature="0.1" damping="1"/>
    <geom name="link1_c" type="capsule" fromto="0 0 -0.19 0 0 0" size="0.06" {_ARM_GEOM}/>
    <body name="link2" quat="0.7071068 -0.7071068 0 0" gravcomp="1">
      <inertial pos="0 -0.03 0" mass="0.65" diaginertia="0.03 0.03 0.008"/>
      <joint name="joint2" axis="0 0 1" {j[1]} armature="0.1" damping="1"/>
      <geom name="link2_c" type="capsule" fromto="0 0 0 0 -0.2 0" size="0.06" {_ARM_GEOM}/>
      <body name="link3" pos="0 -0.316 0" quat="0.7071068 0.7071068 0 0" gravcomp="1">
        <inertial pos="0.03 0.04 -0.07" mass="3.23" diaginertia="0.037 0.036 0.011"/>
        <joint name="joint3" axis="0 0 1" {j[2]} armature="0.1" damping="1"/>
        <geom name="link3_c" type="capsule" fromto="0 0 -0.12 0.0825 0 0" size="0.055" {_ARM_GEOM}/>
        <body name="link4" pos="0.0825 0 0" quat="0.7071068 0.7071068 0 0" gravcomp="1">
          <inertial pos="-0.05 0.1 0.03" mass="3.59" diaginertia="0.026 0.02 0.028"/>
          <joint name="joint4" axis="0 0 1" {j[3]} armature="0.1" damping="1"/>
          <geom name="link4_c" type="capsule" fromto="0 0 0 -0.0825 0.2 0" size="0.055" {_ARM_GEOM}/>
          <body name="link5" pos="-0.0825 0.384 0" quat="0.7071068 -0.7071068 0 0" gravcomp="1">
            <inertial pos="-0.01 0.04 -0.04" mass="1.23" diaginertia="0.036 0.029 0.009"/>
            <joint name="joint5" axis="0 0 1" {j[4]} armature="0.1" damping="1"/>
            <geom name="link5_c" type="capsule" fromto="0 0 -0.22 0 0.06 -0.05" size="0.045" {_ARM_GEOM}/>
            <body name="link6" quat="0.7071068 0.7071068 0 0" gravcomp="1">
              <inertial pos="0.06 -0.01 -0.01" mass="1.67" diaginertia="0.002 0.0044 0.0054"/>
              <joint name="joint6" axis="0 0 1" {j[5]} armature="0.1" damping="1"/>
              <geom name="link6_c" type="capsule" fromto="0 0 -0.01 0.088 0 0" size="0.045" {_ARM_GEOM}/>
              <body name="link7" pos="0.088 0 0" quat="0.7071068 0.7071068 0 0" gravcomp="1">
                <inertial pos="0.01 0 0.06" mass="0.74" diaginertia="0.0125 0.01 0.0048"/>
                <joint name="joint7" axis="0 0 1" {j[6]} armature="0.1" damping="1"/>
                <geom name="link7_c" type="cylinder" fromto="0 0 0 0 0 0.07" size="0.045" {_ARM_GEOM}/>
                <body name="hand" pos="0 0 0.107" quat="0.9238795 0 0 -0.3826834" gravcomp="1">
                  <inertial pos="0 0 0.04" mass="0.73" diaginertia="0.001 0.0025 0.0017"/>
                  <geom name="hand_c" type="box" size="0.025 0.09 0.03" pos="0 0 0.03" {_ARM_GEOM}/>
                  <geom name="fingers_c" type="box" size="0.007 0.012 {(FINGER_LENGTH - TIP_SHAFT) / 2}"
                        pos="0 0 {0.058 + (FINGER_LENGTH - TIP_SHAFT) / 2}" {_ARM_GEOM}/>
                  <geom name="fingertip_c" type="capsule" fromto="0 0 {HAND_TO_TIP - TIP_SHAFT} 0 0 {HAND_TO_TIP}"
                        size="{TIP_RADIUS}" contype="2" conaffinity="1" group="1" rgba="0.2 0.2 0.25 1"
                        friction="0.5 0.005 0.002"/>
                  <site name="{FINGERTIP_SITE}" pos="0 0 {HAND_TO_TIP}" size="0.004"/>
                </body>
              </body>
            </body>
          </body>
        </body>
      </body>
    </body>
  </body>
</body>"""


def arm_actuator_xml() -> str:
    """Position actuators whose target (the activation) integrates the control."""
    return "\n".join(
        f'<general name="act{i + 1}" joint="{name}" dyntype="integrator" gaintype="fixed" gainprm="{KP}" '
        f'biastype="affine" biasprm="0 {-KP} {-KV}" actlimited="true" '
        f'actrange="{JOINT_LIMITS[i][0]} {JOINT_LIMITS[i][1]}" ctrllimited="true" ctrlrange="-10 10" '
        f'forcelimited="true" forcerange="{-TORQUE_LIMITS[i]} {TORQUE_LIMITS[i]}"/>'
        for i, name in enumerate(JOINTS)
    )


def ik_model_xml(obstacles: tuple[Box, ...]) -> str:
    """The arm-only model the IK runs on: the arm, the table and the obstacles."""
    from affordplan.sim.mjcf import obstacle_geom_xml

    boxes = "\n".join(obstacle_geom_xml(i, b) for i, b in enumerate(obstacles))
    return f"""<mujoco model="arm_ik">
<compiler angle="radian"/>
<worldbody>
  <geom name="table" type="plane" size="1.5 1.5 0.05"/>
  {boxes}
  {arm_body_xml()}
</worldbody>
</mujoco>"""


def fingertip_rotation(xy) -> np.ndarray:
    """Target orientation of the fingertip site: pointing down, hand yawed along the radial direction."""
    yaw = math.atan2(float(xy[1]), float(xy[0]))
    c, s = math.cos(yaw), math.sin(yaw)
    down = np.diag([1.0, -1.0, -1.0])  # site z along world -z
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ down


class ArmIK:
    """Differential IK for the fingertip on the arm-only model (mink, daqp)."""

    def __init__(self, obstacles: tuple[Box, ...] = ()):
        self.model = mujoco.MjModel.from_xml_string(ik_model_xml(tuple(obstacles)))
        self.configuration = mink.Configuration(self.model)
        self.frame_task = mink.FrameTask(FINGERTIP_SITE, "site", position_cost=1.0, orientation_cost=0.3,
                                         lm_damping=1e-3)
        self.posture_task = mink.PostureTask(self.model, cost=1e-3)
        self.posture_task.set_target(np.array(HOME))
        obstacle_geoms = [f"obstacle{i}" for i in range(len(obstacles))]
        pairs = [(list(TABLE_CLEAR_GEOMS), ["table"])]
        if obstacle_geoms:
            pairs.append((list(OBSTACLE_CLEAR_GEOMS), obstacle_geoms))
        self.limits = [
            mink.ConfigurationLimit(self.model),
            mink.VelocityLimit(self.model, dict(zip(JOINTS, VELOCITY_LIMITS))),
            mink.CollisionAvoidanceLimit(self.model, pairs, minimum_distance_from_collisions=0.01,
                                         collision_detection_distance=0.08),
        ]
        self._site = self.model.site(FINGERTIP_SITE).id
        self.configuration.update(np.array(HOME))

    @property
    def q(self) -> np.ndarray:
        return self.configuration.q.copy()

    def set_q(self, q: np.ndarray) -> None:
        self.configuration.update(np.asarray(q, dtype=float))

    def tip(self) -> np.ndarray:
        return self.configuration.data.site_xpos[self._site].copy()

    def step(self, target: np.ndarray, dt: float = IK_DT, limits: bool = True) -> np.ndarray:
        """One IK step toward the fingertip ``target`` (world, metres); returns the new joint vector."""
        R = fingertip_rotation(target)
        self.frame_task.set_target(mink.SE3.from_rotation_and_translation(mink.SO3.from_matrix(R), target))
        v = mink.solve_ik(self.configuration, [self.frame_task, self.posture_task], dt, "daqp",
                          damping=1e-4, limits=self.limits if limits else self.limits[:1])
        self.configuration.integrate_inplace(v, dt)
        return self.configuration.q.copy()

    def solve(self, target: np.ndarray, q_seed: np.ndarray, iterations: int = 60,
              tolerance: float = 0.002) -> tuple[np.ndarray, float]:
        """Converge on ``target`` from ``q_seed`` (joint limits only); returns (q, position error)."""
        self.set_q(q_seed)
        err = float(np.linalg.norm(self.tip() - target))
        for _ in range(iterations):
            if err < tolerance:
                break
            self.step(target, dt=0.1, limits=False)
            err = float(np.linalg.norm(self.tip() - target))
        return self.configuration.q.copy(), err

    def check_reachable(self, points: list[np.ndarray], q_seed: np.ndarray, tolerance: float = 0.01) -> None:
        """Raise :class:`ReachabilityError` unless the fingertip can reach every point, pointing down."""
        q_saved = self.q
        try:
            q = np.asarray(q_seed, dtype=float)
            for p in points:
                q, err = self.solve(np.asarray(p, dtype=float), q)
                if err > tolerance:
                    raise ReachabilityError(
                        f"the arm cannot reach ({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}) m with the fingertip "
                        f"pointing down: closest {1000 * err:.0f} mm away")
        finally:
            self.set_q(q_saved)
