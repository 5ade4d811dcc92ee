"""Scripted exploration for push: the rule reads only the observation, pushes a cube straight, and is wired into
exploring actions for push alone."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import affordplan as ap
from affordplan.errors import InputError
from primitives import rewards
from primitives.networks import HybridActorCritic
from primitives.training.env import EnvConfig, PrimitiveEnv, skill_observation
from primitives.training.rollouts import Exploration, act
from primitives.training.scripted import scripted_push
from primitives.training.train import TrainConfig, check_config


def _cube_env(p_params: float, seed: int = 0) -> PrimitiveEnv:
    return PrimitiveEnv(EnvConfig("push", objects=("cube",), n_points=256, p_params=p_params,
                                  episodes_per_object=1, sim_cache=1), seed=seed)


def test_an_asked_direction_is_pushed_along_from_the_face_against_it():
    env = _cube_env(p_params=1.0)
    rng = np.random.default_rng(0)
    for _ in range(5):
        obs = env.reset(resting_state=0)
        idx, motion = scripted_push(obs, rng)
        assert obs[idx, 3] < -0.5  # the contact's normal (goal frame) faces against +x, the asked direction
        assert abs(obs[idx, 1]) < 0.02  # within 2 cm of the line through the cloud's centre (256 points)
        assert 0.6 <= motion[0] <= 1.0 and motion[1] == 0.0 and -0.5 <= motion[2] <= 0.0
    env.close()


def test_scripted_pushes_move_a_square_on_cube_along_the_asked_direction(cube):
    """Physics outcome: a cube with a face within 10 deg of square to the asked direction is pushed 4-9 cm along
    it, < 1 cm across, and straight (< 5 deg) in most trials: the 256-point cloud leaves the contact up to ~2 cm
    off the centre line, which turns the cube (module docstring of primitives.research.ceiling)."""
    sim = ap.Simulator(cube, seed=0, sensor="surface")  # the scripted rule's geometry, on the exact surface
    rng = np.random.default_rng(0)
    successes = 0
    for _ in range(8):
        direction = rng.uniform(-math.pi, math.pi)
        sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=direction + math.radians(rng.uniform(-10.0, 10.0)))
        seen = skill_observation(sim, "push", {"direction": direction}, 256)
        idx, motion = scripted_push(seen.obs, rng)
        out = sim.execute(seen.points[idx], seen.motion_to_world(motion), normal=seen.normals[idx])
        d = np.array([math.cos(direction), math.sin(direction)])
        m = rewards.motion(out.pose_before, out.pose_after)
        assert out.valid
        assert 0.04 <= float(m.p[:2] @ d) <= 0.09
        assert abs(float(m.p[0] * d[1] - m.p[1] * d[0])) < 0.015
        assert m.theta_deg < 20.0
        successes += rewards.success("push", out.pose_before, out.pose_after, {"direction": direction}, cube)
    assert successes >= 4


def test_without_a_direction_the_push_yaw_is_drawn():
    env = _cube_env(p_params=0.0)
    rng = np.random.default_rng(0)
    obs = env.reset(resting_state=0)
    yaws = {round(math.atan2(m[1], m[0]), 6) for m in (scripted_push(obs, rng)[1] for _ in range(10))}
    assert len(yaws) == 10
    env.close()


def test_exploration_uses_the_script_with_its_probability():
    env = _cube_env(p_params=1.0)
    obs = env.reset(resting_state=0)
    model = HybridActorCritic()
    rng_a, rng_b = np.random.default_rng(7), np.random.default_rng(7)
    rng_b.random()  # act draws one number to decide, then the script draws the rest
    got, want = act(model, obs, Exploration(p_scripted=1.0), rng_a, torch.Generator()), scripted_push(obs, rng_b)
    assert got[0] == want[0] and np.array_equal(got[1], want[1])
    # p_scripted = 0 draws nothing extra: the policy's action, as before the option existed
    gen_a, gen_b = torch.Generator().manual_seed(1), torch.Generator().manual_seed(1)
    rng_a, rng_b = np.random.default_rng(3), np.random.default_rng(3)
    a = act(model, obs, Exploration(), rng_a, gen_a)
    b = act(model, obs, Exploration(p_scripted=0.0), rng_b, gen_b)
    assert a[0] == b[0] and np.array_equal(a[1], b[1])
    env.close()


@pytest.mark.parametrize("primitive, p, message", [("spin", 0.3, "push only"), ("push", 1.5, "probability")])
def test_scripted_exploration_is_refused_where_it_does_not_apply(primitive, p, message):
    with pytest.raises(InputError, match=message):
        check_config(TrainConfig(primitive=primitive, p_scripted=p))
