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

Parameterised variants (:func:`loss` and :func:`success` with ``params``; see :mod:`primitives.params`)
generalise these and reduce to them when ``params`` is ``None``:

- push ``{"direction": a}``, ``d = (cos a, sin a, 0)``: ``L = 20 max(0.05 - p.d, 0) + theta/180 +
  10 |p_xy - (p.d) d|`` (progress along ``d`` saturating at 5 cm, turning, sideways slip); success
  ``|p| >= 0.05``, ``theta < 5`` and ``p_xy`` within 15 deg of ``d``.
- spin ``{"angle": a}``: with ``phi`` the signed turn about +z (``theta sign(w.z)``, degrees),
  ``L = 1 - |w.z| + |phi - a|/30 + 2.5 |p_xy|``; success ``|phi - a| <= 10`` and ``|w.z| >= cos 45deg``.
- roll ``{"target": j}``: with ``tilt`` the angle (degrees) between the pose's up-vector and the
  nearest up-vector of state ``j``, ``L = tilt/60 + 0.5 |p_xy|``; success: the settled pose is in
  state ``j``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from affordplan.geometry import check_pose, relative_rotation
from affordplan.objects.model import ObjectModel

PUSH_DISTANCE = 0.05  # metres
PUSH_MAX_ROTATION_DEG = 5.0
ROLL_MIN_ROTATION_DEG = 60.0
SPIN_MIN_ROTATION_DEG = 30.0
PUSH_DIRECTION_TOLERANCE_DEG = 15.0
PUSH_SLIP_WEIGHT = 10.0  # per metre of sideways slip
SPIN_ANGLE_TOLERANCE_DEG = 10.0
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


# ------------------------------------------------------------------------ parameterised objectives
def signed_turn_deg(m: Motion) -> float:
    """The turn about +z in degrees, signed (counter-clockwise positive)."""
    return m.theta_deg * (1.0 if m.w[2] >= 0 else -1.0)


def _push_dir(T0, T1, direction: float) -> tuple[float, bool]:
    m = motion(T0, T1)
    d = np.array([math.cos(direction), math.sin(direction), 0.0])
    along = float(m.p @ d)
    slip = float(np.linalg.norm(m.p[:2] - along * d[:2]))
    loss = 20.0 * max(PUSH_DISTANCE - along, 0.0) + m.theta_deg / 180.0 + PUSH_SLIP_WEIGHT * slip
    off = math.degrees(math.atan2(slip, along)) if m.p_xy > 0 else 180.0
    ok = (np.linalg.norm(m.p) >= PUSH_DISTANCE - _EPS and m.theta_deg < PUSH_MAX_ROTATION_DEG
          and off <= PUSH_DIRECTION_TOLERANCE_DEG + _EPS)
    return loss, bool(ok)


def _spin_angle(T0, T1, angle: float) -> tuple[float, bool]:
    m = motion(T0, T1)
    err = abs(signed_turn_deg(m) - math.degrees(angle))
    loss = 1.0 - m.wz + err / SPIN_MIN_ROTATION_DEG + 2.5 * m.p_xy
    # met modulo a full turn, so that any angle up to half a turn can be asked (primitives.strokes.spin_by); for the
    # skill's own 15-45 deg this is the plain error (the two differ only past 135 deg off, far outside the tolerance)
    off = abs((err + 180.0) % 360.0 - 180.0)
    ok = off <= SPIN_ANGLE_TOLERANCE_DEG + _EPS and m.wz >= math.cos(math.radians(AXIS_TOLERANCE_DEG)) - _EPS
    return loss, bool(ok)


def _roll_target(T0, T1, target: int, obj: ObjectModel) -> tuple[float, bool]:
    m = motion(T0, T1)
    tilt = math.degrees(obj.tilt_from_state(T1, target))
    return tilt / ROLL_MIN_ROTATION_DEG + 0.5 * m.p_xy, obj.classify(T1) == target


def _parameterised(primitive: str, T0, T1, params: dict, obj: ObjectModel | None) -> tuple[float, bool]:
    if primitive == "push":
        return _push_dir(T0, T1, params["direction"])
    if primitive == "spin":
        return _spin_angle(T0, T1, params["angle"])
    if primitive == "roll":
        if obj is None:
            raise ValueError("a roll target needs the object model (obj=...)")
        return _roll_target(T0, T1, params["target"], obj)
    raise ValueError(f"unknown primitive {primitive!r}")


def loss(primitive: str, T0: np.ndarray, T1: np.ndarray, params: dict | None = None,
         obj: ObjectModel | None = None) -> float:
    """``L`` of the named primitive; the seed's when ``params`` is ``None``."""
    if params is None:
        return LOSSES[primitive](T0, T1)
    return _parameterised(primitive, T0, T1, params, obj)[0]


def success(primitive: str, T0: np.ndarray, T1: np.ndarray, params: dict | None = None,
            obj: ObjectModel | None = None) -> bool:
    """The success test of the named primitive; the seed's when ``params`` is ``None``."""
    if params is None:
        return SUCCESSES[primitive](T0, T1)
    return _parameterised(primitive, T0, T1, params, obj)[1]
