"""Closed-loop execution (planner.execute): replanning after failures, the failure memory, the step log, the
greedy baseline.

Skills are replaced by stand-ins with known behaviour (tests/planner_fakes.py), some failing on purpose.
"""

import math

import numpy as np
import pytest
from planner_fakes import IdealSkill, StubPredictor, ideal_planner

import affordplan as ap
from planner.execute import execute_plan
from planner.plan import DETOUR_ANGLES, Planner
from primitives import params as skill_params


def test_forced_failure_replans_without_repeating_the_failed_step():
    cube = ap.load_object("cube")
    direct = skill_params.roll_targets(cube, 0)[0]
    planner = ideal_planner(cube, fail_roll=(0, direct))
    goal = ap.Goal(xy=(0.55, 0.05), resting_state=direct)
    plan = planner.plan(cube.resting_states[0].pose((0.5, 0.0), 0.0), goal)
    assert plan.route == [0, direct]
    sim = ap.Simulator(cube, seed=0)
    sim.set_object_pose(plan.start_pose, settle=False)
    ex = execute_plan(plan, sim=sim, max_primitives=20)
    assert ex.success, str(ex)
    rolls = planner.predictor.skills["roll"].calls
    failed = [c for c in rolls if c == (0, {"target": direct})]
    assert len(failed) == 2  # tried twice, then avoided
    assert rolls[:2] == failed  # the two failures came first
    assert ex.replans == 2  # one replan after each failed roll
    via = rolls[2][1]["target"]  # then two more rolls: round another face
    assert via not in (0, direct) and rolls[2:] == [(0, {"target": via}), (via, {"target": direct})]
    assert cube.classify(ex.final_pose) == direct
    # why: two failures of a roll cut its rating (the stand-in's 0.8) by RestingStateGraph.penalise's 0.25, below
    # the 0.8 * 0.8 of going round
    memory = ideal_planner(cube)
    T0 = plan.start_pose
    assert memory.graph.probability(0, direct) == pytest.approx(0.8) and memory.graph.route(0, direct) == [0, direct]
    for _ in range(2):
        memory.record_failure("roll", {"target": direct}, T0)
    assert memory.graph.probability(0, direct) == pytest.approx(0.8 * 0.25)
    assert memory.graph.route(0, direct) == [0, via, direct]


class RollsFailNear(IdealSkill):
    """Rolls that fail (leaving the object where it is) within 3 cm of one place."""

    def __init__(self, xy):
        super().__init__("roll")
        self.xy, self.where = xy, []

    def execute(self, sim, params, stop_at_angle=True, steer=True):
        T0 = sim.object_pose()
        self.where.append((float(T0[0, 3]), float(T0[1, 3])))
        self.fail = lambda p, state: math.hypot(T0[0, 3] - self.xy[0], T0[1, 3] - self.xy[1]) < 0.03
        return super().execute(sim, params)


def test_a_place_where_rolls_failed_twice_is_left_for_another():
    cube = ap.load_object("cube")
    target = skill_params.roll_targets(cube, 0)[0]
    skills = {n: IdealSkill(n) for n in ("push", "spin")}
    skills["roll"] = RollsFailNear((0.45, 0.0))
    planner = Planner(cube, (), predictor=StubPredictor(skills), time_limit=5.0, seed=0)
    goal = ap.Goal(xy=(0.45, 0.0), resting_state=target)  # the goal is where rolls fail
    plan = planner.plan(cube.resting_states[0].pose((0.45, 0.0), 0.0), goal)
    sim = ap.Simulator(cube, seed=0)
    sim.set_object_pose(plan.start_pose, settle=False)
    ex = execute_plan(plan, sim=sim, max_primitives=20)
    assert ex.success, str(ex)
    where = skills["roll"].where
    at_bad = [w for w in where if math.hypot(w[0] - 0.45, w[1]) < 0.03]
    assert len(at_bad) == 2  # two failures there, then the roll moved elsewhere
    assert where[:2] == at_bad and all(math.hypot(w[0] - 0.45, w[1]) > 0.04 for w in where[2:])  # never back
    assert math.hypot(where[-1][0] - 0.45, where[-1][1]) > 0.04


class WhereIdeal(IdealSkill):
    """An ideal skill that also records where (x, y) each call was made."""

    def __init__(self, name, fail=lambda params, state: False):
        super().__init__(name, fail)
        self.where = []

    def execute(self, sim, params, stop_at_angle=True, steer=True):
        self.where.append(tuple(np.round(sim.object_pose()[:2, 3], 4)))
        return super().execute(sim, params)


def test_a_push_that_failed_twice_is_not_repeated_there_under_a_detour():
    """Pushes towards the goal fail, and so does one side of the detour round them: neither is tried a third time
    where it failed.

    The detour round a failing push is a push on each side of it; a detour direction that has itself failed
    twice is turned further, instead of being planned (and failing) again on every replan. Failures count where they
    happened (``PUSH_FAILURE_RADIUS``): once the object has moved on, the direction is tried again.
    """
    cube = ap.load_object("cube")
    failing = lambda params, state: -10.0 <= math.degrees(params["direction"]) <= 40.0  # noqa: E731
    skills = {n: IdealSkill(n) for n in ("spin", "roll")}
    skills["push"] = WhereIdeal("push", fail=failing)
    planner = Planner(cube, (), predictor=StubPredictor(skills), time_limit=5.0, seed=0)
    goal = ap.Goal(xy=(0.62, 0.0), resting_state=0)
    plan = planner.plan(cube.resting_states[0].pose((0.45, 0.0), 0.0), goal)
    sim = ap.Simulator(cube, seed=0)
    sim.set_object_pose(plan.start_pose, settle=False)
    ex = execute_plan(plan, sim=sim, max_primitives=40)
    assert ex.success, str(ex)
    push = skills["push"]
    failed = [(round(math.degrees(c[1]["direction"])), xy) for c, xy in zip(push.calls, push.where)
              if failing(c[1], c[0])]
    # the planner remembers failures per 45 deg sector, where they happened
    places = [(round(d / 45.0), xy) for d, xy in failed]
    assert all(places.count(p) <= 2 for p in set(places)), failed
    # straight at the goal (0 deg) twice, then the detour's side that also fails (its first turn, 35 deg) twice;
    # the other side (-35 deg) carries the object on
    near = round(math.degrees(DETOUR_ANGLES[0]))
    assert [d for d, _ in failed[:4]] == [0, 0, near, near] and len({xy for _, xy in failed[:4]}) == 1, failed


def test_push_failures_count_where_they_happened():
    cube = ap.load_object("cube")
    planner = ideal_planner(cube)
    here, there = cube.resting_states[0].pose((0.45, 0.0), 0.0), cube.resting_states[0].pose((0.52, 0.0), 0.0)
    push = {"direction": 0.0}
    assert planner.record_failure("push", push, here) == 1 and planner.record_failure("push", push, here) == 2
    assert planner.memory.avoided("push", push, here) and not planner.memory.avoided("push", push, there)
    assert planner.record_failure("push", push, there) == 1
    # spins and rolls are remembered wherever they failed
    spin = {"angle": 0.5}
    planner.record_failure("spin", spin, here)
    planner.record_failure("spin", spin, here)
    assert planner.memory.avoided("spin", spin, there)


def test_failure_memory_counts_calls_that_did_not_move_the_object_as_asked():
    """A push that slid 6 cm but turned 7 deg fails push-straight, yet served the plan: it is not held against it."""
    from planner.execute import made_progress

    cube = ap.load_object("cube")
    T0 = cube.resting_states[0].pose((0.5, 0.0), 0.0)
    slid = cube.resting_states[0].pose((0.56, 0.005), math.radians(7.0))
    assert made_progress(cube, "push", {"direction": 0.0}, T0, slid)
    assert not made_progress(cube, "push", {"direction": math.pi / 2}, T0, slid)  # it went the wrong way
    assert not made_progress(cube, "push", {"direction": 0.0}, T0, T0)  # blocked: nothing moved
    turned = cube.resting_states[0].pose((0.5, 0.0), math.radians(-12.0))
    assert made_progress(cube, "spin", {"angle": math.radians(-30.0)}, T0, turned)
    assert not made_progress(cube, "spin", {"angle": math.radians(30.0)}, T0, turned)
    target = skill_params.roll_targets(cube, 0)[0]
    rolled = cube.resting_states[target].pose((0.55, 0.0), 0.0)
    assert made_progress(cube, "roll", {"target": target}, T0, rolled)
    assert not made_progress(cube, "roll", {"target": target}, T0, slid)
    assert not made_progress(cube, "push", {"direction": 0.0}, T0, rolled)  # tipped over: not a push's doing


def test_greedy_baseline_reaches_an_open_goal_with_ideal_skills():
    from planner.execute import execute_greedy

    cube = ap.load_object("cube")
    skills = {n: IdealSkill(n) for n in ("push", "spin", "roll")}
    goal = ap.Goal(xy=(0.62, 0.05))
    sim = ap.Simulator(cube, seed=0)
    T0 = sim.reset(0, (0.45, 0.0), 0.0)
    ex = execute_greedy(cube, goal, T0, StubPredictor(skills), sim=sim, max_primitives=15)
    assert ex.success, str(ex)
    assert {e.skill for e in ex.log} == {"push"}
    assert ex.reason == "goal reached" and ex.replans == 0 and all(e.success for e in ex.log)


def test_the_step_log_names_the_resting_states_a_primitive_went_between():
    from planner.execute import LogEntry

    T = np.eye(4)
    tipped = LogEntry(0, "push", {"direction": 0.0}, False, True, T, T, states=(2, 0))
    kept = LogEntry(1, "roll", {"target": 3}, False, True, T, T, states=(0, 0))
    assert "state 2 -> 0 FAIL" in str(tipped)
    assert "state 0 FAIL" in str(kept) and "->  " not in str(kept)


def test_a_primitive_refused_before_any_physics_ends_the_execution():
    """A guard that flags the resting pose itself would refuse every later primitive: stop, do not loop."""
    from types import SimpleNamespace

    from planner.execute import _terminal

    refused = SimpleNamespace(valid=False, invalid_reason="sank", n_steps=0)
    pressed = SimpleNamespace(valid=False, invalid_reason="sank", n_steps=700)  # pressed in during a push
    carried = SimpleNamespace(valid=False, invalid_reason="off_table", n_steps=900)
    assert "before any motion" in _terminal(refused)
    assert _terminal(pressed) is None
    assert "off_table" in _terminal(carried)
    assert _terminal(SimpleNamespace(valid=True, invalid_reason=None, n_steps=0)) is None


def test_execution_does_not_mutate_the_plans_planner():
    """Failures are remembered in a fork (Planner.fork): the plan's planner, its failure memory and its roll graph
    are as they were, and planning again from the start gives the same plan."""
    cube = ap.load_object("cube")
    direct = skill_params.roll_targets(cube, 0)[0]
    planner = ideal_planner(cube, fail_roll=(0, direct))
    goal = ap.Goal(xy=(0.55, 0.05), resting_state=direct)
    T0 = cube.resting_states[0].pose((0.5, 0.0), 0.0)
    plan = planner.plan(T0, goal)
    before = [(s.skill, s.params) for s in plan.steps]
    sim = ap.Simulator(cube, seed=0)
    sim.set_object_pose(plan.start_pose, settle=False)
    ex = execute_plan(plan, sim=sim, max_primitives=20)
    assert ex.success and ex.replans == 2  # the roll failed twice in the execution's memory
    assert not planner.failures and not planner.failed_roll_spots
    assert planner.graph.probability(0, direct) == pytest.approx(0.8)
    assert [(s.skill, s.params) for s in planner.plan(T0, goal).steps] == before
    # a memory passed in is the one that learns
    memory = planner.fork()
    sim.set_object_pose(plan.start_pose, settle=False)
    execute_plan(plan, sim=sim, max_primitives=20, memory=memory)
    assert memory.failures and memory.graph.probability(0, direct) < 0.8 and not planner.failures


def test_a_plans_p_success_falls_when_a_skill_is_forced_to_fail():
    cube = ap.load_object("cube")
    goal = ap.Goal(xy=(0.62, 0.08))
    T0 = cube.resting_states[0].pose((0.45, -0.05), 0.0)
    skills = {n: IdealSkill(n) for n in ("push", "spin", "roll")}
    sure = Planner(cube, predictor=StubPredictor(skills, p=0.9), seed=0).plan(T0, goal)
    failing = Planner(cube, predictor=StubPredictor(skills, p=0.05), seed=0).plan(T0, goal)
    assert [s.skill for s in sure.steps] == [s.skill for s in failing.steps]
    assert sure.p_success > 0.99 and failing.p_success < sure.p_success - 0.3
    assert failing.expected_primitives > sure.expected_primitives


def test_a_push_of_several_strides_is_one_primitive_of_several_strokes():
    cube = ap.load_object("cube")
    T0, goal = cube.resting_states[0].pose((0.40, -0.1), 0.0), ap.Goal(xy=(0.70, 0.1))
    runs = {}
    for k in (1, 4):
        skills = {n: IdealSkill(n) for n in ("push", "spin", "roll")}
        plan = Planner(cube, predictor=StubPredictor(skills), seed=0, max_strides=k).plan(T0, goal)
        sim = ap.Simulator(cube, seed=0)
        sim.set_object_pose(T0, settle=False)
        ex = execute_plan(plan, sim=sim, max_primitives=30)
        assert ex.success, str(ex)
        assert ex.strokes == sum(len(s.calls) for s in skills.values())  # every stroke counted once
        runs[k] = ex
    # no more strokes than one per stride (a last stroke within STOP_WITHIN of the target is left out)
    assert runs[4].n_primitives < runs[1].n_primitives and runs[4].strokes <= runs[1].strokes
    assert any(e.strokes > 1 for e in runs[4].log) and all(e.strokes == 1 for e in runs[1].log)
    assert "strokes" in str(runs[4])


def test_on_primitive_is_told_each_primitive_once_in_order_a_push_of_several_strides_as_one():
    from planner.execute import execute_greedy

    cube = ap.load_object("cube")
    T0, goal = cube.resting_states[0].pose((0.40, -0.1), 0.0), ap.Goal(xy=(0.70, 0.1))
    skills = {n: IdealSkill(n) for n in ("push", "spin", "roll")}
    plan = Planner(cube, predictor=StubPredictor(skills), seed=0, max_strides=4).plan(T0, goal)
    sim = ap.Simulator(cube, seed=0)
    sim.set_object_pose(T0, settle=False)
    told = []
    ex = execute_plan(plan, sim=sim, max_primitives=30, on_primitive=told.append)
    assert ex.success and len(told) == ex.n_primitives and all(a is b for a, b in zip(told, ex.log))
    assert any(e.strokes > 1 for e in told)
    sim.set_object_pose(T0, settle=False)
    told = []
    greedy = execute_greedy(cube, goal, T0, StubPredictor(skills), sim=sim, max_primitives=15, on_primitive=told.append)
    assert told and all(a is b for a, b in zip(told, greedy.log)) and len(told) == greedy.n_primitives
    with pytest.raises(ap.errors.InputError, match="on_primitive must be callable"):
        execute_plan(plan, sim=sim, on_primitive=3)
    with pytest.raises(ap.errors.InputError, match="on_primitive must be callable"):
        execute_greedy(cube, goal, T0, StubPredictor(skills), sim=sim, on_primitive="log")


class HalfSpin(IdealSkill):
    """A spin that turns the object half the asked angle (a real policy's turn follows its ask loosely)."""

    def execute(self, sim, params, stop_at_angle=True, steer=True):
        return super().execute(sim, {"angle": 0.5 * params["angle"]})


def test_a_spin_step_of_several_strokes_asks_for_the_rest_of_its_turn_within_one_call():
    cube = ap.load_object("cube")
    T0 = cube.resting_states[0].pose((0.5, 0.0), 0.0)
    goal = ap.Goal(xy=(0.5, 0.0), yaw=math.radians(40.0), yaw_tol=math.radians(15.0))
    runs = {}
    for k in (1, 4):
        skills = {"push": IdealSkill("push"), "spin": HalfSpin("spin"), "roll": IdealSkill("roll")}
        plan = Planner(cube, predictor=StubPredictor(skills), seed=0).plan(T0, goal)
        assert [s.skill for s in plan.steps] == ["spin"]
        sim = ap.Simulator(cube, seed=0)
        sim.set_object_pose(T0, settle=False)
        runs[k] = execute_plan(plan, sim=sim, max_primitives=10, spin_strokes=k)
        assert runs[k].success, str(runs[k])
    # one stroke a call: the half turn (20 deg) leaves the object off plan, and a replanned spin turns it 10 more
    assert runs[1].n_primitives == 2 and runs[1].replans == 1
    # calls of several strokes: the first call asks for the rest (20 deg) itself and stops within 10 deg of 40
    assert runs[4].n_primitives == 1 and runs[4].log[0].strokes == 2 and runs[4].replans == 0
    with pytest.raises(ap.errors.InputError, match="spin_strokes"):
        execute_plan(plan, sim=ap.Simulator(cube, seed=0), spin_strokes=0)


def test_a_skill_named_in_sensors_acts_on_that_sensors_clouds_and_the_others_on_the_simulators():
    cube = ap.load_object("cube")
    T0 = cube.resting_states[0].pose((0.45, 0.0), 0.0)
    target = skill_params.roll_targets(cube, 0)[0]
    goal = ap.Goal(xy=(0.6, 0.0), resting_state=target)
    seen: list[tuple[str, str]] = []

    class Looking(IdealSkill):
        def execute(self, sim, params, stop_at_angle=True, steer=True):
            seen.append((self.name, sim.sensor))
            return super().execute(sim, params)

    skills = {n: Looking(n) for n in ("push", "spin", "roll")}
    plan = Planner(cube, predictor=StubPredictor(skills), seed=0).plan(T0, goal)
    assert {s.skill for s in plan.steps} >= {"push", "roll"}
    sim = ap.Simulator(cube, seed=0, sensor="surface")
    sim.set_object_pose(T0, settle=False)
    ex = execute_plan(plan, sim=sim, max_primitives=20, sensors={"roll": "cameras"})
    assert ex.success, str(ex)
    assert {sensor for name, sensor in seen if name == "roll"} == {"cameras"}
    assert {sensor for name, sensor in seen if name != "roll"} == {"surface"}
    assert sim.sensor == "surface"
    with pytest.raises(ap.errors.InputError, match="sensors maps"):
        execute_plan(plan, sim=ap.Simulator(cube, seed=0), sensors={"roll": "eyes"})
    with pytest.raises(ap.errors.InputError, match="sensors maps"):
        execute_plan(plan, sim=ap.Simulator(cube, seed=0), sensors={"lift": "cameras"})
