"""Skills that re-observe within their call: a push to a point, a spin by any angle, a roll to a state.

DESIGN.md's decisions allow a skill to re-observe within its call. Each function here makes one call of up to a
few strokes of a trained skill, observing the object before each, and judges the call by where it left the object.

**push_to.** The push skill's one stroke moves an object about 5 cm (:data:`primitives.params.PUSH_STEP`; the policies
move it 5-9 cm) and drifts sideways as it goes. A straight run of a plan is several such strides. Made as one
stride per call, each stride's drift is found only after it and corrected by a replan. :func:`push_to` makes
the run one call instead, as DESIGN.md's decisions allow (a skill may re-observe within its call): before each
stroke it observes the object, aims the stroke at the run's end from where the object now lies, and stops when
the object is within ``STOP_WITHIN`` of it, has passed it, has left its resting state or turned, has not moved,
or the strokes are spent (the run's strides, plus :data:`EXTRA_STROKES`).

**spin_by.** One spin stroke turns an object by an asked angle within ``SPIN_ANGLE_TOLERANCE_DEG`` (10 deg) about a
third of the time on unseen household objects: the policies turn it about 26 deg when asked 15. :func:`spin_by`
asks the rest: after each stroke it measures the object's turn so far and asks what remains (clamped into the
skill's [``SPIN_MIN``, ``SPIN_MAX``]), until the criterion is met, the object left its resting state, or the
strokes are spent. It also takes angles past ``SPIN_MAX`` (up to half a turn).

**roll_to.** A roll that leaves the object where it was (it slid, or tipped back) is tried again from the new
cloud, up to the strokes given; a roll into another state than the asked one ends the call.

Frames and units: positions are world x, y on the table in metres, directions world headings and angles about
world +z in radians (counter-clockwise positive).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from affordplan.checks import as_finite, as_vector, as_whole
from affordplan.errors import AffordplanError, InputError
from affordplan.geometry import wrap_angle
from primitives import rewards
from primitives.params import SPIN_MAX, SPIN_MIN, made_progress, roll_targets

if TYPE_CHECKING:
    from affordplan.sim.simulator import Outcome, Simulator
    from primitives.skills import Skill

EXTRA_STROKES = 1  # strokes a call may take beyond its strides (one stroke that fell short)
STOP_WITHIN = 0.025  # metres from the target at which the strokes stop (the executor replans past it: XY_TOL)
MAX_TURN = math.radians(12.0)  # push_to's default max_turn: the call ends past this turn (the executor's YAW_TOL)
MAX_STROKES = 20  # the most strokes one call may be given


@dataclass
class Strokes:
    """What a call of several strokes did: the combined outcome (``pose_before`` of the first stroke, the rest of the
    last; ``success``: the call's own criterion, see each function), the strokes made, and why they stopped."""

    outcome: Outcome
    strokes: int
    stopped: str


def _make_strokes(skill: Skill, sim: Simulator, max_strokes: int, ask: Callable[[], dict[str, float]],
                  stop: Callable[[Outcome], str | None], steer: bool = True) -> tuple[Outcome, Outcome, int, str]:
    """Up to ``max_strokes`` strokes of ``skill`` in ``sim``, each with the parameter ``ask()`` gives just before it;
    after each valid stroke ``stop(outcome)`` says why the call ends there (``None``: go on).

    An invalid stroke ends the call. An error in a later stroke (no contact the arm can reach) ends it with the
    strokes made; in the first, it is raised. Returns the first and last strokes' outcomes, the strokes made and
    why they stopped."""
    first: Outcome | None = None
    last: Outcome | None = None
    for n in range(1, max_strokes + 1):
        try:
            stroke = skill.execute(sim, ask(), steer=steer)
        except AffordplanError as exc:
            if first is None or last is None:
                raise
            return first, last, n - 1, f"no stroke: {exc}"
        first, last = first or stroke, stroke
        if not stroke.valid:
            return first, last, n, f"invalid stroke ({stroke.invalid_reason})"
        why = stop(stroke)
        if why is not None:
            return first, last, n, why
    assert first is not None and last is not None  # max_strokes >= 1
    return first, last, max_strokes, "strokes spent"


def _combined(first: Outcome, last: Outcome, success: bool) -> Outcome:
    """``last`` with ``first``'s ``pose_before`` and the call's ``success``."""
    out = copy.copy(last)
    out.pose_before = first.pose_before
    out.success = bool(success)
    return out


def push_to(skill: Skill, sim: Simulator, target_xy: tuple[float, float], strides: int,
            direction: float | None = None, max_turn: float = MAX_TURN, steer: bool = False) -> Strokes:
    """Push the object in ``sim`` to ``target_xy`` (world, metres) with up to ``strides + EXTRA_STROKES`` strokes
    of the push ``skill``, observing before each (module docstring).

    ``direction``: the first stroke's heading (radians; default: towards the target); later strokes aim at the
    target from where the object lies. ``max_turn``: the most the strokes may turn the object in all (radians,
    ``MAX_TURN`` by default). The call ends after a stroke that left the object's resting state, turned it more than
    ``max_turn`` in all, did not move it ``MIN_PUSH_PROGRESS`` its way (a stroke that fails once here
    fails again: the cloud is the same), or carried it past the target; after an invalid stroke; and within
    ``STOP_WITHIN`` of the target. An error in a later stroke (no contact the arm can reach) ends the call with
    the strokes made; in the first, it is raised. ``Strokes.outcome.success``: the object ended within
    ``STOP_WITHIN`` of the target in its resting state, validly. ``steer``: each stroke bends against the object's
    turn (:func:`primitives.params.motion_steer`); off by default, as plans push: on 50 validation plan tasks
    (``affordplan bench plan --objects validation --seed 0``) steered pushes reached 36 against 37.

    Raises:
        InputError: a target that is not two finite numbers, ``strides`` not a whole number from 1 to 100,
            ``max_turn`` not in (0, pi], or a skill that is not the push.
    """
    if skill.name != "push":
        raise InputError(f"push_to takes the push skill, got {skill.name!r}")
    target = as_vector("target_xy (m)", target_xy, 2)
    strides = as_whole("strides", strides, 1, 100)
    max_turn = as_finite("max_turn (rad)", max_turn, 1e-6, math.pi)
    obj = sim.obj
    state, x0, y0, yaw0 = obj.planar_pose(sim.object_pose())
    heading0 = math.atan2(target[1] - y0, target[0] - x0)
    asked: list[float] = []  # each stroke's heading

    def ask() -> dict[str, float]:
        rest = target - sim.object_pose()[:2, 3]
        asked.append(float(direction) if not asked and direction is not None else math.atan2(rest[1], rest[0]))
        return {"direction": asked[-1]}

    def stop(out: Outcome) -> str | None:
        s1, x1, y1, yaw1 = obj.planar_pose(out.pose_after)
        if s1 != state:
            return "left its resting state"
        if abs(float(wrap_angle(yaw1 - yaw0))) > max_turn:
            return "turned"
        if not made_progress(obj, "push", {"direction": asked[-1]}, out.pose_before, out.pose_after):
            return "did not move"
        if (target[0] - x1) * math.cos(heading0) + (target[1] - y1) * math.sin(heading0) < -STOP_WITHIN:
            return "passed the target"
        return "at the target" if math.hypot(target[0] - x1, target[1] - y1) <= STOP_WITHIN else None

    first, last, n, stopped = _make_strokes(skill, sim, strides + EXTRA_STROKES, ask, stop, steer)
    s1, x1, y1, _ = obj.planar_pose(last.pose_after)
    ok = last.valid and s1 == state and math.hypot(target[0] - x1, target[1] - y1) <= STOP_WITHIN
    return Strokes(_combined(first, last, ok), n, stopped)


def spin_by(skill: Skill, sim: Simulator, angle: float, max_strokes: int = 6) -> Strokes:
    """Turn the object in ``sim`` by ``angle`` (radians about world +z, counter-clockwise positive) in place, with up
    to ``max_strokes`` strokes of the spin ``skill``, each asking the turn that remains (module docstring).

    The turn so far is the object's yaw in its resting state, followed stroke by stroke (so past half a turn).
    ``Strokes.outcome.success``: every stroke valid, the object in its starting resting state, and the seed's
    spin-by-angle criterion (:func:`primitives.rewards.success`, met modulo a full turn) from start to end. The call
    ends when it is met, after an invalid stroke or one that left the resting state, and when the strokes are spent.
    A stroke that turned the object about a tilted axis (a can on its side rolled about its length) does not end it:
    later strokes often undo it (on ``housekeep:validation`` ending there cost 0.804 -> 0.738 of calls of 6 strokes).
    An error in a later stroke (no contact the arm can reach) ends the call with the strokes made; in the first, it
    is raised.

    ``max_strokes``: 6 by default, chosen on ``housekeep:validation`` (240 asked angles, camera clouds): success within
    1 / 2 / 4 / 6 strokes 0.400 / 0.554 / 0.742 / 0.804 (``python -m primitives.evaluate spin --params random
    --frames shipped --strokes 6 --objects housekeep:validation --trials 20``), before each stroke stopped at the
    angle (:func:`primitives.params.motion_stop`); on the unseen household objects the stopping strokes reach 0.680 /
    0.765 / 0.805 / 0.832.

    Raises:
        InputError: ``angle`` not finite or not with ``SPIN_MIN <= |angle| <= pi``, ``max_strokes`` not a whole
            number from 1 to ``MAX_STROKES``, or a skill that is not the spin.
    """
    if skill.name != "spin":
        raise InputError(f"spin_by takes the spin skill, got {skill.name!r}")
    angle = as_finite("angle (rad)", angle)
    if not SPIN_MIN - 1e-9 <= abs(angle) <= math.pi + 1e-9:
        raise InputError(f"spin_by turns by {math.degrees(SPIN_MIN):.0f} to 180 degrees either way, "
                         f"got {math.degrees(angle):.1f}")
    max_strokes = as_whole("max_strokes", max_strokes, 1, MAX_STROKES)
    obj = sim.obj
    T0 = sim.object_pose()
    state, _, _, yaw0 = obj.planar_pose(T0)
    yaw = [yaw0, 0.0]  # the last stroke's yaw, and the turn since the start summed stroke by stroke (no wrap)

    def ask() -> dict[str, float]:
        rest = angle - yaw[1]
        return {"angle": math.copysign(min(max(abs(rest), SPIN_MIN), SPIN_MAX), rest)}

    def stop(out: Outcome) -> str | None:
        now, _, _, yaw1 = obj.planar_pose(out.pose_after)
        if now != state:
            return "left its resting state"
        yaw[1] += float(wrap_angle(yaw1 - yaw[0]))
        yaw[0] = yaw1
        if rewards.success("spin", T0, out.pose_after, {"angle": angle}):
            return "at the angle"
        return None

    first, last, n, stopped = _make_strokes(skill, sim, max_strokes, ask, stop)
    ok = last.valid and obj.classify(last.pose_after) == state and rewards.success("spin", T0, last.pose_after,
                                                                                    {"angle": angle})
    return Strokes(_combined(first, last, ok), n, stopped)


def roll_to(skill: Skill, sim: Simulator, target: int, max_strokes: int = 3) -> Strokes:
    """Roll the object in ``sim`` into resting state ``target`` (one roll away from its own) with up to
    ``max_strokes`` strokes of the roll ``skill``: a stroke that leaves the object in its state is tried again
    from the new cloud (module docstring).

    ``Strokes.outcome.success``: the last stroke valid and the object in ``target``. The call ends in ``target``,
    in any other state, after an invalid stroke, and when the strokes are spent. An error in a later stroke ends
    the call with the strokes made; in the first, it is raised.

    ``max_strokes``: 3 by default; on ``housekeep:validation`` (240 starts asked a state one roll away where there is
    one, cameras) success within 1 / 2 / 3 / 4 / 6 strokes was 0.317 / 0.367 / 0.388 / 0.408 / 0.417
    (``python -m primitives.evaluate roll --params random --frames shipped --strokes 6 --objects housekeep:validation
    --trials 20``): past three, a stroke more buys about 0.02.

    Raises:
        InputError: ``target`` not a state one roll away, ``max_strokes`` not a whole number from 1 to
            ``MAX_STROKES``, or a skill that is not the roll.
    """
    if skill.name != "roll":
        raise InputError(f"roll_to takes the roll skill, got {skill.name!r}")
    max_strokes = as_whole("max_strokes", max_strokes, 1, MAX_STROKES)
    obj = sim.obj
    state = obj.classify(sim.object_pose())
    target = as_whole("target (resting state)", target, 0, len(obj.resting_states) - 1)
    if target not in roll_targets(obj, state):
        raise InputError(f"state {target} is not one roll away from state {state} of {obj.name}; "
                         f"one roll away: {roll_targets(obj, state)}")

    def stop(out: Outcome) -> str | None:
        now = obj.classify(out.pose_after)
        if now == target:
            return "in the target state"
        return None if now == state else f"rolled into state {now}"

    first, last, n, stopped = _make_strokes(skill, sim, max_strokes, lambda: {"target": target}, stop)
    return Strokes(_combined(first, last, last.valid and obj.classify(last.pose_after) == target), n, stopped)
