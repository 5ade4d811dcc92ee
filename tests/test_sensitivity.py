"""The sensitivity benchmark: each decision executed again, slightly changed, from the same start."""

import json

import numpy as np
import pytest

from affordplan.errors import InputError
from primitives.research.frame_ceiling import frame_ceiling
from primitives.research.sensitivity import VARIANTS, Sensitivity, StartDecisions, main, sensitivity


def test_the_base_outcomes_are_the_frame_ceilings_and_zero_sized_variants_repeat_them():
    """Each drawn decision's base outcome is that option's outcome when the frame ceiling executes every option
    from the same evaluation start; with a 0 deg turn and a 0 mm move every variant executes the base decision
    again (the scene shift resets the simulator's data to the same pose) and must end the same way. Both search with
    the policy's own frames file, which has no option ranker, so the ceiling reports the success model's ratings as
    the sensitivity does (with the camera search's ranker it would report the ranker's scores)."""
    from primitives.weights_file import SHIPPED_DIR

    frames = str(SHIPPED_DIR / "spin_frames.json")
    result = sensitivity("spin", starts=2, params="random", options=3, seed=1234, motion_rad=0.0, contact_m=0.0,
                         frames=frames, progress=False)
    ceiling = frame_ceiling("spin", starts=2, params="random", seed=1234, frames=frames, progress=False)
    for mine, every in zip(result.starts, ceiling.starts, strict=True):
        assert len(mine.row) == 3 and len(set(mine.row.tolist())) == 3
        assert np.array_equal(mine.base, every.success[mine.row])
        assert np.allclose(mine.rating, every.rating[mine.row])
        assert np.array_equal(mine.variants, np.repeat(mine.base[:, None], len(VARIANTS), axis=1))
    assert all(rate == 0.0 for rate in result.flip_rates().values())


def test_within_start_auroc_scores_the_model_and_the_neighbours_on_mixed_starts_only():
    def start(base, rating, neighbours):
        variants = np.column_stack([np.array(neighbours, bool)] * 4 + [np.array(base, bool)])
        return StartDecisions(np.arange(len(base)), np.array(rating), np.array(base, bool), variants)

    result = Sensitivity("spin", "random", 0.05, 0.002, [
        start([True, False, False], [0.9, 0.2, 0.1], [True, False, False]),  # both rank it right
        start([True, False], [0.1, 0.8], [False, True]),  # both wrong
        start([True, True], [0.5, 0.5], [True, True]),  # not mixed: left out
    ])
    auc = result.within_start_auroc()
    assert auc == {"success model": pytest.approx(0.5), "neighbours' mean": pytest.approx(0.5)}
    flips = result.flip_rates()
    assert flips["scene shift"] == 0.0 and flips["motion +a"] == pytest.approx(2 / 7)
    assert Sensitivity("spin", "random", 0.05, 0.002, [start([True], [0.5], [True])]).within_start_auroc() == {
        "success model": None, "neighbours' mean": None}


def test_the_command_prints_the_figures_and_refuses_bad_input(tmp_path, capsys):
    assert main(["push", "--starts", "2", "--options", "2", "--params", "none", "--json",
                 "--plot", str(tmp_path / "s.png")]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["starts"] == 2 and d["decisions"] == 4 and set(d["flip_rates"]) == set(VARIANTS)
    assert all(0.0 <= v <= 1.0 for v in d["flip_rates"].values())
    assert d["motion_deg"] == pytest.approx(3.0) and d["contact_mm"] == pytest.approx(2.0)
    assert (tmp_path / "s.png").stat().st_size > 0
    assert main(["spin", "--starts", "1", "--contact-mm", "-1"]) == 2
    assert "must be finite and >= 0" in capsys.readouterr().err
    with pytest.raises(InputError):
        sensitivity("spin", starts=0, progress=False)
