"""Skill parameters: checking, roll adjacency, goal flow, and the parameterised objectives."""

import math

import numpy as np
import pytest

import affordplan as ap
from affordplan.errors import InputError
from affordplan.geometry import make_pose, rot_z
from primitives import params, rewards


def _pose(xy=(0.5, 0.0), yaw=0.0, z=0.05, R=None):
    return make_pose(rot_z(yaw) if R is None else R, (xy[0], xy[1], z))


def test_check_normalises_and_rejects():
    cube = ap.load_object("cube")
    assert params.check("push", None) is None
    assert params.check("push", {"direction": 3 * math.pi})["direction"] == pytest.approx(-math.pi)
    assert params.check("spin", {"angle": -math.radians(30)}) == {"angle": -math.radians(30)}
    assert params.check("roll", {"target": 1}, cube, 0) == {"target": 1}
    bad = [("push", {"direction": float("nan")}), ("push", {"angle": 0.2}), ("push", 0.3),
           ("spin", {"angle": math.radians(10)}), ("spin", {"angle": math.radians(50)}),
           ("spin", {"angle": "left"}), ("roll", {"target": 1.0}), ("roll", {"target": True})]
    for skill, p in bad:
        with pytest.raises(InputError):
            params.check(skill, p)
    with pytest.raises(InputError, match="not a resting state"):
        params.check("roll", {"target": 6}, cube, 0)


def test_roll_targets_are_one_roll_away():
    cube = ap.load_object("cube")
    for s in range(6):
        targets = params.roll_targets(cube, s)
        assert len(targets) == 4 and s not in targets  # the four neighbouring faces, not the opposite one
        up = cube.resting_states[s].up
        opposite = [t for t in range(6) if t != s and t not in targets]
        assert len(opposite) == 1 and cube.resting_states[opposite[0]].up @ up < -0.99
    with pytest.raises(InputError, match="one roll away"):
        params.check("roll", {"target": opposite[0]}, cube, s)


def test_goal_flow_matches_the_asked_motion():
    cube = ap.load_object("cube")
    T = cube.resting_states[0].pose((0.5, 0.1), 0.3)
    pts = np.array([[0.55, 0.1, 0.05], [0.5, 0.15, 0.1]])
    flow = params.goal_flow("push", {"direction": math.pi / 2}, pts, T)
    assert np.allclose(flow, [[0, 0.05, 0]] * 2, atol=1e-6)
    flow = params.goal_flow("spin", {"angle": math.pi / 2}, pts, T)
    assert np.allclose(flow[0], [-0.05, 0.05, 0.0], atol=1e-6)  # (0.05, 0) about the centre -> (0, 0.05)
    assert not params.goal_flow("push", None, pts, T).any()
    # Roll: after the asked tip, the target state's up-vector points up and the centre sits at its height.
    for target in params.roll_targets(cube, 0):
        Tp = params.goal_transform("roll", {"target": target}, T, cube)
        T_after = Tp @ T
        assert cube.classify(T_after) == target
        assert T_after[2, 3] == pytest.approx(cube.resting_states[target].height)
        theta = math.degrees(np.arccos((np.trace(Tp[:3, :3]) - 1) / 2))
        assert theta == pytest.approx(90.0, abs=1.0)


def test_parameterised_objectives_reduce_to_the_seed_and_judge_the_parameter():
    T0 = _pose()
    east = _pose((0.56, 0.0))
    north = _pose((0.5, 0.06))
    for T1 in (east, north):
        assert rewards.loss("push", T0, T1) == rewards.push_loss(T0, T1)
        assert rewards.success("push", T0, T1) == rewards.push_success(T0, T1)
    assert rewards.success("push", T0, east, {"direction": 0.0})
    assert not rewards.success("push", T0, north, {"direction": 0.0})  # moved, but the wrong way
    assert rewards.success("push", T0, _pose((0.556, 0.014)), {"direction": 0.0})  # 14 deg off: inside 15
    assert not rewards.success("push", T0, _pose((0.556, 0.016)), {"direction": 0.0})  # 16 deg off
    assert rewards.loss("push", T0, east, {"direction": 0.0}) == pytest.approx(0.0)
    assert rewards.loss("push", T0, north, {"direction": 0.0}) == pytest.approx(1.0 + 10 * 0.06)

    left = _pose(yaw=math.radians(28))
    assert rewards.success("spin", T0, left, {"angle": math.radians(35)})  # 7 deg short: inside 10
    assert not rewards.success("spin", T0, left, {"angle": -math.radians(35)})  # wrong way
    assert not rewards.success("spin", T0, left, {"angle": math.radians(40)})  # 12 deg short
    assert rewards.loss("spin", T0, left, {"angle": math.radians(28)}) == pytest.approx(0.0, abs=1e-9)
    assert rewards.loss("spin", T0, T0, {"angle": math.radians(30)}) == pytest.approx(rewards.spin_loss(T0, T0))

    cube = ap.load_object("cube")
    Ts = cube.resting_states[0].pose((0.5, 0.0), 0.0)
    target = params.roll_targets(cube, 0)[0]
    Tt = cube.resting_states[target].pose((0.52, 0.0), 0.4)
    assert rewards.success("roll", Ts, Tt, {"target": target}, cube)
    assert not rewards.success("roll", Ts, Ts, {"target": target}, cube)
    assert rewards.loss("roll", Ts, Tt, {"target": target}, cube) == pytest.approx(0.5 * 0.02, abs=1e-6)
    assert rewards.loss("roll", Ts, Ts, {"target": target}, cube) == pytest.approx(90 / 60, abs=1e-3)


def test_sample_covers_the_ranges():
    rng = np.random.default_rng(0)
    cube = ap.load_object("cube")
    spins = [params.sample("spin", rng, cube, 0, 1.0)["angle"] for _ in range(200)]
    assert min(map(abs, spins)) >= params.SPIN_MIN and max(map(abs, spins)) <= params.SPIN_MAX
    assert min(spins) < 0 < max(spins)
    rolls = {params.sample("roll", rng, cube, 0, 1.0)["target"] for _ in range(100)}
    assert rolls == set(params.roll_targets(cube, 0))
    assert sum(params.sample("push", rng, cube, 0, 0.5) is None for _ in range(400)) in range(160, 240)


def test_goal_frame_makes_each_request_canonical():
    cube = ap.load_object("cube")
    T = cube.resting_states[0].pose((0.5, 0.1), 0.3)
    a = 2.0
    A = params.goal_frame("push", {"direction": a}, T)
    assert np.allclose(A @ [math.cos(a), math.sin(a), 0.0], [1.0, 0.0, 0.0])  # the asked direction is +x
    assert np.allclose(A.T @ A, np.eye(3)) and np.allclose(A[2], [0.0, 0.0, 1.0])
    # Spin: a clockwise request is mirrored into a counter-clockwise one.
    pts = T[:3, 3] + np.array([[0.05, 0.0, 0.0]])
    for angle in (math.radians(30), -math.radians(30)):
        A = params.goal_frame("spin", {"angle": angle}, T)
        flow_frame = params.goal_flow("spin", {"angle": angle}, pts, T) @ A.T
        offset_frame = (pts - T[:3, 3]) @ A.T
        assert np.cross(offset_frame[0], flow_frame[0])[2] > 0  # counter-clockwise in the goal frame
    # Roll: the face that should end up up points along +x, so the top moves towards -x.
    for target in params.roll_targets(cube, 0):
        A = params.goal_frame("roll", {"target": target}, T, cube)
        up_frame = A @ params.target_up(cube, T[:3, :3], target)
        assert up_frame[0] > 0.99
        top = T[:3, 3] + np.array([[0.0, 0.0, 0.05]])
        assert (params.goal_flow("roll", {"target": target}, top, T, cube) @ A.T)[0, 0] < -0.03
    assert np.array_equal(params.goal_frame("roll", None, T, cube), np.eye(3))


def test_goal_frame_motion_reaches_the_world():
    """A goal-frame push along +x, from the point the frame puts last along x, moves the cube along the direction."""
    from primitives.training.env import skill_observation

    sim = ap.Simulator(ap.load_object("cube"), seed=0, sensor="surface")  # frames, not sensing, are tested here
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.4)
    seen = skill_observation(sim, "push", {"direction": math.pi / 2}, 256)
    assert np.allclose(seen.obs[:, 6:9], [0.05, 0.0, 0.0], atol=1e-6)  # the flow is "+x" for every point
    mid = np.abs(seen.obs[:, 2] - 0.03) < 0.015
    i = int(np.flatnonzero(mid)[np.argmin(seen.obs[mid, 0])])
    out = sim.execute(seen.points[i], seen.motion_to_world([1.0, 0.0, 0.0]), normal=seen.normals[i])
    moved = out.pose_after[:3, 3] - out.pose_before[:3, 3]
    assert 0.04 < moved[1] < 0.12 and abs(moved[0]) < 0.02  # along world +y, the asked direction


# ---------------------------------------------------------- typed parameters (PushParams, SpinParams, RollParams)
def test_skills_are_listed_once_in_one_order():
    from typing import get_args

    assert params.SKILLS == ("push", "roll", "spin") == get_args(params.SkillName)
    assert tuple(params.PARAM_KEYS) == tuple(params.PARAMS_TYPES) == params.SKILLS
    assert all(params.PARAMS_TYPES[name].skill == name for name in params.SKILLS)


def test_typed_params_round_trip_and_check_like_their_dicts():
    cube = ap.load_object("cube")
    target = params.roll_targets(cube, 0)[0]
    pairs = [("push", params.PushParams(direction=3 * math.pi), {"direction": 3 * math.pi}),
             ("spin", params.SpinParams(angle=-math.radians(30)), {"angle": -math.radians(30)}),
             ("roll", params.RollParams(target=np.int64(target)), {"target": target})]
    for skill, typed, d in pairs:
        assert typed.as_dict() == d and type(typed).from_dict(d) == typed
        assert params.as_params(skill, typed) == params.as_params(skill, d) == d
        assert params.check(skill, typed, cube, 0) == params.check(skill, d, cube, 0)
    assert params.check("push", params.PushParams(3 * math.pi))["direction"] == pytest.approx(-math.pi)
    assert type(params.RollParams(np.int64(2)).target) is int
    assert params.as_params("push", None) is None and params.check("push", None) is None
    opposite = next(t for t in range(1, 6) if t not in params.roll_targets(cube, 0))
    with pytest.raises(InputError, match="not one roll away"):  # the object-dependent checks still apply
        params.check("roll", params.RollParams(target=opposite), cube, 0)


@pytest.mark.parametrize("make", [
    lambda: params.PushParams(True), lambda: params.PushParams(float("nan")), lambda: params.PushParams("east"),
    lambda: params.SpinParams(math.inf), lambda: params.SpinParams(math.radians(10)),
    lambda: params.SpinParams(False), lambda: params.RollParams(1.0), lambda: params.RollParams(True),
    lambda: params.RollParams(-1),
    lambda: params.PushParams.from_dict({"angle": 0.2}), lambda: params.SpinParams.from_dict({}),
    lambda: params.RollParams.from_dict({"target": 1, "extra": 2}), lambda: params.PushParams.from_dict(0.3),
    lambda: params.as_params("spin", params.PushParams(0.1)), lambda: params.as_params("push", 0.3),
    lambda: params.as_params("walk", {"direction": 0.1}), lambda: params.check("roll", params.SpinParams(0.5)),
])
def test_bad_typed_params_are_refused_with_input_errors(make):
    with pytest.raises(InputError):
        make()


def _finger_sim(cube):
    sim = ap.Simulator(cube, pusher="finger", seed=0, sensor="surface")
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.3)
    return sim


def test_a_skill_sees_and_does_the_same_for_a_typed_value_and_its_dict():
    """Same sim state (a fresh seeded simulator each time: the cloud is drawn from its generator), same request in
    either form: the same observation, action, rating and outcome."""
    from primitives import load_skill

    cube = ap.load_object("cube")
    target = params.roll_targets(cube, 0)[0]
    requests = [("push", params.PushParams(0.7), {"direction": 0.7}),
                ("spin", params.SpinParams(-math.radians(30)), {"angle": -math.radians(30)}),
                ("roll", params.RollParams(target), {"target": target})]
    for name, typed, d in requests:
        skill = load_skill(name)
        seen_typed, seen_dict = skill.observe(_finger_sim(cube), typed), skill.observe(_finger_sim(cube), d)
        assert seen_typed.params == seen_dict.params
        assert np.array_equal(seen_typed.obs, seen_dict.obs)
        assert np.array_equal(seen_typed.A_frame_world, seen_dict.A_frame_world)
        assert skill.success_probability(_finger_sim(cube), typed) == skill.success_probability(_finger_sim(cube), d)
    push = load_skill("push")
    c1, m1 = push.act(_finger_sim(cube), params.PushParams(0.7))
    c2, m2 = push.act(_finger_sim(cube), {"direction": 0.7})
    assert np.array_equal(c1, c2) and np.array_equal(m1, m2)
    out_typed = push.execute(_finger_sim(cube), params.PushParams(0.7))
    out_dict = push.execute(_finger_sim(cube), {"direction": 0.7})
    assert out_typed.success == out_dict.success and np.allclose(out_typed.pose_after, out_dict.pose_after)
    with pytest.raises(InputError):
        push.act(_finger_sim(cube), params.SpinParams(0.5))


def test_motion_stop_ends_a_spin_by_an_angle_once_turned_that_far_about_the_vertical():
    T0 = make_pose(rot_z(0.3), (0.5, 0.0, 0.04))
    stop = params.motion_stop("spin", {"angle": math.radians(20.0)}, T0)
    turned = lambda deg: make_pose(rot_z(0.3 + math.radians(deg)), (0.52, 0.01, 0.04))  # noqa: E731
    assert not stop(turned(19.0)) and stop(turned(20.5)) and not stop(turned(-25.0))
    back = params.motion_stop("spin", params.SpinParams(-math.radians(20.0)), T0)
    assert back(turned(-21.0)) and not back(turned(21.0))
    # a roll about a horizontal axis is no turn about the vertical
    rolled = T0.copy()
    rolled[:3, :3] = T0[:3, :3] @ np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])
    assert not stop(rolled)


@pytest.mark.parametrize("skill, asked", [("spin", None), ("push", {"direction": 0.4}), ("roll", None)])
def test_motion_stop_lets_other_calls_run_their_full_motion(skill, asked):
    assert params.motion_stop(skill, asked, np.eye(4)) is None


def test_motion_steer_turns_a_push_against_the_objects_turn_about_the_vertical():
    T0 = make_pose(rot_z(0.3), (0.5, 0.0, 0.04))
    steer = params.motion_steer("push", None, T0)
    step = np.array([0.001, 0.0, -0.0002])
    assert np.allclose(steer(T0, step.copy()), step)  # no turn, no bend
    turned = make_pose(rot_z(0.3 + 0.1), (0.52, 0.01, 0.04))
    bent = steer(turned, step.copy())
    assert bent[2] == step[2] and np.linalg.norm(bent[:2]) == pytest.approx(np.linalg.norm(step[:2]))
    assert math.atan2(bent[1], bent[0]) == pytest.approx(params.PUSH_STEER_GAIN * 0.1)  # the way it turned
    far = steer(make_pose(rot_z(0.3 - 1.0), (0.5, 0.0, 0.04)), step.copy())
    assert math.atan2(far[1], far[0]) == pytest.approx(-params.PUSH_STEER_MAX)
    assert callable(params.motion_steer("push", {"direction": 1.0}, T0))


@pytest.mark.parametrize("skill, asked", [("spin", None), ("spin", {"angle": 0.4}), ("roll", None)])
def test_motion_steer_lets_spins_and_rolls_run_straight(skill, asked):
    assert params.motion_steer(skill, asked, np.eye(4)) is None


def test_motion_steer_refuses_bad_input():
    with pytest.raises(InputError):
        params.motion_steer("push", {"angle": 0.4}, np.eye(4))
    with pytest.raises(InputError):
        params.motion_steer("push", None, np.eye(3))


def test_motion_loop_closes_a_push_on_its_reach_a_spin_on_its_angle_and_leaves_rolls_open():
    T0 = make_pose(rot_z(0.3), (0.5, 0.0, 0.04))
    push = params.motion_loop("push", None, T0)
    assert callable(push.steer) and push.motion_steps == params.PUSH_REACH_STEPS
    near = make_pose(rot_z(0.3), (0.5 + 0.8 * params.PUSH_REACH, 0.0, 0.04))
    far = make_pose(rot_z(0.3), (0.5, -params.PUSH_REACH, 0.05))  # any horizontal direction counts; height not
    assert not push.until(near) and push.until(far)
    assert params.motion_loop("push", None, T0, steer=False) == params.MotionLoop()
    spin = params.motion_loop("spin", {"angle": 0.4}, T0)
    assert callable(spin.until) and spin.steer is None and spin.motion_steps is None
    assert params.motion_loop("spin", {"angle": 0.4}, T0, stop_at_angle=False) == params.MotionLoop()
    assert params.motion_loop("roll", None, T0) == params.MotionLoop()
    assert set(push.as_kwargs()) == {"until", "steer", "motion_steps"}


def test_motion_stop_refuses_bad_input():
    with pytest.raises(InputError):
        params.motion_stop("spin", {"angle": 3.0}, np.eye(4))
    with pytest.raises(InputError):
        params.motion_stop("spin", {"angle": 0.4}, np.eye(3))
