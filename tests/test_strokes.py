"""Skills that re-observe within their call (primitives.strokes): push_to, spin_by, roll_to."""

import math

import numpy as np
import pytest
from planner_fakes import IdealSkill
from scipy.spatial.transform import Rotation

import affordplan as ap
from affordplan.errors import InputError
from affordplan.geometry import rot_z
from affordplan.sim.simulator import Outcome
from primitives.params import PUSH_STEP, roll_targets
from primitives.strokes import EXTRA_STROKES, STOP_WITHIN, push_to, roll_to, spin_by


class Veering(IdealSkill):
    """A push that moves the object ``PUSH_STEP`` but ``veer`` radians to the left of the asked heading."""

    def __init__(self, veer: float):
        super().__init__("push")
        self.veer = veer

    def execute(self, sim, params, stop_at_angle=True, steer=True):
        T0 = sim.object_pose()
        self.calls.append((sim.obj.classify(T0), dict(params)))
        a = params["direction"] + self.veer
        T1 = T0.copy()
        T1[:2, 3] += PUSH_STEP * np.array([math.cos(a), math.sin(a)])
        sim.set_object_pose(T1, settle=False)
        return Outcome(T0, T1, 0, True, True, 0.0, success=True)


@pytest.fixture()
def sim(cube):
    s = ap.Simulator(cube, seed=0)
    s.set_object_pose(cube.resting_states[0].pose((0.42, 0.0), 0.0), settle=False)
    return s


def test_an_ideal_push_reaches_a_target_three_strides_away_in_one_call_of_three_strokes(sim):
    skill = IdealSkill("push")
    made = push_to(skill, sim, (0.57, 0.0), strides=3)
    assert made.outcome.success and made.strokes == 3 == len(skill.calls) and made.stopped == "at the target"
    np.testing.assert_allclose(sim.object_pose()[:2, 3], (0.57, 0.0), atol=1e-9)
    np.testing.assert_allclose(made.outcome.pose_before[:2, 3], (0.42, 0.0), atol=1e-9)


def test_strokes_that_veer_are_aimed_back_at_the_target(sim):
    target = np.array([0.57, 0.0])
    skill = Veering(math.radians(20.0))
    made = push_to(skill, sim, tuple(target), strides=3)
    corrected = float(np.linalg.norm(sim.object_pose()[:2, 3] - target))
    headings = [c[1]["direction"] for c in skill.calls]
    assert headings[0] == pytest.approx(0.0) and all(h < -0.1 for h in headings[1:])  # aimed right of the veer
    # three strokes all along +x would have ended 15 sin(20 deg) = 5.1 cm to the left
    assert corrected <= STOP_WITHIN < 3 * PUSH_STEP * math.sin(math.radians(20.0))
    assert made.outcome.success and made.strokes <= 3 + EXTRA_STROKES


def test_a_stroke_that_does_not_move_the_object_ends_the_call(sim):
    skill = IdealSkill("push", fail=lambda params, state: True)
    made = push_to(skill, sim, (0.57, 0.0), strides=3)
    assert made.strokes == 1 and made.stopped == "did not move" and not made.outcome.success


class Turning(IdealSkill):
    """An ideal push whose every stroke also turns the object ``turn`` radians about world +z."""

    def __init__(self, turn: float):
        super().__init__("push")
        self.turn = turn

    def execute(self, sim, params, stop_at_angle=True, steer=True):
        out = super().execute(sim, params)
        T1 = out.pose_after.copy()
        T1[:3, :3] = rot_z(self.turn) @ T1[:3, :3]
        sim.set_object_pose(T1, settle=False)
        out.pose_after = T1
        return out


def test_a_stroke_that_turns_the_object_ends_the_call(sim):
    made = push_to(Turning(math.radians(30.0)), sim, (0.57, 0.0), strides=3)
    assert made.strokes == 1 and made.stopped == "turned" and not made.outcome.success


def test_the_strokes_are_capped(sim):
    class Short(IdealSkill):  # each stroke moves the object 1.5 cm: progress, but far from the target
        def execute(self, sim, params, stop_at_angle=True, steer=True):
            T0 = sim.object_pose()
            self.calls.append(params)
            T1 = T0.copy()
            T1[0, 3] += 0.015 * math.cos(params["direction"])
            T1[1, 3] += 0.015 * math.sin(params["direction"])
            sim.set_object_pose(T1, settle=False)
            return Outcome(T0, T1, 0, True, True, 0.0, success=False)

    skill = Short("push")
    made = push_to(skill, sim, (0.57, 0.0), strides=2)
    assert made.strokes == 2 + EXTRA_STROKES == len(skill.calls) and made.stopped == "strokes spent"
    assert not made.outcome.success


def test_bad_requests_are_refused(sim):
    with pytest.raises(InputError):
        push_to(IdealSkill("spin"), sim, (0.57, 0.0), strides=2)
    with pytest.raises(InputError):
        push_to(IdealSkill("push"), sim, (math.nan, 0.0), strides=2)
    with pytest.raises(InputError):
        push_to(IdealSkill("push"), sim, (0.57, 0.0, 0.0), strides=2)
    with pytest.raises(InputError):
        push_to(IdealSkill("push"), sim, (0.57, 0.0), strides=0)


# ---------------------------------------------------------------- spin_by
class Overturning(IdealSkill):
    """A spin that turns the object ``gain`` times the asked angle about its own place (real policies overshoot)."""

    def __init__(self, gain: float):
        super().__init__("spin")
        self.gain = gain

    def execute(self, sim, params, stop_at_angle=True, steer=True):
        T0 = sim.object_pose()
        self.calls.append((sim.obj.classify(T0), dict(params)))
        T1 = T0.copy()
        T1[:3, :3] = rot_z(self.gain * params["angle"]) @ T0[:3, :3]
        sim.set_object_pose(T1, settle=False)
        return Outcome(T0, T1, 0, True, True, 0.0, success=False)


def _yaw_turned(made) -> float:
    R = made.outcome.pose_before[:3, :3].T @ made.outcome.pose_after[:3, :3]
    return math.degrees(math.atan2(R[1, 0], R[0, 0]))


def test_an_ideal_spin_turns_past_its_one_stroke_limit_in_strokes_of_at_most_spin_max(sim):
    skill = IdealSkill("spin")
    made = spin_by(skill, sim, math.radians(110.0), max_strokes=4)
    asked = [math.degrees(c[1]["angle"]) for c in skill.calls]
    assert made.outcome.success and made.stopped == "at the angle" and made.strokes == 3
    assert asked == pytest.approx([45.0, 45.0, 20.0])  # the last asks the rest
    assert _yaw_turned(made) == pytest.approx(110.0)


def test_a_spin_that_overturns_is_turned_back_by_its_second_stroke(sim):
    skill = Overturning(1.4)
    one = spin_by(skill, sim, math.radians(40.0), max_strokes=1)
    assert not one.outcome.success and _yaw_turned(one) == pytest.approx(56.0)  # 16 deg over: one stroke fails
    sim.set_object_pose(one.outcome.pose_before, settle=False)
    skill.calls.clear()
    made = spin_by(skill, sim, math.radians(40.0), max_strokes=4)
    assert [math.degrees(c[1]["angle"]) for c in skill.calls] == pytest.approx([40.0, -16.0])
    assert made.outcome.success and made.strokes == 2 and _yaw_turned(made) == pytest.approx(33.6)


def test_a_spin_call_turns_clockwise_for_a_negative_angle(sim):
    made = spin_by(IdealSkill("spin"), sim, math.radians(-30.0))
    assert made.outcome.success and made.strokes == 1 and _yaw_turned(made) == pytest.approx(-30.0)


def test_a_spin_that_tips_the_object_over_ends_the_call_unsuccessfully(sim, cube):
    class Tipping(IdealSkill):
        def execute(self, sim, params, stop_at_angle=True, steer=True):
            T0 = sim.object_pose()
            T1 = cube.resting_states[1].pose(tuple(T0[:2, 3]), 0.0)
            sim.set_object_pose(T1, settle=False)
            return Outcome(T0, T1, 0, True, True, 0.0, success=False)

    made = spin_by(Tipping("spin"), sim, math.radians(90.0), max_strokes=4)
    assert made.strokes == 1 and made.stopped == "left its resting state" and not made.outcome.success


def test_a_stroke_that_rolls_the_object_about_a_level_axis_is_no_spin(sim, cube):
    """A can on its side rolled about its length stays in its resting state but is not spun: the call goes on."""

    class Rolling(IdealSkill):
        def execute(self, sim, params, stop_at_angle=True, steer=True):
            T0 = sim.object_pose()
            self.calls.append((0, dict(params)))
            T1 = T0.copy()
            T1[:3, :3] = Rotation.from_rotvec([math.radians(40.0), 0.0, 0.0]).as_matrix() @ T0[:3, :3]
            sim.set_object_pose(T1, settle=False)
            return Outcome(T0, T1, 0, True, True, 0.0, success=False)

    skill = Rolling("spin")
    made = spin_by(skill, sim, math.radians(40.0), max_strokes=1)
    assert cube.classify(made.outcome.pose_after) == cube.classify(made.outcome.pose_before)  # still "in its state"
    assert made.stopped == "strokes spent" and not made.outcome.success  # a 40 deg turn, but about a level axis
    assert [c[1]["angle"] for c in skill.calls] == pytest.approx([math.radians(40.0)])


def test_spin_by_refuses_bad_input(sim):
    for angle in (math.radians(5.0), math.radians(-200.0), float("nan"), "30"):
        with pytest.raises(InputError):
            spin_by(IdealSkill("spin"), sim, angle)
    with pytest.raises(InputError, match="max_strokes"):
        spin_by(IdealSkill("spin"), sim, 0.5, max_strokes=0)
    with pytest.raises(InputError, match="spin skill"):
        spin_by(IdealSkill("push"), sim, 0.5)


# ---------------------------------------------------------------- roll_to
def test_a_roll_that_leaves_the_object_in_its_state_is_tried_again(sim):
    target = roll_targets(sim.obj, 0)[0]
    tries = []
    skill = IdealSkill("roll", fail=lambda params, state: tries.append(1) or len(tries) == 1)  # the first fails
    made = roll_to(skill, sim, target, max_strokes=3)
    assert made.outcome.success and made.strokes == 2 and made.stopped == "in the target state"
    assert sim.obj.classify(sim.object_pose()) == target
    assert sim.obj.classify(made.outcome.pose_before) == 0


def test_a_roll_that_keeps_failing_spends_its_strokes(sim):
    made = roll_to(IdealSkill("roll", fail=lambda params, state: True), sim, roll_targets(sim.obj, 0)[0], 3)
    assert made.strokes == 3 and made.stopped == "strokes spent" and not made.outcome.success


def test_a_roll_into_another_state_ends_the_call(sim):
    first, other = roll_targets(sim.obj, 0)[:2]

    class Astray(IdealSkill):
        def execute(self, sim, params, stop_at_angle=True, steer=True):
            return super().execute(sim, {"target": other})

    made = roll_to(Astray("roll"), sim, first, max_strokes=3)
    assert made.strokes == 1 and made.stopped == f"rolled into state {other}" and not made.outcome.success


def test_roll_to_refuses_a_state_not_one_roll_away_and_other_skills(sim):
    here = sim.obj.classify(sim.object_pose())
    far = [s.index for s in sim.obj.resting_states if s.index != here and s.index not in roll_targets(sim.obj, here)]
    with pytest.raises(InputError, match="one roll away"):
        roll_to(IdealSkill("roll"), sim, here)
    if far:
        with pytest.raises(InputError, match="one roll away"):
            roll_to(IdealSkill("roll"), sim, far[0])
    with pytest.raises(InputError):
        roll_to(IdealSkill("roll"), sim, 99)
    with pytest.raises(InputError, match="roll skill"):
        roll_to(IdealSkill("spin"), sim, roll_targets(sim.obj, here)[0])


def test_a_push_may_be_let_turn_the_object_further(sim):
    default = push_to(Turning(math.radians(20.0)), sim, (0.62, 0.0), strides=4)
    assert default.strokes == 1 and default.stopped == "turned"  # 20 deg > MAX_TURN (12 deg)
    sim.set_object_pose(sim.obj.resting_states[0].pose((0.42, 0.0), 0.0), settle=False)
    loose = push_to(Turning(math.radians(20.0)), sim, (0.62, 0.0), strides=4, max_turn=math.radians(45.0))
    assert loose.strokes == 3 and loose.stopped == "turned"  # 60 deg after the third stroke
    for bad in (0.0, -0.1, 4.0, math.nan):
        with pytest.raises(InputError):
            push_to(IdealSkill("push"), sim, (0.57, 0.0), strides=2, max_turn=bad)
