"""Trained primitives as skills a planner or a user can call on a simulator.

    from primitives import load_skill
    push = load_skill("push")            # the shipped weights (primitives/weights/push.pt)
    contact, motion = push.act(sim)      # greedy: argmax of the critic map, the actor's motion
    outcome = push.execute(sim)          # Outcome with .success by the seed's criterion

This release runs the seed's unparameterised objectives (``params=None``); parameterised skills and
learned success models are the next step.
"""

from __future__ import annotations

import os

import numpy as np
import torch

from affordplan.errors import InputError
from affordplan.sim.simulator import Outcome, Simulator
from primitives import rewards
from primitives.env import PRIMITIVES, observation
from primitives.evaluate import greedy_action, load_policy
from primitives.networks import HybridActorCritic


class Skill:
    """A trained primitive acting greedily on a simulator's point cloud."""

    def __init__(self, name: str, model: HybridActorCritic, n_points: int = 256):
        self.name = name
        self.model = model
        self.n_points = n_points

    def _decide(self, sim: Simulator, params) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if params is not None:
            raise InputError(f"the {self.name} skill of this release takes no parameters (got {params!r})")
        points, normals = sim.point_cloud(self.n_points)
        idx, motion, _ = greedy_action(self.model, observation(points, normals))
        return points[idx], normals[idx], motion

    def act(self, sim: Simulator, params=None) -> tuple[np.ndarray, np.ndarray]:
        """The contact point (world, metres) and motion in [-1, 1]^3 the policy picks."""
        contact, _, motion = self._decide(sim, params)
        return contact, motion

    def execute(self, sim: Simulator, params=None) -> Outcome:
        """Act and execute; ``Outcome.success`` is the seed's criterion (and the sample valid)."""
        contact, normal, motion = self._decide(sim, params)
        out = sim.execute(contact, motion, normal=normal)
        out.success = bool(out.valid and rewards.SUCCESSES[self.name](out.pose_before, out.pose_after))
        return out


def load_skill(name: str, weights: str | os.PathLike | None = None) -> Skill:
    """The ``push``, ``roll`` or ``spin`` skill, from the shipped weights or a given file."""
    if name not in PRIMITIVES:
        raise InputError(f"unknown skill {name!r}; expected one of {PRIMITIVES}")
    torch.set_num_threads(max(1, min(torch.get_num_threads(), 2)))
    return Skill(name, load_policy(weights, name))
