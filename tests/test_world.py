"""The table-top world (affordplan.world): the workspace and its margins, box obstacles checked at construction,
the scene-file dict form both ways, footprint corners."""

from __future__ import annotations

import math

import numpy as np
import pytest

from affordplan.errors import InputError
from affordplan.world import WORLD_BOUND, Box, Workspace, as_box


def test_the_workspace_contains_its_region_grown_by_a_margin():
    ws = Workspace()
    assert (ws.x, ws.y) == ((0.3, 0.75), (-0.3, 0.3)) and ws.center == pytest.approx((0.525, 0.0))
    assert ws.contains((0.3, -0.3)) and ws.contains((0.75, 0.3))  # the edges belong to it
    assert not ws.contains((0.76, 0.0)) and ws.contains((0.76, 0.0), margin=0.02)
    assert not ws.contains((0.5, -0.35), margin=0.04) and ws.contains((0.5, -0.35), margin=0.05)
    small = Workspace(x=(0.4, 0.5), y=(0.0, 0.2))
    assert small.center == pytest.approx((0.45, 0.1)) and not small.contains((0.5, -0.01))
    with pytest.raises(AttributeError):
        ws.x = (0.0, 1.0)  # frozen: safe as a default argument


def test_a_box_holds_plain_floats_and_refuses_what_is_not_a_box():
    box = Box(center=np.array([0.6, 0.1]), size=[0.02, 0.3, 0.1], yaw=np.float32(0.5))
    assert box.center == (0.6, 0.1) and box.size == (0.02, 0.3, 0.1)
    assert all(type(v) is float for v in (*box.center, *box.size, box.yaw))
    assert box == Box((0.6, 0.1), (0.02, 0.3, 0.1), float(np.float32(0.5))) and hash(box) == hash(Box(**vars(box)))
    for bad in (dict(size=(0.1, 0.0, 0.1)), dict(size=(0.1, -0.1, 0.1)), dict(center=(math.nan, 0.0)),
                dict(center=(0.5,)), dict(size=(0.1, 0.1, 2 * WORLD_BOUND)), dict(yaw=math.inf)):
        with pytest.raises(InputError):
            Box(**{**dict(center=(0.5, 0.0), size=(0.1, 0.1, 0.1)), **bad})


def test_a_box_s_footprint_corners_turn_with_its_yaw_counter_clockwise():
    box = Box(center=(0.5, 0.1), size=(0.2, 0.1, 0.05))
    assert box.corners_xy() == pytest.approx(np.array([[0.4, 0.05], [0.6, 0.05], [0.6, 0.15], [0.4, 0.15]]))
    turned = Box(center=(0.5, 0.1), size=(0.2, 0.1, 0.05), yaw=math.pi / 2).corners_xy()
    assert turned == pytest.approx(np.array([[0.55, 0.0], [0.55, 0.2], [0.45, 0.2], [0.45, 0.0]]))
    x, y = turned[:, 0], turned[:, 1]
    assert 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) == pytest.approx(0.02)  # positive area: CCW


def test_the_dict_form_round_trips_and_takes_degrees():
    box = Box(center=(0.6, -0.2), size=(0.02, 0.3, 0.1), yaw=0.3)
    assert Box.from_dict(box.as_dict()) == box
    assert Box.from_dict({"center": [0.6, 0.0], "size": [0.1, 0.1, 0.1], "yaw_deg": 90}).yaw == pytest.approx(
        math.pi / 2)
    assert Box.from_dict({"center": np.array([0.6, 0.0]), "size": (0.1, 0.1, 0.1)}).yaw == 0.0
    assert as_box(box) is box and as_box(box.as_dict()) == box


@pytest.mark.parametrize("d, words", [
    ({"center": [0.6, 0.0]}, "obstacles[2]: missing field 'size'"),
    ({"center": [0.6, 0.0], "size": [0.1, 0.1, 0.1], "colour": "red"}, "obstacles[2]: unknown field(s) ['colour']"),
    ({"center": [0.6, 0.0], "size": [0.1, 0.1]}, "obstacles[2].size must be a list of 3 numbers"),
    ({"center": [0.6, "a"], "size": [0.1, 0.1, 0.1]}, "obstacles[2].center[1]"),
    ({"center": [0.6, 0.0], "size": [0.1, 0.0, 0.1]}, "obstacles[2].size must be positive"),
    ({"center": [0.6, 0.0], "size": [0.1, 0.1, 0.1], "yaw": 1.0, "yaw_deg": 5}, "not both"),
    ({"center": [60.0, 0.0], "size": [0.1, 0.1, 0.1]}, "magnitude at most 10 metres"),
    ([0.6, 0.0, 0.1], "obstacles[2] must be a mapping"),
])
def test_a_bad_dict_is_refused_naming_the_field(d, words):
    with pytest.raises(InputError) as info:
        Box.from_dict(d, "obstacles[2]")
    assert words in str(info.value)


def test_as_box_refuses_anything_else():
    with pytest.raises(InputError, match="must be an affordplan.Box or a dict"):
        as_box((0.5, 0.0, 0.1), "wall")
