"""Evaluation of a policy (primitives.training.evaluate): deterministic figures and greedy actions, what a result
reports, calls of several strokes, the objects an evaluation names."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from affordplan.errors import InputError
from primitives.networks import HybridActorCritic
from primitives.skills import load_skill
from primitives.training.env import SEED_SEVEN, EnvConfig, PrimitiveEnv
from primitives.training.evaluate import (
    EvalResult,
    evaluate,
    evaluate_strokes,
    greedy_action,
    main,
    object_list,
    seed_reference,
)


def test_evaluation_is_deterministic():
    torch.manual_seed(1)
    model = HybridActorCritic().eval()
    a = evaluate(model, "spin", ("cube",), trials=4, seed=5, progress=False)
    b = evaluate(model, "spin", ("cube",), trials=4, seed=5, progress=False)
    assert a.per_object == b.per_object
    env = PrimitiveEnv(EnvConfig("spin", objects=("cube",), n_points=64), seed=0)
    obs = env.reset()
    first, second = greedy_action(model, obs), greedy_action(model, obs)
    assert first[0] == second[0] and np.array_equal(first[1], second[1])


def test_results_count_per_object_and_the_stand_ins_a_search_acted_as():
    result = EvalResult("push", "seed7", per_object={"cube": [True, False, True, True], "mug": [False, False]},
                        outcomes=[True, False, True, True, False, False], acted_as=[None, {"direction": 0.0}, None,
                                                                                   None, {"direction": 1.0}, None])
    assert result.success_rate == 0.5 and result.rates() == {"cube": 0.75, "mug": 0.0}
    assert result.calibration() is None  # nothing rated
    d = result.as_dict()
    assert d["trials"] == 6 and d["per_object"] == {"cube": 0.75, "mug": 0.0} and "calibration" not in d
    assert d["stand_in_share"] == pytest.approx(2 / 6) and d["stand_in_success"] == 0.0
    rated = EvalResult("spin", "random", per_object={"random": [True, False]}, outcomes=[True, False],
                       predicted=[0.9, 0.2], frames="best of 12 free frames")
    assert rated.as_dict()["frames"] == "best of 12 free frames" and rated.calibration()["auroc"] == 1.0
    assert EvalResult("roll", "random").success_rate == 0.0  # no trials yet


def test_the_seed_objects_and_their_real_counterparts_are_named_for_evaluation():
    assert object_list("seed7") == SEED_SEVEN and object_list("cube") == ("cube",)
    real = object_list("seed7:real")
    assert len(real) == 7 and all(name.startswith("housekeep/") for name in real)
    assert [seed_reference(name) for name in real] == [seed_reference(name) for name in SEED_SEVEN]
    assert seed_reference("cube") is not None and seed_reference("teapot") is None


def test_calls_of_several_strokes_report_success_within_each_number_of_strokes():
    spin = load_skill("spin")
    made = evaluate_strokes(spin, ("cube",), trials=6, seed=3, max_strokes=3, progress=False)
    again = evaluate_strokes(spin, ("cube",), trials=6, seed=3, max_strokes=3, progress=False)
    assert made.outcomes == again.outcomes and made.strokes == again.strokes  # deterministic
    assert len(made.strokes) == 6 and all(1 <= n <= 3 for n in made.strokes)
    within = made.within()
    assert list(within) == list(range(1, max(made.strokes) + 1))
    assert all(a <= b for a, b in zip(list(within.values()), list(within.values())[1:]))
    assert within[max(made.strokes)] == made.success_rate
    d = made.as_dict()
    assert sum(d["stopped"].values()) == 6 and d["mean_strokes"] == pytest.approx(np.mean(made.strokes))
    # a call that stopped short of its strokes stopped for a reason other than running out of them
    assert all(r != "strokes spent" for r, n in zip(made.stopped, made.strokes) if n < 3)


def test_several_strokes_are_refused_where_there_is_no_such_call(capsys):
    for argv in (["push", "--params", "random", "--strokes", "3"], ["spin", "--strokes", "3"],
                 ["spin", "--params", "random", "--strokes", "0"]):
        with pytest.raises(SystemExit) as exit_:
            main(argv)
        assert exit_.value.code == 2
    with pytest.raises(InputError, match="spin_by and roll_to"):
        evaluate_strokes(load_skill("push"), ("cube",), trials=1)


def test_a_start_with_nothing_to_ask_is_one_stroke_of_the_seed_objective(monkeypatch):
    import primitives.params as skill_params

    monkeypatch.setattr(skill_params, "sample", lambda *args, **kwargs: None)  # as from a state with no neighbour
    made = evaluate_strokes(load_skill("roll"), ("cube",), trials=2, seed=3, max_strokes=3, progress=False)
    assert made.strokes == [1, 1] and all(r.startswith("no parameter") for r in made.stopped)
