"""What pushes: a free fingertip (fast, for training) or the 7-DOF arm (what a user runs).

Both expose the same small interface to :class:`~affordplan.sim.simulator.Simulator`, which owns
the primitive protocol and the physics loop:

- ``home()``: put the pusher out of the way, at rest (no physics);
- ``go_to(pos, servo)``: bring the fingertip to ``pos`` before an approach (the finger teleports;
  the arm transits at a safe height, using ``servo`` to run physics);
- ``can_descend_to(pos)``: whether nothing blocks the way down to ``pos`` (always true for the finger);
- ``command(target)``: set the fingertip target for the next control chunk;
- ``leave(servo)``: get clear of the object after a primitive;
- ``tip()``, ``tilt()``: fingertip position (world, metres) and its angle from pointing down (rad).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import mujoco
import numpy as np

from affordplan.sim import arm
from affordplan.sim.scene import FINGER_BODY, FINGER_RADIUS, PARK_POSITION

Servo = Callable[[np.ndarray, np.ndarray, float], None]


class FingerPusher:
    """A capsule fingertip on three world-axis slide joints; its tip sphere centre is the body origin.

    Each axis is a position actuator (kp 2000 N/m, kv 40 N s/m) capped at 10 N (``scene.FINGER_MAX_FORCE``),
    like a robot's fingertip; an unbounded push (a mocap weld) squeezes objects out against the table at speeds no
    robot produces, and a learned policy finds that exploit.
    """

    name = "finger"
    radius = FINGER_RADIUS

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData):
        self.model, self.data = model, data
        self._body = model.body(FINGER_BODY).id
        self._qpos = np.array([int(model.joint(f"finger_{a}").qposadr[0]) for a in "xyz"])
        self._qvel = np.array([int(model.joint(f"finger_{a}").dofadr[0]) for a in "xyz"])
        self._ctrl = np.array([model.actuator(f"finger_{a}").id for a in "xyz"])
        self.geoms = np.array([model.geom("finger_tip").id])

    def home(self) -> None:
        self._teleport(np.asarray(PARK_POSITION, dtype=float))

    def go_to(self, pos: np.ndarray, servo: Servo) -> None:
        self._teleport(pos)

    def can_descend_to(self, pos: np.ndarray) -> bool:
        return True  # the finger teleports to the pre-contact point

    def command(self, target: np.ndarray) -> None:
        self.data.ctrl[self._ctrl] = target

    def target(self) -> np.ndarray:
        return self.data.ctrl[self._ctrl].copy()

    def leave(self, servo: Servo) -> None:
        self.home()

    def tip(self) -> np.ndarray:
        return self.data.xpos[self._body].copy()

    def tilt(self) -> float:
        return 0.0  # slide joints only: the finger always points down

    def state(self) -> tuple:
        """What the finger keeps outside ``MjData``: nothing (:meth:`Simulator.snapshot`)."""
        return ()

    def restore(self, state: tuple) -> None:
        """Undo to :meth:`state` (with ``MjData`` restored by the caller)."""

    def _teleport(self, pos: np.ndarray) -> None:
        d = self.data
        d.qpos[self._qpos] = pos
        d.qvel[self._qvel] = 0.0
        d.ctrl[self._ctrl] = pos
        mujoco.mj_forward(self.model, d)


class ArmPusher:
    """The 7-DOF arm of :mod:`affordplan.sim.arm`, its fingertip driven by mink IK at 50 Hz.

    **Force limit.** The arm's joints are stiff (their torque caps allow ~170 N at the fingertip), and the
    IK target runs on whether or not the arm is blocked, so a motion into an object pressed it into the table
    (the ``"sank"`` guard) where the training finger, capped at 10 N an axis, would have stopped. Each
    control chunk, the net contact force the arm feels beyond ``max_force`` (N) moves the commanded target
    back along that force by the excess over ``admittance_stiffness`` (N/m); below the limit the offset
    relaxes towards zero by ``offset_relax`` of itself a chunk. Free motion (no contact) is unchanged.
    """

    name = "arm"
    radius = arm.TIP_RADIUS
    transit_speed = 0.5  # m/s, fingertip speed between primitives
    max_force = 15.0  # N: about the training finger's (10 N an axis)
    admittance_stiffness = 20000.0  # N/m
    offset_relax = 0.2

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, ik: arm.ArmIK, chunk_time: float,
                 safe_height: Callable[[], float]):
        self.model, self.data, self.ik = model, data, ik
        self._chunk_time = chunk_time
        self._safe_height = safe_height
        joints = [model.joint(n) for n in arm.JOINTS]
        self._qpos = np.array([int(j.qposadr[0]) for j in joints])
        self._qvel = np.array([int(j.dofadr[0]) for j in joints])
        acts = [model.actuator(f"act{i + 1}").id for i in range(7)]
        self._act = np.array([int(model.actuator_actadr[a]) for a in acts])
        self._ctrl = np.array(acts)
        self._site = model.site(arm.FINGERTIP_SITE).id
        self._target = np.zeros(3)
        self._offset = np.zeros(3)  # metres added to the commanded target by the force limit
        bodies = {model.body(n).id for n in arm.ARM_BODIES}
        self.geoms = np.array([g for g in range(model.ngeom) if int(model.geom_bodyid[g]) in bodies])
        self._own_geoms = frozenset(int(g) for g in self.geoms)
        self._wrench = np.zeros(6)

    @property
    def q(self) -> np.ndarray:
        return self.data.qpos[self._qpos].copy()

    def home(self) -> None:
        self.set_q(arm.HOME)

    def set_q(self, q) -> None:
        """Place the arm at rest at joint configuration ``q`` (7, radians), its fingertip target where the tip is."""
        d = self.data
        d.qpos[self._qpos] = q
        d.qvel[self._qvel] = 0.0
        d.act[self._act] = q
        d.ctrl[self._ctrl] = 0.0
        self.ik.set_q(np.array(q, dtype=float))
        mujoco.mj_forward(self.model, d)
        self._target = self.tip()
        self._offset = np.zeros(3)

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """What the arm keeps outside ``MjData`` (:meth:`Simulator.snapshot`): the commanded fingertip target
        (world, metres), the force limit's offset to it (metres) and the IK's joint configuration (radians)."""
        return self._target.copy(), self._offset.copy(), self.ik.q

    def restore(self, state: tuple[np.ndarray, np.ndarray, np.ndarray]) -> None:
        """Undo to :meth:`state` (with ``MjData`` restored by the caller)."""
        target, offset, q_ik = state
        self._target, self._offset = target.copy(), offset.copy()
        self.ik.set_q(q_ik)

    def go_to(self, pos: np.ndarray, servo: Servo) -> None:
        """Transit: up to the safe height, across, and down to ``pos``."""
        start = self._target.copy()
        z_safe = max(self._safe_height(), start[2], pos[2])
        waypoints = [start, np.array([start[0], start[1], z_safe]), np.array([pos[0], pos[1], z_safe]), pos]
        for a, b in zip(waypoints[:-1], waypoints[1:]):
            dist = float(np.linalg.norm(b - a))
            if dist > 1e-4:
                servo(a, b, max(dist / self.transit_speed, self._chunk_time))

    def can_descend_to(self, pos: np.ndarray) -> bool:
        """Whether the fingertip can come straight down to ``pos`` (world, metres) from the safe height.

        Five vertical rays (the axis and four at 0.9 of the tip radius) are cast from the safe height;
        anything but the arm itself met above the tip's lowest point at ``pos`` blocks the way (a mug's
        handle over the pre-contact point: descending through it hooks the mug and lifts it off).
        """
        top = max(self._safe_height(), float(pos[2])) + 0.01
        floor = float(pos[2]) - self.radius
        down = np.array([0.0, 0.0, -1.0])
        hit = np.zeros(1, dtype=np.int32)
        for dx, dy in ((0.0, 0.0), (1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)):
            start = np.array([pos[0] + 0.9 * self.radius * dx, pos[1] + 0.9 * self.radius * dy, top])
            while True:  # skip the arm's own geoms (it may hang above the spot)
                dist = mujoco.mj_ray(self.model, self.data, start, down, None, 1, -1, hit)
                if dist < 0 or start[2] - dist <= floor:
                    break
                if int(hit[0]) not in self._own_geoms:
                    return False
                start = start + (dist + 1e-4) * down
        return True

    def command(self, target: np.ndarray) -> None:
        self._target = np.asarray(target, dtype=float).copy()
        force = self.contact_force()
        excess = float(np.linalg.norm(force)) - self.max_force
        if excess > 0.0:
            self._offset += force / np.linalg.norm(force) * (excess / self.admittance_stiffness)
        else:
            self._offset *= 1.0 - self.offset_relax
        q_next = self.ik.step(self._target + self._offset)
        self.data.ctrl[self._ctrl] = (q_next - self.data.act[self._act]) / self._chunk_time

    def contact_force(self) -> np.ndarray:
        """Net force (world frame, N) that everything the arm touches exerts on it, now."""
        d = self.data
        total = np.zeros(3)
        if d.ncon == 0:
            return total
        c = d.contact
        mine1, mine2 = np.isin(c.geom[:, 0], self.geoms), np.isin(c.geom[:, 1], self.geoms)
        for i in np.flatnonzero(mine1 != mine2):  # the arm against something else
            mujoco.mj_contactForce(self.model, d, int(i), self._wrench)
            f_world = c.frame[i].reshape(3, 3).T @ self._wrench[:3]  # on geom2, from geom1 (normal: 1 -> 2)
            total += f_world if mine2[i] else -f_world
        return total

    def target(self) -> np.ndarray:
        return self._target.copy()

    def leave(self, servo: Servo) -> None:
        start = self._target.copy()
        up = np.array([start[0], start[1], max(self._safe_height(), start[2])])
        if up[2] - start[2] > 1e-4:
            servo(start, up, max((up[2] - start[2]) / self.transit_speed, self._chunk_time))
        self.data.ctrl[self._ctrl] = 0.0  # hold the last target

    def tip(self) -> np.ndarray:
        return self.data.site_xpos[self._site].copy()

    def tilt(self) -> float:
        axis = self.data.site_xmat[self._site].reshape(3, 3)[:, 2]  # points down when vertical
        return math.acos(float(np.clip(-axis[2], -1.0, 1.0)))
