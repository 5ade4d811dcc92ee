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

**spin_by.** One spin stroke turns an object by an asked angle within ``SPIN_ANGLE_TOLERANCE_DEG`` (10 deg) less
than half the time on unseen household objects: the policies turn it about 26 deg when asked 15. :func:`spin_by`
asks the rest: after each stroke it measures the object's turn so far and asks what remains (clamped into the
skill's [``SPIN_MIN``, ``SPIN_MAX``]), until the turn is within the tolerance, the object left its resting state,
or the strokes are spent. It also takes angles past ``SPIN_MAX`` (up to half a turn).

**roll_to.** A roll that leaves the object where it was (it slid, or tipped back) is tried again from the new
cloud, up to the strokes given; a roll into another state than the asked one ends the call.

Frames and units: positions are world x, y on the table in metres, directions world headings and angles about
world +z in radians (counter-clockwise positive).
"""

from __future__ import annotations

import copy
import math
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
MAX_TURN = math.radians(12.0)  # turning the object more than this ends the call (the executor's YAW_TOL is it)
SPIN_TOLERANCE = math.radians(rewards.SPIN_ANGLE_TOLERANCE_DEG)  # a spin call stops within this of its angle
MAX_STROKES = 20  # the most strokes one call may be given


@dataclass
class Strokes:
    """What a call of several strokes did: the combined outcome (``pose_before`` of the first stroke, the rest of the
    last; ``success``: the call's own criterion, see each function), the strokes made, and why they stopped."""

    outcome: Outcome
    strokes: int
    stopped: str


def push_to(skill: Skill, sim: Simulator, target_xy: tuple[float, float], strides: int,
            direction: float | None = None) -> Strokes:
    """Push the object in ``sim`` to ``target_xy`` (world, metres) with up to ``strides + EXTRA_STROKES`` strokes
    of the push ``skill``, observing before each (module docstring).

    ``direction``: the first stroke's heading (radians; default: towards the target); later strokes aim at the
    target from where the object lies. The call ends after a stroke that left the object's resting state, turned
    it more than ``MAX_TURN`` in all, did not move it ``MIN_PUSH_PROGRESS`` its way (a stroke that fails once here
    fails again: the cloud is the same), or carried it past the target; after an invalid stroke; and within
    ``STOP_WITHIN`` of the target. An error in a later stroke (no contact the arm can reach) ends the call with
    the strokes made; in the first, it is raised.

    Raises:
        InputError: a target that is not two finite numbers, ``strides`` not a whole number from 1 to 100, or a
            skill that is not the push.
    """
    if skill.name != "push":
        raise InputError(f"push_to takes the push skill, got {skill.name!r}")
    target = as_vector("target_xy (m)", target_xy, 2)
    strides = as_whole("strides", strides, 1, 100)
    obj = sim.obj
    state, x0, y0, yaw0 = obj.planar_pose(sim.object_pose())
    heading0 = math.atan2(target[1] - y0, target[0] - x0)
    first, out, stopped, n = None, None, "strokes spent", 0
    for n in range(1, strides + EXTRA_STROKES + 1):
        rest = target - sim.object_pose()[:2, 3]
        heading = float(direction) if n == 1 and direction is not None else math.atan2(rest[1], rest[0])
        try:
            stroke = skill.execute(sim, {"direction": heading})
        except AffordplanError as exc:  # e.g. no contact the arm can reach: the strokes made so far stand
            if out is None:
                raise
            n -= 1
            stopped = f"no stroke: {exc}"
            break
        out, first = stroke, first or stroke
        s1, x1, y1, yaw1 = obj.planar_pose(out.pose_after)
        if not out.valid:
            stopped = f"invalid stroke ({out.invalid_reason})"
            break
        if s1 != state:
            stopped = "left its resting state"
            break
        if abs(float(wrap_angle(yaw1 - yaw0))) > MAX_TURN:
            stopped = "turned"
            break
        if not made_progress(obj, "push", {"direction": heading}, out.pose_before, out.pose_after):
            stopped = "did not move"
            break
        if (target[0] - x1) * math.cos(heading0) + (target[1] - y1) * math.sin(heading0) < -STOP_WITHIN:
            stopped = "passed the target"
            break
        if math.hypot(target[0] - x1, target[1] - y1) <= STOP_WITHIN:
            stopped = "at the target"
            break
    assert out is not None and first is not None  # the loop makes at least one stroke (s1, x1, y1: its last)
    combined = copy.copy(out)
    combined.pose_before = first.pose_before
    combined.success = bool(out.valid and s1 == state and math.hypot(target[0] - x1, target[1] - y1) <= STOP_WITHIN)
    return Strokes(combined, n, stopped)


def _combined(first: Outcome, last: Outcome, success: bool) -> Outcome:
    """``last`` with ``first``'s ``pose_before`` and the call's ``success``."""
    out = copy.copy(last)
    out.pose_before = first.pose_before
    out.success = bool(success)
    return out


def _turn(T_before, T_after) -> float:
    """The signed turn about world +z from ``T_before`` to ``T_after`` (radians, within one half turn)."""
    return math.radians(rewards.signed_turn_deg(rewards.motion(T_before, T_after)))


def spin_by(skill: Skill, sim: Simulator, angle: float, max_strokes: int = 4) -> Strokes:
    """Turn the object in ``sim`` by ``angle`` (radians about world +z, counter-clockwise positive) in place, with up
    to ``max_strokes`` strokes of the spin ``skill``, each asking the turn that remains (module docstring).

    ``Strokes.outcome.success``: every stroke valid, the object in its starting resting state, its axis within
    the spin criterion's tilt, and its turn within ``SPIN_TOLERANCE`` of ``angle`` (the seed's spin-by-angle
    criterion; for ``|angle| <= SPIN_MAX`` exactly :func:`primitives.rewards.success`). The call ends within
    ``SPIN_TOLERANCE`` of the angle, after an invalid stroke or one that left the resting state, and when the strokes
    are spent. An error in a later stroke (no contact the arm can reach) ends the call with the strokes made; in
    the first, it is raised.

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
    state = obj.classify(T0)
    turned = 0.0  # summed stroke by stroke: no wrap at half a turn
    first, out, stopped, n = None, None, "strokes spent", 0
    for n in range(1, max_strokes + 1):
        rest = angle - turned
        ask = math.copysign(min(max(abs(rest), SPIN_MIN), SPIN_MAX), rest)
        try:
            stroke = skill.execute(sim, {"angle": ask})
        except AffordplanError as exc:
            if out is None:
                raise
            n -= 1
            stopped = f"no stroke: {exc}"
            break
        out, first = stroke, first or stroke
        turned += _turn(out.pose_before, out.pose_after)
        if not out.valid:
            stopped = f"invalid stroke ({out.invalid_reason})"
            break
        if obj.classify(out.pose_after) != state:
            stopped = "left its resting state"
            break
        if abs(angle - turned) <= SPIN_TOLERANCE:
            stopped = "at the angle"
            break
    assert out is not None and first is not None
    m = rewards.motion(T0, out.pose_after)
    upright = m.wz >= math.cos(math.radians(rewards.AXIS_TOLERANCE_DEG)) - 1e-9
    on_angle = abs(float(wrap_angle(_turn(T0, out.pose_after) - angle))) <= SPIN_TOLERANCE + 1e-9
    ok = out.valid and obj.classify(out.pose_after) == state and upright and on_angle
    return Strokes(_combined(first, out, ok), n, stopped)


def roll_to(skill: Skill, sim: Simulator, target: int, max_strokes: int = 3) -> Strokes:
    """Roll the object in ``sim`` into resting state ``target`` (one roll away from its own) with up to
    ``max_strokes`` strokes of the roll ``skill``: a stroke that leaves the object in its state is tried again
    from the new cloud (module docstring).

    ``Strokes.outcome.success``: the last stroke valid and the object in ``target``. The call ends in ``target``,
    in any other state, after an invalid stroke, and when the strokes are spent. An error in a later stroke ends
    the call with the strokes made; in the first, it is raised.

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
    first, out, stopped, n = None, None, "strokes spent", 0
    for n in range(1, max_strokes + 1):
        try:
            stroke = skill.execute(sim, {"target": target})
        except AffordplanError as exc:
            if out is None:
                raise
            n -= 1
            stopped = f"no stroke: {exc}"
            break
        out, first = stroke, first or stroke
        now = obj.classify(out.pose_after)
        if not out.valid:
            stopped = f"invalid stroke ({out.invalid_reason})"
            break
        if now == target:
            stopped = "in the target state"
            break
        if now != state:
            stopped = f"rolled into state {now}"
            break
    assert out is not None and first is not None
    return Strokes(_combined(first, out, out.valid and obj.classify(out.pose_after) == target), n, stopped)
