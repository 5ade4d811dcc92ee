"""The planner's ratings of resting states (planner.ratings): asked once, at one place, read off as asked."""

import math

import numpy as np
import pytest

import affordplan as ap
from planner.ratings import SPIN_RATE_GRID, StateRatings


class CountingPredictor:
    """Rates a spin by its angle (0.9 at 15 deg falling to 0.3 at 45 deg; half that clockwise), a roll by its
    target, and records every query."""

    def __init__(self):
        self.asked = []

    def p_success_many(self, queries):
        self.asked.append(list(queries))
        out = []
        for skill, params, _ in queries:
            if skill == "spin":
                a = params["angle"]
                p = 0.9 - 0.6 * (abs(a) - math.radians(15)) / math.radians(30)
                out.append(p if a > 0 else 0.5 * p)
            else:
                out.append(0.1 * (params["target"] + 1))
        return np.array(out)


@pytest.fixture
def ratings():
    return StateRatings(ap.load_object("cube"), CountingPredictor(), (0.5, -0.1))


def test_spin_rates_interpolate_one_row_per_sense(ratings):
    rate = ratings.spin_rate(1)
    assert rate(math.radians(20)) == pytest.approx(0.8)  # between the 15 and 25 deg entries
    assert rate(math.radians(45)) == pytest.approx(0.3)
    assert rate(-math.radians(20)) == pytest.approx(0.4)
    rate(math.radians(33))
    rate(-math.radians(40))
    assert len(ratings.predictor.asked) == 2  # one row each way
    assert all(len(q) == len(SPIN_RATE_GRID) for q in ratings.predictor.asked)


def test_rolls_are_rated_in_one_batch_from_each_edges_own_state(ratings):
    p = ratings.rolls([(0, 1), (0, 2), (3, 0)])
    assert p == pytest.approx([0.2, 0.3, 0.1])
    (query,) = ratings.predictor.asked
    assert [ratings.obj.classify(q[2]) for q in query] == [0, 0, 3]
