"""Pictures of resting states (affordplan.app.render), called directly: one rendered image per asked state, labels
naming each state, a labelled grid, and the states and sizes it refuses."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from affordplan.app.render import render_states, save_states_picture, state_label
from affordplan.errors import InputError


def test_each_asked_state_is_rendered_and_the_states_look_different(lunch_box):
    images = render_states(lunch_box, [0, 2], width=64, height=48)
    assert [s for s, _ in images] == [0, 2]
    for _, image in images:
        assert image.shape == (48, 64, 3) and image.dtype == np.uint8 and image.std() > 5  # a scene, not a blank
    assert np.abs(images[0][1].astype(int) - images[1][1].astype(int)).mean() > 1.0  # lying flat vs on its side
    again = render_states(lunch_box, [2], width=64, height=48)
    assert np.array_equal(again[0][1], images[1][1])  # the same state renders the same


@pytest.mark.parametrize("states, size, words", [
    ([6], (64, 48), "lunch_box has 6 resting states (0..5), got state 6"),
    ([1.5], (64, 48), "got state 1.5"),
    ([0], (8, 48), "image size must be within 16x16..1280x960 pixels, got 8x48"),
    ([0], (64, 2000), "got 64x2000"),
])
def test_states_and_sizes_out_of_range_are_refused(lunch_box, states, size, words):
    with pytest.raises(InputError) as info:
        render_states(lunch_box, states, width=size[0], height=size[1])
    assert words in str(info.value)


def test_labels_name_the_state_its_probability_and_up_vector(cube, pill_bottle):
    assert state_label(cube, 0) == f"state 0  p={cube.resting_states[0].probability:.2f}  up (+0.00, +0.00, +1.00)"
    rolling = next(s.index for s in pill_bottle.resting_states if s.is_rolling_family)
    assert state_label(pill_bottle, rolling).endswith("(rolls)")


def test_the_picture_lays_the_tiles_out_in_a_grid(cube, tmp_path):
    tiles = [(i, np.full((30, 40, 3), 40 * i, np.uint8)) for i in range(5)]
    path = save_states_picture(cube, tiles, tmp_path / "sub" / "cube.png", columns=3)
    assert path == tmp_path / "sub" / "cube.png"
    grid = np.asarray(Image.open(path).convert("RGB"))
    assert grid.shape == (60, 120, 3)  # 2 rows of 3 columns
    assert np.all(grid[25, 45] == 40) and np.all(grid[55, 45] == 160)  # tile 1 top-middle, tile 4 bottom-middle
    assert np.all(grid[55, 100] == 255)  # the sixth place is empty
    assert (grid[2:14, 2:38] < 128).any()  # a label over each tile
    with pytest.raises(InputError, match="no images"):
        save_states_picture(cube, [], tmp_path / "none.png")
