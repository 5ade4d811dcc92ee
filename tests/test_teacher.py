"""The privileged push teacher: pushes along the line through the true centre of mass, all from one start, for
push alone."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from scipy.spatial.transform import Rotation

from affordplan.errors import InputError
from primitives.env import EnvConfig, PrimitiveEnv
from primitives.networks import HybridActorCritic
from primitives.rollouts import Exploration, explore_episode
from primitives.teacher import com_in_observation, teacher_pushes
from primitives.train import TrainConfig, check_config


def _env(objects: tuple[str, ...], p_params: float, seed: int = 0) -> PrimitiveEnv:
    return PrimitiveEnv(EnvConfig("push", objects=objects, n_points=256, p_params=p_params, episodes_per_object=1,
                                  sim_cache=1), seed=seed)


def test_the_centre_of_mass_is_mapped_as_the_observation_maps_points():
    rng = np.random.default_rng(0)
    points = rng.uniform(-0.05, 0.05, size=(50, 3)) + np.array([0.5, 0.1, 0.05])
    A_frame_world = Rotation.from_euler("z", 0.7).as_matrix().T  # world vectors -> a goal frame turned 0.7 rad
    com_world = points[7]
    centred = points.copy()
    centred[:, :2] -= points[:, :2].mean(axis=0)
    assert np.allclose(com_in_observation(com_world, points, A_frame_world), A_frame_world @ centred[7])


def test_teacher_pushes_run_along_the_asked_direction_through_the_centre_of_mass():
    """On a lopsided cloud the contacts sit on the line through the given centre of mass, not the cloud's centre."""
    env = _env(("mug",), p_params=1.0)
    obs = env.reset(resting_state=0)
    com_obs = np.array([0.0, 0.02, 0.03])  # 2 cm to the side of the cloud's centre, in the goal frame
    pushes = teacher_pushes(obs, com_obs, 8, np.random.default_rng(0))
    assert len(pushes) == 8
    assert len({(i, tuple(m)) for i, m in pushes}) == 8  # drawn without replacement
    for idx, motion in pushes:
        assert obs[idx, 3] < -0.5  # the contact faces against +x, the asked direction
        assert abs(obs[idx, 1] - 0.02) < 0.02  # near the line y = 2 cm, not y = 0
        assert motion[1] == 0.0 and 0.7 <= motion[0] <= 1.0 and -0.5 <= motion[2] <= 0.0
    env.close()


def test_a_teacher_episode_pushes_k_times_from_one_start_and_often_moves_a_cube_straight():
    """Physics outcome: every push starts from the same observation; pushes along the centre-of-mass line of a
    cube succeed (>= 5 cm, < 5 deg, along the asked direction) in more than a third of the tries."""
    env = _env(("cube",), p_params=1.0)
    rng, gen = np.random.default_rng(3), torch.Generator().manual_seed(3)
    model = HybridActorCritic()
    successes = tries = 0
    for _ in range(3):
        transitions = explore_episode(model, env, Exploration(p_teacher=1.0, teacher_k=6), rng, gen)
        assert len(transitions) == 6
        obs0 = transitions[0][0]
        assert all(np.array_equal(t[0], obs0) for t in transitions)
        assert all(t[5] for t in transitions)  # valid: restored starts do not trip the physics guards
        successes += sum(t[4] for t in transitions)
        tries += len(transitions)
    assert successes / tries > 1 / 3
    env.close()


def test_without_the_teacher_an_episode_is_one_exploring_action():
    env = _env(("cube",), p_params=1.0)
    transitions = explore_episode(HybridActorCritic(), env, Exploration(), np.random.default_rng(0),
                                  torch.Generator().manual_seed(0))
    assert len(transitions) == 1
    env.close()


@pytest.mark.parametrize("field, value", [("p_teacher", 1.5), ("p_teacher", float("nan")), ("teacher_k", 0)])
def test_bad_teacher_settings_are_refused(tmp_path, field, value):
    with pytest.raises(InputError):
        check_config(TrainConfig(out=str(tmp_path), **{field: value}))


def test_the_teacher_is_for_push_only(tmp_path):
    with pytest.raises(InputError, match="push only"):
        check_config(TrainConfig(primitive="spin", p_teacher=0.2, out=str(tmp_path)))
