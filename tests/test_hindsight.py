"""Hindsight relabelling: exact rewards of the same outcome under the request it achieved and the seed's."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from affordplan.sim.simulator import Outcome
from primitives import rewards
from primitives.training.env import EnvConfig, PrimitiveEnv, observe_cloud
from primitives.training.hindsight import achieved, relabel
from primitives.training.train import TrainConfig, train


def _start(skill: str, params):
    env = PrimitiveEnv(EnvConfig(skill, objects=("cube",), n_points=64, episodes_per_object=1), seed=3)
    env.reset(params=params)
    T0 = env.sim.object_pose()
    return env, T0


def _moved(T0, dxy=(0.0, 0.0), yaw_deg=0.0, R_extra=None):
    T1 = T0.copy()
    T1[:3, :3] = Rotation.from_euler("z", yaw_deg, degrees=True).as_matrix() @ T0[:3, :3]
    if R_extra is not None:
        T1[:3, :3] = R_extra @ T1[:3, :3]
    T1[:2, 3] += dxy
    return T1


def _outcome(T0, T1, valid=True) -> Outcome:
    return Outcome(pose_before=T0, pose_after=T1, n_steps=10, approach_ok=True, valid=valid, tracking_error_max=0.0)


def test_a_spin_short_of_its_angle_is_a_success_at_the_angle_it_turned():
    env, T0 = _start("spin", {"angle": math.radians(40.0)})
    seen = env.seen
    out = _outcome(T0, _moved(T0, yaw_deg=-20.0))
    assert not rewards.success("spin", T0, out.pose_after, seen.params)
    motion = np.array([0.3, -0.5, 0.1])
    copies = relabel("spin", env.sim.obj, seen, motion, out, success=False)
    assert len(copies) == 2  # the seed's objective and the achieved turn
    (obs_none, m_none, r_none, s_none), (obs_hit, m_hit, r_hit, s_hit) = copies
    # the seed's objective: world frame, no flow, the seed's reward; 20 deg is short of its 30
    assert np.allclose(obs_none[:, 6:], 0.0) and np.allclose(m_none, seen.motion_to_world(motion))
    assert r_none == pytest.approx(-rewards.spin_loss(T0, out.pose_after)) and not s_none
    # the achieved turn: a clockwise 20 deg spin, seen mirrored, succeeds with its own loss
    goal = achieved("spin", env.sim.obj, out)
    assert goal["angle"] == pytest.approx(math.radians(-20.0), abs=1e-6)
    view = observe_cloud(env.sim.obj, "spin", goal, seen.points, seen.normals, T0)
    assert np.allclose(obs_hit, view.obs) and s_hit
    assert r_hit == pytest.approx(-rewards.loss("spin", T0, out.pose_after, goal))
    # the same world motion in the mirrored frame
    assert np.allclose(view.motion_to_world(m_hit), seen.motion_to_world(motion))


def test_turns_are_clamped_to_the_spin_range_and_tiny_ones_teach_nothing():
    env, T0 = _start("spin", {"angle": math.radians(30.0)})
    obj = env.sim.obj
    assert achieved("spin", obj, _outcome(T0, _moved(T0, yaw_deg=10.0)))["angle"] == pytest.approx(math.radians(15))
    assert achieved("spin", obj, _outcome(T0, _moved(T0, yaw_deg=52.0)))["angle"] == pytest.approx(math.radians(45))
    assert achieved("spin", obj, _outcome(T0, _moved(T0, yaw_deg=3.0))) is None
    # a 10 deg turn relabelled to 15 deg is within the 10 deg tolerance: a success
    copies = relabel("spin", obj, env.seen, np.zeros(3), _outcome(T0, _moved(T0, yaw_deg=10.0)), success=False)
    assert [c[3] for c in copies] == [False, True]


def test_a_straight_push_off_its_heading_is_a_push_along_the_heading_it_took():
    env, T0 = _start("push", {"direction": math.radians(90.0)})
    seen = env.seen
    heading = math.radians(30.0)
    out = _outcome(T0, _moved(T0, dxy=0.06 * np.array([math.cos(heading), math.sin(heading)])))
    motion = np.array([0.5, 0.2, -0.1])  # goal frame of the asked heading
    copies = relabel("push", env.sim.obj, seen, motion, out, success=False)
    assert [c[3] for c in copies] == [True, True]  # the seed's objective and the heading taken
    obs_hit, m_hit = copies[1][0], copies[1][1]
    view = observe_cloud(env.sim.obj, "push", {"direction": heading}, seen.points, seen.normals, T0)
    assert np.allclose(obs_hit, view.obs)
    assert np.allclose(view.motion_to_world(m_hit), seen.motion_to_world(motion))
    # the flow of the relabelled request points along +x of its goal frame
    assert np.allclose(obs_hit[:, 6:], [0.05, 0.0, 0.0], atol=1e-6)


def test_a_push_whose_motion_would_leave_the_box_in_the_new_frame_is_not_relabelled():
    env, T0 = _start("push", {"direction": 0.0})
    out = _outcome(T0, _moved(T0, dxy=(0.04, 0.04)))  # moved along 45 deg
    motion = np.array([1.0, 1.0, 0.0])  # world (1, 1): sqrt(2) along the 45 deg heading
    copies = relabel("push", env.sim.obj, env.seen, motion, out, success=False)
    assert len(copies) == 1 and np.allclose(copies[0][1], motion)  # only the seed's objective, world frame


def test_a_successful_or_unparameterised_or_invalid_primitive_adds_only_what_is_new():
    env, T0 = _start("push", None)
    out = _outcome(T0, _moved(T0, dxy=(0.06, 0.0)))
    assert len(relabel("push", env.sim.obj, env.seen, np.zeros(3), out, success=True)) == 0
    assert len(relabel("push", env.sim.obj, env.seen, np.zeros(3), out, success=False)) == 1  # heading only
    bad = _outcome(T0, _moved(T0, dxy=(0.06, 0.0)), valid=False)
    assert relabel("push", env.sim.obj, env.seen, np.zeros(3), bad, success=False) == []


def test_a_roll_that_ends_one_roll_away_is_a_roll_to_that_state():
    env, T0 = _start("roll", None)
    obj = env.sim.obj
    tipped = _moved(T0, R_extra=Rotation.from_euler("y", 90.0, degrees=True).as_matrix())
    out = _outcome(T0, tipped)
    goal = achieved("roll", obj, out)
    assert goal == {"target": obj.classify(tipped)} and goal["target"] != obj.classify(T0)
    (obs, _, reward, success), = relabel("roll", obj, env.seen, np.zeros(3), out, success=False)
    assert success and reward == pytest.approx(-rewards.loss("roll", T0, tipped, goal, obj))
    assert achieved("roll", obj, _outcome(T0, _moved(T0, dxy=(0.02, 0.0)))) is None  # same state


@pytest.mark.slow
def test_training_with_hindsight_stores_copies_but_counts_primitives(tmp_path):
    cfg = TrainConfig(primitive="spin", steps=60, workers=0, seed=0, out=str(tmp_path), objects=("cube",),
                      learning_starts=20, replay_size=1000, n_points=64, checkpoint_minutes=60.0, p_params=0.85,
                      hindsight=True)
    summary = train(cfg, progress=False)
    from primitives.training import checkpoint as ckpt

    saved = ckpt.load(tmp_path / "checkpoint.pt")
    assert summary["steps"] == saved["state"]["global_step"] == 60
    # about 0.85 of spins ask for an angle (one seed's-objective copy each) and most turn >= 5 deg
    assert saved["replay"]["size"] > 60 + 30
