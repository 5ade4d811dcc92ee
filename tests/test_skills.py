"""Skills with the arm: a contact it cannot reach is masked out and the policy's next best one is tried."""

from __future__ import annotations

import numpy as np
import pytest

import affordplan as ap
from affordplan.errors import ReachabilityError
from primitives import load_skill
from primitives import skills as skills_module


class _ReachLimited(ap.Simulator):
    """A finger simulator that refuses (before any physics, as the arm does) the first ``refuse`` contacts."""

    def __init__(self, *args, refuse: int, **kwargs):
        super().__init__(*args, **kwargs)
        self.refuse = refuse
        self.asked: list[np.ndarray] = []

    def execute(self, contact, motion, normal=None):
        self.asked.append(np.asarray(contact, dtype=float))
        if len(self.asked) <= self.refuse:
            raise ReachabilityError("the arm cannot reach this contact (test)")
        return super().execute(contact, motion, normal=normal)


def test_an_unreachable_contact_gives_way_to_the_next_best_reachable_one(cube):
    sim = _ReachLimited(cube, seed=0, refuse=2)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.0)
    out = load_skill("push").execute(sim, {"direction": 0.0})
    assert len(sim.asked) == 3 and out.valid and isinstance(out.success, bool)
    assert np.allclose(out.contact, sim.asked[2])  # the third choice was executed
    # each retry is outside the masked neighbourhood of every contact refused before it
    for k in (1, 2):
        gaps = [np.linalg.norm(sim.asked[k] - sim.asked[j]) for j in range(k)]
        assert min(gaps) > skills_module.UNREACHABLE_RADIUS


def test_a_skill_gives_up_after_its_retries_with_the_reachability_error(cube):
    sim = _ReachLimited(cube, seed=0, refuse=10**6)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.0)
    with pytest.raises(ReachabilityError):
        load_skill("push").execute(sim, {"direction": 0.0})
    assert len(sim.asked) == skills_module.MAX_REACH_RETRIES + 1
