"""The one-step environment (primitives.training.env): the seed's reward, cached object models, refused configs."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from primitives.training.env import EnvConfig, PrimitiveEnv


def test_env_step_returns_the_seed_reward():
    env = PrimitiveEnv(EnvConfig("push", objects=("cube",), n_points=64), seed=0)
    obs = env.reset()
    assert obs.shape == (64, 9) and obs.dtype == np.float32
    assert np.allclose(obs[:, :2].mean(axis=0), 0.0, atol=1e-5)
    res = env.step(0, np.array([1.0, 0.0, 0.0]))
    from primitives import rewards

    assert res.reward == pytest.approx(-rewards.push_loss(res.outcome.pose_before, res.outcome.pose_after))


def test_env_builds_each_object_model_once_and_the_cache_changes_no_episode():
    """Three objects drawn in turn through one cached simulator: with the model cache each object's model
    (resting states, surface samples) is built once and reused when its simulator is rebuilt; without it,
    rebuilt. The clouds and rewards are the same either way."""
    def run(model_cache):
        env = PrimitiveEnv(EnvConfig("spin", objects=("cube", "tape", "pill_bottle"), n_points=64,
                                     episodes_per_object=1, sim_cache=1, model_cache=model_cache), seed=4)
        seen, rng = [], np.random.default_rng(0)
        for key in ("cube", "tape", "cube", "pill_bottle", "tape", "cube"):
            obs = env.reset(object_key=key)
            res = env.step(int(rng.integers(64)), rng.uniform(-1, 1, size=3))
            seen.append((key, env.sim.obj, obs, res.reward))
        env.close()
        return seen

    cached, uncached = run(512), run(0)
    models = {}
    for key, model, _, _ in cached:
        assert models.setdefault(key, model) is model  # one model per object, reused
    assert len({id(model) for key, model, _, _ in uncached if key == "cube"}) == 3  # rebuilt each draw (held)
    for (_, _, obs_c, r_c), (_, _, obs_u, r_u) in zip(cached, uncached):
        assert np.array_equal(obs_c, obs_u) and r_c == r_u


@pytest.mark.parametrize("field, value, words", [
    ("primitive", "jump", "unknown primitive 'jump'"),
    ("sim_cache", 0, "EnvConfig.sim_cache must be a whole number >= 1, got 0"),  # would close the sim in use
    ("model_cache", -1, "EnvConfig.model_cache must be a whole number >= 0, got -1"),
    ("n_points", 8.0, "EnvConfig.n_points must be a whole number >= 16, got 8.0"),
    ("episodes_per_object", 0, "EnvConfig.episodes_per_object must be a whole number >= 1"),
    ("p_params", float("nan"), "EnvConfig.p_params is a probability in [0, 1], got nan"),
])
def test_env_refuses_a_config_it_cannot_run(field, value, words):
    from affordplan.errors import InputError

    with pytest.raises(InputError) as info:
        PrimitiveEnv(replace(EnvConfig("push", objects=("cube",)), **{field: value}))
    assert words in str(info.value)
    env = PrimitiveEnv(EnvConfig("push", objects=("cube",), n_points=16, sim_cache=1, model_cache=0))
    assert env.reset().shape == (16, 9)  # the least values run


def test_full_motion_runs_a_spin_by_an_angle_to_the_end_of_its_motion():
    """The same spins by an angle from the same starts: by default a spin that turns the box the asked angle ends
    its motion there (``Outcome.stopped``), with ``full_motion`` none does, and a spin that never got that far is the
    same primitive either way."""
    def run(full_motion):
        env = PrimitiveEnv(EnvConfig("spin", objects=("lunch_box",), n_points=64, p_params=1.0,
                                     full_motion=full_motion), seed=3)
        rng, rows = np.random.default_rng(1), []
        for _ in range(16):
            env.reset(params={"angle": 0.3})
            res = env.step(int(rng.integers(64)), rng.uniform(-1, 1, size=3))
            rows.append((res.outcome.stopped, res.outcome.pose_after))
        env.close()
        return rows

    stopping, full = run(False), run(True)
    assert any(stopped for stopped, _ in stopping) and not all(stopped for stopped, _ in stopping)
    assert not any(stopped for stopped, _ in full)
    for (stopped, T_after), (_, T_full) in zip(stopping, full):
        if not stopped:
            assert np.allclose(T_after, T_full, atol=1e-9)
