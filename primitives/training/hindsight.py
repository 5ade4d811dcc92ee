"""Hindsight relabelling: what else one executed primitive teaches the critic.

A primitive's outcome is a pair of poses; the objective only turns it into a reward. The same
pair scored against *another* request is an equally exact sample, because the request enters the
policy only through its input (goal flow and goal frame, :mod:`primitives.params`), never through the
physics. :func:`relabel` returns, for one executed primitive, the transitions it is under two other
requests:

- **the achieved request**: a spin that turned the object by ``phi`` is a spin by ``phi`` (clamped to the
  15-45 deg range; turns under 5 deg are not relabelled), a push that moved it ``p`` is a push along
  ``p``'s heading (moves under 1 cm are not relabelled), a roll that ended one roll away in state ``j``
  is a roll to ``j``. Skipped when the episode already succeeded at what it asked.
- **the seed's objective** (``params=None``), for an episode that asked for a parameter, so every
  episode also trains the unparameterised objective, which a parameterised run otherwise forgets
  (RECORD.md, the spin continuation after 0.4).

The contact index is the same point of the same cloud; the motion is re-expressed in the new goal frame,
so that it maps back to the same world motion (a push relabelled to a heading at which that motion would
leave ``[-1, 1]^3`` is skipped: the policy could not have output it). HER for a one-step task: a spin
that turned 20 deg when 40 were asked fails, and is a clean success example of a 20 deg spin. Measured
with the shipped spin exploring as in training, 400 episodes on the training split: 0.33 of spins by an
angle succeed, 0.68 succeed at the angle they achieved (push: 0.06 and 0.08: pushes fail by tipping and
turning, which no heading fixes).

A relabelled goal is chosen after seeing the outcome, so for a start whose outcome is uncertain (the
policy does not see the centre of mass or the friction) it sees the lucky outcomes more often than an
unbiased sample would; the original transition stays in the replay beside it.
"""

from __future__ import annotations

import math

import numpy as np

from affordplan.objects.model import ObjectModel
from affordplan.sim.simulator import Outcome
from primitives import params as skill_params
from primitives import rewards
from primitives.training.env import SkillObservation, observe_cloud

MIN_PUSH_MOVE = 0.01  # metres: shorter moves have no heading worth relabelling to
MIN_SPIN_TURN = math.radians(5.0)


def achieved(skill: str, obj: ObjectModel, outcome: Outcome) -> dict | None:
    """The request the outcome fulfilled best (see the module docstring), or ``None`` for none."""
    T0, T1 = outcome.pose_before, outcome.pose_after
    m = rewards.motion(T0, T1)
    if skill == "push":
        if m.p_xy < MIN_PUSH_MOVE:
            return None
        return {"direction": math.atan2(m.p[1], m.p[0])}
    if skill == "spin":
        phi = math.radians(rewards.signed_turn_deg(m))
        if abs(phi) < MIN_SPIN_TURN:
            return None
        return {"angle": math.copysign(min(max(abs(phi), skill_params.SPIN_MIN), skill_params.SPIN_MAX), phi)}
    start, end = obj.classify(T0), obj.classify(T1)
    if end == start or end not in skill_params.roll_targets(obj, start):
        return None
    return {"target": int(end)}


def relabel(skill: str, obj: ObjectModel, seen: SkillObservation, motion: np.ndarray, outcome: Outcome,
            success: bool) -> list[tuple[np.ndarray, np.ndarray, float, bool]]:
    """The executed primitive under other requests: ``[(obs, motion, reward, success), ...]``.

    ``seen`` is what the policy saw, ``motion`` the goal-frame motion it executed (in ``seen``'s frame),
    ``outcome`` the simulator's, ``success`` whether it met the asked request. Invalid outcomes (the physics
    guards) teach nothing: ``[]``.
    """
    if not outcome.valid:
        return []
    goals = []
    if seen.params is not None:
        goals.append(None)
    if not success:
        goal = achieved(skill, obj, outcome)
        if goal is not None and goal != seen.params:
            goals.append(goal)
    T0, T1 = outcome.pose_before, outcome.pose_after
    motion_world = seen.motion_to_world(motion)
    out = []
    for goal in goals:
        view = observe_cloud(obj, skill, goal, seen.points, seen.normals, T0)
        motion_goal = view.A_frame_world @ motion_world
        if np.any(np.abs(motion_goal) > 1.0 + 1e-6):
            continue
        out.append((view.obs, np.clip(motion_goal, -1.0, 1.0),
                    -rewards.loss(skill, T0, T1, goal, obj), bool(rewards.success(skill, T0, T1, goal, obj))))
    return out
