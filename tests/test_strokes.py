"""A push that corrects its course between strokes (primitives.strokes.push_to)."""

import math

import numpy as np
import pytest
from planner_fakes import IdealSkill

import affordplan as ap
from affordplan.errors import InputError
from affordplan.geometry import rot_z
from affordplan.sim.simulator import Outcome
from primitives.params import PUSH_STEP
from primitives.strokes import EXTRA_STROKES, STOP_WITHIN, push_to


class Veering(IdealSkill):
    """A push that moves the object ``PUSH_STEP`` but ``veer`` radians to the left of the asked heading."""

    def __init__(self, veer: float):
        super().__init__("push")
        self.veer = veer

    def execute(self, sim, params):
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


def test_a_stroke_that_turns_the_object_ends_the_call(sim):
    class Turning(IdealSkill):
        def execute(self, sim, params):
            out = super().execute(sim, params)
            T1 = out.pose_after.copy()
            T1[:3, :3] = rot_z(math.radians(30.0)) @ T1[:3, :3]
            sim.set_object_pose(T1, settle=False)
            out.pose_after = T1
            return out

    made = push_to(Turning("push"), sim, (0.57, 0.0), strides=3)
    assert made.strokes == 1 and made.stopped == "turned" and not made.outcome.success


def test_the_strokes_are_capped(sim):
    class Short(IdealSkill):  # each stroke moves the object 1.5 cm: progress, but far from the target
        def execute(self, sim, params):
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
