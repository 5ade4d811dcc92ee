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

The timings are **interleaved**: the ``repeats`` of every cell (skill, rater, thread count) are split into
``rounds``, and each round times a share of every cell in turn. A shared machine's speed drifts from minute to
minute (by up to 2x within five minutes on the 2-core development machine); timed one after another, that
drift would show as a difference between skills, interleaved it falls on all of them alike. Each row also
gives the fastest and slowest round's median of one query, how far the machine moved during the run.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
import torch

from affordplan.errors import InputError
from primitives import params as skill_params
from primitives.training.env import PRIMITIVES, skill_observation
from primitives.training.success import time_calls

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
    single_ms_rounds: tuple[float, float]  # the fastest and the slowest round's median of one query

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def bench_queries(skills: tuple[str, ...] = PRIMITIVES, repeats: int = 100, batch: int = 32,
                  threads: tuple[int, ...] = (1, 2), seed: int = 0,
                  weights_dir: str | os.PathLike | None = None, rounds: int = 10) -> list[QueryTiming]:
    """Time the skills' success queries (a parameter asked; see the module docstring), interleaved over ``rounds``.

    Raises:
        InputError: a count under 1, or an unusable ``weights_dir`` (before anything is timed).
    """
    import affordplan as ap
    from primitives.skills import load_skill

    if repeats < 1 or batch < 1 or rounds < 1 or not threads or min(threads) < 1:
        raise InputError("repeats, batch, rounds and threads must be positive")
    rounds = min(rounds, repeats)
    before = torch.get_num_threads()  # loading a skill caps it at 2; put back when done, whatever happens
    sim = None
    try:
        # every skill first, so that an unusable weights_dir is refused before anything is timed
        skills_of = {name: [load_skill(name, searched=searched, weights_dir=weights_dir)
                            for searched in (True, False)] for name in skills}
        rng = np.random.default_rng(seed)
        sim = ap.Simulator(ap.load_object("mug"), seed=seed)
        sim.reset()
        state = sim.obj.classify(sim.object_pose())
        cells = []  # (skill, rater, threads, query, one observation, a batch of them)
        for name in skills:
            params = skill_params.sample(name, rng, sim.obj, state, p_params=1.0)
            for searched, skill in zip((True, False), skills_of[name]):
                if searched and skill.searched_model is None:
                    continue
                obs = skill_observation(sim, name, params, skill.n_points).obs
                n_frames = len(skill.frames(params))
                rater = ("searched model" if searched else f"frame search ({n_frames} frames)" if n_frames > 1
                         else "success model (goal frame)")
                cells += [(name, rater, n, skill.success_probability_obs, obs[None],
                           np.repeat(obs[None], batch, axis=0)) for n in threads]
        single = [[] for _ in cells]  # per cell, per round: seconds of each timed call
        batched = [[] for _ in cells]
        per_round, per_round_batched = -(-repeats // rounds), -(-max(3, repeats // 10) // rounds)  # ceilings
        for r in range(rounds):
            for c, (_, _, n, query, one, many) in enumerate(cells):
                torch.set_num_threads(n)
                warm_up = WARM_UP if r == 0 else 1
                single[c].append(time_calls(query, one, per_round, warm_up))
                batched[c].append(time_calls(query, many, per_round_batched, warm_up))
        rows = []
        for c, (name, rater, n, *_) in enumerate(cells):
            medians = [1e3 * float(np.median(t)) for t in single[c]]
            rows.append(QueryTiming(name, rater, n, 1e3 * float(np.median(np.concatenate(single[c]))),
                                    1e3 * float(np.median(np.concatenate(batched[c]))) / batch, batch,
                                    (min(medians), max(medians))))
    finally:
        torch.set_num_threads(before)
        if sim is not None:
            sim.close()
    return rows


def report(rows: list[QueryTiming]) -> str:
    lines = [f"{'skill':6s} {'rater':26s} {'threads':>7s} {'one query':>10s} {'rounds':>15s} {'in a batch':>11s}",
             "-" * 80]
    for r in rows:
        lo, hi = r.single_ms_rounds
        lines.append(f"{r.skill:6s} {r.rater:26s} {r.threads:7d} {r.single_ms:8.2f} ms {lo:6.2f}-{hi:5.2f} ms "
                     f"{r.batched_ms:8.2f} ms")
    lines.append(f"(median, the skills interleaved; 'rounds': the fastest and slowest round's median of one query; "
                 f"'in a batch': per query, {rows[0].batch if rows else 0} queries a batch; "
                 f"target one query < {TARGET_MS:g} ms on 2 cores)")
    return "\n".join(lines)
