"""Benchmarks that print figures (never timed unit tests).

``bench_sim``: the cost of a primitive against the raw physics it needs. It executes N random
primitives (random resting state, position, yaw, contact on the point cloud and motion), times the
``execute`` calls, and compares that wall time with the raw ``mj_step`` time of the very same steps
(same model, same states: the time spent inside the ``mj_step(model, data, nstep)`` calls that the
primitives make, each over a 10-step chunk). The ratio is the cost of everything the library adds:
the protocol, target updates, guards, Python.

For reference it also times one ``mj_step(nstep=N)`` call over as many steps from a resting state
(no finger contact, so cheaper per step than a push: a lower bound, not the same work).
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass

import mujoco
import numpy as np
from tqdm import tqdm

from affordplan.errors import ReachabilityError
from affordplan.geometry import relative_rotation
from affordplan.objects.model import ObjectModel, load_object
from affordplan.sim.simulator import Simulator


@dataclass
class SimBenchResult:
    object: str
    pusher: str
    primitives: int
    steps: int
    wall_s: float
    in_loop_physics_s: float
    raw_physics_s: float
    invalid: int
    approach_failed: int
    unreachable: int = 0
    tracking_median_m: float = 0.0  # median over all 20 ms samples of every push
    tracking_p95_m: float = 0.0
    tracking_max_m: float = 0.0

    @property
    def primitives_per_s(self) -> float:
        return self.primitives / self.wall_s

    @property
    def ratio(self) -> float:
        """Wall time of the primitives over the raw ``mj_step`` time of the same steps."""
        return self.wall_s / self.in_loop_physics_s

    @property
    def ratio_resting(self) -> float:
        """Wall time over ``mj_step`` time for as many steps of the object at rest."""
        return self.wall_s / self.raw_physics_s

    def as_dict(self) -> dict:
        d = asdict(self)
        d.update(primitives_per_s=self.primitives_per_s, ratio=self.ratio,
                 ratio_resting=self.ratio_resting, physics_steps_per_s=self.steps / self.in_loop_physics_s,
                 resting_steps_per_s=self.steps / self.raw_physics_s)
        return d

    def report(self) -> str:
        return "\n".join([
            f"object {self.object}, pusher {self.pusher}: {self.primitives} random primitives, "
            f"{self.steps} physics steps",
            f"  primitives per second      {self.primitives_per_s:8.1f}  "
            f"({1000 * self.wall_s / self.primitives:.1f} ms each)",
            f"  mj_step rate, these steps  {self.steps / self.in_loop_physics_s:8.0f} steps/s",
            f"  wall / raw physics         {self.ratio:8.2f}x   (same steps and states; target <= 1.5x)",
            f"  mj_step rate, at rest      {self.steps / self.raw_physics_s:8.0f} steps/s "
            f"(reference: wall / that = {self.ratio_resting:.2f}x)",
            f"  invalid (guards) {self.invalid}, approach failed {self.approach_failed}, "
            f"unreachable {self.unreachable}",
            f"  fingertip tracking during pushes: median {1000 * self.tracking_median_m:.2f} mm, "
            f"p95 {1000 * self.tracking_p95_m:.2f} mm, max {1000 * self.tracking_max_m:.2f} mm "
            "(random motions include pushes into the table, which stop the tip)",
        ])


def random_primitive(sim: Simulator, rng: np.random.Generator, n_points: int = 64):
    """Reset ``sim`` to a random resting state, position and yaw; draw a random contact and motion.

    Returns ``(contact, normal, motion)``; the draws depend on ``rng`` alone, so two simulators of
    the same object fed generators in the same state get the same primitive.
    """
    n_states = len(sim.obj.resting_states)
    sim.reset(resting_state=int(rng.integers(n_states)),
              xy=(rng.uniform(0.4, 0.65), rng.uniform(-0.2, 0.2)), yaw=rng.uniform(-np.pi, np.pi))
    points, normals = sim.point_cloud(n_points)
    i = int(rng.integers(len(points)))
    return points[i], normals[i], rng.uniform(-1.0, 1.0, size=3)


def bench_sim(object_name: str = "cube", n: int = 500, pusher: str = "finger", seed: int = 0,
              progress: bool = True) -> SimBenchResult:
    """Run ``n`` random primitives on ``object_name`` and time them (see the module docstring)."""
    obj = load_object(object_name)
    sim = Simulator(obj, pusher=pusher, seed=seed)
    rng = np.random.default_rng(seed)
    wall = physics = 0.0
    steps = invalid = approach_failed = unreachable = 0
    tracking: list[np.ndarray] = []
    for _ in tqdm(range(n), desc=f"bench sim ({object_name}, {pusher})", disable=not progress, unit="prim"):
        contact, normal, motion = random_primitive(sim, rng)
        physics0, steps0 = sim.physics_time, sim.physics_steps
        t0 = time.perf_counter()
        try:
            out = sim.execute(contact, motion, normal=normal)
        except ReachabilityError:
            unreachable += 1
            continue
        finally:
            wall += time.perf_counter() - t0
            physics += sim.physics_time - physics0
            steps += sim.physics_steps - steps0
        invalid += not out.valid
        approach_failed += not out.approach_ok
        tracking.append(np.asarray(sim.last_tracking_errors))
    sim.reset()
    t0 = time.perf_counter()
    mujoco.mj_step(sim.model, sim.data, nstep=steps)
    raw = time.perf_counter() - t0
    samples = np.concatenate(tracking) if tracking else np.zeros(1)
    return SimBenchResult(object_name, pusher, n, steps, wall, physics, raw, invalid, approach_failed,
                          unreachable, float(np.median(samples)), float(np.percentile(samples, 95)),
                          float(samples.max()))


@dataclass
class Sim2SimResult:
    object: str
    compared: int
    skipped: int  # unreachable for the arm, or invalid in either sim
    displacement_diff_m: np.ndarray  # |t_finger - t_arm| of the final poses, per primitive
    rotation_diff_rad: np.ndarray  # angle between the final orientations, per primitive
    displacement_m: np.ndarray  # the finger's own displacement, for scale

    def report(self) -> str:
        d, r = self.displacement_diff_m, self.rotation_diff_rad
        return "\n".join([
            f"finger vs arm on {self.object}: {self.compared} identical random primitives compared "
            f"({self.skipped} skipped: unreachable or invalid)",
            f"  final position difference  mean {100 * d.mean():5.2f} cm   p90 {100 * np.percentile(d, 90):5.2f} cm",
            f"  final rotation difference  mean {np.degrees(r.mean()):5.1f} deg  p90 "
            f"{np.degrees(np.percentile(r, 90)):5.1f} deg",
            f"  (finger displacement itself: mean {100 * self.displacement_m.mean():.2f} cm)",
        ])


def bench_sim2sim(object_name: str = "cube", n: int = 100, seed: int = 0, progress: bool = True) -> Sim2SimResult:
    """The same ``n`` random primitives run by the finger and by the arm; how far their outcomes differ."""
    obj: ObjectModel = load_object(object_name)
    finger, arm = Simulator(obj, pusher="finger", seed=seed), Simulator(obj, pusher="arm", seed=seed)
    rng_f, rng_a = np.random.default_rng(seed), np.random.default_rng(seed)
    disp, rot, own = [], [], []
    skipped = 0
    for _ in tqdm(range(n), desc=f"sim2sim ({object_name})", disable=not progress, unit="prim"):
        cf, nf, mf = random_primitive(finger, rng_f)
        ca, na, ma = random_primitive(arm, rng_a)
        try:
            out_a = arm.execute(ca, ma, normal=na)
        except ReachabilityError:
            skipped += 1
            continue
        out_f = finger.execute(cf, mf, normal=nf)
        if not (out_f.valid and out_a.valid):
            skipped += 1
            continue
        disp.append(float(np.linalg.norm(out_f.pose_after[:3, 3] - out_a.pose_after[:3, 3])))
        rot.append(relative_rotation(out_f.pose_after, out_a.pose_after)[0])
        own.append(float(np.linalg.norm(out_f.pose_after[:3, 3] - out_f.pose_before[:3, 3])))
    return Sim2SimResult(object_name, len(disp), skipped, np.array(disp), np.array(rot), np.array(own))
