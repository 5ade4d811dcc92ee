"""``affordplan bench plan``: random plan-and-execute tasks, affordplan against the greedy baseline.

Each task draws an object from the procedural *test* split (never trained on; task ``i`` of seed ``S`` takes
object ``OBJECTS_PER_SEED * S + i``, so each seed meets other objects), a scene (a wall with
a gap between start and goal, two or three blocks, or an open table), a start (resting state by its
probability, position on the near side, random yaw) and a goal (the far side; a different resting
state in 40 % of tasks; a goal yaw in half of them). Every task can be solved in principle: the start and
the goal (at its yaw, when one is asked) are free, and the goal's resting state is reachable by a chain
of rolls (:func:`primitives.params.roll_targets`). Both planners run the same task in the same
simulator kind; success is the goal reached within 3 cm, 15 deg (when a yaw is asked) and in the
right resting state, within ``max_primitives``.
"""

from __future__ import annotations

import math
import os
import time
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field

import networkx as nx
import numpy as np
from tqdm import tqdm

from affordplan import versions, versions_text
from affordplan.errors import AffordplanError, InputError
from affordplan.goal import Goal
from affordplan.objects import housekeep
from affordplan.objects.model import ObjectModel, load_object, random_object
from affordplan.robot import SKILLS
from affordplan.world import Box, Workspace
from planner.execute import check_sensors
from planner.graph import RestingStateGraph
from planner.plan import CLEARANCE, MAX_STRIDES, inflated_footprints, make_checkers
from planner.predict import Predictor
from primitives.skills import load_skills

# seed S's tasks take test objects 1000 S, 1000 S + 1, ... (until release 0.7: objects 0-49 for every seed)
OBJECTS_PER_SEED = 1000
# Goal states in which fewer random drops come to rest are reported apart (an ellipsoid on its tip: the roll
# into them, and every push there, rarely succeeds); they stay in the tasks and in the success rate.
RARE_GOAL_STATE = 0.05
# What the tasks' objects are: the procedural test split, HACMan's unseen household meshes (never trained on,
# housekeep.names("unseen")), or the two by turns (even tasks procedural, odd ones household); "training": the
# training objects by turns (procedural train split, housekeep.names("training")), for fitting what the planner
# learns from plan outcomes (planner.odds.STUCK_RATES), never for reporting.
OBJECT_SETS = ("procedural", "household", "mixed", "training", "validation")


@dataclass
class Task:
    object_index: int
    scene: str
    obstacles: tuple[Box, ...]
    start: dict
    goal: Goal


@dataclass
class TaskResult:
    planner: str
    scene: str
    success: bool
    planning_time: float  # first plan, seconds
    primitives: int
    replans: int
    reason: str = ""
    goal_state_probability: float = 1.0  # share of random drops that come to rest in the goal's state
    # where the object ended: metres from the goal, radians off its yaw (0 when none is asked)
    final_xy_error: float = float("nan")
    final_yaw_error: float = float("nan")
    # what a failed task missed: "no plan", "state" (the wrong resting state), "position" (the right state, off by
    # more than the goal's tolerance) or "yaw" (in place, turned wrong); "" on success
    missed: str = ""
    task: int = -1  # index of the task in its seed's draw (object OBJECTS_PER_SEED * seed + task)
    # the first plan's predicted odds within the execution's budget (Plan.odds(max_primitives): Plan.p_success and
    # Plan.expected_primitives where the budget is the planner's own); nan for greedy or no plan
    p_success: float = float("nan")
    expected_primitives: float = float("nan")
    max_planning_time: float = float("nan")  # the longest of the first plan and the replans, seconds
    object_name: str = ""
    # the first plan's steps as its odds see them: (skill, predicted success of one try); empty for greedy
    steps: list[tuple] = field(default_factory=list)
    strokes: int = 0  # fingertip strokes over the execution's calls (a push of several strides may make more than one)


@dataclass
class BenchReport:
    results: list[TaskResult] = field(default_factory=list)
    draw: int = 0  # which draw of the run's random numbers (bench_plan's ``draw``)
    objects: str = "procedural"  # the tasks' objects (OBJECT_SETS)
    max_primitives: int = 40  # each execution's budget
    seed: int | None = None  # the bench seed the tasks were drawn with (None: pooled from several)

    @property
    def planners(self) -> list[str]:
        """The planners of the results, in the order they first ran."""
        return list(dict.fromkeys(r.planner for r in self.results))

    def summary(self, planner: str) -> dict:
        rs = [r for r in self.results if r.planner == planner]
        if not rs:
            return {}
        rare = [r for r in rs if r.goal_state_probability < RARE_GOAL_STATE]
        primitives = [r.primitives for r in rs]
        longest = [r.max_planning_time for r in rs if np.isfinite(r.max_planning_time)]
        return dict(planner=planner, tasks=len(rs), success=float(np.mean([r.success for r in rs])),
                    median_planning_time_s=float(np.median([r.planning_time for r in rs])),
                    max_planning_time_s=float(max(longest)) if longest else float("nan"),
                    mean_primitives=float(np.mean(primitives)),
                    median_primitives=float(np.median(primitives)),
                    p90_primitives=float(np.percentile(primitives, 90)),
                    mean_strokes=float(np.mean([r.strokes for r in rs])),
                    median_strokes=float(np.median([r.strokes for r in rs])),
                    calibration=plan_calibration([r.p_success for r in rs], [r.success for r in rs]),
                    mean_replans=float(np.mean([r.replans for r in rs])),
                    success_by_scene={s: float(np.mean([r.success for r in rs if r.scene == s]))
                                      for s in sorted({r.scene for r in rs})},
                    rare_goal_states=dict(tasks=len(rare), reached=sum(r.success for r in rare)),
                    failures=dict(Counter(r.missed for r in rs if not r.success)))

    def report(self) -> str:
        lines = ["versions: " + versions_text(),
                 f"{'planner':10s} {'tasks':>5s} {'success':>8s} {'plan time (median / max)':>25s} "
                 f"{'primitives (mean / median / p90)':>33s} {'replans/task':>13s}  by scene; goal state rarer "
                 f"than {RARE_GOAL_STATE:.0%} of drops"]
        summaries = [self.summary(name) for name in self.planners]
        for s in summaries:
            scenes = ", ".join(f"{k} {v:.2f}" for k, v in s["success_by_scene"].items())
            rare = s["rare_goal_states"]
            rare_text = f"{rare['reached']}/{rare['tasks']}" if rare["tasks"] else "none"
            lines.append(f"{s['planner']:10s} {s['tasks']:5d} {s['success']:8.2f} "
                         f"{1e3 * s['median_planning_time_s']:10.0f} / {_ms(s['max_planning_time_s']):>6s} ms "
                         f"{s['mean_primitives']:17.1f} / {s['median_primitives']:4.0f} / {s['p90_primitives']:4.0f} "
                         f"{s['mean_replans']:13.1f}  {scenes}; rare goal {rare_text}; fingertip strokes (mean / "
                         f"median) {s['mean_strokes']:.1f} / {s['median_strokes']:.0f}")
        for s in summaries:
            cal = s["calibration"]
            if cal["plans"]:
                bins = ", ".join(f"[{b['lo']:.1f}, {b['hi']:.1f}): {b['predicted']:.2f} vs {b['reached']:.2f} "
                                 f"({b['plans']})" for b in cal["bins"])
                lines.append(f"{s['planner']} plan-level calibration, {cal['plans']} plans: Brier {cal['brier']:.3f}, "
                             f"mean predicted {cal['mean_predicted']:.2f} vs reached {cal['reached']:.2f}; "
                             f"by predicted p_success: {bins}")
        for s in summaries:
            name, missed = s["planner"], s["failures"]
            if missed:
                lines.append(f"{name} failures, by what they missed: "
                             + ", ".join(f"{k} {v}" for k, v in sorted(missed.items(), key=lambda kv: -kv[1])))
        return "\n".join(lines)

    def as_dict(self) -> dict:
        return dict(versions=versions(), seed=self.seed, draw=self.draw, objects=self.objects,
                    max_primitives=self.max_primitives, summary=[self.summary(n) for n in self.planners],
                    tasks=[asdict(r) for r in self.results])


def _scene(rng: np.random.Generator, kind: str, radius: float) -> tuple[Box, ...]:
    if kind == "wall_gap":
        x = rng.uniform(0.56, 0.6)
        gap = 2 * radius + 0.06
        c = rng.uniform(-0.08, 0.08)
        lo, hi = c - gap / 2, c + gap / 2
        return (Box(center=(x, (lo - 0.32) / 2), size=(0.02, lo + 0.32, 0.1)),
                Box(center=(x, (hi + 0.32) / 2), size=(0.02, 0.32 - hi, 0.1)))
    if kind == "blocks":
        n = int(rng.integers(2, 4))
        return tuple(Box(center=(rng.uniform(0.5, 0.62), rng.uniform(-0.2, 0.2)), size=(0.06, 0.06, 0.08),
                         yaw=rng.uniform(0, math.pi)) for _ in range(n))
    return ()


def task_object(index: int, objects: str = "procedural") -> ObjectModel:
    """Task ``index``'s object (:data:`OBJECT_SETS`): procedural test object ``index``, or unseen household mesh
    ``index`` (cycling through the 25); ``"mixed"`` takes the household one for odd indices; ``"training"`` as
    ``"mixed"`` from the training objects (procedural train split, household training meshes); ``"validation"``
    household validation mesh ``index`` (cycling through the 12 carved out of HACMan's train split), for choosing
    settings on objects the test figures do not use."""
    if objects not in OBJECT_SETS:
        raise InputError(f"objects must be one of {OBJECT_SETS}, got {str(objects)[:40]!r}")
    if objects == "validation":
        names = housekeep.names("validation")
        return load_object(f"housekeep/{names[index % len(names)]}")
    if objects == "household" or (objects in ("mixed", "training") and index % 2):
        names = housekeep.names("training" if objects == "training" else "unseen")
        return load_object(f"housekeep/{names[index % len(names)]}")
    return random_object(index, "train" if objects == "training" else "test")


def make_task(rng: np.random.Generator, index: int, workspace: Workspace = Workspace(),
              objects: str = "procedural") -> tuple[Task, ObjectModel]:
    """A random task on object ``index`` of ``objects`` (:func:`task_object`) whose start and goal are free
    (resampled until they are)."""
    obj = task_object(index, objects)
    states = obj.resting_states
    probs = np.array([s.probability for s in states])
    radius = max(float(np.linalg.norm(obj.mesh.extents[:2])) / 2, 0.03)
    kind = str(rng.choice(["wall_gap", "blocks", "open"], p=[0.5, 0.3, 0.2]))
    footprints = inflated_footprints(obj, CLEARANCE)
    rolls = RestingStateGraph(obj, lambda i, j: 1.0).graph  # the roll edges alone, no success model
    reachable = {s.index: sorted(nx.descendants(rolls, s.index)) for s in states}  # by a chain of rolls
    for _ in range(200):
        obstacles = _scene(rng, kind, radius)
        s0 = int(rng.choice(len(states), p=probs / probs.sum()))
        start = dict(resting_state=s0, xy=(float(rng.uniform(0.38, 0.46)), float(rng.uniform(-0.15, 0.15))),
                     yaw=float(rng.uniform(-math.pi, math.pi)))
        goal_state = s0
        if reachable[s0] and rng.random() < 0.4:
            goal_state = int(rng.choice(reachable[s0]))
        goal = Goal(xy=(float(rng.uniform(0.64, 0.7)), float(rng.uniform(-0.12, 0.12))),
                    yaw=float(rng.uniform(-math.pi, math.pi)) if rng.random() < 0.5 else None,
                    resting_state=goal_state)
        checker = make_checkers(footprints, obstacles, workspace)
        yaws = [goal.yaw] if goal.yaw is not None else np.linspace(-3.1, 3.1, 12)
        if checker[s0].is_free(*start["xy"], start["yaw"]) and \
                any(checker[goal_state].is_free(*goal.xy, a) for a in yaws):
            return Task(index, kind, obstacles, start, goal), obj
    raise AffordplanError(f"could not place a free start and goal on test object {index}")


def plan_calibration(predicted: Sequence[float], reached: Sequence[bool], bins: int = 5) -> dict:
    """Plan-level calibration of predicted ``p_success`` against whether the goal was reached (plans without a
    prediction, nan, are left out): the Brier score, and per equal-width bin the mean prediction and the share
    reached."""
    p = np.asarray(predicted, dtype=float)
    y = np.asarray(reached, dtype=float)
    keep = np.isfinite(p)
    p, y = p[keep], y[keep]
    if not len(p):
        return dict(plans=0, brier=float("nan"), mean_predicted=float("nan"), reached=float("nan"), bins=[])
    edges = np.linspace(0.0, 1.0, bins + 1)
    which = np.clip(np.digitize(p, edges) - 1, 0, bins - 1)
    rows = [dict(lo=float(edges[b]), hi=float(edges[b + 1]), plans=int(np.sum(which == b)),
                 predicted=float(np.mean(p[which == b])), reached=float(np.mean(y[which == b])))
            for b in range(bins) if np.any(which == b)]
    return dict(plans=int(len(p)), brier=float(np.mean((p - y) ** 2)), mean_predicted=float(np.mean(p)),
                reached=float(np.mean(y)), bins=rows)


def run_task(task: Task, obj: ObjectModel, planner_name: str, sim: str, predictor: Predictor, seed: int,
             max_primitives: int, time_limit: float, log: Callable[[str], None] | None = None,
             max_strides: int = MAX_STRIDES, spin_strokes: int | None = None,
             sensors: Mapping[str, str] | None = None) -> TaskResult:
    """Plan and execute ``task`` with one planner; ``log``, when given, receives the first plan and the
    execution's step log (:class:`planner.execute.Execution`) as text. ``max_strides``: as
    :func:`planner.api.plan`; ``spin_strokes``, ``sensors``: as :meth:`planner.plan.Plan.execute`."""
    from planner.api import plan as make_plan

    p_goal = float(obj.resting_states[task.goal.resting_state].probability)
    t0 = time.perf_counter()
    try:
        p = make_plan(obj, task.goal, start=task.start, obstacles=task.obstacles, time_limit=time_limit,
                      planner=planner_name, seed=seed, predictor=predictor, max_strides=max_strides)
    except AffordplanError as exc:
        if log is not None:
            log(f"{planner_name}: no plan: {exc}")
        return TaskResult(planner_name, task.scene, False, time.perf_counter() - t0, 0, 0, f"no plan: {exc}",
                          p_goal, missed="no plan")
    ex = p.execute(sim=sim, max_primitives=max_primitives, seed=seed, spin_strokes=spin_strokes, sensors=sensors)
    if log is not None:
        log(f"{planner_name}: {p}\n{ex}")
    first = p.planning_time if planner_name == "affordplan" else ex.planning_time / max(1, ex.n_primitives)
    goal = task.goal
    xy_error, yaw_error, state_ok = goal.errors(obj, ex.final_pose)
    missed = "" if ex.success else "state" if not state_ok else "position" if xy_error > goal.xy_tol else "yaw"
    longest = max(ex.plan_times) if planner_name == "affordplan" and ex.plan_times else float("nan")
    predicted = (float("nan"), float("nan"))
    if planner_name == "affordplan":  # the odds within this execution's budget, not the planner's default 60
        odds = p.odds(max_primitives)
        predicted = (float(odds.p_success), float(odds.expected_primitives))
    return TaskResult(planner_name, task.scene, ex.success, first, ex.n_primitives, ex.replans, ex.reason, p_goal,
                      float(xy_error), float(yaw_error), missed, p_success=predicted[0],
                      expected_primitives=predicted[1], max_planning_time=float(longest), object_name=obj.name,
                      steps=p.planner.odds_steps(p.steps) if planner_name == "affordplan" else [],
                      strokes=ex.strokes)


def _ms(seconds: float) -> str:
    """``seconds`` in whole milliseconds, or ``-`` where there is no figure (greedy's longest plan: it makes none)."""
    return f"{1e3 * seconds:.0f}" if np.isfinite(seconds) else "-"


def _describe(task: Task) -> str:
    """The task's start and goal, short: positions in metres, yaws in degrees."""
    s, g = task.start, task.goal
    goal_yaw = "any yaw" if g.yaw is None else f"yaw {math.degrees(g.yaw):+.0f} deg"
    return (f"start state {s['resting_state']} at ({s['xy'][0]:.3f}, {s['xy'][1]:.3f}) yaw "
            f"{math.degrees(s['yaw']):+.0f} deg; goal state {g.resting_state} at ({g.xy[0]:.3f}, {g.xy[1]:.3f}) "
            f"{goal_yaw}")


def task_seed(seed: int, task: int | None, draw: int = 0) -> int:
    """The seed of task ``task`` of bench seed ``seed`` for planning and executing (OMPL, point-cloud samples), or
    with ``task=None`` the run's own (the success-model queries' point-cloud samples): ``seed + task`` and ``seed``
    in the standard draw (0), as since the bench began; other, independent ones per ``draw > 0``."""
    if draw == 0:
        return seed if task is None else seed + task
    return int(np.random.SeedSequence([seed, 0 if task is None else task + 1, draw]).generate_state(1)[0])


def bench_plan(n_tasks: int = 50, sim: str = "arm", seed: int = 0, planners=("affordplan", "greedy"),
               max_primitives: int = 40, time_limit: float = 5.0, progress: bool = True,
               only: Sequence[int] | None = None, log: Callable[[str], None] | None = None,
               weights_dir: str | os.PathLike | None = None, draw: int = 0, objects: str = "procedural",
               max_strides: int = MAX_STRIDES, spin_strokes: int | None = None,
               sensors: Mapping[str, str] | None = None) -> BenchReport:
    """Run ``n_tasks`` random tasks with each planner (see the module docstring).

    ``draw``: 0 runs the standard bench; ``k > 0`` runs the same tasks (objects, scenes, starts, goals) with the
    run's other random numbers drawn afresh (:func:`task_seed`: OMPL's, and the point-cloud samples of the
    simulator and of the success-model queries), so that the spread between draws shows how far a task's
    outcome moves by chance alone, the yardstick for a change that alters plans.

    ``weights_dir``: run the skills from this folder's files instead of the shipped ones
    (:func:`primitives.skills.load_skills`; a skill without files there stays shipped), e.g. to bench a
    candidate set of weights before shipping it.

    ``objects``: the tasks' objects, one of :data:`OBJECT_SETS` (:func:`task_object`).

    ``max_strides``: the 5 cm strides one push call of the affordplan planner may make (:func:`planner.api.plan`);
    1 benches pushes of one stroke each, as until 0.24. ``spin_strokes``: the strokes one spin step of the affordplan
    planner's plans may make (:meth:`planner.plan.Plan.execute`; default :data:`planner.execute.SPIN_STROKES`). Each
    task reports its calls (``primitives``) and its fingertip strokes. ``sensors``: the clouds each named skill of
    the affordplan planner's plans is shown while it acts (default :data:`planner.execute.EXECUTION_SENSORS`).

    ``only``: run just these tasks of the seed's draw (indices; the same tasks, objects and scenes as in the whole
    run, which draws them in order). ``log``: receives, per task and planner, a header, the first plan and the
    execution's step log.
    """
    if draw < 0:
        raise InputError(f"draw must be >= 0, got {draw}")
    if not 0 < n_tasks <= OBJECTS_PER_SEED:
        raise InputError(f"n_tasks must be 1-{OBJECTS_PER_SEED} (seed S's tasks take test objects "
                         f"{OBJECTS_PER_SEED} S + i), got {n_tasks}")
    wanted = range(n_tasks) if only is None else sorted(set(only))
    if not wanted or not all(0 <= i < OBJECTS_PER_SEED for i in wanted):
        raise InputError(f"task indices must be 0-{OBJECTS_PER_SEED - 1}, got {list(only or [])}")
    sensors = check_sensors(sensors)
    skills = None if weights_dir is None else load_skills(weights_dir)
    rng = np.random.default_rng(seed)
    report = BenchReport(draw=draw, objects=objects, max_primitives=max_primitives, seed=seed)
    bar = tqdm(total=len(wanted), desc=f"bench plan ({sim})", disable=not progress, unit="task")
    for i in range(max(wanted) + 1):
        # drawn in order: task i is the same in any run
        task, obj = make_task(rng, OBJECTS_PER_SEED * seed + i, objects=objects)
        if i not in wanted:
            continue
        predictor = Predictor(obj, skills=skills, seed=task_seed(seed, None, draw))
        for name in planners:
            if log is not None:
                log(f"=== seed {seed} task {i}: {obj.name} ({task.scene}); {_describe(task)}")
            result = run_task(task, obj, name, sim, predictor, task_seed(seed, i, draw), max_primitives, time_limit,
                              log, max_strides, spin_strokes, sensors)
            result.task = i
            report.results.append(result)
        bar.update(1)
    bar.close()
    return report


def _training_plans(reports: Sequence[dict], training: bool = True
                    ) -> tuple[list[list[tuple]], list[bool], int]:
    """The affordplan first plans' steps as :func:`planner.odds.mc_odds` reads them (``(skill, p, tip)``, and
    ``(skill, p, tip, strides)`` for a push of several strides; runs saved before tips were recorded give tip 0),
    whether each reached, and the runs' execution budget, from saved bench runs (on training objects, unless
    ``training`` is false)."""
    plans, reached, budgets = [], [], set()
    for report in reports:
        if training and report.get("objects") != "training":
            raise InputError(f"the stuck rates are fitted on --objects training runs only, got a run on "
                             f"{str(report.get('objects'))[:40]!r}")
        budgets.add(int(report["max_primitives"]))
        for task in report["tasks"]:
            if task["planner"] == "affordplan" and task.get("steps"):
                plans.append([(step[0], float(step[1]), float(step[2]) if len(step) > 2 else 0.0)
                              + ((int(step[3]),) if len(step) > 3 else ()) for step in task["steps"]])
                reached.append(bool(task["success"]))
    if not plans:
        raise InputError("no affordplan plans with steps in these runs")
    if len(budgets) != 1:
        raise InputError(f"the runs used different execution budgets: {sorted(budgets)}")
    return plans, reached, budgets.pop()


def fit_stuck(reports: Sequence[dict], held_out: Sequence[dict] = (), grid_step: float = 0.1, seed: int = 0) -> dict:
    """Fit :data:`planner.odds.STUCK_RATES` and :data:`planner.odds.TIP_FATAL` to the affordplan plans of saved
    bench runs (``BenchReport.as_dict``, as ``affordplan bench plan --objects training --json`` prints it): the
    values whose first-plan ``p_success`` (:func:`planner.odds.mc_odds` through the shipped outcome models, the runs'
    execution budget) has the least Brier score against whether the goal was reached (:func:`planner.odds.fit_odds`).
    ``held_out``: other runs, on any objects (scored, never fitted on), scored with the fitted values and with
    neither stuck steps nor tips.

    Returns ``dict(rates, tip_fatal, plans, reached, brier, brier_without)``, with ``held_out=dict(plans, reached,
    brier, brier_without)`` when given.

    Raises:
        InputError: a run on objects other than the training ones (held-out objects are never fitted on), or no
            affordplan plans with their steps.
    """
    from planner.odds import fit_odds, mc_odds
    from primitives.outcome_model import OutcomeModel

    plans, reached, budget = _training_plans(reports)
    models = {name: OutcomeModel.load(name) for name in SKILLS}
    grid = np.round(np.arange(0.0, 1.0 + 1e-9, grid_step), 6)
    rates, fatal, brier, without = fit_odds(plans, reached, models, budget=budget, grid=grid, fatal_grid=grid,
                                            seed=seed)
    fit = dict(rates=rates, tip_fatal=fatal, plans=len(plans), reached=float(np.mean(reached)), brier=brier,
               brier_without=without)
    if held_out:
        plans, reached, budget = _training_plans(held_out, training=False)
        y = np.asarray(reached, dtype=float)
        scores = [float(np.mean((np.array([mc_odds(steps, models, budget, seed=seed, stuck_rate=r,
                                                   tip_fatal=f).p_success for steps in plans]) - y) ** 2))
                  for r, f in ((rates, fatal), (0.0, 0.0))]
        fit["held_out"] = dict(plans=len(plans), reached=float(y.mean()), brier=scores[0], brier_without=scores[1])
    return fit


def pool(reports: Sequence[dict]) -> BenchReport:
    """One :class:`BenchReport` of the tasks of several saved runs (``BenchReport.as_dict``, as ``affordplan bench
    plan --json`` prints it), e.g. the eight seeds of the plan bench, so that its summary (success, primitives,
    planning times, plan-level calibration) is over all of their tasks.

    Raises:
        InputError: no runs, a run that is not a saved plan bench, runs that differ in their execution budget,
            objects or draw (their tasks would not be one bench), or two runs of one seed by the same planner (runs
            of one seed by different planners, e.g. ``--planner greedy`` beside affordplan, pool side by side).
    """
    if not reports:
        raise InputError("no bench runs to pool")
    known = set(TaskResult.__dataclass_fields__)
    kinds, seeds = set(), []
    results = []
    for i, report in enumerate(reports):
        try:
            kinds.add((int(report["max_primitives"]), str(report["objects"]), int(report.get("draw", 0))))
            if report.get("seed") is not None:  # runs saved before 0.24 carry no seed
                seeds += [(name, int(report["seed"])) for name in sorted({t["planner"] for t in report["tasks"]})]
            for task in report["tasks"]:
                task = {k: v for k, v in task.items() if k in known}
                task["steps"] = [tuple(step) for step in task.get("steps", [])]
                results.append(TaskResult(**task))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"run {i + 1} is not a saved `affordplan bench plan --json` run ({exc!r:.80})") from None
    if len(kinds) != 1:
        raise InputError("the runs differ in budget, objects or draw: "
                         + "; ".join(f"budget {b}, objects {o}, draw {d}" for b, o, d in sorted(kinds)))
    twice = sorted({s for s in seeds if seeds.count(s) > 1})
    if twice:
        raise InputError("runs of the same seed and planner given twice: "
                         + ", ".join(f"seed {seed} ({name})" for name, seed in twice))
    (budget, objects, draw), = kinds
    return BenchReport(results=results, draw=draw, objects=objects, max_primitives=budget)


def plot_report(report: BenchReport, path: str | os.PathLike) -> None:
    """A picture of a bench report: each planner's primitives per task (reached and not), and the affordplan
    plans' predicted ``p_success`` against how often they reached (plan-level calibration, 5 bins)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    summaries = {name: report.summary(name) for name in report.planners}
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    top = max([r.primitives for r in report.results] + [report.max_primitives])
    edges = np.arange(0, top + 3, 2) - 0.5
    for (name, s), colour in zip(summaries.items(), ("#2b6cd9", "#888888", "#d98c2b")):
        rs = [r for r in report.results if r.planner == name]
        ax.hist([r.primitives for r in rs if r.success], bins=edges, histtype="step", color=colour, linewidth=1.5,
                label=f"{name}: reached {s['success']:.2f}, median {s['median_primitives']:.0f}")
        ax.hist([r.primitives for r in rs if not r.success], bins=edges, histtype="step", color=colour,
                linestyle=":", label=f"{name}: not reached")
    ax.axvline(report.max_primitives, color="black", linewidth=0.8)
    ax.set_xlabel("primitives per task (the line: the budget)")
    ax.set_ylabel("tasks")
    ax.set_title(f"{len(report.results) // max(1, len(summaries))} tasks ({report.objects} objects)", fontsize=9)
    ax.legend(fontsize=7)
    cal = summaries["affordplan"]["calibration"] if "affordplan" in summaries else None
    ax2.plot([0, 1], [0, 1], color="grey", linestyle="--", label="perfect calibration")
    if cal and cal["plans"]:
        centres = [b["predicted"] for b in cal["bins"]]
        ax2.plot(centres, [b["reached"] for b in cal["bins"]], "o-", color="#2b6cd9", label="reached, per bin")
        for b in cal["bins"]:
            ax2.annotate(str(b["plans"]), (b["predicted"], b["reached"]), textcoords="offset points",
                         xytext=(4, -10), fontsize=7)
        ax2.set_title(f"affordplan plans: Brier {cal['brier']:.3f}, predicted {cal['mean_predicted']:.2f} vs "
                      f"reached {cal['reached']:.2f}", fontsize=9)
    ax2.set_xlim(0, 1)
    ax2.set_ylim(0, 1)
    ax2.set_xlabel("predicted p_success (bin mean; numbers: plans)")
    ax2.set_ylabel("share reached")
    ax2.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
