"""Pictures of plans (planner.plot, matplotlib's Agg backend): a plan drawn to a PNG shows its obstacles and path in
their colours, an execution adds to it, and a frame strip lays the chosen frames side by side."""

from __future__ import annotations

import types

import numpy as np
import pytest
from PIL import Image
from planner_fakes import ideal_planner

import affordplan as ap
from planner.plot import plot_plan, save_frames

WALLS = (ap.Box(center=(0.6, -0.2), size=(0.02, 0.2, 0.1)), ap.Box(center=(0.6, 0.2), size=(0.02, 0.2, 0.1)))


def _pixels(path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB")).reshape(-1, 3)


def _share(pixels: np.ndarray, colour: str) -> float:
    rgb = np.array([int(colour[i:i + 2], 16) for i in (1, 3, 5)])
    return float(np.mean(np.all(np.abs(pixels.astype(int) - rgb) <= 2, axis=1)))


@pytest.fixture(scope="module")
def plan(cube):
    return ideal_planner(cube, WALLS).plan(cube.resting_states[0].pose((0.42, 0.15), 0.4),
                                           ap.Goal(xy=(0.69, 0.0), yaw=0.0))


def test_a_plan_is_drawn_with_its_obstacles_and_path(plan, tmp_path):
    plot_plan(plan, tmp_path / "plan.png")
    pixels = _pixels(tmp_path / "plan.png")
    assert Image.open(tmp_path / "plan.png").size == (720, 840)  # 6 x 7 inches at 120 dpi
    assert len(np.unique(pixels, axis=0)) > 20  # a picture, not one colour
    assert _share(pixels, "#ffffff") > 0.5  # mostly background
    assert _share(pixels, "#555555") > 0.002  # the walls, filled
    assert _share(pixels, "#2e8b57") > 1e-4  # the planned path (a thin line: 60 pixels or more)


def test_an_execution_adds_its_path_and_final_footprint(plan, tmp_path):
    plot_plan(plan, tmp_path / "plan.png")
    T = plan.start_pose.copy()
    T_end = plan.steps[-1].expected_pose.copy()
    execution = types.SimpleNamespace(log=[types.SimpleNamespace(pose_before=T)], final_pose=T_end, success=True,
                                      n_primitives=1, replans=0)
    plot_plan(plan, tmp_path / "executed.png", execution=execution, title="executed")
    before, after = _pixels(tmp_path / "plan.png"), _pixels(tmp_path / "executed.png")
    assert before.shape == after.shape and not np.array_equal(before, after)
    assert _share(after, "#000000") > _share(before, "#000000")  # the executed path is drawn in black


def test_a_frame_strip_shows_evenly_spaced_frames_first_and_last_included(tmp_path):
    frames = [np.full((40, 60, 3), 25 * i, np.uint8) for i in range(10)]
    save_frames(frames, tmp_path / "strip.png", n=4)
    strip = Image.open(tmp_path / "strip.png")
    assert strip.size == (1200, 240)  # four 3 x 2.4 inch panels at 100 dpi
    pixels = _pixels(tmp_path / "strip.png")
    for shade in (0, 75, 150, 225):  # frames 0, 3, 6 and 9
        assert _share(pixels, f"#{shade:02x}{shade:02x}{shade:02x}") > 0.01
    assert _share(pixels, "#323232") < 0.001  # frame 2 is not among them
    save_frames([], tmp_path / "none.png")
    assert not (tmp_path / "none.png").exists()  # nothing to show: nothing written
