"""The frame-search ceiling: every option executed from one start, against the skill's own outcomes."""

import json

import numpy as np
import pytest

from primitives.frames import load_frame_search
from primitives.research.frame_ceiling import frame_ceiling, main
from primitives.training.evaluate import evaluate, load_policy


@pytest.mark.slow
@pytest.mark.parametrize(("skill", "params"), [("spin", "random"), ("push", "none")])
def test_the_goal_frame_and_the_searchs_pick_are_what_evaluate_measures_on_the_same_starts(skill, params):
    """Row 0 is the policy as trained, the pick is the shipped skill's choice (push with the seed's objective
    tries the stand-in directions too): both give, start by start, the outcomes of ``evaluate`` with and without
    the frame search, so every option really was executed from the evaluation's start."""
    p_params = 1.0 if params == "random" else 0.0
    result = frame_ceiling(skill, starts=3, params=params, seed=1234, progress=False)
    policy = load_policy(None, skill)
    plain = evaluate(policy, skill, trials=3, seed=1234, p_params=p_params, progress=False)
    searched = evaluate(policy, skill, trials=3, seed=1234, p_params=p_params, progress=False,
                        frame_search=load_frame_search(skill, "shipped"))
    assert [bool(o.success[0]) for o in result.starts] == plain.outcomes
    assert [bool(o.success[o.pick]) for o in result.starts] == searched.outcomes
    search = load_frame_search(skill, "shipped")
    for start in result.starts:
        n_options = len(search.frames(skill, start.params))
        if params == "none":  # the stand-in directions, each with its own (mirror) frames
            n_options += search.stand_ins * len(search.frames(skill, {"direction": 0.0}))
            assert start.option.max() == search.stand_ins
        assert len(start.success) == n_options
    rates = result.rates()
    assert rates["best option"] >= max(rates.values())
    assert min(o.success.mean() for o in result.starts) <= rates["random option"] <= rates["best option"]


def test_the_command_prints_the_figures_and_refuses_bad_input(tmp_path, capsys):
    assert main(["spin", "--starts", "2", "--json", "--plot", str(tmp_path / "ceiling.png")]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["starts"] == 2 and d["options_per_start"] == 12.0
    assert set(d["success"]) == {"goal frame", "random option", "critic's pick", "search's pick", "best option"}
    assert all(0.0 <= v <= 1.0 for v in d["success"].values())
    assert (tmp_path / "ceiling.png").stat().st_size > 0
    broken = tmp_path / "frames.json"
    broken.write_text("{not json")
    assert main(["spin", "--starts", "1", "--frames", str(broken)]) == 2
    assert "unreadable" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["spin", "--starts", "0"])


def test_within_start_auroc_counts_only_starts_with_mixed_outcomes():
    from primitives.research.frame_ceiling import FrameCeiling, StartOptions

    def start(success, rating):
        n = len(success)
        return StartOptions(None, np.zeros(n, int), np.arange(n), np.array(rating), np.zeros(n),
                            np.array(success, bool), 0)

    result = FrameCeiling("spin", "random", [start([1, 0, 0], [0.9, 0.1, 0.2]),  # ranked right: 1.0
                                             start([0, 1], [0.8, 0.3]),  # ranked wrong: 0.0
                                             start([1, 1], [0.1, 0.2])])  # not mixed: left out
    assert result.within_start_auroc() == pytest.approx(0.5)
    assert result.as_dict()["mixed_share"] == pytest.approx(2 / 3)
    assert result.rates()["search's pick"] == pytest.approx(2 / 3)
    assert result.rates()["best option"] == 1.0


@pytest.mark.slow
def test_named_objects_give_the_same_pick_as_evaluate_on_them():
    """``objects``: the starts cycle through the named objects, as ``evaluate`` draws them, seen by ``sensor``."""
    result = frame_ceiling("spin", starts=2, params="random", seed=1234, progress=False, objects="mug",
                           sensor="surface")
    searched = evaluate(load_policy(None, "spin"), "spin", objects="mug", trials=2, seed=1234, p_params=1.0,
                        progress=False, sensor="surface", frame_search=load_frame_search("spin", "shipped"))
    assert (result.objects, result.sensor) == ("mug", "surface")
    assert [bool(o.success[o.pick]) for o in result.starts] == searched.outcomes
