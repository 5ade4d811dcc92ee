"""Scripted pushes read off a policy observation: an exploration prior for training push.

A push-straight succeeds only when the push line passes within millimetres of the centre of mass and the
contact sits low enough not to tip the object (:mod:`primitives.research.ceiling`): about one push in three of
that shape succeeds on the held-out family, while an exploring policy early in training succeeds on
6-8 % of its pushes, so the critic sees few positives. With probability ``Exploration.p_scripted``
a training worker replaces its action with :func:`scripted_push`; the transition enters the replay like
any other. The critic regresses the immediate reward, so off-policy samples need no correction, and the
actor then climbs towards what the critic learned from them.

The rule uses only what the policy itself sees (the goal-frame observation of
:func:`primitives.training.env.observation`): points centred on their horizontal mean, outward normals, and the
goal flow. No centre of mass, no dense cloud:

- **direction**: +x of the goal frame when a direction is asked (the flow is non-zero), otherwise a
  uniformly drawn yaw (the seed's objective takes any direction);
- **contact**: among points whose normal faces against the push by more than 60 deg, in a height band
  drawn at random (the lower 70 % of the cloud's height: higher contacts tip objects), one of the
  ``NEAREST`` nearest to the line through the cloud's horizontal centre along the push;
- **motion**: along the push, a stroke of 0.6-1.0 of the full one, pressing down by 0-0.5.
"""

from __future__ import annotations

import math

import numpy as np

FACING_COS = -0.5  # normal . push below this: the surface faces the push (by more than 60 deg)
HEIGHT_BANDS = ((0.05, 0.3), (0.3, 0.5), (0.5, 0.7))  # fractions of the cloud's height (the top quarter tips)
NEAREST = 2  # the contact is drawn among this many points nearest the push line through the centre
STROKE = (0.6, 1.0)  # fraction of the full stroke along the push
PRESS = (0.0, 0.5)  # downward motion component


def facing_and_offset(points: np.ndarray, normals: np.ndarray, centre: np.ndarray,
                      d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For a push along the horizontal unit vector ``d``: which points face it (normal against it by more than
    60 deg), and each point's horizontal distance from the push line through ``centre`` (metres)."""
    rel = points - centre
    return normals @ d < FACING_COS, np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0])


def scripted_push(obs: np.ndarray, rng: np.random.Generator) -> tuple[int, np.ndarray]:
    """A scripted push for a goal-frame observation ``(n, 9)``: contact index and goal-frame motion in [-1, 1]^3."""
    obs = np.asarray(obs, dtype=np.float64)
    points, normals, flow = obs[:, :3], obs[:, 3:6], obs[:, 6:9]
    yaw = 0.0 if np.abs(flow).max() > 0 else rng.uniform(-math.pi, math.pi)
    d = np.array([math.cos(yaw), math.sin(yaw), 0.0])
    facing, lateral = facing_and_offset(points, normals, np.zeros(3), d)  # the cloud is centred horizontally
    if not facing.any():  # degenerate cloud: the point furthest against the push
        facing = points @ d <= (points @ d).min() + 1e-9
    z0, z1 = points[:, 2].min(), points[:, 2].max()
    lo, hi = HEIGHT_BANDS[int(rng.integers(len(HEIGHT_BANDS)))]
    band = facing & (points[:, 2] >= z0 + lo * (z1 - z0)) & (points[:, 2] <= z0 + hi * (z1 - z0))
    idx = np.flatnonzero(band if band.any() else facing)
    nearest = idx[np.argsort(lateral[idx], kind="stable")[:NEAREST]]
    index = int(nearest[int(rng.integers(len(nearest)))])
    motion = rng.uniform(*STROKE) * d + np.array([0.0, 0.0, -rng.uniform(*PRESS)])
    return index, np.clip(motion, -1.0, 1.0)
