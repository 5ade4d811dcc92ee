"""Every option of a frame search executed from one start: the data of an option ranker
(:mod:`primitives.training.ranker`) and of the frame ceiling (:mod:`primitives.research.frame_ceiling`).

A frame search (:mod:`primitives.frames`) sees a start in every frame its request leaves free and, for the seed's
objective, as each stand-in request; each (option, frame) pair is one way the skill could act.
:func:`execute_every_option` acts greedily in each, from the same simulator state (:meth:`Simulator.snapshot`,
restored before each and after the last), and records the policy's decision and the outcome, judged as the skill
judges it: by the request, or by the seed's objective for a stand-in.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from primitives.frames import FrameSearch
from primitives.networks import HybridActorCritic
from primitives.observation import SkillObservation
from primitives.success_model import decision_features
from primitives.training.env import PrimitiveEnv


@dataclass(frozen=True)
class ExecutedOptions:
    """One start's options (:meth:`FrameSearch.options`) and what acting in each did, one row per (option, frame)
    in the order the options list them (the request's goal frame first).

    ``option``: the option of each row (0: the request itself, ``k > 0``: the k-th stand-in); ``frame``: the row's
    frame index within its option; ``decision``: the policy's greedy decision features there ``(m, 14)``
    (:func:`primitives.success_model.decision_features`; column 0 is the critic's value at the chosen contact);
    ``success``: the outcome of executing it from the start.
    """

    options: list[tuple[SkillObservation, np.ndarray]]
    option: np.ndarray
    frame: np.ndarray
    decision: np.ndarray
    success: np.ndarray

    def __len__(self) -> int:
        return len(self.success)

    @property
    def parameterised(self) -> np.ndarray:
        """``(m,)`` bool: the row's option asks for a parameter (a stand-in or the request with one)."""
        return np.array([self.options[k][0].params is not None for k in self.option], dtype=bool)

    def row(self, k: int, j: int) -> int:
        """The row of option ``k``'s frame ``j``."""
        return int(np.flatnonzero((self.option == k) & (self.frame == j))[0])


@torch.no_grad()
def execute_every_option(env: PrimitiveEnv, policy: HybridActorCritic, search: FrameSearch) -> ExecutedOptions:
    """Act greedily in every option of ``search`` on ``env``'s current start, from the start each time (module
    docstring). ``env`` is left at the start, showing the start's own observation."""
    skill, sim, seen = env.config.primitive, env.sim, env.seen
    start = sim.snapshot()
    options = search.options(skill, seen, sim)
    keys = [(k, j) for k, (_, frames) in enumerate(options) for j in range(len(frames))]
    acting = [search.acting(options, k, j) for k, j in keys]
    index, motion, decision = decision_features(policy, torch.from_numpy(
        np.stack([a.obs for a in acting]).astype(np.float32)))
    success = []
    try:
        for n, a in enumerate(acting):
            sim.restore(start)
            env.seen = a
            success.append(env.step(int(index[n]), motion[n].numpy().astype(np.float64)).success)
    finally:
        sim.restore(start)
        env.seen = seen
    return ExecutedOptions(options, np.array([k for k, _ in keys]), np.array([j for _, j in keys]),
                           decision.numpy(), np.array(success, dtype=bool))
