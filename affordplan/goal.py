"""Goals for the planner: where the object should end up, in which resting state, and how closely."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, TypeAlias, TypedDict

import numpy as np

from affordplan.checks import as_finite, as_vector, describe, is_whole
from affordplan.errors import GoalError, InputError
from affordplan.geometry import wrap_period
from affordplan.objects.model import ObjectModel


class Start(TypedDict, total=False):
    """Where :func:`affordplan.plan` starts the object (every key optional).

    Keys:
        resting_state: index into ``obj.resting_states`` (default 0).
        xy: centre of mass on the table, metres, world frame (default: the workspace's centre).
        yaw: heading in that resting state, radians (default 0).
    """

    resting_state: int
    xy: tuple[float, float]
    yaw: float


# What affordplan.plan's ``start`` takes: a Start dict, or a 4x4 world pose resting on the table; None: the defaults.
StartLike: TypeAlias = Start | dict[str, Any] | np.ndarray | None


@dataclass(frozen=True)
class Goal:
    """A target for the object on the table.

    Args:
        xy: position of the centre of mass on the table, metres, world frame.
        yaw: heading in the goal's resting state, radians (see :mod:`affordplan.objects.resting`);
            ``None``: any.
        resting_state: index into ``obj.resting_states``; ``None``: any (the start's is kept).
        xy_tol: reached when the centre is within this distance, metres.
        yaw_tol: and the yaw within this angle, radians.
        yaw_symmetric: compare yaws modulo the resting state's symmetry about the vertical
            (:meth:`ObjectModel.yaw_period`): a cube on a face at yaw 90 deg is the same solid in the same place
            as at 0, an upright 32-facet cylinder at any yaw is within 5.6 deg of every other. ``False`` when
            the object's markings tell those poses apart (a die's pips, a labelled box): then the yaw is the
            frame's.
    """

    xy: tuple[float, float]
    yaw: float | None = None
    resting_state: int | None = None
    xy_tol: float = 0.03
    yaw_tol: float = math.radians(15.0)
    yaw_symmetric: bool = True

    def __post_init__(self):
        try:
            xy = as_vector("goal xy (metres)", self.xy, 2)
            yaw = None if self.yaw is None else as_finite("goal yaw (radians)", self.yaw)
            tolerances = [as_finite(f"goal {name}", getattr(self, name)) for name in ("xy_tol", "yaw_tol")]
        except InputError as exc:
            raise GoalError(str(exc)) from None
        if self.resting_state is not None and not is_whole(self.resting_state):  # its range: plan() checks it
            raise GoalError(f"goal resting_state must be an integer index or None, got {describe(self.resting_state)}")
        state = None if self.resting_state is None else int(self.resting_state)
        if not isinstance(self.yaw_symmetric, (bool, np.bool_)):
            raise GoalError(f"goal yaw_symmetric must be True or False, got {describe(self.yaw_symmetric)}")
        for name, v in zip(("xy_tol", "yaw_tol"), tolerances):
            if v <= 0:
                raise GoalError(f"goal {name} must be a positive number, got {v!r}")
        object.__setattr__(self, "xy", (float(xy[0]), float(xy[1])))
        object.__setattr__(self, "yaw", yaw)
        object.__setattr__(self, "resting_state", state)
        object.__setattr__(self, "yaw_symmetric", bool(self.yaw_symmetric))
        object.__setattr__(self, "xy_tol", tolerances[0])
        object.__setattr__(self, "yaw_tol", tolerances[1])

    @classmethod
    def from_degrees(cls, xy: tuple[float, float], yaw_deg: float | None = None, resting_state: int | None = None,
                     xy_tol: float = 0.03, yaw_tol_deg: float = 15.0, yaw_symmetric: bool = True) -> Goal:
        """The goal with its yaw and yaw tolerance in degrees (as scene files may give them); the constructor's
        unit stays radians. ``Goal.from_degrees((0.6, 0.0), 90)`` is ``Goal((0.6, 0.0), math.radians(90))``."""
        try:
            yaw = None if yaw_deg is None else math.radians(as_finite("goal yaw_deg (degrees)", yaw_deg))
            yaw_tol = math.radians(as_finite("goal yaw_tol_deg (degrees)", yaw_tol_deg))
        except InputError as exc:
            raise GoalError(str(exc)) from None
        return cls(xy=xy, yaw=yaw, resting_state=resting_state, xy_tol=xy_tol, yaw_tol=yaw_tol,
                   yaw_symmetric=yaw_symmetric)

    def check_object(self, obj: ObjectModel) -> None:
        """Raise :class:`GoalError` when the resting state does not exist for ``obj``."""
        n = len(obj.resting_states)
        if self.resting_state is not None and not 0 <= self.resting_state < n:
            raise GoalError(f"goal resting_state {self.resting_state} does not exist: {obj.name} has {n} resting "
                            f"states (0..{n - 1})")

    def period(self, obj: ObjectModel, state: int) -> float:
        """Radians by which yaws in ``state`` are equal for this goal: the state's symmetry, or ``2 pi``."""
        return obj.yaw_period(state) if self.yaw_symmetric else 2.0 * math.pi

    def yaw_near(self, obj: ObjectModel, state: int, yaw: float) -> float | None:
        """Of the yaws in ``state`` that meet this goal's yaw exactly, the one nearest ``yaw`` (radians); ``None``
        without a goal yaw."""
        if self.yaw is None:
            return None
        period = self.period(obj, state)
        return float(yaw - wrap_period(yaw - self.yaw, period))

    def yaw_error(self, obj: ObjectModel, state: int, yaw: float) -> float:
        """``|yaw error|`` (radians) of a pose of ``state`` at ``yaw``; 0 without a goal yaw."""
        if self.yaw is None:
            return 0.0
        return abs(wrap_period(yaw - self.yaw, self.period(obj, state)))

    def yaw_free(self, obj: ObjectModel, state: int) -> bool:
        """Whether every yaw of ``state`` meets the goal (no goal yaw, or symmetry finer than twice the tolerance)."""
        return self.yaw is None or self.period(obj, state) <= 2.0 * self.yaw_tol

    def errors(self, obj: ObjectModel, T_world_object: np.ndarray) -> tuple[float, float, bool]:
        """``(xy distance in metres, |yaw error| in radians (0 without a goal yaw), state matches)``."""
        state, x, y, yaw = obj.planar_pose(T_world_object)
        d = float(np.hypot(x - self.xy[0], y - self.xy[1]))
        return d, self.yaw_error(obj, state, yaw), self.resting_state is None or state == self.resting_state

    def reached(self, obj: ObjectModel, T_world_object: np.ndarray) -> bool:
        d, yaw_err, state_ok = self.errors(obj, T_world_object)
        return state_ok and d <= self.xy_tol and yaw_err <= self.yaw_tol

