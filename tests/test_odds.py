"""A plan's odds under closed-loop execution (planner.odds): retried steps within a primitive budget."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from affordplan.errors import InputError
from planner.odds import Q_FLOOR, fit_stuck_rates, mc_odds, plan_odds, primitives_pmf
from primitives.outcome_model import OutcomeModel


def test_certain_steps_take_one_primitive_each():
    odds = plan_odds([1.0, 1.0, 1.0], budget=10)
    assert odds.p_success == pytest.approx(1.0)
    assert odds.expected_primitives == pytest.approx(3.0)
    assert plan_odds([1.0, 1.0, 1.0], budget=2).p_success == pytest.approx(0.0)


def test_one_step_is_a_geometric_distribution():
    pmf = primitives_pmf([0.4], budget=5)
    assert pmf[1:] == pytest.approx([0.4 * 0.6 ** (k - 1) for k in range(1, 6)])
    assert plan_odds([0.4], budget=5).p_success == pytest.approx(1 - 0.6 ** 5)


def test_an_empty_plan_has_reached():
    odds = plan_odds([], budget=0)
    assert odds.p_success == 1.0 and odds.expected_primitives == 0.0


def test_a_large_budget_gives_the_mean_of_retries():
    odds = plan_odds([0.5, 0.25], budget=400)
    assert odds.p_success == pytest.approx(1.0, abs=1e-9)
    assert odds.expected_primitives == pytest.approx(1 / 0.5 + 1 / 0.25, rel=1e-6)


def test_matches_a_simulation_of_retried_steps():
    q, budget = [0.3, 0.6, 0.45, 0.8], 9
    rng = np.random.default_rng(0)
    totals = sum(rng.geometric(p, size=200_000) for p in q)
    assert plan_odds(q, budget).p_success == pytest.approx(np.mean(totals <= budget), abs=0.005)


@given(st.lists(st.floats(0.0, 1.0), min_size=1, max_size=8), st.integers(1, 80), st.floats(0.0, 0.5))
def test_odds_fall_when_a_step_gets_less_likely(q, budget, drop):
    worse = list(q)
    worse[0] = max(0.0, worse[0] - drop)
    assert plan_odds(worse, budget).p_success <= plan_odds(q, budget).p_success + 1e-12
    assert 0.0 <= plan_odds(q, budget).p_success <= 1.0


def test_a_step_rated_zero_is_floored_not_impossible():
    assert plan_odds([0.0], budget=60).p_success == pytest.approx(1 - (1 - Q_FLOOR) ** 60)


@pytest.mark.parametrize("bad", [[math.nan], [1.5], [-0.1]])
def test_bad_probabilities_are_refused(bad):
    with pytest.raises(InputError):
        plan_odds(bad)


# ------------------------------------------------------------------ mc_odds: Monte Carlo through outcome models
# (retries alone: stuck_rate=0.0; the shipped stuck rates have their own tests below)
class Constant:
    """An outcome model whose every call achieves ``value`` of the asked effect."""

    def __init__(self, value: float):
        self.value = value

    def sample_progress(self, p_strict, rng, n):
        return np.full(n, self.value)


def _model(skill: str, scale: float = 1.0, seed: int = 0) -> OutcomeModel:
    """Progress ~ scale * U(0, 2 p + 0.2): likelier calls achieve more."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(0.0, 1.0, 400)
    return OutcomeModel(skill, p, scale * rng.uniform(0.0, 2 * p + 0.2))


def test_mc_odds_is_deterministic_per_seed():
    models = {"push": _model("push"), "roll": _model("roll"), "spin": _model("spin")}
    steps = [("push", 0.3), ("push", 0.1), ("roll", 0.6), ("spin", 0.5), ("push", 0.2)]
    a, b = mc_odds(steps, models, budget=30, seed=4), mc_odds(steps, models, budget=30, seed=4)
    assert a == b
    other = mc_odds(steps, models, budget=30, seed=5)
    assert other.p_success == pytest.approx(a.p_success, abs=0.06)
    assert other.expected_primitives == pytest.approx(a.expected_primitives, rel=0.1)


@pytest.mark.parametrize("n_steps", [1, 3, 8])
def test_calls_that_always_achieve_their_step_take_one_primitive_each(n_steps):
    odds = mc_odds([("push", 0.05)] * n_steps, {"push": Constant(1.0)}, budget=20, n=100, stuck_rate=0.0)
    assert odds.p_success == 1.0 and odds.expected_primitives == n_steps


def test_odds_fall_when_progress_halves():
    steps = [("push", 0.05)] * 4
    assert mc_odds(steps, {"push": Constant(0.5)}, budget=8, stuck_rate=0.0).expected_primitives == 8
    assert mc_odds(steps, {"push": Constant(0.5)}, budget=7, stuck_rate=0.0).p_success == 0.0
    steps = [("push", 0.5)] * 4  # about 7 primitives at full progress, 14 at half
    full, half = _model("push"), _model("push", scale=0.5)
    for budget in (6, 10, 20):
        slow, fast = (mc_odds(steps, {"push": m}, budget, stuck_rate=0.0) for m in (half, full))
        assert slow.p_success < fast.p_success
    assert (mc_odds(steps, {"push": half}, 200, stuck_rate=0.0).expected_primitives
            == pytest.approx(2 * mc_odds(steps, {"push": full}, 200, stuck_rate=0.0).expected_primitives, rel=0.15))


def test_the_budget_caps():
    steps = [("push", 0.5)] * 5
    odds = mc_odds(steps, {"push": Constant(1.0)}, budget=3, stuck_rate=0.0)
    assert odds.p_success == 0.0 and odds.expected_primitives == 3 and odds.budget == 3
    assert mc_odds(steps, {"push": Constant(0.0)}, budget=40, stuck_rate=0.0).expected_primitives == 40
    assert mc_odds(steps, {"push": Constant(1.0)}, budget=0, stuck_rate=0.0).expected_primitives == 0


def test_surplus_carries_over_within_a_stretch_of_one_skill_only():
    models = {"push": Constant(1.4), "roll": Constant(1.0), "spin": Constant(1.4)}
    # five pushes: 1.4, 2.8, 4.2, 5.6 -> four primitives
    assert mc_odds([("push", 0.5)] * 5, models, budget=20, stuck_rate=0.0).expected_primitives == 4
    # a roll between two pairs of pushes: 2 + 1 + 2 primitives (no carry across the roll)
    steps = [("push", 0.5)] * 2 + [("roll", 0.5)] + [("push", 0.5)] * 2
    assert mc_odds(steps, models, budget=20, stuck_rate=0.0).expected_primitives == 5
    # a spin after a push starts from nothing
    assert mc_odds([("push", 0.5), ("spin", 0.5)], models, budget=20, stuck_rate=0.0).expected_primitives == 2


def test_negative_progress_counts_zero_and_a_roll_needs_its_state():
    assert mc_odds([("push", 0.5)], {"push": Constant(-3.0)}, budget=10, stuck_rate=0.0).p_success == 0.0
    roll_misses = {"roll": Constant(0.9)}
    assert mc_odds([("roll", 0.9)], roll_misses, budget=10, stuck_rate=0.0).p_success == 0.0
    assert mc_odds([("roll", 0.9), ("roll", 0.9)], {"roll": Constant(2.0)}, 10, stuck_rate=0.0).expected_primitives == 2


def test_mc_odds_follows_the_geometric_model_for_all_or_nothing_calls():
    q = [0.3, 0.6, 0.45]
    models = {s: OutcomeModel(s, np.full(1000, p), (np.arange(1000) < 1000 * p).astype(float), k=1000)
              for s, p in zip(("push", "spin", "roll"), q)}
    steps = [("push", 0.3), ("spin", 0.6), ("roll", 0.45)]
    odds = mc_odds(steps, models, budget=9, n=20_000, stuck_rate=0.0)
    assert odds.p_success == pytest.approx(plan_odds(q, 9).p_success, abs=0.015)


def test_an_empty_plan_has_reached_by_mc():
    odds = mc_odds([], {}, budget=5, stuck_rate=0.0)
    assert odds.p_success == 1.0 and odds.expected_primitives == 0.0


@pytest.mark.parametrize("steps", [[("push", 1.5)], [("push", math.nan)], [("slide", 0.5)], [("push",)]])
def test_mc_odds_refuses_bad_steps(steps):
    with pytest.raises(InputError):
        mc_odds(steps, {"push": Constant(1.0)}, budget=10, stuck_rate=0.0)


# ------------------------------------------------------------------ stuck steps
def _all_or_nothing(skills=("push", "spin", "roll")) -> dict:
    """Outcome models whose calls achieve their whole step with probability p, else nothing."""
    grid = np.linspace(0.0, 1.0, 1001)
    rng = np.random.default_rng(0)
    return {s: OutcomeModel(s, grid, (rng.random(grid.size) < grid).astype(float), k=50) for s in skills}


def test_a_stuck_step_fails_its_run_however_large_the_budget():
    q = [0.3, 0.8, 0.6]
    steps = list(zip(("push", "spin", "roll"), q))
    models = _all_or_nothing()
    assert mc_odds(steps, models, budget=200, n=20_000, stuck_rate=0.0).p_success > 0.99
    for rate in (0.3, 1.0):
        expected = float(np.prod([1.0 - rate * (1.0 - qi) for qi in q]))
        odds = mc_odds(steps, models, budget=200, n=20_000, stuck_rate=rate)
        assert odds.p_success == pytest.approx(expected, abs=0.015)
        free = mc_odds(steps, models, budget=200, n=20_000, stuck_rate=0.0)
        assert odds.expected_primitives > free.expected_primitives


def test_certain_steps_are_never_stuck():
    odds = mc_odds([("push", 1.0)] * 3, {"push": Constant(1.0)}, budget=10, n=500, stuck_rate=1.0)
    assert odds.p_success == 1.0 and odds.expected_primitives == 3.0


@pytest.mark.parametrize("rate", [-0.1, 1.5, math.nan])
def test_a_stuck_rate_outside_zero_one_is_refused(rate):
    with pytest.raises(InputError, match="stuck_rate"):
        mc_odds([("push", 0.5)], {"push": Constant(1.0)}, budget=10, stuck_rate=rate)


def test_fit_stuck_rates_recovers_the_rates_that_made_the_outcomes():
    rng = np.random.default_rng(3)
    models = _all_or_nothing()
    truth = {"push": 0.1, "roll": 0.9, "spin": 0.0}
    plans, reached = [], []
    for _ in range(300):
        steps = [(str(rng.choice(["push", "spin", "roll"])), float(rng.uniform(0.05, 0.95)))
                 for _ in range(int(rng.integers(1, 5)))]
        plans.append(steps)
        reached.append(bool(rng.random() < np.prod([1.0 - truth[k] * (1.0 - q) for k, q in steps])))
    rates, brier, without = fit_stuck_rates(plans, reached, models, budget=80, grid=np.linspace(0, 1, 11), n=300)
    assert set(rates) == {"push", "roll", "spin"}
    assert rates["roll"] >= 0.6 and rates["push"] <= 0.3 and rates["spin"] <= 0.3
    assert brier < without
    with pytest.raises(InputError):
        fit_stuck_rates(plans, reached[:-1], models)


def test_a_rate_per_skill_applies_to_that_skills_steps_only():
    models = _all_or_nothing()
    steps = [("push", 0.5), ("roll", 0.5)]
    only_roll = mc_odds(steps, models, budget=200, n=20_000, stuck_rate={"push": 0.0, "roll": 1.0, "spin": 1.0})
    assert only_roll.p_success == pytest.approx(0.5, abs=0.015)


def test_the_shipped_stuck_rates_make_a_doubtful_roll_a_doubtful_plan():
    """With the shipped rates (roll 0.7), a roll rated 0.5 leaves a plan about 1 - 0.7 * 0.5 = 0.65 to reach its goal
    however large the budget; retries alone would promise it."""
    from planner.odds import STUCK_RATES

    models = _all_or_nothing()
    shipped = mc_odds([("roll", 0.5)], models, budget=200, n=20_000)
    assert shipped.p_success == pytest.approx(1.0 - STUCK_RATES["roll"] * 0.5, abs=0.015)
    assert mc_odds([("roll", 0.5)], models, budget=200, n=20_000, stuck_rate=0.0).p_success > 0.99


# ------------------------------------------------------------------ tips
def test_a_step_that_cannot_tip_keeps_its_odds_exactly():
    models = {"push": _model("push"), "roll": _model("roll"), "spin": _model("spin")}
    pairs = [("push", 0.3), ("roll", 0.6), ("spin", 0.5)]
    triples = [(k, p, 0.0) for k, p in pairs]
    assert mc_odds(pairs, models, budget=30, seed=2) == mc_odds(triples, models, budget=30, seed=2)


def test_a_fatal_tip_loses_the_run_on_each_try():
    """Two pushes that always achieve their step, each try lost with probability t: the run survives 1 - t twice."""
    steps = [("push", 0.5, 0.3), ("push", 0.5, 0.3)]
    odds = mc_odds(steps, {"push": Constant(1.0)}, budget=20, n=20_000, stuck_rate=0.0, tip_fatal=1.0)
    assert odds.p_success == pytest.approx(0.7 ** 2, abs=0.015)
    half = mc_odds(steps, {"push": Constant(1.0)}, budget=20, n=20_000, stuck_rate=0.0, tip_fatal=0.5)
    assert half.p_success == pytest.approx(0.85 ** 2, abs=0.015)
    assert mc_odds(steps, {"push": Constant(1.0)}, budget=20, stuck_rate=0.0, tip_fatal=0.0).p_success == 1.0


def test_slow_steps_risk_a_tip_on_every_try():
    """A push achieving half its step takes two tries, so it risks two tips."""
    one = mc_odds([("push", 0.5, 0.2)], {"push": Constant(0.5)}, budget=20, n=20_000, stuck_rate=0.0, tip_fatal=1.0)
    assert one.p_success == pytest.approx(0.8 ** 2, abs=0.015)


@pytest.mark.parametrize("steps,kwargs", [([("push", 0.5, 1.5)], {}), ([("push", 0.5, math.nan)], {}),
                                          ([("push", 0.5, 0.1, 0.2)], {}), ([("push", 0.5, 0.1)], {"tip_fatal": 2.0})])
def test_bad_tips_are_refused(steps, kwargs):
    with pytest.raises(InputError, match="tip"):
        mc_odds(steps, {"push": Constant(1.0)}, budget=10, **kwargs)


def test_fit_odds_recovers_the_fatal_share_of_tips():
    from planner.odds import fit_odds

    rng = np.random.default_rng(5)
    models = {"push": Constant(1.0)}
    plans, reached = [], []
    for _ in range(400):
        steps = [("push", 0.5, float(rng.choice([0.0, 0.5]))) for _ in range(int(rng.integers(1, 4)))]
        plans.append(steps)
        reached.append(bool(rng.random() < np.prod([1.0 - 0.6 * t for _, _, t in steps])))
    rates, fatal, brier, without = fit_odds(plans, reached, models, budget=20, grid=[0.0, 0.5, 1.0],
                                            fatal_grid=np.linspace(0, 1, 11), n=2000)
    assert fatal == pytest.approx(0.6, abs=0.15)
    assert rates["push"] == 0.0  # a step that always achieves its effect is never stuck: q = 0.5 gives nothing
    assert brier < without


# ------------------------------------------------------------------ pushes of several strides: one call, many strokes
def test_a_push_of_several_strides_is_one_call_of_up_to_strides_plus_one_strokes():
    # three strides, every stroke a full stride: one call
    assert mc_odds([("push", 0.5, 0.0, 3)], {"push": Constant(1.0)}, budget=20, stuck_rate=0.0
                   ).expected_primitives == 1
    # half a stride per stroke: six strokes; the first call makes four (2 strides), the second the other two
    assert mc_odds([("push", 0.5, 0.0, 3)], {"push": Constant(0.5)}, budget=20, stuck_rate=0.0
                   ).expected_primitives == 2
    # the same three strides as three one-stroke calls: six primitives
    assert mc_odds([("push", 0.5)] * 3, {"push": Constant(0.5)}, budget=20, stuck_rate=0.0).expected_primitives == 6
    # a call ends with its strides: the spin after it is a call of its own
    models = {"push": Constant(1.0), "spin": Constant(1.0)}
    assert mc_odds([("push", 0.5, 0.0, 2), ("spin", 0.5)], models, budget=20, stuck_rate=0.0
                   ).expected_primitives == 2


def test_one_stride_is_a_step_as_before():
    models = {"push": _model("push"), "roll": _model("roll"), "spin": _model("spin")}
    plain = [("push", 0.3, 0.1), ("roll", 0.6, 0.0), ("push", 0.2, 0.05)]
    assert mc_odds(plain, models, budget=30, seed=2) == mc_odds([s + (1,) for s in plain], models, budget=30, seed=2)


def test_merging_strides_raises_the_odds_within_a_budget():
    models = {"push": _model("push")}
    one = mc_odds([("push", 0.4)] * 8, models, budget=8, stuck_rate=0.0)
    merged = mc_odds([("push", 0.4, 0.0, 4)] * 2, models, budget=8, stuck_rate=0.0)
    assert merged.p_success > one.p_success and merged.expected_primitives < one.expected_primitives


@pytest.mark.parametrize("bad", [("push", 0.5, 0.0, 0), ("push", 0.5, 0.0, 1.5), ("push", 0.5, 0.0, 2, 9)])
def test_bad_strides_are_refused(bad):
    with pytest.raises(InputError):
        mc_odds([bad], {"push": Constant(1.0)}, budget=5)


def test_stuck_rates_fit_plans_with_strides():
    """A push of three strides is stuck per stride, as mc_odds draws it: at rate 1 and p 0.5 it gets through with
    probability 0.5 ** 3, not 0.5."""
    plans = [[("push", 0.5, 0.0, 3)]]
    rates, brier, bare = fit_stuck_rates(plans, [False], {"push": Constant(1.0)}, budget=10, n=200, grid=(0.0, 1.0))
    assert rates["push"] == 1.0 and bare == 1.0 and brier == pytest.approx(0.125 ** 2)
