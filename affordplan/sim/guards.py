"""Physics guards: flag simulation states that no policy may learn from.

The seed paper saw its policies exploit broken physics. A guard looks at the object after every
control chunk and names the first fault it sees; the primitive is then stopped and its outcome
marked ``valid=False``. Checks (a few numbers each, no per-contact Python):

- ``"nan"``: a non-finite position or velocity;
- ``"unstable"``: MuJoCo's bad-acceleration warning fired (it resets the state when it does);
- ``"left_workspace"``: the centre of mass is off the workspace by more than ``workspace_margin``;
- ``"speed"``: linear or angular speed above a bound no push can cause;
- ``"sank"``: the lowest hull vertex is deeper under the table than ``max_penetration``;
- ``"off_table"`` (:meth:`PhysicsGuard.check_rest`, once the object has settled): its lowest hull vertex
  is more than ``max_rest_height`` above the table, so it hangs on the pusher or lies on an obstacle
  (a fingertip caught in a mug's opening lifts the mug on the retract).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from affordplan.world import Workspace


@dataclass(frozen=True)
class GuardLimits:
    """Bounds beyond which a state is physically implausible (SI units)."""

    workspace_margin: float = 0.15  # metres beyond the workspace edge
    max_linear_speed: float = 2.0  # m/s
    max_angular_speed: float = 40.0  # rad/s
    max_penetration: float = 0.006  # metres below the table surface
    max_rest_height: float = 0.01  # metres: lowest point above the table once settled


class PhysicsGuard:
    """Checks one free object of a MuJoCo model for physical faults."""

    def __init__(
        self, model: mujoco.MjModel, data: mujoco.MjData, body_id: int, hull_vertices: np.ndarray,
        workspace: Workspace, limits: GuardLimits = GuardLimits(),
    ):
        self._data = data
        self._body = body_id
        joint = int(model.body_jntadr[body_id])
        self._qpos = slice(int(model.jnt_qposadr[joint]), int(model.jnt_qposadr[joint]) + 7)
        self._qvel = slice(int(model.jnt_dofadr[joint]), int(model.jnt_dofadr[joint]) + 6)
        self._hull = np.asarray(hull_vertices, dtype=float)
        self._workspace = workspace
        self.limits = limits
        self._warnings0 = 0

    def arm(self) -> None:
        """Start a new check window (remembers MuJoCo's warning counter)."""
        self._warnings0 = int(self._data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number)

    def check(self) -> str | None:
        """Name of the first fault found, or ``None`` when the state is sane.

        Runs after every 20 ms control chunk, so it reads the 13 numbers as Python floats (a few
        microseconds; numpy's per-call overhead made it an eighth of a chunk's physics).
        """
        d = self._data
        qpos, qvel = d.qpos[self._qpos].tolist(), d.qvel[self._qvel].tolist()
        if not all(map(math.isfinite, qpos + qvel)):
            return "nan"
        if int(d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number) > self._warnings0:
            return "unstable"
        if not self._workspace.contains(qpos[:2], self.limits.workspace_margin):
            return "left_workspace"
        if (math.hypot(*qvel[:3]) > self.limits.max_linear_speed
                or math.hypot(*qvel[3:]) > self.limits.max_angular_speed):
            return "speed"
        if self.lowest_point() < -self.limits.max_penetration:
            return "sank"
        return None

    def lowest_point(self) -> float:
        """Height of the object's lowest hull vertex above the table, metres (world z)."""
        R = self._data.xmat[self._body].reshape(3, 3)
        return float(np.min(self._hull @ R[2]) + self._data.xpos[self._body, 2])

    def check_rest(self) -> str | None:
        """After settling: ``"off_table"`` when the object does not rest on the table, else ``None``."""
        if self.lowest_point() > self.limits.max_rest_height:
            return "off_table"
        return None
