"""The MuJoCo simulator: reset an object, observe it, execute one primitive.

A primitive follows HACMan's protocol (docs/architecture.md): the fingertip is brought 4 cm out along the
contact's outward normal (the finger teleports there; the arm transits at a safe height above the
obstacles and the object, then descends), servoes to 2 cm, then to the contact (the tip's surface touching it); the
motion is 3 control steps that each move the target by ``motion * 3 cm`` over 0.5 s (a caller's ``until``
may end it early: the fingertip then holds where it is); the finger
backs off 2 cm along the normal, rises 5 cm and leaves (the arm rises to the safe height), and the object settles (until
still, at most 2 s).

Physics runs in chunks of ``CHUNK_STEPS`` steps through ``mj_step(..., nstep)``; the pusher target is
updated and the guards run once per chunk (every 20 ms), so no Python runs per physics step.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import mujoco
import numpy as np
from scipy.spatial import cKDTree

from affordplan.checks import as_finite, as_seed, as_vector, as_whole, describe
from affordplan.errors import InputError, PerceptionError, ReachabilityError
from affordplan.geometry import check_pose, make_pose, relative_rotation, transform_points
from affordplan.objects.model import ObjectModel
from affordplan.robot import Protocol
from affordplan.sim.arm import HOME, ArmIK
from affordplan.sim.guards import GuardLimits, PhysicsGuard
from affordplan.sim.pushers import ArmPusher, FingerPusher
from affordplan.sim.scene import OBJECT_BODY, PUSHERS, build_mjcf, set_free_pose
from affordplan.sim.sensor import TABLE_CONTACT_HEIGHT, CameraSensor, check_sensor, surface_cloud
from affordplan.world import Box, Workspace

MAX_COORDINATE = 10.0  # metres: no contact, normal or motion component is larger
OVERLAP_TOLERANCE = 0.002  # metres of penetration into an obstacle that reset() accepts (contact softness)
MAX_CLOUD_POINTS = 100_000  # most points one cloud may ask for
CHUNK_STEPS = 10  # physics steps between target updates and guard checks (20 ms)
__all__ = ["CHUNK_STEPS", "TABLE_CONTACT_HEIGHT", "Outcome", "Protocol", "SimState", "Simulator"]


@dataclass
class Outcome:
    """What one primitive did.

    Attributes:
        pose_before, pose_after: object 4x4 world poses before the approach and after settling.
        n_steps: physics steps simulated.
        approach_ok: the fingertip reached the contact without disturbing the object first.
        valid: no physics guard fired (see :mod:`affordplan.sim.guards`).
        tracking_error_max, tracking_error_median: fingertip-to-target distance during the motion,
            sampled every 20 ms, metres.
        invalid_reason: name of the guard that fired, if any.
        contact, normal, motion: the action as executed (world frame; motion clipped to [-1, 1]).
        success: set by skills that judge the outcome; ``None`` here.
        arm_collisions: (arm geom, obstacle or table geom) name pairs that touched during the
            primitive (arm pusher; the fingertip touching the table is not counted).
        stopped: the motion ended before its last control step because the caller's ``until`` held.
    """

    pose_before: np.ndarray
    pose_after: np.ndarray
    n_steps: int
    approach_ok: bool
    valid: bool
    tracking_error_max: float
    tracking_error_median: float = 0.0
    invalid_reason: str | None = None
    contact: np.ndarray = field(default_factory=lambda: np.zeros(3))
    normal: np.ndarray = field(default_factory=lambda: np.zeros(3))
    motion: np.ndarray = field(default_factory=lambda: np.zeros(3))
    success: bool | None = None
    arm_collisions: tuple[tuple[str, str], ...] = ()
    stopped: bool = False


# Guard faults after which the object is left to settle (the primitive stays invalid): transients of a
# sound simulation. NaN and instability leave nothing worth simulating; an object off the workspace or
# resting off the table already is where it will stay.
SETTLE_AFTER_FAULTS = ("sank", "speed")


@dataclass(frozen=True)
class SimState:
    """Everything the simulator's next primitive depends on, copied (:meth:`Simulator.snapshot`): MuJoCo's state
    and the pusher's own (the arm's commanded target, its force-limit offset and its IK configuration)."""

    model: mujoco.MjModel  # the simulator's own: a state restores only there
    data: mujoco.MjData
    pusher: tuple


MAX_MOTION_STEPS = 10  # the most control steps one call's motion may run (execute's motion_steps)


class _Abort(Exception):
    """Internal: a guard fired; carries its reason."""


class Simulator:
    """A table-top MuJoCo scene with one object, optional box obstacles and a pusher.

    Args:
        obj: the object to simulate.
        obstacles: boxes standing on the table.
        pusher: ``"finger"`` (a force-limited fingertip on slide joints; fast, for training) or ``"arm"``
            (a 7-DOF arm driven by mink IK; see :mod:`affordplan.sim.arm`).
        seed: seeds the point-cloud sampling and the sensor's noise; physics itself is deterministic.
        sensor: ``"cameras"`` (depth cameras, :mod:`affordplan.sim.sensor`; the default) or ``"surface"`` (the
            privileged even sample of the surface the object's parts expose, for ablations only); see
            :meth:`point_cloud`.
        workspace: where objects live; the guards allow a margin around it.
    """

    def __init__(
        self, obj: ObjectModel, obstacles=(), pusher: str = "finger", seed: int = 0,
        workspace: Workspace = Workspace(), protocol: Protocol = Protocol(),
        guard_limits: GuardLimits = GuardLimits(), sensor: str = "cameras",
    ):
        if pusher not in PUSHERS:
            raise InputError(f"unknown pusher {pusher!r}; expected one of {PUSHERS}")
        check_sensor(sensor)
        if not isinstance(obj, ObjectModel):
            raise InputError(f"obj must be an ObjectModel (see affordplan.load_object), got {type(obj).__name__}")
        seed = as_seed("seed", seed)
        if isinstance(obstacles, (str, bytes)) or not hasattr(obstacles, "__iter__"):
            raise InputError(f"obstacles must be a sequence of affordplan.Box, got {describe(obstacles)}")
        obstacles = tuple(obstacles)
        for box in obstacles:
            if not isinstance(box, Box):
                raise InputError(f"obstacles must be affordplan.Box instances, got {type(box).__name__}")
        self.obj = obj
        self.obstacles: tuple[Box, ...] = obstacles
        self.pusher = pusher
        self.sensor = sensor
        self.workspace = workspace
        self.protocol = protocol
        self.model = mujoco.MjModel.from_xml_string(build_mjcf(obj, self.obstacles, pusher))
        self.data = mujoco.MjData(self.model)
        self._rng = np.random.default_rng(seed)
        m = self.model
        self._object_body = m.body(OBJECT_BODY).id
        self._object_qpos = int(m.jnt_qposadr[m.body_jntadr[self._object_body]])
        self._object_qvel = int(m.jnt_dofadr[m.body_jntadr[self._object_body]])
        if pusher == "finger":
            self._pusher = FingerPusher(m, self.data)
            self._ik = None
        else:
            self._ik = ArmIK(self.obstacles)
            self._pusher = ArmPusher(m, self.data, self._ik, CHUNK_STEPS * m.opt.timestep, self._safe_height)
        self._obstacle_geoms = np.array([m.geom(f"obstacle{i}").id for i in range(len(self.obstacles))], dtype=int)
        self._table_geom = m.geom("table").id
        # The arm's fingertip may touch the table (it pushes low); other arm geoms may not.
        self._fingertip_geom = m.geom("fingertip_c").id if pusher == "arm" else -1
        self._collisions: set[tuple[int, int]] = set()
        self._tracking: list[float] = []  # fingertip tracking errors of the current motion, metres
        # Called with the simulator after every control chunk (20 ms): for videos and probes.
        self.on_chunk: Callable[[Simulator], None] | None = None
        hull = obj.hull.vertices
        step = max(1, len(hull) // 256)
        self._guard = PhysicsGuard(m, self.data, self._object_body, hull[::step], workspace, guard_limits)
        self._samples_obj, self._normals_obj = obj.surface_samples()
        self._kdtree = cKDTree(self._samples_obj)
        self._camera = CameraSensor(m, self._object_body) if sensor == "cameras" else None
        self._radius = float(np.max(np.linalg.norm(obj.hull.vertices, axis=1)))
        self.physics_time = 0.0  # seconds spent inside mj_step, for benchmarks
        self.physics_steps = 0
        self._renderers: dict[tuple[int, int], mujoco.Renderer] = {}
        # Where an obstacle stands at the default start the object is thrown clear; reset() refuses such starts.
        self.set_object_pose(obj.resting_states[0].pose((0.5, 0.0), 0.0))

    # ------------------------------------------------------------------ state
    def reset(self, resting_state: int = 0, xy=(0.5, 0.0), yaw: float = 0.0) -> np.ndarray:
        """Place the object in ``resting_state`` at ``xy`` (metres) and ``yaw`` (radians), let it settle.

        Returns the settled 4x4 world pose.
        """
        resting_state = as_whole("resting_state", resting_state, 0, len(self.obj.resting_states) - 1)
        xy = as_vector("xy", xy, 2)
        yaw = as_finite("yaw", yaw)
        if not self.workspace.contains(xy):
            raise InputError(f"xy={tuple(xy)} is outside the workspace {self.workspace}")
        return self.set_object_pose(self.obj.resting_states[int(resting_state)].pose(xy, yaw), check_clear=True)

    def set_object_pose(self, T_world_object: np.ndarray, settle: bool = True, check_clear: bool = False
                        ) -> np.ndarray:
        """Put the object at a 4x4 world pose (velocities zeroed), optionally let it settle.

        ``check_clear``: raise :class:`InputError` (and leave the simulator as it was) when the object would overlap
        an obstacle by more than ``OVERLAP_TOLERANCE``; physics would throw it out.
        """
        T = check_pose(T_world_object, "T_world_object")
        if check_clear and len(self._obstacle_geoms):
            self._check_clear(T)
        mujoco.mj_resetData(self.model, self.data)
        set_free_pose(self.data, self._object_qpos, T)
        self._pusher.home()
        if settle:
            try:
                self._guard.arm()
                self._settle(max_time=0.5)
            except _Abort:
                pass
        return self.object_pose()

    def _check_clear(self, T: np.ndarray) -> None:
        """Raise :class:`InputError` when the object at ``T`` overlaps an obstacle (MuJoCo's contacts, one pass)."""
        data = mujoco.MjData(self.model)
        mujoco.mj_copyData(data, self.model, self.data)
        set_free_pose(data, self._object_qpos, T)
        mujoco.mj_forward(self.model, data)
        n = data.ncon
        if n == 0:
            return
        geoms = np.array([data.contact.geom1[:n], data.contact.geom2[:n]]).T
        object_geom = self.model.geom_bodyid[geoms] == self._object_body
        obstacle = np.isin(geoms, self._obstacle_geoms)
        pair = (object_geom[:, 0] & obstacle[:, 1]) | (object_geom[:, 1] & obstacle[:, 0])
        deep = pair & (data.contact.dist[:n] < -OVERLAP_TOLERANCE)
        if deep.any():
            i = int(np.flatnonzero(deep)[0])
            box = int(geoms[i][obstacle[i]][0])
            raise InputError(f"the object at ({T[0, 3]:.3f}, {T[1, 3]:.3f}) m overlaps {self.model.geom(box).name} by "
                             f"{1000 * -data.contact.dist[i]:.0f} mm; choose a start clear of the obstacles")

    def snapshot(self) -> SimState:
        """A copy of the current state, to :meth:`restore` later: e.g. to try several primitives from one start."""
        data = mujoco.MjData(self.model)
        mujoco.mj_copyData(data, self.model, self.data)
        return SimState(self.model, data, self._pusher.state())

    def restore(self, state: SimState) -> None:
        """Return to a :meth:`snapshot` of this simulator: what a primitive executed next does is then what it
        did from the snapshot (physics is deterministic)."""
        if not isinstance(state, SimState) or state.model is not self.model:
            raise InputError("restore takes a SimState from this simulator's snapshot()")
        mujoco.mj_copyData(self.data, self.model, state.data)
        self._pusher.restore(state.pusher)

    def object_pose(self) -> np.ndarray:
        """The object's 4x4 world pose ``T_world_object``."""
        q = self.data.qpos[self._object_qpos:self._object_qpos + 7]
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, q[3:])
        return make_pose(R.reshape(3, 3), q[:3])

    def point_cloud(self, n: int = 512) -> tuple[np.ndarray, np.ndarray]:
        """``n`` points on the object's surface and their outward unit normals, world frame.

        ``sensor="cameras"`` (the default): the object as the depth cameras of :mod:`affordplan.sim.sensor` see it,
        segmented out by geom, with range noise, dropout and holes at grazing angles; what the table, obstacles or
        the arm hide is missing; normals are estimated from the cloud. ``sensor="surface"``: an even sample of the
        surface the object's convex parts expose, with its exact outward normals (privileged; for ablations;
        :meth:`ObjectModel.surface_samples`). Either way points touching the table are
        left out and the points are drawn with the simulator's seeded generator.

        Raises:
            InputError: ``n`` is not a whole number in [1, 100000].
            PerceptionError: no camera sees the object (it is hidden behind obstacles or the arm).
        """
        n = as_whole("n", n, 1, MAX_CLOUD_POINTS)
        if self._camera is not None:
            mujoco.mj_kinematics(self.model, self.data)
            points, normals = self._camera.cloud(self.data, self._rng, self._radius, n)
            if len(points) == 0:
                raise PerceptionError("no camera sees the object (hidden behind obstacles or the arm)")
            return points, normals
        return surface_cloud(self._samples_obj, self._normals_obj, self.object_pose(), self._rng, n)

    @contextmanager
    def seeing(self, sensor: str) -> Iterator[Simulator]:
        """This simulator showing ``sensor``'s clouds (:meth:`point_cloud`) inside the ``with`` block, and its own
        sensor again after it: e.g. one skill of a plan looking through the cameras its ratings were fitted to while
        the others see the surface sample. The physics and the random generator are the simulator's own.

        Raises:
            InputError: an unknown sensor.
        """
        check_sensor(sensor)
        before = self.sensor, self._camera
        self.sensor = sensor
        self._camera = None if sensor == "surface" else before[1] or CameraSensor(self.model, self._object_body)
        try:
            yield self
        finally:
            self.sensor, self._camera = before

    def surface_normal(self, point_world: np.ndarray) -> np.ndarray:
        """Outward normal (world frame) of the surface sample nearest to ``point_world``."""
        T = self.object_pose()
        p_obj = (np.asarray(point_world) - T[:3, 3]) @ T[:3, :3]
        _, i = self._kdtree.query(p_obj)
        return T[:3, :3] @ self._normals_obj[i]

    # ------------------------------------------------------------- primitive
    def _approach_points(self, contact: np.ndarray, normal) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(unit normal, touch, pre-contact point) of a primitive at ``contact`` (world, metres): the fingertip's
        centre touching the surface, and ``protocol.standoff`` further out along the normal (both kept above
        the table). ``normal``: the outward surface normal; by default that of the nearest surface sample."""
        normal = self.surface_normal(contact) if normal is None else _vector(normal, "normal")
        norm = np.linalg.norm(normal)
        normal = normal / norm if norm > 1e-9 else np.array([0.0, 0.0, 1.0])
        touch = self._clamp(contact + self._pusher.radius * normal)
        return normal, touch, self._clamp(touch + self.protocol.standoff * normal)

    def approach_clear(self, contact, normal=None) -> bool:
        """Whether the pusher can come down to the pre-contact point of ``contact`` (world point, metres) with
        outward ``normal``, as :meth:`execute` would place it; no physics is run. Always, for the finger."""
        _, _, pre = self._approach_points(_vector(contact, "contact"), normal)
        return bool(self._pusher.can_descend_to(pre))

    def _check_reach(self, points: list[np.ndarray]) -> None:
        """Raise :class:`ReachabilityError` unless the arm can reach ``points`` (world, metres), pointing down.

        The check runs differential IK seeded with the arm's configuration. A push near the edge of the reach can
        leave the arm in a configuration from which that IK stalls short of targets it reaches from ``HOME``
        (measured in the plan bench: after a push to x = 0.71 m, every contact of 26 further requests was refused,
        "closest 14-86 mm away", all reachable from ``HOME``). So where the check fails from the arm's
        configuration it is repeated from ``HOME``; when that reaches, the arm is homed (as after a fault: it stands
        retracted above the table) and the primitive goes on from there. Only what ``HOME`` cannot reach raises.
        """
        try:
            self._ik.check_reachable(points, self._pusher.q)
            return
        except ReachabilityError:
            pass
        self._ik.check_reachable(points, np.array(HOME))
        self._pusher.home()

    def execute(self, contact, motion, normal=None,
                until: Callable[[np.ndarray], bool] | None = None,
                steer: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
                motion_steps: int | None = None) -> Outcome:
        """Run one primitive: approach ``contact`` (world point, metres), then move by ``motion``.

        ``motion`` is (3,) in [-1, 1] (values beyond are clipped): each of the protocol's control steps (3, or
        ``motion_steps``, at most ``MAX_MOTION_STEPS``) moves the fingertip target by ``motion * 3 cm``; a call
        that ends on ``until`` may ask for more steps than it expects to need (a push that goes on until the object
        has travelled far enough, :func:`primitives.params.motion_loop`). ``normal`` is the outward surface normal at
        the contact; by default that of the nearest surface sample. ``until``, when given, is called with the
        object's world pose ``T_world_object`` (4x4) after every 20 ms of the motion; once it returns true
        the fingertip target holds at the fingertip's position, the motion ends there and the retract follows
        (``Outcome.stopped``): a spin by an angle ends where the object has turned that far
        (:func:`primitives.params.motion_stop`). ``steer``, when given, is called every 20 ms of the motion with
        the object's world pose and the fingertip target's next increment ``step`` (world, metres) and returns the
        increment to make instead: the motion's path bends where the object's pose asks it to (a push that keeps
        the object from turning, :func:`primitives.params.motion_steer`).
        """
        if until is not None and not callable(until):
            raise InputError(f"until must be a function of the object's pose or None, got {describe(until)}")
        if steer is not None and not callable(steer):
            raise InputError(f"steer must be a function of the object's pose and a step or None, got {describe(steer)}")
        n_motion = self.protocol.motion_steps if motion_steps is None else as_whole(
            "motion_steps", motion_steps, 1, MAX_MOTION_STEPS)
        contact = _vector(contact, "contact")
        motion = np.clip(as_vector("motion", motion, 3), -1.0, 1.0)  # any finite motion; clipped as documented
        normal, touch, pre = self._approach_points(contact, normal)
        p = self.protocol
        steps0 = self.physics_steps
        pose_before = self.object_pose()
        if self._ik is not None:
            self._check_reach([pre, touch])
        result = dict(approach_ok=False, valid=True, invalid_reason=None, stopped=False)
        self._guard.arm()
        self._collisions.clear()
        self._tracking.clear()
        try:
            reason = self._guard.check()  # a start already faulty (sunk, thrown) is never a valid sample
            if reason is not None:
                raise _Abort(reason)
            # The arm comes down onto the pre-contact point from above: when something is in the way (a
            # handle over it), the approach fails without touching anything.
            if self._pusher.can_descend_to(pre):
                result["approach_ok"] = self._approach(pre, touch, normal, pose_before)
                if result["approach_ok"]:
                    target = touch
                    for _ in range(n_motion):
                        if steer is not None:
                            target, stop = self._steered(target, p.motion_step * motion, p.motion_step_time,
                                                         steer, until)
                            if stop:
                                result["stopped"] = True
                                break
                            continue
                        nxt = self._clamp(target + p.motion_step * motion)
                        if self._servo(target, nxt, p.motion_step_time, track=True, until=until):
                            result["stopped"] = True
                            break
                        target = nxt
                self._retract(normal)
            self._settle(p.settle_time_max)
            reason = self._guard.check_rest()
            if reason is not None:
                raise _Abort(reason)
        except _Abort as abort:
            result.update(valid=False, invalid_reason=str(abort))
            self._pusher.home()
            if self.physics_steps > steps0 and str(abort) in SETTLE_AFTER_FAULTS:  # not a refused start
                # The sample is void, but the world goes on: an object caught mid-impact (6 mm into the
                # table for a few milliseconds, say) comes to rest, so the next primitive starts from a
                # settled state instead of inheriting the transient and being refused.
                self._settle(p.settle_time_max, guarded=False)
        names = tuple(sorted({(self.model.geom(a).name, self.model.geom(b).name) for a, b in self._collisions}))
        return Outcome(
            pose_before=pose_before, pose_after=self.object_pose(),
            n_steps=self.physics_steps - steps0, contact=contact, normal=normal, motion=motion,
            arm_collisions=names,
            tracking_error_max=max(self._tracking, default=0.0),
            tracking_error_median=float(np.median(self._tracking)) if self._tracking else 0.0,
            **result,
        )

    def _approach(self, pre: np.ndarray, touch: np.ndarray, normal: np.ndarray, pose_before: np.ndarray) -> bool:
        p = self.protocol
        mid = self._clamp(touch + p.mid_standoff * normal)
        self._pusher.go_to(pre, self._servo)
        if self._pusher_penetrates():
            return False
        self._servo(pre, mid, p.approach_time)
        self._servo(mid, touch, p.approach_time)
        pose = self.object_pose()
        moved = np.linalg.norm(pose[:3, 3] - pose_before[:3, 3])
        turned, _ = relative_rotation(pose_before, pose)
        return bool(
            np.linalg.norm(self._pusher.tip() - touch) <= p.approach_position_tolerance
            and self._pusher.tilt() <= p.approach_tilt_tolerance
            and moved <= p.approach_disturbance
            and turned <= p.approach_disturbance_angle
        )

    def _retract(self, normal: np.ndarray) -> None:
        """Back off along the contact normal, then rise (rising straight from inside a cavity lifts the object)."""
        p = self.protocol
        start = self._pusher.target()
        back = self._clamp(start + p.mid_standoff * normal)
        self._servo(start, back, p.retract_time)
        self._servo(back, back + np.array([0.0, 0.0, p.retract_height]), p.retract_time)
        self._pusher.leave(self._servo)

    def _servo(self, start: np.ndarray, end: np.ndarray, duration: float, track: bool = False,
               until: Callable[[np.ndarray], bool] | None = None) -> bool:
        """Move the fingertip target linearly from ``start`` to ``end``; ``track`` logs the error. With ``until``,
        checked on the object's pose after every chunk: once it holds, the target holds at the fingertip and this
        returns ``True`` (the move ended early)."""
        n_chunks = self._chunks(duration)
        for k in range(1, n_chunks + 1):
            target = start + (end - start) * (k / n_chunks)
            self._pusher.command(target)
            self._step(CHUNK_STEPS)
            if track:
                self._tracking.append(float(np.linalg.norm(self._pusher.tip() - target)))
            if until is not None and until(self.object_pose()):
                self._pusher.command(self._pusher.tip())
                return True
        return False

    def _steered(self, start: np.ndarray, move: np.ndarray, duration: float,
                 steer: Callable[[np.ndarray, np.ndarray], np.ndarray],
                 until: Callable[[np.ndarray], bool] | None) -> tuple[np.ndarray, bool]:
        """Move the fingertip target from ``start`` by ``move`` (world, metres) over ``duration`` seconds, each 20 ms
        increment as ``steer`` bends it from the object's pose; returns the target reached and whether ``until``
        ended the move (the target then holds at the fingertip)."""
        n_chunks = self._chunks(duration)
        step = np.asarray(move, dtype=float) / n_chunks
        target = np.array(start, dtype=float)
        for _ in range(n_chunks):
            bent = as_vector("steer's step", steer(self.object_pose(), step.copy()), 3)
            target = self._clamp(target + bent)
            self._pusher.command(target)
            self._step(CHUNK_STEPS)
            self._tracking.append(float(np.linalg.norm(self._pusher.tip() - target)))
            if until is not None and until(self.object_pose()):
                self._pusher.command(self._pusher.tip())
                return self._pusher.tip(), True
        return target, False

    def _settle(self, max_time: float, guarded: bool = True) -> None:
        p = self.protocol
        still = 0
        for _ in range(self._chunks(max_time)):
            self._step(CHUNK_STEPS, guarded)
            v = self.data.qvel[self._object_qvel:self._object_qvel + 6]
            if np.linalg.norm(v[:3]) < p.settle_linear_speed and np.linalg.norm(v[3:]) < p.settle_angular_speed:
                still += 1
                if still >= p.settle_chunks:
                    return
            else:
                still = 0

    def _chunks(self, duration: float) -> int:
        """Number of control chunks (at least one) covering ``duration`` seconds."""
        return max(1, round(duration / (CHUNK_STEPS * self.model.opt.timestep)))

    def _step(self, n: int, guarded: bool = True) -> None:
        t0 = time.perf_counter()
        mujoco.mj_step(self.model, self.data, nstep=n)
        self.physics_time += time.perf_counter() - t0
        self.physics_steps += n
        if self._ik is not None:
            self._record_arm_collisions()
        if self.on_chunk is not None:
            self.on_chunk(self)
        if not guarded:
            return
        reason = self._guard.check()
        if reason is not None:
            raise _Abort(reason)

    def _record_arm_collisions(self) -> None:
        d = self.data
        if d.ncon == 0:
            return
        pairs = d.contact.geom
        arm_geoms = self._pusher.geoms
        for a_col, b_col in ((0, 1), (1, 0)):
            is_arm = np.isin(pairs[:, a_col], arm_geoms)
            other = pairs[:, b_col]
            hit = is_arm & (np.isin(other, self._obstacle_geoms) | (other == self._table_geom))
            for a, b in pairs[hit][:, [a_col, b_col]]:
                if not (b == self._table_geom and a == self._fingertip_geom):
                    self._collisions.add((int(a), int(b)))

    def _safe_height(self) -> float:
        """Fingertip height for arm transit: clear of the obstacles and the object."""
        tallest = max([b.size[2] for b in self.obstacles] + [0.0])
        top = float(np.max(transform_points(self.object_pose(), self.obj.hull.vertices)[:, 2]))
        return max(tallest, top) + self.protocol.transit_clearance

    @property
    def last_tracking_errors(self) -> list[float]:
        """Fingertip-to-target distances (metres, every 20 ms) during the last primitive's motion."""
        return list(self._tracking)

    # -------------------------------------------------------------- pusher
    def _clamp(self, p: np.ndarray) -> np.ndarray:
        """Keep the fingertip above the table."""
        q = np.array(p, dtype=float)
        q[2] = max(q[2], self._pusher.radius + 0.001)
        return q

    def _pusher_penetrates(self, depth: float = 0.001) -> bool:
        """Whether the pusher is inside the object or an obstacle by more than ``depth`` metres."""
        d = self.data
        if d.ncon == 0:
            return False
        c = d.contact
        involved = np.isin(c.geom[:, 0], self._pusher.geoms) | np.isin(c.geom[:, 1], self._pusher.geoms)
        not_table = (c.geom[:, 0] != self._table_geom) & (c.geom[:, 1] != self._table_geom)
        return bool(np.any(involved & not_table & (c.dist < -depth)))

    # -------------------------------------------------------------- render
    def render(self, width: int = 640, height: int = 480, camera: str = "overview") -> np.ndarray:
        """An RGB image (height, width, 3) of the scene. Headless: set ``MUJOCO_GL=egl``."""
        if mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_CAMERA, camera) < 0:
            names = [self.model.camera(i).name for i in range(self.model.ncam)]
            raise InputError(f"unknown camera {camera!r}; this scene has {names}")
        buffer = self.model.vis.global_
        key = (as_whole("width", width, 1, buffer.offwidth), as_whole("height", height, 1, buffer.offheight))
        if key not in self._renderers:
            self._renderers[key] = mujoco.Renderer(self.model, height=key[1], width=key[0])
        renderer = self._renderers[key]
        renderer.update_scene(self.data, camera=camera)
        return renderer.render()

    def close(self) -> None:
        """Free rendering contexts."""
        for r in self._renderers.values():
            r.close()
        self._renderers.clear()


def _vector(v, name: str) -> np.ndarray:
    """3 finite numbers (metres or a unitless motion), at most ``MAX_COORDINATE`` in magnitude."""
    return as_vector(name, v, 3, MAX_COORDINATE)
