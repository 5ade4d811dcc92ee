"""The robot's constants that the simulator and the planner both read: the fingertip, its reach, and the timing
and geometry of one primitive (HACMan's protocol as measured here). SI units; the world frame has z up, the table top
at z = 0 and the arm's base at the origin."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

SkillName = Literal["push", "roll", "spin"]
SKILLS: tuple[SkillName, ...] = ("push", "roll", "spin")  # the robot's skills, in the one order every listing uses

TIP_RADIUS = 0.008  # metres: the fingertip sphere
# Metres from the base (the world origin) within which the arm's IK accepts a fingertip target pointing down:
# measured 0.814-0.816 m at heights 2-10 cm and headings 0-40 deg, from the arm's home pose.
FINGERTIP_REACH = 0.815
TABLE_CONTACT_HEIGHT = 0.003  # points lower than this touch the table and are left out (no fingertip reaches), metres


@dataclass(frozen=True)
class Protocol:
    """Timing and geometry of one primitive (SI units)."""

    standoff: float = 0.04  # pre-contact distance along the normal
    mid_standoff: float = 0.02
    approach_time: float = 0.1  # per approach segment, seconds
    motion_step: float = 0.03  # target displacement per control step and unit of motion
    motion_steps: int = 3
    motion_step_time: float = 0.5
    retract_height: float = 0.05
    retract_time: float = 0.1
    settle_time_max: float = 2.0
    settle_linear_speed: float = 0.005  # m/s
    settle_angular_speed: float = 0.05  # rad/s
    settle_chunks: int = 5  # consecutive still chunks that count as settled
    approach_position_tolerance: float = 0.02
    approach_tilt_tolerance: float = math.radians(5.0)
    approach_disturbance: float = 0.005  # object displacement before contact that fails approach
    approach_disturbance_angle: float = math.radians(3.0)
    transit_clearance: float = 0.12  # arm transit height above the tallest obstacle or the object
