"""The shipped skills run by the training finger and by the arm from the same starts: the success gap.

The policies are trained with a free fingertip; a user runs them with the 7-DOF arm. For ``n`` draws
(an object of the held-out procedural split, one of its resting states by index, a position in the middle
of the workspace, a yaw, and a parameter), each sim is reset to that start and the skill executed once
with that parameter. The report counts successes in each and the calls that succeeded in one only.
``affordplan bench sim2sim --skill roll -n 80`` prints it.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from affordplan.errors import AffordplanError
from affordplan.objects.model import random_object
from affordplan.sim.simulator import Simulator
from primitives import params as skill_params
from primitives.skills import load_skill

HELD_OUT_OBJECTS = 200  # drawn from the first 200 objects of the held-out split


@dataclass
class SkillSim2SimResult:
    skill: str
    n: int
    finger: list[bool] = field(default_factory=list)  # success per draw
    arm: list[bool] = field(default_factory=list)
    arm_invalid: Counter = field(default_factory=Counter)  # guard that voided an arm call, by name
    finger_invalid: Counter = field(default_factory=Counter)
    errors: int = 0  # draws where either sim refused the call (unreachable, ...)

    def report(self) -> str:
        f, a = np.array(self.finger, bool), np.array(self.arm, bool)
        lines = [
            f"{self.skill}: {len(f)} draws with the same start and parameter in both sims ({self.errors} refused)",
            f"  finger {f.sum():3d} successes ({f.mean():.2f})   arm {a.sum():3d} ({a.mean():.2f})",
            f"  finger only {int((f & ~a).sum())}, arm only {int((a & ~f).sum())}",
        ]
        for name, c in (("finger", self.finger_invalid), ("arm", self.arm_invalid)):
            if c:
                lines.append(f"  {name} calls voided by a guard: " + ", ".join(f"{k} {v}" for k, v in c.most_common()))
        return "\n".join(lines)


def skill_sim2sim(skill: str, n: int = 80, seed: int = 0, progress: bool = True) -> SkillSim2SimResult:
    """Run ``skill`` ``n`` times in both sims from the same draws (module docstring)."""
    rng = np.random.default_rng(seed)
    policy = load_skill(skill)
    result = SkillSim2SimResult(skill, n)
    for i in tqdm(range(n), desc=f"sim2sim {skill}", disable=not progress, unit="draw"):
        obj = random_object(int(rng.integers(HELD_OUT_OBJECTS)), "test")
        state = int(rng.integers(len(obj.resting_states)))
        xy = (float(rng.uniform(0.45, 0.6)), float(rng.uniform(-0.1, 0.1)))
        yaw = float(rng.uniform(-3.0, 3.0))
        outcomes, params = {}, None
        for pusher in ("finger", "arm"):
            sim = Simulator(obj, pusher=pusher, seed=i)
            try:
                sim.reset(resting_state=state, xy=xy, yaw=yaw)
                if params is None:  # drawn once, from the finger's settled state
                    settled = obj.classify(sim.object_pose())
                    params = skill_params.sample(skill, np.random.default_rng(i), obj, settled, 1.0)
                outcomes[pusher] = policy.execute(sim, params)
            except AffordplanError:
                outcomes[pusher] = None
            finally:
                sim.close()
        if outcomes["finger"] is None or outcomes["arm"] is None:
            result.errors += 1
            continue
        for pusher, out in outcomes.items():
            getattr(result, pusher).append(bool(out.success))
            if not out.valid:
                getattr(result, f"{pusher}_invalid")[out.invalid_reason] += 1
    return result
