"""A privileged push teacher for training: pushes along the line through the true centre of mass.

The push ceiling (:mod:`primitives.ceiling`) found that about one push in three along the line through the
centre of mass succeeds on the held-out family, and that some such push succeeds on 67 % of starts with a
direction (87 % on the seed's objective), while the policy reaches 0.45-0.55: its critic does not yet tell
the one push that works from its neighbours. Observation-only scripted pushes (:mod:`primitives.scripted`)
aim at the cloud's horizontal centre, which misses the centre of mass of lopsided objects.

In training only, the simulator knows the centre of mass. With probability ``Exploration.p_teacher`` a
worker's episode becomes a **teacher episode**: :func:`teacher_pushes` draws ``Exploration.teacher_k``
pushes along the line through the centre of mass (contacts among the policy's own 256 points, facing the
push, in three height bands of the lower 70 %; strokes and presses as the ceiling's), and the worker executes
each from the same start (the simulator state is restored between them). All of them enter the replay with
their rewards: several actions on one observation, some that work and some that do not, which is the
contrast the critic lacks. The policy never sees the centre of mass; the critic regresses rewards, so these
off-policy samples need no correction (as for the scripted pushes).
"""

from __future__ import annotations

import math

import numpy as np

from primitives.scripted import HEIGHT_BANDS, facing_and_offset

PER_BAND = 2  # facing points nearest the centre-of-mass line, per height band
STROKES = (0.7, 1.0)  # fractions of the full stroke along the push
PRESSES = (0.0, 0.5)  # downward motion components


def com_in_observation(com_world: np.ndarray, points_world: np.ndarray, A_frame_world: np.ndarray) -> np.ndarray:
    """The centre of mass (world, metres) in the observation's frame: horizontally centred on the cloud's mean,
    rotated into the goal frame (as :func:`primitives.env.observation` maps the points)."""
    rel = np.array(com_world, dtype=float)
    rel[:2] -= np.asarray(points_world, dtype=float)[:, :2].mean(axis=0)
    return np.asarray(A_frame_world, dtype=float) @ rel


def teacher_pushes(obs: np.ndarray, com_obs: np.ndarray, k: int,
                   rng: np.random.Generator) -> list[tuple[int, np.ndarray]]:
    """Up to ``k`` pushes (contact index, goal-frame motion in [-1, 1]^3) along the line through ``com_obs``.

    The push runs along +x of the goal frame when the observation asks for a direction (non-zero flow),
    otherwise along one uniformly drawn yaw (the seed's objective takes any direction). ``k`` are drawn
    without replacement from every (band contact, stroke, press) combination.
    """
    obs = np.asarray(obs, dtype=np.float64)
    points, normals, flow = obs[:, :3], obs[:, 3:6], obs[:, 6:9]
    yaw = 0.0 if np.abs(flow).max() > 0 else rng.uniform(-math.pi, math.pi)
    d = np.array([math.cos(yaw), math.sin(yaw), 0.0])
    facing, lateral = facing_and_offset(points, normals, np.asarray(com_obs, dtype=float), d)
    z0, z1 = points[:, 2].min(), points[:, 2].max()
    contacts: list[int] = []
    for lo, hi in HEIGHT_BANDS:
        band = np.flatnonzero(facing & (points[:, 2] >= z0 + lo * (z1 - z0)) & (points[:, 2] <= z0 + hi * (z1 - z0)))
        contacts += [int(i) for i in band[np.argsort(lateral[band], kind="stable")[:PER_BAND]]]
    if not contacts:  # degenerate cloud: the point furthest against the push
        contacts = [int(np.argmin(points @ d))]
    pushes = [(i, np.clip(s * d + np.array([0.0, 0.0, -p]), -1.0, 1.0))
              for i in dict.fromkeys(contacts) for s in STROKES for p in PRESSES]
    chosen = rng.choice(len(pushes), size=min(k, len(pushes)), replace=False)
    return [pushes[int(j)] for j in chosen]
