"""A push that corrects its course between strokes: one call that moves the object to a point on the table.

The push skill's one stroke moves an object about 5 cm (:data:`primitives.params.PUSH_STEP`; the policies
move it 5-9 cm) and drifts sideways as it goes. A straight run of a plan is several such strides. Made as one
stride per call, each stride's drift is found only after it and corrected by a replan. :func:`push_to` makes
the run one call instead, as DESIGN.md's decisions allow (a skill may re-observe within its call): before each
stroke it observes the object, aims the stroke at the run's end from where the object now lies, and stops when
the object is within ``STOP_WITHIN`` of it, has passed it, has left its resting state or turned, has not moved,
or the strokes are spent (the run's strides, plus :data:`EXTRA_STROKES`).

Frames and units: positions are world x, y on the table in metres, directions world headings in radians.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from affordplan.checks import as_vector, as_whole
from affordplan.errors import AffordplanError, InputError
from affordplan.geometry import wrap_angle
from primitives.params import made_progress

if TYPE_CHECKING:
    from affordplan.sim.simulator import Outcome, Simulator
    from primitives.skills import Skill

EXTRA_STROKES = 1  # strokes a call may take beyond its strides (one stroke that fell short)
STOP_WITHIN = 0.025  # metres from the target at which the strokes stop (the executor replans past it: XY_TOL)
MAX_TURN = math.radians(12.0)  # turning the object more than this ends the call (the executor's YAW_TOL is it)


@dataclass
class Strokes:
    """What :func:`push_to` did: the combined outcome (``pose_before`` of the first stroke, the rest of the last;
    ``success``: the object ended within ``STOP_WITHIN`` of the target in its resting state, validly), the strokes
    made, and why they stopped."""

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
