"""Pose helpers and the world's obstacles and workspace."""

from __future__ import annotations

import math

import numpy as np
import pytest

import affordplan as ap
from affordplan import geometry
from affordplan.errors import InputError


def test_relative_rotation_is_in_the_world_frame():
    R0 = geometry.rot_z(0.8)
    R1 = geometry.rot_z(0.8 + 0.5)
    theta, w = geometry.relative_rotation(geometry.make_pose(R0), geometry.make_pose(R1))
    assert theta == pytest.approx(0.5) and np.allclose(w, [0, 0, 1])


def test_wrap_angle():
    assert geometry.wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    assert geometry.wrap_angle(-0.25) == pytest.approx(-0.25)


def test_transform_points():
    T = geometry.make_pose(geometry.rot_z(math.pi / 2), (1.0, 0.0, 0.0))
    assert np.allclose(geometry.transform_points(T, np.array([[1.0, 0.0, 0.0]])), [[1.0, 1.0, 0.0]])


def test_box_footprint_and_validation():
    box = ap.Box(center=(0.5, 0.0), size=(0.2, 0.1, 0.05), yaw=math.pi / 2)
    corners = box.corners_xy()
    assert np.allclose(corners.min(axis=0), [0.45, -0.1]) and np.allclose(corners.max(axis=0), [0.55, 0.1])
    with pytest.raises(InputError):
        ap.Box(center=(np.nan, 0.0), size=(0.1, 0.1, 0.1))
    with pytest.raises(InputError):
        ap.Box(center=(0.5, 0.0), size=(0.1, 0.0, 0.1))


def test_workspace_contains():
    ws = ap.Workspace()
    assert ws.contains((0.5, 0.0)) and not ws.contains((0.2, 0.0))
    assert ws.contains((0.2, 0.0), margin=0.1)
