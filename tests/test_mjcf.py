"""MJCF pieces (affordplan.sim.mjcf): number lists as MJCF writes them, and an obstacle's geom, which parses with
mujoco.MjModel.from_xml_string and stands where the Box says, turned by its yaw."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from affordplan.sim.mjcf import floats, obstacle_geom_xml
from affordplan.world import Box


def test_floats_are_space_separated_with_six_significant_digits():
    assert floats([1, 0.5, -2]) == "1 0.5 -2"
    assert floats(np.array([[1.0, 2.0], [3.0, 4.0]])) == "1 2 3 4"  # flattened
    assert floats([math.pi, 1e-7, 123456789.0]) == "3.14159 1e-07 1.23457e+08"
    assert floats([]) == ""


def _model(*boxes: Box) -> mujoco.MjModel:
    geoms = "\n".join(obstacle_geom_xml(i, b) for i, b in enumerate(boxes))
    return mujoco.MjModel.from_xml_string(f"<mujoco><worldbody>{geoms}</worldbody></mujoco>")


def test_an_obstacle_geom_parses_and_stands_on_the_table_where_its_box_is():
    boxes = (Box(center=(0.6, -0.2), size=(0.02, 0.3, 0.1)), Box(center=(0.45, 0.15), size=(0.1, 0.05, 0.2), yaw=0.7))
    m = _model(*boxes)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    for i, box in enumerate(boxes):
        g = m.geom(f"obstacle{i}")
        assert g.type[0] == mujoco.mjtGeom.mjGEOM_BOX
        assert g.size == pytest.approx(np.asarray(box.size) / 2)
        assert d.geom_xpos[g.id] == pytest.approx([*box.center, box.size[2] / 2])  # standing on z = 0
        R = d.geom_xmat[g.id].reshape(3, 3)
        half = np.asarray(box.size[:2]) / 2
        local = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * half
        corners = d.geom_xpos[g.id][:2] + local @ R[:2, :2].T
        assert corners == pytest.approx(box.corners_xy(), abs=1e-6)  # the footprint the planner uses
        assert g.contype[0] == 1 and g.conaffinity[0] == 3  # met by the object (1) and the pusher (2)
