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

from affordplan.objects.model import load_object
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
            f"  invalid (guards) {self.invalid}, approach failed {self.approach_failed}",
        ])


def bench_sim(object_name: str = "cube", n: int = 500, pusher: str = "finger", seed: int = 0,
              progress: bool = True) -> SimBenchResult:
    """Run ``n`` random primitives on ``object_name`` and time them (see the module docstring)."""
    obj = load_object(object_name)
    sim = Simulator(obj, pusher=pusher, seed=seed)
    rng = np.random.default_rng(seed)
    n_states = len(obj.resting_states)
    wall = physics = 0.0
    steps = invalid = approach_failed = 0
    for _ in tqdm(range(n), desc=f"bench sim ({object_name})", disable=not progress, unit="prim"):
        sim.reset(resting_state=int(rng.integers(n_states)),
                  xy=(rng.uniform(0.4, 0.65), rng.uniform(-0.2, 0.2)), yaw=rng.uniform(-np.pi, np.pi))
        points, normals = sim.point_cloud(64)
        i = int(rng.integers(len(points)))
        motion = rng.uniform(-1.0, 1.0, size=3)
        physics0, steps0 = sim.physics_time, sim.physics_steps
        t0 = time.perf_counter()
        out = sim.execute(points[i], motion, normal=normals[i])
        wall += time.perf_counter() - t0
        physics += sim.physics_time - physics0
        steps += sim.physics_steps - steps0
        invalid += not out.valid
        approach_failed += not out.approach_ok
    sim.reset()
    t0 = time.perf_counter()
    mujoco.mj_step(sim.model, sim.data, nstep=steps)
    raw = time.perf_counter() - t0
    return SimBenchResult(object_name, pusher, n, steps, wall, physics, raw, invalid, approach_failed)
