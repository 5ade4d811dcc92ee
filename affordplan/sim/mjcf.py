"""MJCF pieces with no dependencies inside the simulator: number lists and the table's box obstacles (a leaf that
:mod:`affordplan.sim.scene` and :mod:`affordplan.sim.arm` both build from)."""

from __future__ import annotations

import math

import numpy as np

from affordplan.world import Box


def floats(values) -> str:
    """Numbers as MJCF writes them: space-separated, 6 significant digits."""
    return " ".join(f"{v:.6g}" for v in np.asarray(values, dtype=float).reshape(-1))


def obstacle_geom_xml(i: int, box: Box) -> str:
    """MJCF geom of obstacle ``i`` (named ``obstacle{i}``)."""
    half = np.asarray(box.size) / 2
    quat = [math.cos(box.yaw / 2), 0.0, 0.0, math.sin(box.yaw / 2)]
    return (
        f'<geom name="obstacle{i}" type="box" size="{floats(half)}" '
        f'pos="{floats([box.center[0], box.center[1], half[2]])}" quat="{floats(quat)}" '
        f'contype="1" conaffinity="3" rgba="0.45 0.5 0.6 1" friction="0.5 0.005 0.002"/>'
    )
