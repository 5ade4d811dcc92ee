"""What the planner asks the success models about a resting state as such, wherever the object lies in it.

A route is chosen before its placements are known, and a turn is split into spins before the spins are placed, so
the planner rates rolls between resting states and spins within one at a fixed place: the workspace centre, yaw 0.
With the shipped skills' frame searches a rating hardly depends on the yaw (it is the best over turns of the
frame), and each is one batched query, asked once per state (or edge) and kept: :class:`StateRatings`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from affordplan.objects.model import ObjectModel
from planner.predict import Predictor, state_pose

SPIN_RATE_GRID = np.radians([15.0, 25.0, 35.0, 45.0])  # spin angles rated per state to split turns (spin_rate)


class StateRatings:
    """Predicted success of rolls between resting states and of spins within one, asked at ``at`` (x, y, world,
    metres) with yaw 0 and kept.

    Args:
        obj: the object.
        predictor: answers ``p_success_many`` (:class:`planner.predict.Predictor`, or a stand-in).
        at: where the object is taken to lie for every rating (the planner's workspace centre).
    """

    def __init__(self, obj: ObjectModel, predictor: Predictor, at: tuple[float, float]):
        self.obj = obj
        self.predictor = predictor
        self.at = (float(at[0]), float(at[1]))
        self._spin_rows: dict[tuple[int, int], np.ndarray] = {}  # (state, sense) -> P(spin) over SPIN_RATE_GRID

    def _pose(self, state: int) -> np.ndarray:
        return state_pose(self.obj, state, *self.at, 0.0)

    def rolls(self, edges: Sequence[tuple[int, int]]) -> np.ndarray:
        """P(roll i -> j) for each edge ``(i, j)`` (one batched query; :class:`planner.graph.RestingStateGraph`
        asks it once for all its edges)."""
        return self.predictor.p_success_many([("roll", {"target": j}, self._pose(i)) for i, j in edges])

    def spin_rate(self, state: int) -> Callable[[float], float]:
        """``rate(angle)``: predicted success of a spin by ``angle`` (radians, signed, 15-45 deg) in ``state``,
        read off :data:`SPIN_RATE_GRID` by linear interpolation. Each sense's row (``len(SPIN_RATE_GRID)``
        frame-searched queries) is asked when first needed."""
        def rate(angle: float) -> float:
            key = (state, 1 if angle > 0 else -1)
            if key not in self._spin_rows:
                T = self._pose(state)
                self._spin_rows[key] = np.asarray(self.predictor.p_success_many(
                    [("spin", {"angle": float(key[1] * a)}, T) for a in SPIN_RATE_GRID]), dtype=float)
            return float(np.interp(abs(angle), SPIN_RATE_GRID, self._spin_rows[key]))

        return rate
