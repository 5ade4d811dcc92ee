"""Footprints: an object's convex shadow on the table, its inflation and its placement."""

from __future__ import annotations

import math

import numpy as np
import pytest

from affordplan.errors import InputError
from planner.footprint import area, convex_hull_2d, footprint, inflate, place


def _is_ccw_convex(polygon: np.ndarray) -> bool:
    e = np.roll(polygon, -1, axis=0) - polygon
    cross = e[:, 0] * np.roll(e[:, 1], -1) - e[:, 1] * np.roll(e[:, 0], -1)
    return bool(np.all(cross > -1e-12))


def test_cube_footprint_is_a_10cm_square_in_every_state(cube):
    for state in range(len(cube.resting_states)):
        fp = footprint(cube, state)
        assert fp.shape[1] == 2 and _is_ccw_convex(fp)
        assert area(fp) == pytest.approx(0.01, rel=0.01)
        assert np.allclose(fp.max(axis=0) - fp.min(axis=0), 0.1, atol=1e-3)
        assert np.allclose(fp.mean(axis=0), 0.0, atol=1e-3)  # centred on the centre of mass


def test_lying_pill_bottle_is_a_rectangle_along_its_heading(pill_bottle):
    state = next(s for s in pill_bottle.resting_states if s.is_rolling_family)
    fp = footprint(pill_bottle, state.index)
    length, width = fp.max(axis=0) - fp.min(axis=0)
    diameter = float(pill_bottle.mesh.extents[0])
    assert length == pytest.approx(0.1, rel=0.03)  # at yaw 0 the roll axis lies along world x
    assert width == pytest.approx(diameter, rel=0.02)
    assert area(fp) == pytest.approx(length * width, rel=0.05)
    assert _is_ccw_convex(fp)


def test_standing_pill_bottle_is_a_disc(pill_bottle):
    standing = [s for s in pill_bottle.resting_states if not s.is_rolling_family]
    assert standing
    fp = footprint(pill_bottle, standing[0].index)
    radius = 0.5 * float(pill_bottle.mesh.extents[0])
    assert area(fp) == pytest.approx(math.pi * radius**2, rel=0.02)
    assert np.allclose(np.hypot(fp[:, 0], fp[:, 1]), radius, rtol=0.02)


def test_footprint_rejects_unknown_states(cube):
    for bad in (-1, 6, 1.0, True):
        with pytest.raises(InputError):
            footprint(cube, bad)


def test_inflation_grows_the_area_by_perimeter_times_radius():
    square = np.array([[-0.05, -0.05], [0.05, -0.05], [0.05, 0.05], [-0.05, 0.05]])
    r = 0.01
    grown = inflate(square, r)
    assert _is_ccw_convex(grown)
    exact = 0.01 + 0.4 * r + math.pi * r**2  # Minkowski sum with the disc (Steiner formula)
    n = 16
    outer = 0.01 + 0.4 * r + n * math.tan(math.pi / n) * r**2  # with the circumscribing 16-gon
    assert exact - 1e-12 <= area(grown) <= outer + 1e-12
    # the 16-gon has edges facing the axes, so the square's sides move out by exactly r
    assert np.allclose(grown.max(axis=0), 0.05 + r) and np.allclose(grown.min(axis=0), -0.05 - r)
    # and it contains the exact inflated region: every point at distance r from a corner is inside
    t = np.linspace(0.0, 2.0 * math.pi, 200)
    ring = np.array([0.05, 0.05]) + r * np.column_stack([np.cos(t), np.sin(t)])
    e = np.roll(grown, -1, axis=0) - grown
    inward = np.column_stack([-e[:, 1], e[:, 0]])
    assert np.all(np.einsum("kj,pkj->pk", inward, ring[:, None, :] - grown[None]) >= -1e-12)
    assert area(inflate(square, 0.0)) == pytest.approx(0.01)


def test_inflate_validates_its_input():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    with pytest.raises(InputError):
        inflate(square, -0.01)
    with pytest.raises(InputError):
        inflate(square, float("nan"))
    with pytest.raises(InputError):
        inflate(np.array([[0.0, 0.0], [1.0, 1.0]]), 0.01)
    with pytest.raises(InputError):
        convex_hull_2d(np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]))  # collinear


def test_place_rotates_then_translates():
    rect = np.array([[-0.1, -0.02], [0.1, -0.02], [0.1, 0.02], [-0.1, 0.02]])
    placed = place(rect, 0.5, 0.1, math.pi / 2)
    assert np.allclose(placed.min(axis=0), [0.48, 0.0]) and np.allclose(placed.max(axis=0), [0.52, 0.2])
    assert area(placed) == pytest.approx(area(rect))  # orientation (CCW) is kept
    assert np.allclose(placed[1], [0.52, 0.2])  # (0.1, -0.02) turned by 90 deg
    with pytest.raises(InputError):
        place(rect, float("nan"), 0.0, 0.0)
