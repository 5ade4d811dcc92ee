"""The predictor and pose helpers (planner.predict): weights folders or skills, planar poses."""

from pathlib import Path

import pytest

import affordplan as ap
from affordplan.errors import InputError


def test_pose_helpers_round_trip():
    cube = ap.load_object("cube")
    T = cube.resting_states[3].pose((0.52, -0.04), 1.1)
    state, x, y, yaw = cube.planar_pose(T)
    assert (state, round(x, 6), round(y, 6)) == (3, 0.52, -0.04) and yaw == pytest.approx(1.1)


def test_a_predictor_loads_a_weights_folder_or_takes_skills_not_both(cube):
    from planner.predict import Predictor

    kept = Path(__file__).resolve().parents[1] / "candidates" / "push_0.18"  # push only, fitted before the lever arm
    predictor = Predictor(cube, weights_dir=kept)
    assert predictor.skills["push"].success_model.net.n_decision == 13
    assert Predictor(cube).skills["push"].success_model.net.n_decision == 14
    with pytest.raises(InputError, match="not both"):
        Predictor(cube, skills=predictor.skills, weights_dir=kept)
