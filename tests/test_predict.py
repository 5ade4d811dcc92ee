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


def test_each_rating_comes_with_its_members_disagreement(cube):
    """spread_many answers query by query, as p_success_many does: the same query gives the same spread wherever
    it stands in a batch, and the shipped five-member models disagree a little (0 < spread < 0.5)."""
    import numpy as np

    from planner.predict import Predictor

    predictor = Predictor(cube, seed=0)
    T = cube.resting_states[0].pose((0.5, 0.0), 0.3)
    queries = [("push", {"direction": 0.4}, T), ("spin", {"angle": 0.8}, T), ("roll", None, T),
               ("push", None, T)]
    spread = predictor.spread_many(queries)
    p = predictor.p_success_many(queries)
    assert spread.shape == p.shape == (4,) and np.all(np.isfinite(spread))
    assert np.all((spread > 0) & (spread < 0.5))
    again = predictor.spread_many(queries[::-1])[::-1]
    assert np.allclose(again, spread, atol=1e-6)
