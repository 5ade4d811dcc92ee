"""The plan bench (affordplan.app.bench.plan), which plans every task through planner.api.plan: solvable tasks,
seeds and draws, chosen tasks and their logs, the report, household objects, plan-level calibration."""

import numpy as np
import pytest
from planner_fakes import ideal_planner

from affordplan.errors import InputError


def test_bench_tasks_can_be_solved_in_principle():
    """Free start, goal free at its asked yaw, goal state reachable by rolls: no task is lost before it starts."""
    import networkx as nx

    from affordplan.app.bench.plan import make_task
    from planner.graph import RestingStateGraph

    rng = np.random.default_rng(0)
    for i in range(12):
        task, obj = make_task(rng, i)
        planner = ideal_planner(obj, task.obstacles)
        s = task.start["resting_state"]
        assert planner.checkers[s].is_free(*task.start["xy"], task.start["yaw"])
        g = task.goal.resting_state
        assert g is not None and 0 <= g < len(obj.resting_states)
        assert planner.check_goal(task.goal, s) == g  # raises GoalError for a goal in a wall at its yaw
        assert g == s or nx.has_path(RestingStateGraph(obj, lambda a, b: 1.0).graph, s, g)


def test_bench_seeds_draw_their_own_objects_and_cap_the_task_count():
    from affordplan.app.bench.plan import OBJECTS_PER_SEED, bench_plan, make_task

    _, obj = make_task(np.random.default_rng(3), OBJECTS_PER_SEED * 3 + 7)
    assert obj.name.startswith(f"test_{OBJECTS_PER_SEED * 3 + 7}_")
    with pytest.raises(InputError, match="n_tasks"):
        bench_plan(OBJECTS_PER_SEED + 1, seed=0, progress=False)


def test_bench_runs_chosen_tasks_of_the_seed_s_draw_and_logs_their_executions():
    """``only=[3]`` runs the task a whole run meets fourth (tasks are drawn in order), and the log shows its plan
    and each executed primitive with the resting states it went between."""
    from affordplan.app.bench.plan import OBJECTS_PER_SEED, _describe, bench_plan, make_task
    from affordplan.errors import InputError

    rng = np.random.default_rng(2)
    task = [make_task(rng, OBJECTS_PER_SEED * 2 + i)[0] for i in range(4)][3]
    lines: list[str] = []
    report = bench_plan(50, sim="finger", seed=2, planners=("greedy",), max_primitives=1, progress=False,
                        only=[3], log=lines.append)
    (result,) = report.results
    assert result.task == 3 and result.primitives == 1
    header, execution = lines
    assert header.startswith(f"=== seed 2 task 3: test_{OBJECTS_PER_SEED * 2 + 3}_") and _describe(task) in header
    assert "execution:" in execution and " 0. " in execution and "state " in execution
    assert report.as_dict()["tasks"][0]["task"] == 3
    with pytest.raises(InputError, match="task indices"):
        bench_plan(50, seed=2, progress=False, only=[OBJECTS_PER_SEED])


def test_bench_draws_rerun_the_same_tasks_with_other_random_numbers():
    """``draw=0`` keeps the seeds the bench always used (``seed + task``); each other draw gives every task its own
    seed, and runs the very same task (object, scene, start, goal)."""
    from affordplan.app.bench.plan import bench_plan, task_seed
    from affordplan.errors import InputError

    assert [task_seed(3, i) for i in range(3)] == [3, 4, 5] and task_seed(3, None) == 3
    seeds = {task_seed(s, i, d) for s in range(3) for i in [None, *range(50)] for d in (1, 2)}
    assert len(seeds) == 3 * 51 * 2 and not seeds & set(range(100))
    assert task_seed(3, 7, 1) == task_seed(3, 7, 1)
    headers = {}
    for draw in (0, 1):
        lines: list[str] = []
        report = bench_plan(50, sim="finger", seed=2, planners=("greedy",), max_primitives=1, progress=False,
                            only=[3], log=lines.append, draw=draw)
        assert report.as_dict()["draw"] == draw and report.results[0].task == 3
        headers[draw] = lines[0]
    assert headers[0] == headers[1]
    with pytest.raises(InputError, match="draw"):
        bench_plan(50, seed=2, progress=False, only=[3], draw=-1)


def test_bench_reports_goals_in_rare_resting_states_apart_and_counts_them_in():
    from affordplan.app.bench.plan import RARE_GOAL_STATE, BenchReport, TaskResult

    def result(ok, p_goal, missed=""):
        return TaskResult("affordplan", "open", ok, 0.1, 5, 1, "", p_goal, missed=missed)

    report = BenchReport([result(True, 0.4), result(True, 0.3), result(False, 0.02, "state"), result(True, 0.01),
                          result(False, RARE_GOAL_STATE, "yaw")])
    s = report.summary("affordplan")
    assert s["success"] == pytest.approx(3 / 5)  # rare goals stay in the success rate
    assert s["rare_goal_states"] == dict(tasks=2, reached=1)
    assert s["failures"] == {"state": 1, "yaw": 1}
    assert "rare goal 1/2" in report.report() and "by what they missed: state 1, yaw 1" in report.report()


def test_the_report_prints_a_dash_for_a_longest_plan_it_has_no_figure_for():
    from affordplan.app.bench.plan import BenchReport, TaskResult

    timed = TaskResult("affordplan", "open", True, 0.1, 5, 1, "", 0.4, max_planning_time=0.25)
    greedy = TaskResult("greedy", "open", True, 0.2, 9, 0, "", 0.4)  # greedy makes no plan: no longest one
    rows = {line.split()[0]: line for line in BenchReport([timed, greedy]).report().splitlines()[2:4]}
    assert "100 /    250 ms" in rows["affordplan"] and "200 /      - ms" in rows["greedy"]
    assert "nan" not in rows["greedy"]


def test_household_tasks_take_the_unseen_meshes_validation_tasks_the_validation_ones_and_mixed_alternate():
    from affordplan.app.bench.plan import task_object
    from affordplan.objects import housekeep

    unseen = {f"housekeep/{n}" for n in housekeep.names("unseen")}
    assert task_object(3, "household").name in unseen
    assert task_object(3, "mixed").name in unseen and task_object(4, "mixed").name.startswith("test_4_")
    validation = {f"housekeep/{n}" for n in housekeep.names("validation")}
    assert {task_object(i, "validation").name for i in range(12)} == validation
    assert not validation & unseen
    with pytest.raises(InputError, match="objects"):
        task_object(0, "kitchen")


def test_plan_calibration_scores_predictions_against_outcomes():
    from affordplan.app.bench.plan import plan_calibration

    cal = plan_calibration([1.0, 0.0, 0.5, float("nan")], [True, False, True, True])
    assert cal["plans"] == 3 and cal["brier"] == pytest.approx(0.25 / 3)
    assert cal["reached"] == pytest.approx(2 / 3) and sum(b["plans"] for b in cal["bins"]) == 3
    assert plan_calibration([float("nan")], [True])["plans"] == 0


def test_fit_stuck_fits_training_runs_only():
    from affordplan.app.bench.plan import fit_stuck

    # plans with a roll fail, plans of pushes alone succeed: the roll's stuck rate carries the failures
    tasks = [dict(planner="affordplan", success=not i % 3, steps=[["push", 0.4]] + ([["roll", 0.1]] if i % 3 else []))
             for i in range(12)] + [dict(planner="greedy", success=True, steps=[])]
    run = dict(objects="training", max_primitives=40, tasks=tasks)
    fit = fit_stuck([run], held_out=[run], grid_step=0.25)
    assert fit["plans"] == 12 and fit["reached"] == pytest.approx(4 / 12)
    assert fit["rates"]["roll"] == 1.0 and fit["rates"]["push"] == 0.0
    assert fit["brier"] < fit["brier_without"]
    assert fit["held_out"]["brier"] == pytest.approx(fit["brier"], abs=0.02)
    with pytest.raises(InputError, match="training"):
        fit_stuck([dict(objects="mixed", max_primitives=40, tasks=tasks)])


def test_fit_stuck_reads_a_push_of_several_strides_as_its_odds_do():
    """A saved plan's push of three strides stays a call of three strides in the fit (as ``Plan.odds`` reads it),
    not one stride."""
    from affordplan.app.bench.plan import fit_stuck
    from planner.odds import mc_odds
    from primitives.outcome_model import OutcomeModel

    tasks = [dict(planner="affordplan", success=True, steps=[["push", 0.6, 0.0, 3]]) for _ in range(4)]
    run = dict(objects="training", max_primitives=1, tasks=tasks)
    fit = fit_stuck([run], held_out=[run], grid_step=0.5)
    models = {"push": OutcomeModel.load("push")}
    strided, single = (mc_odds(steps, models, 1, seed=0, stuck_rate=fit["rates"],
                               tip_fatal=fit["tip_fatal"]).p_success
                       for steps in ([("push", 0.6, 0.0, 3)], [("push", 0.6, 0.0)]))
    assert abs(strided - single) > 0.05  # one call covering three strides, against one covering one
    assert fit["held_out"]["brier"] == pytest.approx((1.0 - strided) ** 2)


def _saved_run(seed: int, outcomes: list[bool], p: list[float], objects: str = "mixed") -> dict:

    from affordplan.app.bench.plan import BenchReport, TaskResult

    results = [TaskResult("affordplan", "open", ok, 0.1 + 0.01 * i, 5 + i, 1, p_success=pi, task=i,
                          steps=[("push", 0.5, 0.0, 2)]) for i, (ok, pi) in enumerate(zip(outcomes, p))]
    results += [TaskResult("greedy", "open", not ok, 0.2, 20, 0, task=i) for i, ok in enumerate(outcomes)]
    return BenchReport(results=results, objects=objects, seed=seed).as_dict()


def test_pool_reports_over_the_tasks_of_every_run(tmp_path):
    import json

    from affordplan.app.bench.plan import plan_calibration, plot_report, pool

    runs = [_saved_run(0, [True, False], [0.9, 0.2]), _saved_run(1, [True, True, False], [0.8, 0.7, 0.6])]
    report = pool(json.loads(json.dumps(runs)))  # as read back from the saved files
    s = report.summary("affordplan")
    assert s["tasks"] == 5 and s["success"] == pytest.approx(3 / 5)
    assert s["median_primitives"] == 6 and s["max_planning_time_s"] != s["max_planning_time_s"]  # nan: none saved
    assert s["calibration"]["brier"] == pytest.approx(
        plan_calibration([0.9, 0.2, 0.8, 0.7, 0.6], [True, False, True, True, False])["brier"])
    assert report.summary("greedy")["success"] == pytest.approx(2 / 5)
    assert report.results[0].steps == [("push", 0.5, 0.0, 2)]
    plot_report(report, tmp_path / "bench.png")
    assert (tmp_path / "bench.png").stat().st_size > 10_000


def test_runs_of_one_seed_by_different_planners_pool_side_by_side():
    """`bench plan --planner affordplan` and `--planner greedy`, saved apart, pool into one report of both."""
    from affordplan.app.bench.plan import pool

    both = _saved_run(4, [True, False, True], [0.9, 0.3, 0.7])
    ours = dict(both, tasks=[t for t in both["tasks"] if t["planner"] == "affordplan"])
    greedy = dict(both, tasks=[t for t in both["tasks"] if t["planner"] == "greedy"])
    report = pool([ours, greedy])
    assert report.planners == ["affordplan", "greedy"]
    assert report.summary("affordplan")["success"] == pytest.approx(2 / 3)
    assert report.summary("greedy")["success"] == pytest.approx(1 / 3)
    with pytest.raises(InputError, match=r"seed 4 \(greedy\)"):
        pool([ours, greedy, greedy])


def test_pool_refuses_runs_that_are_not_one_bench():
    from affordplan.app.bench.plan import pool

    with pytest.raises(InputError, match="differ"):
        pool([_saved_run(0, [True], [0.5]), _saved_run(1, [True], [0.5], objects="household")])
    with pytest.raises(InputError, match="same seed"):
        pool([_saved_run(3, [True], [0.5]), _saved_run(3, [False], [0.5])])
    with pytest.raises(InputError, match="not a saved"):
        pool([dict(tasks=[])])
    with pytest.raises(InputError, match="no bench runs"):
        pool([])


def test_the_bench_scores_a_plans_odds_within_the_budget_it_executes_with():
    """A plan's ``p_success`` is for the planner's 60 primitives; a bench run executing with 4 reports (and scores
    the calibration of) the odds within 4."""
    from affordplan.app.bench.plan import bench_plan, task_seed
    from planner.odds import mc_odds
    from primitives.outcome_model import OutcomeModel

    report = bench_plan(50, sim="finger", seed=2, planners=("affordplan",), max_primitives=4, progress=False,
                        only=[3])
    (result,) = report.results
    models = {name: OutcomeModel.load(name) for name in ("push", "roll", "spin")}
    within = {b: mc_odds(result.steps, models, b, seed=task_seed(2, 3)) for b in (4, 60)}
    assert len(result.steps) >= 3
    assert result.p_success == pytest.approx(within[4].p_success)
    assert result.expected_primitives == pytest.approx(within[4].expected_primitives)
    assert within[4].p_success < within[60].p_success
