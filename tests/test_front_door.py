"""The typed front door: ``ap.plan`` and ``Plan.execute`` annotated, obstacles as boxes or scene-file dicts (one
conversion in the core, shared with scene files), plan steps taking typed parameters, py.typed shipped."""

from __future__ import annotations

import inspect
import math
from pathlib import Path
from typing import Literal, get_args, get_origin

import numpy as np
import pytest

import affordplan as ap
import planner
import primitives
from affordplan.app.scene_file import DEMO_SCENE, parse_scene
from affordplan.errors import InputError
from affordplan.world import as_box
from planner.api import PLANNERS
from planner.plan import Plan, Step
from primitives.params import PushParams, RollParams, SpinParams

START = {"resting_state": 0, "xy": (0.45, 0.0), "yaw": 0.0}
WALL = ap.Box(center=(0.55, -0.12), size=(0.02, 0.12, 0.1), yaw=math.radians(20.0))
WALL_DICT = {"center": [0.55, -0.12], "size": [0.02, 0.12, 0.1], "yaw_deg": 20.0}


def test_the_front_door_is_annotated():
    sig = inspect.signature(ap.plan)
    assert all(p.annotation is not inspect.Parameter.empty for p in sig.parameters.values())
    assert sig.return_annotation == "Plan"  # the planner package is imported lazily: a forward reference
    planner_kind = sig.parameters["planner"].annotation
    assert get_origin(planner_kind) is Literal and get_args(planner_kind) == PLANNERS == ("affordplan", "greedy")
    assert [n for n, p in sig.parameters.items() if p.kind is p.KEYWORD_ONLY] == [
        "start", "obstacles", "time_limit", "planner", "seed", "predictor", "workspace"]
    execute = inspect.signature(Plan.execute)
    assert all(p.annotation is not inspect.Parameter.empty for n, p in execute.parameters.items() if n != "self")
    assert "Literal['arm', 'finger']" in execute.parameters["sim"].annotation
    assert execute.return_annotation == "Execution"
    step = inspect.signature(Step).parameters
    assert (step["skill"].annotation, step["params"].annotation) == ("SkillName", "SkillParams | Mapping[str, float]")


def test_each_package_ships_py_typed():
    for package in (ap, planner, primitives):
        assert (Path(package.__file__).parent / "py.typed").is_file()


def test_box_dicts_are_the_scene_file_form():
    assert ap.Box.from_dict(WALL_DICT) == WALL == as_box(WALL) == as_box(WALL.as_dict())
    assert ap.Box.from_dict({"center": (0.6, 0.0), "size": np.array([0.1, 0.1, 0.1])}) == ap.Box((0.6, 0.0),
                                                                                                 (0.1, 0.1, 0.1))
    scene = parse_scene(DEMO_SCENE)
    assert scene.obstacles == tuple(ap.Box.from_dict(d) for d in DEMO_SCENE["obstacles"])


@pytest.mark.parametrize("bad, words", [
    ({"centre": [0.6, 0.0], "size": [0.1, 0.1, 0.1]}, "unknown field(s) ['centre']"),
    ({"center": [0.6, 0.0]}, "missing field 'size'"),
    ({"size": [0.1, 0.1, 0.1]}, "missing field 'center'"),
    ({"center": [0.6], "size": [0.1, 0.1, 0.1]}, "obstacles[0].center must be a list of 2 numbers"),
    ({"center": [0.6, "a"], "size": [0.1, 0.1, 0.1]}, "obstacles[0].center[1] must be a finite number"),
    ({"center": [0.6, 0.0], "size": [0.1, -0.1, 0.1]}, "obstacles[0].size must be positive"),
    ({"center": [0.6, 0.0], "size": [0.1, 0.1, math.nan]}, "obstacles[0].size[2] must be a finite number"),
    ({"center": [0.6, 0.0], "size": [0.1, 0.1, 0.1], "yaw": True}, "obstacles[0].yaw must be a finite number"),
    ({"center": [0.6, 0.0], "size": [0.1, 0.1, 0.1], "yaw": 0.1, "yaw_deg": 5}, "yaw (radians) or yaw_deg"),
    ({"center": [60.0, 0.0], "size": [0.1, 0.1, 0.1]}, "obstacles[0].center must be numbers of magnitude"),
    ("a wall", "obstacles[0] must be an affordplan.Box or a dict"),
])
def test_bad_obstacles_raise_input_errors_naming_the_field(cube, bad, words):
    with pytest.raises(InputError) as info:
        ap.plan(cube, ap.Goal(xy=(0.65, 0.0)), start=START, obstacles=[bad])
    assert words in str(info.value)


def test_one_obstacle_dict_is_not_a_list_of_obstacles(cube):
    with pytest.raises(InputError, match="obstacles must be a sequence"):
        ap.plan(cube, ap.Goal(xy=(0.65, 0.0)), start=START, obstacles=WALL_DICT)


def test_a_dict_obstacle_plans_as_the_equivalent_box(cube):
    goal = ap.Goal.from_degrees((0.65, 0.05), yaw_deg=30.0)
    with_box = ap.plan(cube, goal, start=START, obstacles=[WALL])
    with_dict = ap.plan(cube, goal, start=START, obstacles=(WALL_DICT,))
    assert with_dict.planner.obstacles == with_box.planner.obstacles == (WALL,)
    assert with_box.steps and len(with_dict.steps) == len(with_box.steps)
    for a, b in zip(with_dict.steps, with_box.steps):
        assert (a.skill, a.params) == (b.skill, b.params)
        assert np.allclose(a.expected_pose, b.expected_pose)
    greedy = ap.plan(cube, goal, start=START, obstacles=[WALL_DICT], planner="greedy")
    assert greedy.kind == "greedy" and greedy.planner.obstacles == (WALL,)


def test_plan_steps_take_typed_params():
    T = np.eye(4)
    for skill, typed, d in [("push", PushParams(0.5), {"direction": 0.5}),
                            ("spin", SpinParams(math.radians(-30)), {"angle": math.radians(-30)}),
                            ("roll", RollParams(2), {"target": 2})]:
        step = Step(skill, typed, T, T)
        assert step.params == d and step == Step(skill, d, T, T)  # kept as today's dict
        assert step.typed_params == typed
        assert str(step) == str(Step(skill, d, T, T))
    with pytest.raises(InputError):
        Step("push", SpinParams(0.5), T, T)
