"""Closed-loop execution of plans, and the greedy baseline.

:func:`execute_plan` runs a :class:`planner.plan.Plan` in a simulator: observe the object's pose; if
the goal is reached, stop; if the pose is off the plan (more than ``XY_TOL`` / ``YAW_TOL`` from where
the next step expects it, or in another resting state), replan from the observed pose; execute the
next step's skill with its parameter (a push of several strides is one call that corrects its course between
strokes, :func:`primitives.strokes.push_to`; with ``spin_strokes`` > 1 a spin is one call of up to that many
strokes that asks for the rest of its turn between them, :func:`primitives.strokes.spin_by`); remember failures
(calls that did not move the object the way they asked: :func:`made_progress`), so that a (state, skill,
parameter) that failed twice is avoided by the next plan. It stops on success, on ``max_primitives``, or when no
plan can be found.

:func:`execute_greedy` is the reactive baseline a user would otherwise reach for (HACMan-style):
at every step, among pushes in 8 directions, spins of 30 deg either way and rolls to each state one
roll away, take the call whose predicted outcome (success model times ideal effect) gets closest to
the goal; no resting-state graph, no obstacle-aware path.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from affordplan.checks import as_whole
from affordplan.errors import AffordplanError, InputError
from affordplan.geometry import wrap_period
from affordplan.goal import Goal
from affordplan.objects.model import ObjectModel
from affordplan.sim.sensor import SENSORS
from affordplan.sim.simulator import Simulator
from planner.predict import expected_pose
from primitives import params as skill_params
from primitives.params import made_progress
from primitives.skills import Skill, skills_sensor
from primitives.strokes import MAX_STROKES, MAX_TURN, STOP_WITHIN, push_to, spin_by

if TYPE_CHECKING:  # type-only: planner.plan imports this module to execute its plans
    from planner.plan import Planner

XY_TOL = STOP_WITHIN  # metres off the plan before replanning: where a push's strokes stop short of their target
YAW_TOL = MAX_TURN  # radians off the plan before replanning
# The most a plan's push of several strides may turn the object before its strokes stop (radians). Looser than
# YAW_TOL: a push that turns the object on its way still carries it towards its target, and the replan after it
# (off the plan by more than YAW_TOL) corrects the yaw. 200 validation tasks: mean primitives of the tasks reached
# either way 10.96 -> 10.46 against 12 deg, success 0.745 -> 0.725 (docs/architecture.md, hand-tuned rules).
PUSH_MAX_TURN = math.radians(45.0)
SPIN_STROKES = 1  # strokes one spin call of a plan may make (1: one stroke per spin step)
# The clouds a skill of a plan is shown while it acts, by skill; a skill not named sees its policy's own sensor.
EXECUTION_SENSORS: Mapping[str, str] = {}


def check_sensors(sensors: Mapping[str, str] | None) -> dict[str, str]:
    """``sensors`` (skill -> sensor, :data:`EXECUTION_SENSORS` for ``None``) checked: a dict of known skills and
    sensors. Raises :class:`InputError` otherwise."""
    sensors = EXECUTION_SENSORS if sensors is None else sensors
    if not isinstance(sensors, Mapping):
        raise InputError(f"sensors must map skills to sensors, got {type(sensors).__name__}")
    for skill, sensor in sensors.items():
        if skill not in skill_params.SKILLS or sensor not in SENSORS:
            raise InputError(f"sensors maps a skill ({', '.join(skill_params.SKILLS)}) to a sensor "
                             f"({', '.join(SENSORS)}), got {skill!r:.20}: {sensor!r:.20}")
    return dict(sensors)


@dataclass
class LogEntry:
    """One primitive of an execution."""

    index: int
    skill: str
    params: dict
    success: bool
    valid: bool
    pose_before: np.ndarray = field(repr=False)
    pose_after: np.ndarray = field(repr=False)
    replanned: bool = False
    p_success: float = float("nan")
    note: str = ""
    states: tuple[int, int] | None = None  # resting states before and after
    strokes: int = 1  # fingertip strokes the call made (a push of several strides: primitives.strokes)

    def __str__(self) -> str:
        (k, v), = self.params.items()
        value = f"{math.degrees(v):+.0f} deg" if k in ("direction", "angle") else f"state {v}"
        x0, y0, x1, y1 = self.pose_before[0, 3], self.pose_before[1, 3], self.pose_after[0, 3], self.pose_after[1, 3]
        where = ""
        if self.states:
            a, b = self.states
            where = f"state {a} " if a == b else f"state {a} -> {b} "
        value += f" {self.strokes} strokes" if self.strokes > 1 else ""
        return (f"{self.index:2d}. {self.skill:4s} {k}={value:10s} ({x0:.3f}, {y0:.3f}) -> ({x1:.3f}, {y1:.3f}) "
                f"{where}{'ok ' if self.success else 'FAIL'}{' (replanned)' if self.replanned else ''}"
                f"{' ' + self.note if self.note else ''}")


@dataclass
class Execution:
    """What running a plan did.

    Attributes:
        success: the goal was reached (position, yaw, resting state within the goal's tolerances).
        final_pose: the object's last 4x4 world pose.
        n_primitives: skill calls executed (a push of several strides is one call; :attr:`strokes` counts its
            strokes).
        replans: plans made after the first (the object went off plan or a step failed).
        log: one entry per primitive.
        reason: why it stopped.
        frames: rendered frames, when asked for.
        errors: the final ``(position error m, yaw error rad, resting state right)`` against the goal
            (:meth:`affordplan.Goal.errors`; the yaw error is 0 for a goal without a yaw).
    """

    success: bool
    final_pose: np.ndarray
    n_primitives: int
    replans: int
    log: list[LogEntry]
    reason: str = ""
    planning_time: float = 0.0
    frames: list[np.ndarray] = field(default_factory=list, repr=False)
    errors: tuple[float, float, bool] | None = None
    plan_times: list[float] = field(default_factory=list)  # seconds of the first plan and of each replan

    @property
    def strokes(self) -> int:
        """Fingertip strokes over all calls (a call is one stroke, but a push of several strides may make more)."""
        return sum(e.strokes for e in self.log)

    def __str__(self) -> str:
        head = (f"execution: {'SUCCESS' if self.success else 'FAILED'} after {self.n_primitives} primitives "
                f"({self.strokes} strokes), {self.replans} replans ({self.reason})")
        if self.errors is not None:
            d, yaw, state_ok = self.errors
            head += (f"; final error {100 * d:.1f} cm, {math.degrees(yaw):.0f} deg, resting state "
                     f"{'right' if state_ok else 'WRONG'}")
        return "\n".join([head] + [f"  {e}" for e in self.log])


def _simulator(sim, obj: ObjectModel, obstacles, T_start: np.ndarray, seed: int, sensor: str = "cameras"
               ) -> Simulator:
    """``sim`` itself, or a new ``"arm"`` / ``"finger"`` simulator that shows the skills ``sensor``'s clouds (the
    sensor their weights were trained on, :func:`primitives.skills.skills_sensor`)."""
    if isinstance(sim, Simulator):
        _check_same_world(sim, obj, obstacles)
        return sim
    if sim not in ("arm", "finger"):
        raise AffordplanError(f"sim must be 'arm', 'finger' or a Simulator, got {sim!r}")
    s = Simulator(obj, obstacles=obstacles, pusher=sim, seed=seed, sensor=sensor)
    s.set_object_pose(T_start)
    return s


def _check_same_world(sim: Simulator, obj: ObjectModel, obstacles) -> None:
    """Raise :class:`InputError` unless ``sim`` holds the plan's object and obstacles: a plan executed in another
    world would label poses with the wrong resting states, or walk into a wall it never saw."""
    if sim.obj is not obj and (sim.obj.name != obj.name or len(sim.obj.mesh.vertices) != len(obj.mesh.vertices)
                               or not np.allclose(sim.obj.mesh.vertices, obj.mesh.vertices)):
        raise InputError(f"the simulator holds {sim.obj.name!r:.60}, the plan is for {obj.name!r:.60}")
    if tuple(sim.obstacles) != tuple(obstacles):
        raise InputError(f"the simulator has {len(sim.obstacles)} obstacles that differ from the plan's "
                         f"{len(tuple(obstacles))}; plan with the simulator's obstacles (ap.plan(..., obstacles=...))")


def _states(obj: ObjectModel, T_before: np.ndarray, T_after: np.ndarray | None = None) -> tuple[int, int]:
    """Resting states before and after a call (``T_after`` None: a call that did not run; classified once)."""
    before = obj.classify(T_before)
    return before, before if T_after is None else obj.classify(T_after)


def _off_plan(obj: ObjectModel, goal: Goal, T: np.ndarray, T_expected: np.ndarray) -> bool:
    """Whether ``T`` is off the expected pose (yaws compared modulo the state's symmetry, as the goal does)."""
    s, x, y, yaw = obj.planar_pose(T)
    se, xe, ye, yawe = obj.planar_pose(T_expected)
    turn = wrap_period(yaw - yawe, goal.period(obj, s))
    return s != se or math.hypot(x - xe, y - ye) > XY_TOL or abs(turn) > YAW_TOL


def _frame(sim: Simulator, render) -> np.ndarray | None:
    if not render:
        return None
    camera = render if isinstance(render, str) else "overview"
    return sim.render(camera=camera)


def _record_frame(sim: Simulator, render, frames: list[np.ndarray]) -> None:
    f = _frame(sim, render)
    if f is not None:
        frames.append(f)


def _check_on_primitive(on_primitive) -> None:
    """Refuse an ``on_primitive`` that is neither ``None`` nor callable, before anything is executed."""
    if on_primitive is not None and not callable(on_primitive):
        raise InputError(f"on_primitive must be callable or None, got {type(on_primitive).__name__}")


def _logged(log: list[LogEntry], entry: LogEntry, on_primitive: Callable[[LogEntry], None] | None) -> None:
    """Append ``entry`` to ``log`` and tell ``on_primitive`` (when given) that its primitive is done."""
    log.append(entry)
    if on_primitive is not None:
        on_primitive(entry)


# Guard faults after which the object cannot be manipulated any further: it hangs on the pusher or lies on
# an obstacle, it left the workspace, or the physics broke down.
TERMINAL_FAULTS = ("off_table", "left_workspace", "nan", "unstable")


def _terminal(out) -> str | None:
    """Why execution must stop after ``out`` (a terminal guard fault), or ``None``.

    A primitive refused before any physics (``n_steps == 0``) because a guard flags the object's resting
    pose (it settled over 6 mm into the table, say) would be refused again and again: that ends the run too.
    """
    if out.invalid_reason in TERMINAL_FAULTS:
        return f"the object can no longer be manipulated: the {out.invalid_reason!r} guard fired"
    if not out.valid and out.n_steps == 0:
        return (f"the object can no longer be manipulated: the {out.invalid_reason!r} guard flags its pose "
                f"before any motion")
    return None


def execute_plan(plan, sim="arm", max_primitives: int = 60, render=None, seed: int = 0,
                 skills: Mapping[str, Skill] | None = None, memory: Planner | None = None,
                 spin_strokes: int = SPIN_STROKES, sensors: Mapping[str, str] | None = None,
                 on_primitive: Callable[[LogEntry], None] | None = None) -> Execution:
    """Run ``plan`` closed-loop (see the module docstring).

    ``spin_strokes``: the strokes one spin step may make, re-observing between them (:func:`primitives.strokes.spin_by`
    for the step's angle); 1, one stroke. ``sensors``: the clouds each named skill is shown while it acts
    (:meth:`affordplan.sim.simulator.Simulator.seeing`; default :data:`EXECUTION_SENSORS`); the others see the
    simulator's.

    ``skills``: the skills that act (default: the ones the plan was rated with). ``memory``: the planner that replans
    and remembers failures (default: a fork of the plan's planner, :meth:`planner.plan.Planner.fork`), so the plan
    and its planner are left as they were; pass one planner to several executions to let them share what failed.
    ``on_primitive``: called with each primitive's :class:`LogEntry` as soon as the primitive is done (a progress
    bar, a frame after each primitive; a push of several strides is one primitive).
    """
    spin_strokes = as_whole("spin_strokes", spin_strokes, 1, MAX_STROKES)
    sensors = check_sensors(sensors)
    _check_on_primitive(on_primitive)
    planner, goal = memory if memory is not None else plan.planner.fork(), plan.goal
    skills = skills if skills is not None else planner.predictor.skills
    obj = planner.obj
    sim = _simulator(sim, obj, planner.obstacles, plan.start_pose, seed, skills_sensor(skills))
    steps, k = list(plan.steps), 0
    log: list[LogEntry] = []
    frames: list[np.ndarray] = []
    _record_frame(sim, render, frames)
    replans, planning_time, reason = 0, plan.planning_time, "max_primitives reached"
    plan_times = [plan.planning_time]
    for n in range(max_primitives + 1):
        T = sim.object_pose()
        if goal.reached(obj, T):
            reason = "goal reached"
            break
        if n == max_primitives:
            break
        replanned = False
        if k >= len(steps) or _off_plan(obj, goal, T, steps[k].start_pose):
            try:
                new = planner.plan(T, goal)
            except AffordplanError as exc:  # PlanningError, GoalError, ...
                reason = f"no plan from the observed pose: {exc}"
                break
            steps, k, replanned = list(new.steps), 0, True
            replans += 1
            planning_time += new.planning_time
            plan_times.append(new.planning_time)
            if not steps:
                reason = "planner has nothing left to do but the goal is not reached"
                break
        step = steps[k]
        skill = skills[step.skill]
        strokes, note = 1, ""
        try:
            with sim.seeing(sensors.get(step.skill, sim.sensor)):
                if step.skill == "push" and step.strides > 1:
                    made = push_to(skill, sim, tuple(step.expected_pose[:2, 3]), step.strides,
                                   step.params["direction"], PUSH_MAX_TURN)
                    out, strokes, note = made.outcome, made.strokes, f"(strokes: {made.stopped})"
                elif step.skill == "spin" and spin_strokes > 1:
                    made = spin_by(skill, sim, step.params["angle"], spin_strokes)
                    out, strokes, note = made.outcome, made.strokes, f"(strokes: {made.stopped})"
                else:  # a spin's full motion: plans spent more primitives with spins that stop at the angle;
                    # a straight push: steered ones reached 36 of 50 validation tasks against 37 (seed 0)
                    out = skill.execute(sim, step.params, stop_at_angle=False, steer=False)
        except AffordplanError as exc:  # e.g. a roll target not one roll away from the observed state
            planner.record_failure(step.skill, step.params, T)
            _logged(log, LogEntry(n, step.skill, step.params, False, False, T, T, replanned, step.p_success,
                                  str(exc), _states(obj, T)), on_primitive)
            k = len(steps)
            continue
        if not made_progress(obj, step.skill, step.params, out.pose_before, out.pose_after):
            planner.record_failure(step.skill, step.params, T)
        _logged(log, LogEntry(n, step.skill, step.params, bool(out.success), out.valid, out.pose_before,
                              out.pose_after, replanned, step.p_success, note,
                              _states(obj, out.pose_before, out.pose_after), strokes=strokes), on_primitive)
        _record_frame(sim, render, frames)
        if (stop := _terminal(out)) is not None:
            reason = stop
            break
        k += 1
    T = sim.object_pose()
    return Execution(goal.reached(obj, T), T, len(log), replans, log, reason, planning_time, frames,
                     goal.errors(obj, T), plan_times)


# ------------------------------------------------------------------------------- greedy
def _goal_distance(obj: ObjectModel, goal: Goal, T: np.ndarray) -> float:
    d, yaw_err, state_ok = goal.errors(obj, T)
    return d / goal.xy_tol + yaw_err / goal.yaw_tol + (0.0 if state_ok else 3.0)


def greedy_calls(obj: ObjectModel, state: int) -> list[tuple[str, dict]]:
    calls = [("push", {"direction": a}) for a in np.linspace(-math.pi, math.pi, 8, endpoint=False)]
    calls += [("spin", {"angle": math.radians(30.0)}), ("spin", {"angle": -math.radians(30.0)})]
    calls += [("roll", {"target": t}) for t in skill_params.roll_targets(obj, state)]
    return calls


def execute_greedy(obj: ObjectModel, goal: Goal, T_start: np.ndarray, predictor, sim="arm", obstacles=(),
                   max_primitives: int = 60, render=None, seed: int = 0,
                   on_primitive: Callable[[LogEntry], None] | None = None) -> Execution:
    """The greedy baseline (see the module docstring); ``on_primitive`` as for :func:`execute_plan`."""
    _check_on_primitive(on_primitive)
    sim = _simulator(sim, obj, obstacles, T_start, seed, skills_sensor(predictor.skills))
    log: list[LogEntry] = []
    frames: list[np.ndarray] = []
    _record_frame(sim, render, frames)
    reason, planning_time = "max_primitives reached", 0.0
    for n in range(max_primitives + 1):
        T = sim.object_pose()
        if goal.reached(obj, T):
            reason = "goal reached"
            break
        if n == max_primitives:
            break
        t0 = time.perf_counter()
        state = obj.classify(T)
        calls = greedy_calls(obj, state)
        p = predictor.p_success_many([(s, prm, T) for s, prm in calls])
        now = _goal_distance(obj, goal, T)
        scores = [pi * _goal_distance(obj, goal, expected_pose(obj, s, prm, T)) + (1 - pi) * now
                  for (s, prm), pi in zip(calls, p)]
        best = int(np.argmin(scores))
        planning_time += time.perf_counter() - t0
        skill_name, prm = calls[best]
        try:
            out = predictor.skills[skill_name].execute(sim, prm, stop_at_angle=False, steer=False)
        except AffordplanError as exc:  # e.g. ReachabilityError: the arm cannot reach the chosen contact
            _logged(log, LogEntry(n, skill_name, prm, False, False, T, T, False, float(p[best]), str(exc),
                                  _states(obj, T)), on_primitive)
            continue
        _logged(log, LogEntry(n, skill_name, prm, bool(out.success), out.valid, out.pose_before, out.pose_after,
                              False, float(p[best]), states=_states(obj, out.pose_before, out.pose_after)),
                on_primitive)
        _record_frame(sim, render, frames)
        if (stop := _terminal(out)) is not None:
            reason = stop
            break
    T = sim.object_pose()
    return Execution(goal.reached(obj, T), T, len(log), 0, log, reason, planning_time, frames, goal.errors(obj, T))
