"""Long-horizon plans: face changes on the resting-state graph, SE(2) paths around obstacles, skill calls.

:class:`Planner` builds a :class:`Plan` from a start pose to a :class:`affordplan.goal.Goal`:

1. **Route.** The likeliest chain of rolls from the start's resting state to the goal's
   (:class:`planner.graph.RestingStateGraph`, edges ``-log P(roll)`` from the roll skill's success model).
2. **Roll spots.** Each roll happens where it has room: a disc covering the object before and after the
   roll, grown by ``roll_margin`` (the displacement a roll causes), clear of obstacles: the nearest such place
   to the object (travel after rolling) or to the goal (travel before rolling, in the states the pushes are
   rated likelier in). Each placement is planned and the likeliest plan kept.
3. **Paths.** Between rolls, and from the last one to the goal, OMPL plans the footprint's SE(2) path
   (:mod:`planner.motion`); the footprint of each resting state is inflated by ``clearance`` (the room
   the fingertip needs beside the object).
4. **Calls.** Paths become pushes and spins (:mod:`planner.chain`); each step carries its expected
   pose and its predicted success (:class:`planner.predict.Predictor`); ``Plan.p_success`` is their product.

Failures reported back (:meth:`Planner.record_failure`) down-weight what failed: a roll edge in the
graph, or a push direction (relative to the object) / spin sense in a resting state, which the next
plan then avoids (a push is split into two pushes 35 deg to either side); a place where rolls failed
twice is not rolled at again (the object is pushed to the nearest other room first). A push whose
fingertip would come down on an obstacle is split the same way from the start.

The arm reaches so far (``reach``, from its base at the world origin): footprints stay where the fingertip
can get all round them. (Until 0.24 spins were also moved to where half the object's radius of drift still left
it within reach; on the plan bench's 400 tasks that bought nothing, docs/architecture.md.)
"""

from __future__ import annotations

import copy
import math
import time
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

import numpy as np

from affordplan.checks import as_whole
from affordplan.errors import GoalError, PlanningError
from affordplan.geometry import wrap_angle
from affordplan.goal import Goal
from affordplan.objects.model import ObjectModel
from affordplan.robot import FINGERTIP_REACH, TIP_RADIUS, Protocol
from affordplan.world import Box, Workspace
from planner import chain
from planner.footprint import footprint, inflate, place
from planner.graph import RestingStateGraph
from planner.memory import FAILURES_TO_AVOID, FailureMemory
from planner.motion import FootprintChecker, plan_path
from planner.odds import DEFAULT_BUDGET, Odds, mc_odds, plan_odds
from planner.places import Places, disc
from planner.predict import Predictor, expected_pose, state_pose
from planner.ratings import StateRatings
from primitives.params import PARAMS_TYPES, SkillName, SkillParams, as_params

if TYPE_CHECKING:  # planner.execute imports this module's Planner; Plan.execute imports it when called
    from affordplan.sim.simulator import Simulator
    from planner.execute import Execution, LogEntry

SPLIT_ANGLE = math.radians(35.0)
# Turns tried, in order, on each side of a push that failed twice (the first is SPLIT_ANGLE): each detour
# push must itself not have failed twice, or the plan would repeat a failure under another name.
DETOUR_ANGLES = (SPLIT_ANGLE,) + tuple(math.radians(a) for a in (60.0, 85.0))  # never backwards
CLEARANCE = 0.02  # metres the footprints are grown by (room for the fingertip beside the object)
WORKSPACE_OVERHANG = 0.05  # metres the footprint may reach past the workspace edge
SAME_POSE = 1e-9  # metres or radians within which two path ends are the same (_path)
# Metres from the arm's base (the world origin) that an inflated footprint must stay within, so that the
# fingertip can get behind the object from every side: its pre-contact point lies about 2.5 cm beyond the
# inflated footprint (4 cm standoff and the 0.8 cm tip, less the 2 cm clearance, on a flat side; less on a
# corner) and must be within FINGERTIP_REACH. Without it, a die spun or pushed 7 cm past its goal at
# x = 0.68 m could no longer be pushed back: every contact on its far side was out of reach.
ARM_REACH = FINGERTIP_REACH - 0.025  # 0.79 m
# Radius (metres) of the disc kept clear of obstacles where the fingertip comes down behind an object to push
# it (Planner.push_blocked): the tip's, plus a margin.
FINGER_ROOM = TIP_RADIUS + 0.006
# A straight run of pushes is made as pushes of up to MAX_STRIDES 5 cm strides each, one call apiece that corrects
# its course between strokes (merge_strides, primitives.strokes); pushes whose directions differ by no more than
# MERGE_ANGLE count as one run.
MAX_STRIDES = 4
MERGE_ANGLE = math.radians(3.0)


@dataclass
class Step:
    """One skill call of a plan.

    Attributes:
        skill: ``"push"``, ``"roll"`` or ``"spin"``.
        params: its parameter as a dict, ``{"direction": rad}`` ... (see :mod:`primitives.params`); given as a typed
            value (:class:`~primitives.params.PushParams` ...), its dict is kept; :attr:`typed_params` reads it typed.
        start_pose, expected_pose: 4x4 world poses before and (ideally) after.
        p_success: the skill's predicted success at ``start_pose`` (of one stroke, for a push of several strides).
        strides: a push's 5 cm strides (``PUSH_STEP``) along its direction, made as one call that corrects its
            course between strokes (:func:`primitives.strokes.push_to`, to ``expected_pose``); 1 for every other
            call, and for a push of one stride, which is one stroke.
    """

    skill: SkillName
    params: dict[str, float]
    start_pose: np.ndarray = field(repr=False)
    expected_pose: np.ndarray = field(repr=False)
    p_success: float = float("nan")
    strides: int = 1

    def __init__(self, skill: SkillName, params: SkillParams | Mapping[str, float], start_pose: np.ndarray,
                 expected_pose: np.ndarray, p_success: float = float("nan"), strides: int = 1) -> None:
        self.skill = skill
        self.params = as_params(skill, params)
        self.start_pose = start_pose
        self.expected_pose = expected_pose
        self.p_success = p_success
        self.strides = int(strides)

    @property
    def typed_params(self) -> SkillParams:
        """:attr:`params` as the skill's typed value (:class:`~primitives.params.PushParams` ...)."""
        return PARAMS_TYPES[self.skill].from_dict(self.params)

    def __str__(self) -> str:
        (k, v), = self.params.items()
        value = f"{math.degrees(v):+.0f} deg" if k in ("direction", "angle") else f"state {v}"
        x, y = self.expected_pose[0, 3], self.expected_pose[1, 3]
        times = f" x{self.strides}" if self.strides > 1 else ""
        return f"{self.skill:4s} {k}={value:10s}{times} -> ({x:.3f}, {y:.3f})  P={self.p_success:.2f}"


def merge_strides(steps: Sequence[Step], max_strides: int) -> list[Step]:
    """``steps`` with each run of consecutive pushes along one direction (each within ``MERGE_ANGLE`` of the heading
    of the run merged so far) made into pushes of up to ``max_strides`` strides: one call each, executed with course
    corrections between its strokes (:func:`primitives.strokes.push_to`). A merged push starts where its run starts, is
    expected where it ends, heads from the one to the other, and is rated by the mean of its strides' ratings (one
    stroke's). ``max_strides`` 1 leaves the steps as they are."""
    out: list[Step] = []
    for s in steps:
        last = out[-1] if out else None
        if (last is not None and s.skill == "push" and last.skill == "push" and last.strides < max_strides
                and abs(float(wrap_angle(s.params["direction"] - last.params["direction"]))) <= MERGE_ANGLE):
            dx, dy = s.expected_pose[:2, 3] - last.start_pose[:2, 3]
            n = last.strides + s.strides
            p = (last.p_success * last.strides + s.p_success * s.strides) / n
            heading = math.atan2(dy, dx) if math.hypot(dx, dy) > 1e-9 else last.params["direction"]
            out[-1] = Step("push", {"direction": heading}, last.start_pose, s.expected_pose, p, n)
        else:
            out.append(s)
    return out


def inflated_footprints(obj: ObjectModel, clearance: float) -> dict[int, np.ndarray]:
    """Each resting state's footprint grown by ``clearance`` metres (room for the fingertip)."""
    return {s.index: inflate(footprint(obj, s.index), clearance) for s in obj.resting_states}


def make_checkers(footprints: dict[int, np.ndarray], obstacles: Sequence[Box],
                  workspace: Workspace, reach: float | None = None) -> dict[int, FootprintChecker]:
    """One checker per resting state. The object's centre stays in the workspace (the bounds of the SE(2)
    space the paths are planned in); its (inflated) footprint may overhang it by
    ``WORKSPACE_OVERHANG``, and must stay within ``reach`` metres of the arm's base when that is given."""
    m = WORKSPACE_OVERHANG
    grown = Workspace((workspace.x[0] - m, workspace.x[1] + m), (workspace.y[0] - m, workspace.y[1] + m))
    return {i: FootprintChecker(fp, obstacles, grown, reach) for i, fp in footprints.items()}


class Planner:
    """Plans for one object among fixed obstacles.

    Args:
        obj: the object.
        obstacles: boxes on the table.
        workspace: where the object may go.
        predictor: skills and success models (the shipped ones by default).
        time_limit: seconds for one :meth:`plan` call (OMPL gets what is left).
        seed: seeds OMPL and the predictor.
        clearance: metres the footprint is grown by (room for the fingertip beside the object).
        max_strides: strides of 5 cm one push call may make (:func:`merge_strides`); 1: every push one stroke.
        roll_margin: metres around a roll spot kept clear for the displacement a roll causes.
        reach: metres from the arm's base (the world origin) that the inflated footprints stay within; ``None``: no
            arm to reach.
    """

    def __init__(self, obj: ObjectModel, obstacles: Sequence[Box] = (), workspace: Workspace = Workspace(),
                 predictor: Predictor | None = None, time_limit: float = 5.0, seed: int = 0,
                 clearance: float = CLEARANCE, roll_margin: float = 0.04, reach: float | None = ARM_REACH,
                 max_strides: int = MAX_STRIDES):
        self.obj = obj
        self.obstacles = tuple(obstacles)
        self.workspace = workspace
        self.predictor = predictor or Predictor(obj, seed=seed, obstacles=tuple(obstacles))
        self.time_limit = float(time_limit)
        self.seed = int(seed)
        self.clearance = clearance
        self.roll_margin = roll_margin
        self.memory = FailureMemory(obj)  # failed calls and roll spots (planner.memory)
        self.reach = reach
        self.max_strides = as_whole("max_strides", max_strides, 1, 100)
        self.footprints = inflated_footprints(obj, clearance)
        self._shadows = {s.index: footprint(obj, s.index) for s in obj.resting_states}  # not inflated
        self._finger = FootprintChecker(disc(FINGER_ROOM, 8), self.obstacles, Workspace((-2.0, 2.0), (-2.0, 2.0)))
        self._standoff = Protocol().standoff
        self.checkers = make_checkers(self.footprints, self.obstacles, workspace, reach)
        self.radius = {i: float(np.max(np.linalg.norm(fp, axis=1))) for i, fp in self.footprints.items()}
        self.places = Places(obj, self.checkers, workspace, self.obstacles, self.radius, clearance, roll_margin, reach)
        self.ratings = StateRatings(obj, self.predictor, workspace.center)  # rolls and spins per state
        self.graph = RestingStateGraph(obj, rate_edges=self.ratings.rolls)
        self.budget = DEFAULT_BUDGET  # primitives a plan's odds are rated within (planner.odds)
        self._calls = 0
        self._paths: dict[tuple, np.ndarray] = {}  # this plan call's solved paths (_path)

    def fork(self) -> Planner:
        """A planner with this one's geometry, success queries and caches and a copy of its failure memory (the
        failures, the failed roll spots, the roll graph's penalties): what an execution learns from its failures
        stays in the fork, so running a plan never changes the plan's own planner."""
        other = copy.copy(self)
        other.memory = self.memory.copy()
        other.graph = copy.copy(self.graph)
        other.graph.graph = self.graph.graph.copy()
        return other

    def odds(self, steps: Sequence[Step], budget: int) -> Odds:
        """The odds of ``steps`` within ``budget`` primitives under closed-loop execution: by Monte Carlo through the
        skills' outcome models where the predictor has them (:func:`planner.odds.mc_odds`, seeded by the planner's
        seed; each step with its tip probability, :meth:`odds_steps`), else each step retried with its strict
        probability (:func:`planner.odds.plan_odds`)."""
        outcomes = getattr(self.predictor, "outcomes", None)
        if outcomes and all(s.skill in outcomes for s in steps):
            return mc_odds(self.odds_steps(steps), outcomes, budget, seed=self.seed)
        return plan_odds([s.p_success for s in steps], budget)

    def odds_steps(self, steps: Sequence[Step]) -> list[tuple]:
        """Each step as :func:`planner.odds.mc_odds` reads it: ``(skill, strict p, tip)``, ``tip`` the probability
        that one try leaves the object in another resting state, from the skill's outcome model and the drop
        probability of the state the step starts in (:meth:`primitives.outcome_model.OutcomeModel.p_tip`; 0 without
        outcome models); a push of several strides as ``(skill, strict p, tip, strides)``."""
        outcomes = getattr(self.predictor, "outcomes", None) or {}
        out = []
        for s in steps:
            model, tip = outcomes.get(s.skill), 0.0
            if model is not None and getattr(model, "knows_tips", False):
                tip = model.p_tip(self.obj.resting_states[self.obj.classify(s.start_pose)].probability)
            out.append((s.skill, float(s.p_success), float(tip)) + ((s.strides,) if s.strides > 1 else ()))
        return out

    # ------------------------------------------------------------------ queries
    def record_failure(self, skill: str, params: dict, T_world_object: np.ndarray) -> int:
        """Remember a failed call; returns how often that (state, skill, parameter) has failed."""
        count = self.memory.record(skill, params, T_world_object)
        if skill == "roll" and count >= FAILURES_TO_AVOID:
            self.graph.penalise(self.obj.planar_pose(T_world_object)[0], params["target"])
        return count

    @property
    def failures(self) -> Counter:
        """The failed calls, by :func:`planner.memory.failure_key` (``self.memory.failures``)."""
        return self.memory.failures

    @property
    def failed_roll_spots(self) -> list[tuple[float, float]]:
        """(x, y) of every failed roll, metres (``self.memory.roll_spots``)."""
        return self.memory.roll_spots

    def _avoided(self, skill: str, params: dict, T: np.ndarray) -> bool:
        """Whether the plan goes round this call: it failed twice, or (a push) the fingertip has no way in."""
        if skill == "push" and self.push_blocked(T, params["direction"]):
            return True
        return self.memory.avoided(skill, params, T)

    def push_blocked(self, T_world_object: np.ndarray, direction: float) -> bool:
        """Whether an obstacle stands where the fingertip must come down to push the object (at its settled
        pose ``T_world_object``) along ``direction`` (radians, world): behind the object, on the line through
        its centre, at the skill's standoff and half-way in (a disc of ``FINGER_ROOM``).

        The footprint's 2 cm clearance keeps paths off obstacles but not always room for the finger on the
        side a push needs: a die squeezed past a block, pushed away from it, was pushed at nothing and did not
        move, twice per direction, before the failure memory sent the plan round.
        """
        if not self.obstacles:
            return False
        state, x, y, yaw = self.obj.planar_pose(T_world_object)
        d = np.array([math.cos(direction), math.sin(direction)])
        shadow = place(self._shadows[state], x, y, yaw)
        back = float(np.max((shadow - (x, y)) @ -d))  # how far the object reaches behind its centre
        for gap in (0.5 * self._standoff, self._standoff):
            px, py = np.array([x, y]) - (back + TIP_RADIUS + gap) * d
            if not self._finger.is_free(float(px), float(py), 0.0):
                return True
        return False

    def check_goal(self, goal: Goal, start_state: int) -> int:
        """The goal's resting state; raises :class:`GoalError` for goals that cannot be met: no free placement
        of the object anywhere in the goal's region (:meth:`aim`)."""
        return self._checked_aim(goal, start_state)[0]

    def _checked_aim(self, goal: Goal, start_state: int) -> tuple[int, Goal]:
        """The goal's resting state and :meth:`aim` in it; raises :class:`GoalError` (see :meth:`check_goal`)."""
        goal.check_object(self.obj)
        state = start_state if goal.resting_state is None else goal.resting_state
        if not self.workspace.contains(goal.xy):
            raise GoalError(f"goal xy={goal.xy} is outside the workspace {self.workspace}")
        return state, self.places.aim(goal, state)

    # --------------------------------------------------------------------- plan
    def plan(self, T_start: np.ndarray, goal: Goal) -> Plan:
        """A plan from the settled pose ``T_start`` to ``goal``; raises PlanningError / GoalError.

        Where the route rolls, the placements of its rolls are planned and the likeliest plan kept
        (:meth:`_placements`): rolling where the object is and travelling in the later states, or travelling
        first and rolling near the goal (rated with one more push in the goal's state, for the shift a roll
        causes).
        """
        t0 = time.perf_counter()
        deadline = t0 + self.time_limit
        self._paths = {}
        asked = goal
        state, x, y, yaw = self.obj.planar_pose(T_start)
        goal_state, goal = self._checked_aim(goal, state)  # the free part of the goal's region
        turn = not goal.yaw_free(self.obj, goal_state)  # whether the goal's yaw asks for anything
        route = self.graph.route(state, goal_state)
        best, error = None, None
        for late_from in self._placements(route):
            try:
                calls, paths = self._route_calls(route, (x, y, yaw), goal, goal_state, turn, deadline, late_from)
            except PlanningError as exc:  # no room or no path this way: another placement may have one
                error = error or exc
                continue
            steps = self._steps(state, (x, y, yaw), calls)
            p = float(np.prod([s.p_success for s in steps])) if steps else 1.0
            rolled_late = late_from < len(route) - 1
            score = p * self._settle_push_probability(goal_state, goal, calls[-1][3]) if rolled_late else p
            if best is None or score > best[0]:
                best = (score, steps, p, paths)
        if best is None:
            raise error
        _, steps, p, paths = best
        steps = merge_strides(steps, self.max_strides)
        self._calls += 1
        odds = self.odds(steps, self.budget)
        return Plan(steps=steps, p_success=odds.p_success, planning_time=time.perf_counter() - t0, route=route,
                    paths=paths, expected_primitives=odds.expected_primitives, p_steps=p,
                    goal=asked, start_pose=np.array(T_start), planner=self, aim=goal)

    def _route_calls(self, route: list[int], start: tuple[float, float, float], goal: Goal, goal_state: int,
                     turn: bool, deadline: float, late_from: int) -> tuple[list, list[tuple[int, np.ndarray]]]:
        """The calls (``(state, skill, params, pose after)``) and paths that take the object from ``start``
        (x, y, yaw) along ``route`` to ``goal``; its rolls ``late_from`` on are made near the goal, those before
        where the object is."""
        calls: list[tuple[int, str, dict, tuple[float, float, float]]] = []
        paths: list[tuple[int, np.ndarray]] = []
        cur = start
        for k, (a, b) in enumerate(zip(route, route[1:])):
            spot = self.places.roll_spot(a, b, cur, goal, late=k >= late_from, spoiled=self.memory.spoiled)
            spot_yaw = self.places.free_yaw(a, spot, cur[2])
            segment_paths, segment = self._segment(a, cur, (*spot, spot_yaw), deadline)
            paths += [(a, path) for path in segment_paths]
            calls += [(a, *c) for c in segment]
            if segment:
                cur = segment[-1][2]
            T_before = state_pose(self.obj, a, *cur)
            T_after = expected_pose(self.obj, "roll", {"target": b}, T_before)
            _, ax, ay, ayaw = self.obj.planar_pose(T_after)
            calls.append((a, "roll", {"target": b}, (ax, ay, ayaw)))
            cur = (ax, ay, ayaw)
        # a roll near the goal that leaves the object within half the goal's tolerance is not followed by a
        # stride to the goal's centre (two short pushes in a V, each likelier to overshoot than to help)
        late = late_from < len(route) - 1
        end = cur[:2] if late and math.dist(cur[:2], goal.xy) <= 0.5 * goal.xy_tol else goal.xy
        goal_yaw = (goal.yaw_near(self.obj, goal_state, cur[2]) if turn
                    else self.places.free_yaw(goal_state, end, cur[2]))
        segment_paths, segment = self._segment(goal_state, cur, (*end, goal_yaw), deadline,
                                               goal_yaw if turn else None)
        paths += [(goal_state, path) for path in segment_paths]
        calls += [(goal_state, *c) for c in segment]
        return calls, paths

    @staticmethod
    def _placements(route: list[int]) -> list[int]:
        """Roll placements to plan for ``route``, as ``late_from``: its rolls from that index on are made near the
        goal, the earlier ones where the object is. Every placement of up to two rolls (travel before, between
        or after them), else all here or all near the goal; all here first, so that it wins ties."""
        n = len(route) - 1
        return list(range(n, -1, -1)) if n <= 2 else [n, 0]

    def _settle_push_probability(self, state: int, goal: Goal, at: tuple[float, float, float]) -> float:
        """Predicted success of a push in ``state`` at the goal (yaw of ``at``), the mean over 8 directions: what
        a plan that rolls near the goal is rated with, for the push that puts right the shift the roll causes."""
        T = state_pose(self.obj, state, goal.xy[0], goal.xy[1], at[2])
        pushes = [("push", {"direction": float(a)}, T) for a in np.linspace(-math.pi, math.pi, 8, endpoint=False)]
        return float(np.mean(self.predictor.p_success_many(pushes)))

    def _segment(self, state: int, start, end, deadline: float,
                 final_yaw: float | None = None) -> tuple[list[np.ndarray], list[chain.Call]]:
        """Paths and calls from ``start`` to ``end`` (x, y, yaw) in resting state ``state``; spins to
        ``final_yaw`` at the end when given.

        Where the start is not free (the object was pushed into a tight spot, or a roll is expected to leave it
        there), it is first pushed to the nearest free place (:meth:`Places.nearest_free`).
        """
        def calls_for(path: np.ndarray, yaw: float | None) -> list[chain.Call]:
            return chain.path_to_calls(path, yaw, is_free=self.checkers[state].is_free,
                                       spin_rate=self.ratings.spin_rate(state))

        out: list[chain.Call] = []
        if not self.checkers[state].is_free(*start):
            free = self.places.nearest_free(state, start, end, avoided=self._avoided)
            out.append(("push", {"direction": math.atan2(free[1] - start[1], free[0] - start[0])}, (*free, start[2])))
            start = (*free, start[2])
        path = self._path(state, start, end, deadline)
        return [path], out + calls_for(path, final_yaw)

    def _steps(self, state: int, start: tuple[float, float, float], calls) -> list[Step]:
        steps: list[Step] = []
        T = state_pose(self.obj, state, *start)
        for call_state, skill, params, after in calls:
            if skill == "push" and self._avoided(skill, params, T):  # go round a failing or blocked direction
                for direction in self._detour(params["direction"], T):
                    p = {"direction": direction}
                    T_next = expected_pose(self.obj, "push", p, T)
                    steps.append(Step("push", p, T, T_next))
                    T = T_next
                continue
            new_state = params["target"] if skill == "roll" else call_state
            T_next = state_pose(self.obj, new_state, *after)
            steps.append(Step(skill, params, T, T_next))
            if skill == "spin":  # rated by the state's spin row, as its split was (StateRatings.spin_rate)
                steps[-1].p_success = self.ratings.spin_rate(call_state)(params["angle"])
            T = T_next
        asked = [s for s in steps if s.skill != "spin"]
        if asked:
            ps = self.predictor.p_success_many([(s.skill, s.params, s.start_pose) for s in asked])
            for s, p in zip(asked, ps):
                s.p_success = float(p)
        return steps

    def _detour(self, direction: float, T: np.ndarray) -> list[float]:
        """Pushes that stand in for a push along ``direction`` (radians) from pose ``T`` that is avoided: it
        failed twice, or the fingertip has no way in (:meth:`push_blocked`).

        One push on each side of it, turned by the smallest of :data:`DETOUR_ANGLES` whose own direction is not
        avoided and whose push, from ``T``, would leave the object where it may be (its footprint checker:
        clear of obstacles, within reach); the pair's sum still heads the same way when both turns are equal.
        A side where no turn qualifies is left out; when both are, the best of all turns (unblocked, not failed
        twice, landing free, least failed) is tried: a cylinder beside a block was otherwise pushed 36 times the
        one way that landed free, and never moved.
        """
        state = self.obj.classify(T)

        def lands_free(d: float) -> bool:
            _, x, y, yaw = self.obj.planar_pose(expected_pose(self.obj, "push", {"direction": d}, T))
            return self.checkers[state].is_free(x, y, yaw)

        pushes = []
        for sign in (1.0, -1.0):
            for turn in DETOUR_ANGLES:
                d = float(wrap_angle(direction + sign * turn))
                if not self._avoided("push", {"direction": d}, T) and lands_free(d):
                    pushes.append(d)
                    break
        if pushes:
            return pushes
        turns = [float(wrap_angle(direction + sign * t)) for t in DETOUR_ANGLES for sign in (1.0, -1.0)]
        def rank(d: float) -> tuple:  # blocked, failed twice, landing in the way, failures: what _avoided weighs
            failed = self.memory.count("push", {"direction": d}, T)
            return self.push_blocked(T, d), failed >= FAILURES_TO_AVOID, not lands_free(d), failed

        return [min(turns, key=rank)]

    def _path(self, state: int, start, goal, deadline: float) -> np.ndarray:
        """SE(2) path in resting state ``state`` from ``start`` to ``goal`` (x, y, yaw; :func:`plan_path`).

        A plan call asks the same path once per roll placement that shares a segment (a route with two rolls in
        place asks its last segment three times, its ends computed along different ways that agree to ~1e-16): the
        path solved first in this call for ends within :data:`SAME_POSE` of these is returned again, its ends set
        to these. OMPL is seeded alike throughout a call, so that path is the one solving again would give.
        """
        key = (state, *(round(float(v) / SAME_POSE) for v in (*start, *goal)))
        if key in self._paths:
            path = self._paths[key].copy()
            path[0, :2], path[-1, :2] = start[:2], goal[:2]
            return path
        left = deadline - time.perf_counter()
        if left <= 0:
            raise PlanningError(f"planning ran out of its {self.time_limit:.1f} s before reaching the goal")
        path = plan_path(self.checkers[state], tuple(start), tuple(goal), time_limit=min(left, 1.0),
                         seed=self.seed + self._calls, attempts=2, turn_first=self._turn_first(state, start, goal))
        self._paths[key] = path.copy()
        return path

    def _turn_first(self, state: int, start, goal) -> bool:
        """Whether to turn before moving (push at the goal's yaw) rather than after (push at the start's yaw).

        Paths turn once (:func:`planner.motion.single_turn_path`); the pushes between then all push the same
        way relative to the object, so the yaw they push it at is the one whose push towards the goal the
        success model rates likelier (a box pushed square to a face, not on a corner).
        """
        heading = math.atan2(goal[1] - start[1], goal[0] - start[0])
        if math.hypot(goal[1] - start[1], goal[0] - start[0]) < 1e-6 or abs(wrap_angle(goal[2] - start[2])) < 1e-6:
            return True
        p_start, p_goal = self.predictor.p_success_many(
            [("push", {"direction": heading}, state_pose(self.obj, state, start[0], start[1], yaw))
             for yaw in (start[2], goal[2])])
        return bool(p_goal >= p_start)


@dataclass
class Plan:
    """A plan: skill calls with expected poses and predicted success.

    Attributes:
        steps: the calls, in order.
        p_success: predicted probability that closed-loop execution reaches the goal within the planner's
            primitive budget (``Planner.budget``, 60), by Monte Carlo through the skills' outcome models
            (:meth:`Planner.odds`, :mod:`planner.odds`).
        planning_time: seconds.
        route: resting states visited.
        paths: ``(resting state, (m, 3) SE(2) path)`` per segment.
    """

    steps: list[Step]
    p_success: float
    planning_time: float
    route: list[int] = field(default_factory=list)
    paths: list[tuple[int, np.ndarray]] = field(default_factory=list, repr=False)
    goal: Goal | None = None
    start_pose: np.ndarray | None = field(default=None, repr=False)
    planner: Planner | None = field(default=None, repr=False)
    kind: Literal["affordplan", "greedy"] = "affordplan"  # "greedy": no steps, every call chosen on the spot
    # the primitives closed-loop execution is expected to spend (planner.odds); and the product of the steps'
    # own predicted success, each on its first try (the chain's odds without replanning; what p_success was
    # until 0.24)
    expected_primitives: float = float("nan")
    p_steps: float = float("nan")
    aim: Goal | None = None  # the free part of the goal's region the steps lead to (Places.aim); None: the goal

    def __str__(self) -> str:
        if self.kind == "greedy":
            return "plan: greedy (each call chosen on the spot when executed)"
        head = (f"plan: {len(self.steps)} steps, route {self.route}, p_success {self.p_success:.2f} "
                f"(closed loop), expected {self.expected_primitives:.1f} primitives; every step first time "
                f"{self.p_steps:.3f}; planned in {1e3 * self.planning_time:.0f} ms")
        return "\n".join([head] + [f"  {i:2d}. {s}" for i, s in enumerate(self.steps)])

    def odds(self, budget: int) -> Odds:
        """The plan's odds within ``budget`` primitives (:func:`planner.odds.plan_odds`; ``p_success`` is them
        within the planner's budget)."""
        if self.kind == "greedy" or self.planner is None:
            return Odds(float("nan"), float("nan"), int(budget))
        return self.planner.odds(self.steps, budget)

    def execute(self, sim: Literal["arm", "finger"] | Simulator = "arm", max_primitives: int = 60,
                render: bool | str | None = None, seed: int = 0, spin_strokes: int | None = None,
                sensors: Mapping[str, str] | None = None,
                on_primitive: Callable[[LogEntry], None] | None = None) -> Execution:
        """Run the plan closed-loop (see :mod:`planner.execute`); returns an ``Execution``.

        ``sim``: a new simulator with the ``"arm"`` or the bare ``"finger"`` pusher, or a :class:`Simulator` holding
        the plan's object and obstacles; ``render``: a truthy value records a frame per primitive in
        ``Execution.frames``, a string names the camera (default ``"overview"``); ``seed`` seeds a new simulator.
        ``spin_strokes``: strokes one spin step may make (:func:`planner.execute.execute_plan`; default
        :data:`planner.execute.SPIN_STROKES`). ``sensors``: the clouds each named skill is shown while it acts
        (:func:`planner.execute.execute_plan`; default :data:`planner.execute.EXECUTION_SENSORS`).
        ``on_primitive``: called with each primitive's :class:`~planner.execute.LogEntry` as soon as it is done.
        """
        from planner.execute import SPIN_STROKES, execute_greedy, execute_plan

        max_primitives = as_whole("max_primitives", max_primitives, 1, 10_000)
        seed = as_whole("seed", seed, 0, 2**32 - 1)
        if self.kind == "greedy":
            p = self.planner
            return execute_greedy(p.obj, self.goal, self.start_pose, p.predictor, sim=sim, obstacles=p.obstacles,
                                  max_primitives=max_primitives, render=render, seed=seed, on_primitive=on_primitive)
        return execute_plan(self, sim=sim, max_primitives=max_primitives, render=render, seed=seed,
                            spin_strokes=SPIN_STROKES if spin_strokes is None else spin_strokes, sensors=sensors,
                            on_primitive=on_primitive)
