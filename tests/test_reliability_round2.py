"""Round-2 reliability reproducers: each once wrong or a traceback, now a clear affordplan error."""

from __future__ import annotations

import math

import numpy as np
import pytest

import affordplan as ap
from affordplan.app.cli import main
from affordplan.errors import GoalError, InputError, MeshError


@pytest.fixture(scope="module")
def cube():
    return ap.load_object("cube")


@pytest.fixture(scope="module")
def cube_plan(cube):
    return ap.plan(cube, ap.Goal((0.6, 0.1)), start={"resting_state": 0, "xy": (0.45, 0.0), "yaw": 0.0})


def test_executing_in_a_simulator_of_another_object_or_world_is_refused(cube, cube_plan):
    with pytest.raises(InputError, match="holds 'mug'"):
        cube_plan.execute(sim=ap.Simulator(ap.load_object("mug")))
    wall = ap.Box(center=(0.52, 0.05), size=(0.3, 0.02, 0.1))
    with pytest.raises(InputError, match="obstacles"):
        cube_plan.execute(sim=ap.Simulator(cube, obstacles=[wall]))


@pytest.mark.parametrize("value", [True, -5, 0, 1.5, "3"])
def test_max_primitives_must_be_a_positive_whole_number(cube_plan, value):
    with pytest.raises(InputError, match="max_primitives"):
        cube_plan.execute(sim="finger", max_primitives=value)


def test_reset_into_an_obstacle_is_refused_and_leaves_the_object_where_it_was(cube):
    sim = ap.Simulator(cube, obstacles=[ap.Box(center=(0.6, 0.0), size=(0.05, 0.2, 0.1))])
    before = sim.reset(0, (0.4, 0.0), 0.0)
    with pytest.raises(InputError, match="overlaps obstacle0"):
        sim.reset(0, (0.58, 0.0), 0.0)
    assert np.allclose(sim.object_pose(), before)


def test_a_start_floating_or_tipped_is_refused(cube):
    goal = ap.Goal((0.6, 0.0))
    T = cube.resting_states[0].pose((0.5, 0.0), 0.0)
    floating = T.copy()
    floating[2, 3] += 5.0
    with pytest.raises(GoalError, match="off the table"):
        ap.plan(cube, goal, start=floating)
    c, s = math.cos(math.radians(40)), math.sin(math.radians(40))
    tipped = T.copy()
    tipped[:3, :3] = np.array([[1, 0, 0], [0, c, -s], [0, s, c]]) @ T[:3, :3]
    with pytest.raises(GoalError, match="tipped 40 deg"):
        ap.plan(cube, goal, start=tipped)


@pytest.mark.parametrize("kwargs", [dict(yaw=True), dict(xy=(True, 0.0)), dict(xy="ab"), dict(xy_tol=0),
                                    dict(xy=(10**400, 0.0)), dict(resting_state=1.0)])
def test_goal_refuses_booleans_strings_and_huge_numbers(kwargs):
    args = dict(xy=(0.5, 0.0)) | kwargs
    with pytest.raises(GoalError):
        ap.Goal(**args)


def test_classify_refuses_a_nan_pose(cube):
    with pytest.raises(InputError, match="NaN"):
        cube.classify(np.full((4, 4), np.nan))


@pytest.mark.parametrize("kwargs", [dict(size=True), dict(size=1e6), dict(density=1e-300), dict(size="0.05")])
def test_load_object_refuses_sizes_mujoco_cannot_simulate(kwargs):
    with pytest.raises(InputError):
        ap.load_object("cube", **kwargs)


def test_load_object_of_an_empty_name_says_what_to_give():
    with pytest.raises(MeshError, match="empty object name"):
        ap.load_object("")


@pytest.mark.parametrize("kwargs", [dict(seed=-1), dict(seed=1.5), dict(seed="0"), dict(obstacles=None),
                                    dict(obstacles=5)])
def test_simulator_arguments(cube, kwargs):
    with pytest.raises(InputError):
        ap.Simulator(cube, **kwargs)


@pytest.mark.parametrize("call", [lambda s: s.reset(xy="ab"), lambda s: s.reset(yaw=None),
                                  lambda s: s.execute("abc", (0, 0, 0)), lambda s: s.execute((1e300, 0, 0), (0, 0, 0)),
                                  lambda s: s.point_cloud(10**12), lambda s: s.render(100000, 100000)])
def test_simulator_calls(cube, call):
    with pytest.raises(InputError):
        call(ap.Simulator(cube))


@pytest.mark.parametrize("argv, words", [
    (["render", "mug", "--out", "r.txt"], ".png or .jpg"),
    (["plan", "scene.yaml", "--fps", "1e308"], "frames per second"),
    (["plan", "scene.yaml", "--seed", "-1"], "non-negative"),
    (["render", "mug", "--width", "100000"], "at most 1280"),
])
def test_command_line_arguments_are_checked_before_any_work(tmp_path, capsys, argv, words):
    try:
        rc = main(argv)
    except SystemExit as exc:
        rc = exc.code
    assert rc == 2
    err = capsys.readouterr().err
    assert words in err and "Traceback" not in err


def test_an_execution_prints_its_final_errors(cube_plan):
    execution = cube_plan.execute(sim="finger", max_primitives=1)
    d, yaw, state_ok = execution.errors
    head = str(execution).splitlines()[0]
    assert f"final error {100 * d:.1f} cm, {math.degrees(yaw):.0f} deg, resting state" in head


@pytest.mark.parametrize("kwargs", [dict(seed=-1), dict(obstacles=None), dict(time_limit=True), dict(time_limit=0),
                                    dict(time_limit=float("nan"))])
def test_plan_arguments(cube, kwargs):
    with pytest.raises(InputError):
        ap.plan(cube, ap.Goal((0.6, 0.0)), **kwargs)


@pytest.mark.parametrize("value", [True, 10**400, "a", float("inf"), None])
def test_skill_parameters_refuse_booleans_and_huge_numbers(cube, value):
    from primitives.params import check

    with pytest.raises(InputError):
        check("push", {"direction": value}, cube, 0)
