"""How long a skill takes to answer "will this request succeed?" (``affordplan bench query``).

The planner asks the skills' success models thousands of times per plan, so the cost of one answer matters. A
query here is what the planner asks: :meth:`primitives.skills.Skill.success_probability_obs` on a goal-frame
observation, timed for

- **one query** (a cloud on its own: a user calling ``success_probability``), and
- **one query in a batch** (the planner batches its queries per skill, :meth:`planner.predict.Predictor.p_success_many`;
  the batch's time divided by its size),

with each rater a skill can use: the searched success model (one policy decision in the goal frame and the net)
and the frame search's own rating (the policy and the success model in every free frame, then the best, Platt-
scaled), on 1 and 2 torch threads. Medians of ``repeats`` runs; the cloud is the mug's, posed by ``seed``. The
skills are the shipped ones, or a candidate set's (``weights_dir``, as :func:`primitives.skills.load_skill` reads it).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
import torch

from affordplan.errors import InputError
from primitives import params as skill_params
from primitives.env import PRIMITIVES, skill_observation
from primitives.success import bench_query

TARGET_MS = 5.0  # issue target: one query under 5 ms on 2 cores
WARM_UP = 10  # untimed calls before each timing


@dataclass
class QueryTiming:
    skill: str
    rater: str  # "searched model", "frame search (M frames)" or, without a frame search, "success model (goal frame)"
    threads: int
    single_ms: float
    batched_ms: float  # per query, in a batch of ``batch``
    batch: int

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def bench_queries(skills: tuple[str, ...] = PRIMITIVES, repeats: int = 100, batch: int = 32,
                  threads: tuple[int, ...] = (1, 2), seed: int = 0,
                  weights_dir: str | os.PathLike | None = None) -> list[QueryTiming]:
    """Time the skills' success queries (a parameter asked; see the module docstring).

    Raises:
        InputError: a count under 1, or an unusable ``weights_dir`` (before anything is timed).
    """
    import affordplan as ap
    from primitives.skills import load_skill

    if repeats < 1 or batch < 1 or not threads or min(threads) < 1:
        raise InputError("repeats, batch and threads must be positive")
    before = torch.get_num_threads()  # loading a skill caps it at 2; put back when done, whatever happens
    rows, sim = [], None
    try:
        # every skill first, so that an unusable weights_dir is refused before anything is timed
        skills_of = {name: [load_skill(name, searched=searched, weights_dir=weights_dir)
                            for searched in (True, False)] for name in skills}
        rng = np.random.default_rng(seed)
        sim = ap.Simulator(ap.load_object("mug"), seed=seed)
        sim.reset()
        state = sim.obj.classify(sim.object_pose())
        for name in skills:
            params = skill_params.sample(name, rng, sim.obj, state, p_params=1.0)
            for searched, skill in zip((True, False), skills_of[name]):
                if searched and skill.searched_model is None:
                    continue
                obs = skill_observation(sim, name, params, skill.n_points).obs
                many = np.repeat(obs[None], batch, axis=0)
                n_frames = len(skill.frames(params))
                rater = ("searched model" if searched else f"frame search ({n_frames} frames)" if n_frames > 1
                         else "success model (goal frame)")
                for n in threads:
                    torch.set_num_threads(n)
                    single = bench_query(skill.success_probability_obs, obs[None], repeats, WARM_UP)
                    batched = bench_query(skill.success_probability_obs, many, max(3, repeats // 10), WARM_UP) / batch
                    rows.append(QueryTiming(name, rater, n, 1e3 * single, 1e3 * batched, batch))
    finally:
        torch.set_num_threads(before)
        if sim is not None:
            sim.close()
    return rows


def report(rows: list[QueryTiming]) -> str:
    lines = [f"{'skill':6s} {'rater':26s} {'threads':>7s} {'one query':>10s} {'in a batch':>11s}",
             "-" * 64]
    for r in rows:
        lines.append(f"{r.skill:6s} {r.rater:26s} {r.threads:7d} {r.single_ms:8.2f} ms {r.batched_ms:8.2f} ms")
    lines.append(f"(median; 'in a batch': per query, {rows[0].batch if rows else 0} queries a batch; "
                 f"target one query < {TARGET_MS:g} ms on 2 cores)")
    return "\n".join(lines)
