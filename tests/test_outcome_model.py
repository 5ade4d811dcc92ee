"""The outcome model (primitives.outcome_model): loading, refusing bad files, sampling conditioned on p, intervals."""

from __future__ import annotations

import numpy as np
import pytest

from affordplan.errors import InputError, WeightsError
from primitives.outcome_model import OutcomeModel
from primitives.params import SKILLS
from primitives.weights_file import SHIPPED_DIR


def _fixture(path, skill="push", m=600, seed=0, noise=0.2):
    """A synthetic outcome file: p ~ U(0, 1), progress ~ N(p, noise)."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(0.0, 1.0, m).astype(np.float32)
    progress = rng.normal(p, noise).astype(np.float32)
    np.savez_compressed(path, p=p, progress=progress, made_progress=progress > 0.2, skill=np.asarray(skill))
    return p, progress


@pytest.mark.parametrize("skill", SKILLS)
def test_the_shipped_models_load_and_are_small(skill):
    path = SHIPPED_DIR / f"{skill}_outcome.npz"
    assert path.stat().st_size < 200_000
    with np.load(path, allow_pickle=False) as f:  # a plain file: no pickled objects
        assert str(f["skill"]) == skill and len(f["p"]) == len(f["progress"]) >= 100
    model = OutcomeModel.load(skill)
    assert model.skill == skill and len(model) >= 100
    draws = model.sample_progress(0.5, np.random.default_rng(0), 100)
    assert draws.shape == (100,) and np.all(np.isfinite(draws))
    assert 0.0 <= model.p_progress(0.5) <= 1.0


def test_a_fixture_loads_from_a_path(tmp_path):
    path = tmp_path / "push_outcome.npz"
    p, _ = _fixture(path)
    model = OutcomeModel.load("push", path)
    assert len(model) == len(p) and model.k == 60


def test_a_missing_file_is_refused(tmp_path):
    with pytest.raises(WeightsError, match="no push outcome model"):
        OutcomeModel.load("push", tmp_path / "nothing.npz")


def test_a_damaged_file_is_refused(tmp_path):
    path = tmp_path / "push_outcome.npz"
    _fixture(path)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])  # truncated
    with pytest.raises(WeightsError):
        OutcomeModel.load("push", path)
    path.write_bytes(b"not a zip file at all")
    with pytest.raises(WeightsError):
        OutcomeModel.load("push", path)


def test_a_file_missing_a_column_or_with_bad_values_is_refused(tmp_path):
    path = tmp_path / "a.npz"
    np.savez(path, p=np.array([0.5]), skill=np.asarray("push"))
    with pytest.raises(WeightsError, match="progress"):
        OutcomeModel.load("push", path)
    np.savez(path, p=np.array([0.5, 1.5]), progress=np.zeros(2), made_progress=np.zeros(2, bool))
    with pytest.raises(WeightsError, match="damaged"):
        OutcomeModel.load("push", path)
    np.savez(path, p=np.array([0.5]), progress=np.zeros(2), made_progress=np.zeros(2, bool))
    with pytest.raises(WeightsError, match="damaged"):
        OutcomeModel.load("push", path)


def test_a_pickled_file_is_refused(tmp_path):
    path = tmp_path / "a.npz"
    np.savez(path, p=np.array([{"x": 1}], dtype=object), progress=np.zeros(1), made_progress=np.zeros(1, bool))
    with pytest.raises(WeightsError):
        OutcomeModel.load("push", path)


def test_another_skills_file_is_refused(tmp_path):
    path = tmp_path / "spin_outcome.npz"
    _fixture(path, skill="spin")
    with pytest.raises(WeightsError, match="spin outcome model"):
        OutcomeModel.load("push", path)


def test_samples_are_conditioned_on_p(tmp_path):
    path = tmp_path / "push_outcome.npz"
    _fixture(path)
    model = OutcomeModel.load("push", path)
    rng = np.random.default_rng(1)
    low, high = model.sample_progress(0.1, rng, 2000), model.sample_progress(0.9, rng, 2000)
    assert high.mean() > low.mean() + 0.5
    assert low.mean() == pytest.approx(0.1, abs=0.1) and high.mean() == pytest.approx(0.9, abs=0.1)
    assert model.p_progress(0.9) > model.p_progress(0.1)
    assert model.mean_progress(0.9) > model.mean_progress(0.1)


def test_the_neighbours_are_the_k_nearest_in_p():
    rng = np.random.default_rng(3)
    p = rng.uniform(0.0, 1.0, 300)
    model = OutcomeModel("spin", p, rng.normal(size=300), k=25)
    for q in [0.0, 0.001, 0.3, 0.5, 0.97, 1.0, *rng.uniform(0, 1, 20)]:
        got = np.sort(np.abs(model.p[model.neighbours(q)] - q))
        assert got == pytest.approx(np.sort(np.abs(p - q))[:25])


def test_the_same_seed_gives_the_same_samples(tmp_path):
    path = tmp_path / "push_outcome.npz"
    _fixture(path)
    model = OutcomeModel.load("push", path)
    a = model.sample_progress(0.4, np.random.default_rng(7), 50)
    b = model.sample_progress(0.4, np.random.default_rng(7), 50)
    assert np.array_equal(a, b)


def test_intervals_cover_about_eighty_percent_of_a_known_distribution(tmp_path):
    from primitives.training.outcomes import check

    path = tmp_path / "push_outcome.npz"
    _fixture(path, m=1000, seed=0)
    model = OutcomeModel.load("push", path)
    fresh = tmp_path / "fresh.npz"
    p, progress = _fixture(fresh, m=2000, seed=1)
    data = dict(p=p, progress=progress, made_progress=progress > 0.2, success=progress > 0.9,
                valid=np.ones(len(p), bool))
    report = check(model, data)
    assert report["coverage"] == pytest.approx(0.8, abs=0.06)
    assert report["below"] == pytest.approx(0.1, abs=0.05) and report["above"] == pytest.approx(0.1, abs=0.05)
    assert report["predicted_mean_progress"] == pytest.approx(report["measured_mean_progress"], abs=0.05)


def test_bad_queries_and_models_are_refused():
    model = OutcomeModel("roll", [0.2, 0.8], [0.0, 1.0])
    assert model.k == 2 and model.p_progress(0.5) == 0.5
    with pytest.raises(InputError):
        model.sample_progress(1.5, np.random.default_rng(0), 3)
    with pytest.raises(InputError):
        OutcomeModel("slide", [0.5], [1.0])
    with pytest.raises(InputError):
        OutcomeModel("push", [], [])


# ------------------------------------------------------------------ tips: calls that leave their resting state
def _tip_fixture(path, skill="push", m=800, seed=0):
    """A synthetic outcome file with tips: a call tips with probability 0.4 in states rarer than 0.1, else never."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(0.0, 1.0, m).astype(np.float32)
    prob = np.exp(rng.uniform(np.log(0.01), 0.0, m)).astype(np.float32)
    before = rng.integers(0, 4, m).astype(np.int16)
    tipped = (prob < 0.1) & (rng.random(m) < 0.4)
    np.savez_compressed(path, p=p, progress=p, made_progress=p > 0.2, skill=np.asarray(skill),
                        state_probability=prob, state_before=before,
                        state_after=np.where(tipped, before + 1, before).astype(np.int16))


@pytest.mark.parametrize("skill", ["push", "spin"])
def test_calls_in_states_few_drops_rest_in_tip_more(tmp_path, skill):
    path = tmp_path / f"{skill}_outcome.npz"
    _tip_fixture(path, skill)
    model = OutcomeModel.load(skill, path)
    assert model.knows_tips and "tips" in repr(model)
    assert model.p_tip(0.02) == pytest.approx(0.4, abs=0.15)
    assert model.p_tip(0.6) == 0.0
    assert model.p_tip(np.array([0.02, 0.6])).shape == (2,)


def test_a_roll_has_no_tip_rate_and_an_old_file_knows_no_tips(tmp_path):
    path = tmp_path / "roll_outcome.npz"
    _tip_fixture(path, "roll")
    assert OutcomeModel.load("roll", path).p_tip(0.02) == 0.0  # changing state is a roll's job
    old = tmp_path / "push_outcome.npz"
    _fixture(old)  # no state_probability column
    model = OutcomeModel.load("push", old)
    assert not model.knows_tips and model.p_tip(0.02) == 0.0


@pytest.mark.parametrize("skill", SKILLS)
def test_the_shipped_models_know_tips(skill):
    """The shipped files carry each rollout's drop probability: pushes in rare states tip (the hard drive on edge)."""
    model = OutcomeModel.load(skill)
    assert model.knows_tips
    if skill == "push":
        assert model.p_tip(0.03) > 0.1 > model.p_tip(0.8)


def test_tips_need_both_columns_and_probabilities_in_zero_one():
    with pytest.raises(InputError, match="both"):
        OutcomeModel("push", [0.5], [1.0], state_probability=[0.5])
    with pytest.raises(InputError, match="state_probability"):
        OutcomeModel("push", [0.5], [1.0], state_probability=[0.0], tipped=[False])
    model = OutcomeModel("push", [0.5], [1.0], state_probability=[0.5], tipped=[True])
    assert model.p_tip(0.5) == 1.0
    for bad in (0.0, 1.5, float("nan")):
        with pytest.raises(InputError):
            model.p_tip(bad)
