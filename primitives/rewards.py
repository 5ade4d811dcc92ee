"""The seed paper's objectives for push-straight, roll and spin.

Every function takes ``(T0, T1)``: the object's 4x4 world poses before and after a primitive.
With ``p = t1 - t0`` (metres), ``R = R1 R0^T``, ``theta`` its angle in **degrees** (inside the
formulas only, as in the paper) and ``w`` its unit axis in the world frame (``w = z`` at zero
rotation):

- push:  ``L = 20 max(0.05 - |p|, 0) + theta/180``; success ``|p| >= 0.05`` and ``theta < 5``.
- roll:  ``L = |w.z| + max(1 - theta/60, 0) + 0.5 |p_xy|``; success ``theta >= 60`` and
  ``|w.z| <= sin 45deg``.
- spin:  ``L = 1 - |w.z| + max(1 - theta/30, 0) + 2.5 |p_xy|``; success ``theta >= 30`` and
  ``|w.z| >= cos 45deg``.

The reward of a primitive is ``-L``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from affordplan.geometry import check_pose, relative_rotation

PUSH_DISTANCE = 0.05  # metres
PUSH_MAX_ROTATION_DEG = 5.0
ROLL_MIN_ROTATION_DEG = 60.0
SPIN_MIN_ROTATION_DEG = 30.0
AXIS_TOLERANCE_DEG = 45.0
# Thresholds are inclusive; this slack absorbs floating-point error in the rotation angle so that a
# rotation of exactly 60 deg (say) counts as reaching 60 deg.
_EPS = 1e-9


@dataclass(frozen=True)
class Motion:
    """The change between two poses, in the quantities the objectives use."""

    p: np.ndarray  # (3,) translation t1 - t0, metres, world frame
    theta_deg: float  # rotation angle of R1 R0^T, degrees
    w: np.ndarray  # (3,) unit rotation axis, world frame

    @property
    def p_xy(self) -> float:
        """Planar displacement norm, metres."""
        return float(np.linalg.norm(self.p[:2]))

    @property
    def wz(self) -> float:
        """|w . z|: 1 for a rotation about the vertical, 0 for one about a horizontal axis."""
        return abs(float(self.w[2]))


def motion(T0: np.ndarray, T1: np.ndarray) -> Motion:
    """Decompose the change from ``T0`` to ``T1`` (both 4x4 world poses)."""
    T0 = check_pose(T0, "T0")
    T1 = check_pose(T1, "T1")
    theta, w = relative_rotation(T0, T1)
    return Motion(p=T1[:3, 3] - T0[:3, 3], theta_deg=math.degrees(theta), w=w)


def push_loss(T0: np.ndarray, T1: np.ndarray) -> float:
    m = motion(T0, T1)
    return 20.0 * max(PUSH_DISTANCE - float(np.linalg.norm(m.p)), 0.0) + m.theta_deg / 180.0


def push_success(T0: np.ndarray, T1: np.ndarray) -> bool:
    m = motion(T0, T1)
    return bool(np.linalg.norm(m.p) >= PUSH_DISTANCE - _EPS and m.theta_deg < PUSH_MAX_ROTATION_DEG)


def roll_loss(T0: np.ndarray, T1: np.ndarray) -> float:
    m = motion(T0, T1)
    return m.wz + max(1.0 - m.theta_deg / ROLL_MIN_ROTATION_DEG, 0.0) + 0.5 * m.p_xy


def roll_success(T0: np.ndarray, T1: np.ndarray) -> bool:
    m = motion(T0, T1)
    sin45 = math.sin(math.radians(AXIS_TOLERANCE_DEG))
    return bool(m.theta_deg >= ROLL_MIN_ROTATION_DEG - _EPS and m.wz <= sin45 + _EPS)


def spin_loss(T0: np.ndarray, T1: np.ndarray) -> float:
    m = motion(T0, T1)
    return 1.0 - m.wz + max(1.0 - m.theta_deg / SPIN_MIN_ROTATION_DEG, 0.0) + 2.5 * m.p_xy


def spin_success(T0: np.ndarray, T1: np.ndarray) -> bool:
    m = motion(T0, T1)
    cos45 = math.cos(math.radians(AXIS_TOLERANCE_DEG))
    return bool(m.theta_deg >= SPIN_MIN_ROTATION_DEG - _EPS and m.wz >= cos45 - _EPS)


LOSSES = {"push": push_loss, "roll": roll_loss, "spin": spin_loss}
SUCCESSES = {"push": push_success, "roll": roll_success, "spin": spin_success}


def reward(primitive: str, T0: np.ndarray, T1: np.ndarray) -> float:
    """``-L`` of the named primitive (``"push"``, ``"roll"`` or ``"spin"``)."""
    return -LOSSES[primitive](T0, T1)
