"""The Gymnasium environments ``affordplan/Push-v0``, ``Roll-v0``, ``Spin-v0`` (primitives.training.gym_env)."""

from __future__ import annotations

import importlib
import math
import warnings

import gymnasium as gym
import mujoco
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import primitives.training.gym_env as gym_env
from affordplan.errors import InputError
from primitives.training.env import OBS_DIM
from primitives.training.gym_env import ENV_IDS, PrimitiveGymEnv, contact_index

FAST = dict(objects="train", n_points=64, sensor="surface")


def _can_render() -> bool:
    """Whether MuJoCo can open an offscreen context here (MUJOCO_GL=egl, set by conftest)."""
    try:
        model = mujoco.MjModel.from_xml_string("<mujoco><worldbody><geom size='0.1'/></worldbody></mujoco>")
        with mujoco.Renderer(model, 8, 8) as renderer:
            renderer.update_scene(mujoco.MjData(model))
            renderer.render()
        return True
    except Exception:  # no GL backend on this machine
        return False


@pytest.mark.parametrize("env_id", sorted(ENV_IDS.values()))
def test_check_env_passes(env_id):
    """gymnasium's check_env passes on each registered id; the only warnings it gives are about the observation
    space's infinite bounds (documented: positions and flows scale with the object)."""
    env = gym.make(env_id, **FAST)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            check_env(env.unwrapped, skip_render_check=not _can_render())
    finally:
        env.close()
    other = [str(w.message) for w in caught if "infinity" not in str(w.message)]
    assert not other, other


def test_same_seed_same_first_observation_and_step():
    """reset(seed=s) gives the same observation and, for the same action, the same reward and info, in a fresh
    environment or after other episodes; another seed gives another observation."""
    action = np.array([0.1, 0.8, -0.2, 0.0], dtype=np.float32)
    a, b = PrimitiveGymEnv("push", **FAST), PrimitiveGymEnv("push", **FAST)
    try:
        obs_a, info_a = a.reset(seed=7)
        _, rew_a, *_ , step_a = a.step(action)
        b.reset(seed=3)
        b.step(b.action_space.sample())
        b.reset()
        obs_b, info_b = b.reset(seed=7)
        _, rew_b, *_, step_b = b.step(action)
        assert np.array_equal(obs_a, obs_b) and obs_a.dtype == np.float32
        assert info_a == info_b
        assert rew_a == rew_b and step_a["success"] == step_b["success"]
        assert np.array_equal(step_a["pose_after"], step_b["pose_after"])
        obs_c, _ = b.reset(seed=8)
        assert not np.array_equal(obs_a, obs_c)
    finally:
        a.close()
        b.close()


def test_an_episode_is_one_step():
    """After one step: terminated, not truncated, a finite float reward, info with bool success and valid and the
    episode's params; a second step without reset is refused."""
    env = gym.make("affordplan/Spin-v0", **FAST)
    try:
        obs, info = env.reset(seed=0)
        assert obs.shape == (64, OBS_DIM) and obs in env.observation_space
        assert set(info) == {"params", "object"}
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert terminated is True and truncated is False
        assert isinstance(reward, float) and math.isfinite(reward)
        assert isinstance(info["success"], bool) and isinstance(info["valid"], bool)
        assert "params" in info and 0 <= info["contact_index"] < 64
        assert info["pose_after"].shape == (4, 4)
        assert obs in env.observation_space
        with pytest.raises(gym.error.ResetNeeded):
            env.unwrapped.step(env.action_space.sample())
    finally:
        env.close()


def test_parameterised_episodes_carry_their_params():
    """With p_params=1 every push episode asks for a direction; reset and step report the same one."""
    env = PrimitiveGymEnv("push", p_params=1.0, **FAST)
    try:
        _, info = env.reset(seed=1)
        assert set(info["params"]) == {"direction"}
        *_, step_info = env.step(np.zeros(4, dtype=np.float32))
        assert step_info["params"] == info["params"]
    finally:
        env.close()


def test_reset_options_pick_the_object_and_the_objective():
    env = PrimitiveGymEnv("push", **FAST)
    try:
        _, info = env.reset(seed=0, options={"object": "cube", "params": {"direction": 0.5}})
        assert info["object"] == "cube" and info["params"] == {"direction": 0.5}
        with pytest.raises(InputError, match="unknown reset options"):
            env.reset(options={"colour": "red"})
    finally:
        env.close()


def test_bad_primitive_and_settings_raise_input_error():
    with pytest.raises(InputError, match="unknown primitive"):
        PrimitiveGymEnv("poke")
    with pytest.raises(InputError, match="unknown primitive"):
        gym.make("affordplan/Push-v0", primitive="poke")
    with pytest.raises(InputError):
        PrimitiveGymEnv("push", n_points=4)
    with pytest.raises(InputError):
        PrimitiveGymEnv("push", sensor="lidar")
    with pytest.raises(InputError):
        PrimitiveGymEnv("push", render_mode="human")


def test_bad_actions_raise_input_error_and_step_needs_reset():
    env = PrimitiveGymEnv("push", **FAST)
    try:
        with pytest.raises(gym.error.ResetNeeded):
            env.step(np.zeros(4, dtype=np.float32))
        env.reset(seed=0)
        for bad in (np.array([0.0, np.nan, 0.0, 0.0]), np.zeros(3), np.zeros((1, 4)), "push"):
            with pytest.raises(InputError):
                env.step(bad)
        _, reward, terminated, _, _ = env.step(np.array([5.0, -9.0, 0.0, 2.0]))  # clipped, not refused
        assert terminated and math.isfinite(reward)
    finally:
        env.close()
        env.close()  # twice is allowed


def test_contact_index_splits_minus_one_to_one_into_equal_bins():
    assert contact_index(-1.0, 64) == 0
    assert contact_index(1.0, 64) == 63
    assert contact_index(0.0, 64) == 32
    assert contact_index(-1.0 + 2 / 64 - 1e-9, 64) == 0
    assert contact_index(-1.0 + 2 / 64 + 1e-9, 64) == 1
    assert contact_index(7.0, 64) == 63 and contact_index(-7.0, 64) == 0
    counts = np.bincount([contact_index(a, 16) for a in np.linspace(-1, 1, 16 * 1000, endpoint=False)], minlength=16)
    assert counts.min() == counts.max() == 1000


def test_registration_is_idempotent_and_reachable_by_module_path():
    """Re-importing the module neither warns nor raises, and gym.make finds an id through its module path."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        importlib.reload(gym_env)
    for primitive, env_id in ENV_IDS.items():
        assert gym.spec(env_id).kwargs == {"primitive": primitive}
    env = gym.make("primitives.training.gym_env:affordplan/Roll-v0", **FAST)
    try:
        assert env.unwrapped.config.primitive == "roll"
    finally:
        env.close()


def test_render_returns_an_image():
    if not _can_render():
        pytest.skip("no offscreen GL context here")
    env = PrimitiveGymEnv("push", render_mode="rgb_array", **FAST)
    try:
        env.reset(seed=0)
        image = env.render()
        assert image.shape == (480, 640, 3) and image.dtype == np.uint8
    finally:
        env.close()
