"""Affordance tables (primitives.affordances), with stand-in skills whose odds and outcomes are known: one row per
state and asked parameter, push directions relative to the object's heading, predicted and measured rates averaged
over the trials, and the table as text, dicts and a picture."""

from __future__ import annotations

import math

import numpy as np
import pytest
from PIL import Image

from affordplan.geometry import wrap_angle
from primitives import params as skill_params
from primitives.affordances import SPIN_ANGLE, Affordance, affordance_table, as_dicts, format_table, plot_table


class _Skill:
    """Predicts ``p`` and succeeds on every other execution; records each call's object yaw and parameter."""

    def __init__(self, p: float):
        self.p, self.calls, self.executed = p, [], 0

    def success_probability(self, sim, params):
        T = sim.object_pose()
        state = sim.obj.classify(T)
        self.calls.append((state, sim.obj.resting_states[state].yaw_of(T[:3, :3]), dict(params)))
        return self.p

    def execute(self, sim, params, stop_at_angle=True, steer=True):
        self.executed += 1
        return type("Outcome", (), {"success": self.executed % 2 == 0})()


@pytest.fixture(scope="module")
def table(pill_bottle):
    skills = {"push": _Skill(0.25), "spin": _Skill(0.5), "roll": _Skill(0.75)}
    return skills, affordance_table(pill_bottle, trials=2, sectors=4, seed=0, skills=skills, progress=False)


def test_every_state_gets_a_row_per_asked_parameter(pill_bottle, table):
    _, rows = table
    for s in pill_bottle.resting_states:
        labels = [r.label for r in rows if r.state == s.index]
        rolls = [f"roll -> {t}" for t in skill_params.roll_targets(pill_bottle, s.index)]
        assert labels == ["push 0deg", "push 90deg", "push 180deg", "push 270deg", "spin +30deg", "spin -30deg",
                          *rolls]
    assert all(r.trials == 2 for r in rows)


def test_push_directions_are_turned_with_the_object_s_heading(table):
    skills, rows = table
    pushes = skills["push"].calls
    assert len(pushes) == 2 * sum(r.skill == "push" for r in rows)
    offsets = [params["direction"] - yaw for _, yaw, params in pushes]
    sectors = [math.radians(float(r.label.split()[1].removesuffix("deg"))) for r in rows if r.skill == "push"]
    gaps = [wrap_angle(offset - sector) for offset, sector in zip(offsets, np.repeat(sectors, 2))]
    assert np.abs(gaps) == pytest.approx(np.zeros(len(gaps)), abs=0.03)  # the settled yaw, not the drawn one
    assert {round(p["angle"], 9) for _, _, p in skills["spin"].calls} == {round(SPIN_ANGLE, 9), round(-SPIN_ANGLE, 9)}
    assert len({yaw for _, yaw, _ in pushes}) > 10  # every trial starts at a fresh random yaw


def test_predicted_and_measured_rates_are_means_over_the_trials(table):
    _, rows = table
    assert {r.skill: r.predicted for r in rows} == {"push": 0.25, "spin": 0.5, "roll": 0.75}
    assert all(r.measured == 0.5 for r in rows)  # one success in each pair of executions


def test_the_table_as_text_dicts_and_a_picture(pill_bottle, table, tmp_path):
    _, rows = table
    text = format_table(pill_bottle, rows)
    lines = text.splitlines()
    assert lines[0] == "pill_bottle: predicted P(success) / measured rate (2 trials each)"
    assert sum(line.startswith("state ") for line in lines) == len(pill_bottle.resting_states)
    assert "  push 90deg      0.25 / 0.50" in lines and "rolling family" in text
    assert as_dicts(rows[:1]) == [dict(state=rows[0].state, skill="push", label="push 0deg", predicted=0.25,
                                       measured=0.5, trials=2)]
    assert format_table(pill_bottle, []).splitlines()[0] == "pill_bottle"
    plot_table(pill_bottle, rows, tmp_path / "table.png")
    image = np.asarray(Image.open(tmp_path / "table.png").convert("RGB"))
    assert image.shape[0] > image.shape[1] / 2 and len(np.unique(image.reshape(-1, 3), axis=0)) > 10
    assert Affordance(0, "push", "push 0deg", 0.1, 0.2, 3).trials == 3
