"""What a skill's policy sees (primitives.observation): per-point features that do not change when the cloud moves on
the table, do change with its height, turn with the goal frame, and a goal-frame motion mapped back to the world."""

from __future__ import annotations

import math

import numpy as np
import pytest

import affordplan as ap
from affordplan.errors import InputError
from primitives.observation import OBS_DIM, SkillObservation, observation, skill_observation


def _rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _cloud(n: int = 50, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    points = np.column_stack([rng.uniform(0.45, 0.55, n), rng.uniform(-0.05, 0.05, n), rng.uniform(0.0, 0.1, n)])
    normals = rng.normal(size=(n, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return points, normals, rng.normal(0.0, 0.02, size=(n, 3))


def test_features_do_not_change_when_the_cloud_moves_on_the_table():
    points, normals, flow = _cloud()
    obs = observation(points, normals, flow)
    assert obs.shape == (50, OBS_DIM) and obs.dtype == np.float32
    moved = observation(points + [0.12, -0.2, 0.0], normals, flow)
    assert np.allclose(moved, obs, atol=1e-6)  # a translation on the table changes nothing
    assert np.allclose(obs[:, :2].mean(axis=0), 0.0, atol=1e-6)  # positions relative to the centroid in the plane
    assert np.allclose(obs[:, 2], points[:, 2], atol=1e-6)  # ... but the height above the table is kept
    raised = observation(points + [0.0, 0.0, 0.03], normals, flow)
    assert np.allclose(raised[:, 2], obs[:, 2] + 0.03, atol=1e-6) and np.allclose(raised[:, 3:], obs[:, 3:])
    assert np.array_equal(obs[:, 3:6], normals.astype(np.float32))
    assert np.array_equal(obs[:, 6:], flow.astype(np.float32))
    assert np.all(observation(points, normals)[:, 6:] == 0.0)  # no flow: the seed's objective


def test_a_cloud_turned_about_the_vertical_looks_the_same_in_its_turned_goal_frame():
    points, normals, flow = _cloud(seed=1)
    R = _rot_z(0.9)
    centre = np.array([0.5, 0.0, 0.0])
    turned = (points - centre) @ R.T + centre
    same = observation(turned, normals @ R.T, flow @ R.T, A_frame_world=R.T)
    assert np.allclose(same, observation(points, normals, flow), atol=1e-6)
    assert not np.allclose(observation(turned, normals @ R.T, flow @ R.T), same, atol=1e-3)  # the world frame differs


def test_a_goal_frame_motion_is_mapped_to_the_world_and_clipped_as_the_simulator_clips_it():
    A = _rot_z(math.pi / 4).T  # the goal frame's x axis points along world (1, 1)/sqrt(2)
    seen = SkillObservation(np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 9), np.float32), None, A)
    assert seen.motion_to_world(np.array([1.0, 0.0, 0.0])) == pytest.approx([math.sqrt(0.5), math.sqrt(0.5), 0.0])
    assert seen.motion_to_world(np.array([1.0, 1.0, 0.5])) == pytest.approx([0.0, 1.0, 0.5])  # sqrt(2) clipped to 1


def test_a_skill_observes_the_simulator_s_cloud_with_checked_params(cube):
    sim = ap.Simulator(cube, seed=2, sensor="surface")
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.0)
    seen = skill_observation(sim, "push", {"direction": math.pi / 2}, 64)
    assert seen.points.shape == (64, 3) and seen.obs.shape == (64, OBS_DIM)
    assert seen.A_frame_world @ np.array([0.0, 1.0, 0.0]) == pytest.approx([1.0, 0.0, 0.0])  # asked direction is +x
    assert np.allclose(seen.obs[:, 6:], seen.obs[0, 6:], atol=1e-6) and seen.obs[0, 6] > 0  # a push flows along +x
    assert np.allclose(skill_observation(sim, "push", None, 64).obs[:, 6:], 0.0)
    with pytest.raises(InputError):
        skill_observation(sim, "push", {"direction": float("nan")}, 64)
    with pytest.raises(InputError):
        skill_observation(sim, "spin", {"direction": 0.0}, 64)
