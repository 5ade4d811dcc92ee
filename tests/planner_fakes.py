"""Stand-in skills and predictors with known behaviour, shared by the planner's tests.

The stand-ins move the object to the pose the call asks for, or fail on purpose, so that the tests check the
planner, not the learned policies.
"""

from __future__ import annotations

import numpy as np

from affordplan.sim.simulator import Outcome
from planner.plan import Planner
from planner.predict import expected_pose


class IdealSkill:
    """Does exactly what it is asked (teleports the object), except calls listed in ``fail``."""

    def __init__(self, name: str, fail=lambda params, state: False):
        self.name, self.fail, self.calls = name, fail, []

    def execute(self, sim, params, stop_at_angle=True, steer=True):
        T0 = sim.object_pose()
        state = sim.obj.classify(T0)
        self.calls.append((state, dict(params)))
        ok = not self.fail(params, state)
        T1 = expected_pose(sim.obj, self.name, params, T0) if ok else T0
        sim.set_object_pose(T1, settle=False)
        return Outcome(T0, T1, 0, True, True, 0.0, success=ok)


class StubPredictor:
    """Rates every call ``p`` (0.8 by default)."""

    def __init__(self, skills, p=0.8):
        self.skills, self.p, self.queries = skills, p, 0

    def p_success(self, skill, params, T):
        return self.p

    def p_success_many(self, queries):
        return np.full(len(queries), self.p)


def ideal_planner(obj, obstacles=(), fail_roll=None):
    """A planner over ideal push, spin and roll stand-ins; ``fail_roll=(state, target)``: that roll always fails."""
    skills = {n: IdealSkill(n) for n in ("push", "spin", "roll")}
    if fail_roll:
        skills["roll"] = IdealSkill("roll", fail=lambda params, state: (state, params["target"]) == fail_roll)
    return Planner(obj, obstacles, predictor=StubPredictor(skills), time_limit=5.0, seed=0)
