"""Affordance tables: what each skill is predicted to achieve on an object, state by state, and what it does.

    affordplan affordances lunch_box --trials 10 --plot lunch_box.png

For every resting state of the object, and for every parameter a planner would ask for (push in each
of ``sectors`` directions relative to the object's heading, spin 30 deg each way, roll to each state
one roll away), the table gives the success model's prediction and the rate measured by executing
the skill in the finger sim, over the same ``trials`` starts (random yaw and position near the
middle of the workspace). This is the table the seed's discussion asks for: which actions an object
affords in which state.
"""

from __future__ import annotations

import math
import os
from dataclasses import asdict, dataclass

import numpy as np
from tqdm import tqdm

from affordplan.geometry import wrap_angle
from affordplan.objects.model import ObjectModel
from affordplan.sim.simulator import Simulator
from primitives import params as skill_params
from primitives.params import SKILLS
from primitives.skills import Skill, load_skill

SPIN_ANGLE = math.radians(30.0)


@dataclass
class Affordance:
    state: int
    skill: str
    label: str  # "push 45deg", "spin +30deg", "roll -> 2"
    predicted: float  # mean predicted P(success) over the trials
    measured: float  # success rate measured by executing
    trials: int


def _queries(obj: ObjectModel, state: int, sectors: int) -> list[tuple[str, str, object]]:
    """(skill, label, parameter) triples; push directions are relative to the object's heading."""
    out: list[tuple[str, str, object]] = []
    for k in range(sectors):
        a = 2 * math.pi * k / sectors
        out.append(("push", f"push {math.degrees(a):.0f}deg", a))
    out += [("spin", "spin +30deg", SPIN_ANGLE), ("spin", "spin -30deg", -SPIN_ANGLE)]
    out += [("roll", f"roll -> {t}", t) for t in skill_params.roll_targets(obj, state)]
    return out


def _params(skill: str, value, yaw: float) -> dict:
    if skill == "push":
        return {"direction": wrap_angle(yaw + value)}
    if skill == "spin":
        return {"angle": value}
    return {"target": value}


def affordance_table(obj: ObjectModel, trials: int = 10, sectors: int = 8, seed: int = 0,
                     skills: dict[str, Skill] | None = None, progress: bool = True) -> list[Affordance]:
    """Predicted and measured success of every (state, skill, parameter) on ``obj``."""
    skills = skills or {name: load_skill(name) for name in SKILLS}
    rng = np.random.default_rng(seed)
    sim = Simulator(obj, seed=seed)
    rows: list[Affordance] = []
    jobs = [(s.index, q) for s in obj.resting_states for q in _queries(obj, s.index, sectors)]
    for state, (skill, label, value) in tqdm(jobs, desc=f"affordances {obj.name}", disable=not progress,
                                             unit="action", mininterval=2.0):
        predicted, measured = [], []
        for _ in range(trials):
            yaw = float(rng.uniform(-math.pi, math.pi))
            sim.reset(state, xy=(rng.uniform(0.48, 0.57), rng.uniform(-0.05, 0.05)), yaw=yaw)
            p = _params(skill, value, yaw)
            predicted.append(skills[skill].success_probability(sim, p))
            measured.append(bool(skills[skill].execute(sim, p).success))
        rows.append(Affordance(state, skill, label, float(np.mean(predicted)), float(np.mean(measured)), trials))
    sim.close()
    return rows


def format_table(obj: ObjectModel, rows: list[Affordance]) -> str:
    """A text table: one block per resting state, ``predicted / measured`` per action."""
    lines = [f"{obj.name}: predicted P(success) / measured rate ({rows[0].trials} trials each)" if rows else obj.name]
    for s in obj.resting_states:
        up = np.round(s.up, 2).tolist()
        lines.append(f"state {s.index} (probability {s.probability:.2f}, object up {up}"
                     f"{', rolling family' if s.is_rolling_family else ''})")
        for r in (r for r in rows if r.state == s.index):
            lines.append(f"  {r.label:14s} {r.predicted:5.2f} / {r.measured:4.2f}")
    return "\n".join(lines)


def plot_table(obj: ObjectModel, rows: list[Affordance], path: str | os.PathLike) -> None:
    """One panel per resting state: predicted and measured success per action."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    states = obj.resting_states
    fig, axes = plt.subplots(len(states), 1, figsize=(9, 2.3 * len(states)), squeeze=False)
    for ax, s in zip(axes[:, 0], states):
        rs = [r for r in rows if r.state == s.index]
        x = np.arange(len(rs))
        ax.bar(x - 0.2, [r.predicted for r in rs], 0.4, label="predicted", color="#4c78a8")
        ax.bar(x + 0.2, [r.measured for r in rs], 0.4, label="measured", color="#d98c2b")
        ax.set_xticks(x, [r.label for r in rs], rotation=30, fontsize=7)
        ax.set_ylim(0, 1)
        ax.set_ylabel("P(success)")
        ax.set_title(f"{obj.name}, resting state {s.index} (probability {s.probability:.2f})", fontsize=9)
    axes[0, 0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def as_dicts(rows: list[Affordance]) -> list[dict]:
    return [asdict(r) for r in rows]
