"""The option ranker: its features, its file, and a frame search that acts on its ranking."""

from dataclasses import replace

import numpy as np
import pytest
import torch

import affordplan as ap
from affordplan.errors import InputError, WeightsError
from primitives import weights_file
from primitives.frames import FrameSearch, free_frames
from primitives.option_ranker import (
    N_FEATURES,
    N_OPTION,
    OptionRanker,
    cloud_extents,
    load_ranker,
    option_features,
    request_size,
    save_ranker,
)
from primitives.success_model import N_DECISION, decision_features
from primitives.training.env import skill_observation
from primitives.training.evaluate import load_policy


def _features(m: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return option_features(rng.normal(size=(m, N_DECISION)), rng.uniform(0.05, 0.95, m), rng.uniform(0, 0.8, m),
                           rng.random(m) < 0.5, rng.random(m) < 0.5, np.array([0.4, 0.3, 0.2]))


def test_option_features_carry_each_option_and_its_difference_from_the_starts_mean():
    x = _features(7)
    assert x.shape == (7, N_FEATURES) and x.dtype == np.float32
    own, centred = x[:, :N_OPTION], x[:, N_OPTION:]
    assert np.allclose(centred, own - own.mean(axis=0), atol=1e-5)
    assert np.allclose(centred.sum(axis=0), 0.0, atol=1e-4)
    assert np.allclose(own[:, -3:], [0.4, 0.3, 0.2])  # the cloud's extents, the same for every option
    assert np.allclose(centred[:, -3:], 0.0)
    one = _features(1)  # a start with one option: nothing sets it apart
    assert np.allclose(one[:, N_OPTION:], 0.0)


def test_cloud_extents_are_the_same_in_every_frame_a_search_tries():
    sim = ap.Simulator(ap.load_object("mug"), seed=3)
    sim.reset(yaw=0.4)
    points, _ = sim.point_cloud(256)
    e = cloud_extents(points)
    assert e.shape == (3,) and np.all(np.diff(e) <= 0) and np.all(e > 0)
    for B in free_frames("push", None, 6, True):
        assert np.allclose(cloud_extents(points @ B.T), e, atol=1e-9)
    assert 0.05 < e[0] < 0.5  # dm: a mug's cloud spreads a few centimetres


def test_request_size_is_a_spins_asked_turn():
    assert request_size("spin", {"angle": -0.5}) == pytest.approx(0.5)
    assert request_size("spin", None) == 0.0
    assert request_size("push", {"direction": 2.0}) == 0.0
    assert request_size("roll", {"target": 1}) == 0.0


def test_an_ensembles_logit_is_its_members_mean():
    torch.manual_seed(0)
    ranker = OptionRanker(8, members=3).eval()
    x = torch.from_numpy(_features(6))
    each = ranker.member_logits(x)
    assert each.shape == (3, 6) and not torch.allclose(each[0], each[1])
    assert torch.allclose(ranker(x), each.mean(dim=0))
    with pytest.raises(InputError, match="positive"):
        OptionRanker(8, members=0)


def test_a_ranker_file_round_trips_and_is_checked(tmp_path):
    torch.manual_seed(0)
    ranker = OptionRanker(16, members=2)
    ranker.mean.copy_(torch.linspace(-1, 1, N_FEATURES))
    path = tmp_path / "spin_ranker.pt"
    save_ranker(path, ranker, "spin", "cameras", {"starts": 3})
    back = load_ranker(path, "spin")
    assert back.width == 16 and len(back.nets) == 2
    x = _features(5)
    assert np.allclose(back.score(x), ranker.eval().score(x))
    assert np.all((back.score(x) > 0) & (back.score(x) < 1))
    assert weights_file.load(path, kind="ranker")[1]["sensor"] == "cameras"
    with pytest.raises(WeightsError, match="push"):
        load_ranker(path, "push")
    with pytest.raises(WeightsError, match="not a ranker"):
        load_ranker(weights_file.rating_path("spin", "success"))
    torch.save({"not": "a ranker"}, tmp_path / "bare.pt")
    with pytest.raises(WeightsError, match="metadata"):
        load_ranker(tmp_path / "bare.pt")


class _Pick(OptionRanker):
    """A stand-in ranker that rates one option (by its row in the batch) above every other."""

    def __init__(self, row: int):
        super().__init__(4)
        self.row = row

    def score(self, features):
        p = np.full(len(features), 0.1)
        p[self.row] = 0.9
        return p


def test_a_search_with_a_ranker_acts_where_the_ranker_says_and_reports_that_frames_rating(tmp_path):
    sim = ap.Simulator(ap.load_object("cube"), seed=0, sensor="surface")
    sim.reset()
    seen = skill_observation(sim, "spin", None, 64)  # the seed's objective: the ranker picks
    policy = load_policy(None, "spin")
    frames = free_frames("spin", None, 6, False)

    def rating(obs):  # the ratings would pick frame 0
        return np.linspace(0.8, 0.3, len(obs))

    def decide(obs):  # the same ratings, and the policy's decisions
        return rating(obs), decision_features(policy, torch.from_numpy(obs))[2].numpy()

    plain = FrameSearch(6, False)
    chosen, p = plain.select("spin", seen, rating, sim)
    assert np.allclose(chosen.A_frame_world, seen.A_frame_world) and p == pytest.approx(0.8)
    ranked = FrameSearch(6, False, ranker_file="spin_ranker.pt", ranker=_Pick(4))
    chosen, p = ranked.select("spin", seen, rating, sim, decide=decide)
    assert np.allclose(chosen.A_frame_world, frames[4] @ seen.A_frame_world)
    assert p == pytest.approx(np.linspace(0.8, 0.3, 6)[4])  # the success model's rating of the ranked frame
    with pytest.raises(InputError, match="decide"):
        ranked.select("spin", seen, rating, sim)
    with pytest.raises(InputError, match="ranker"):
        FrameSearch(6, False, ranker_file="spin_ranker.pt")
    asked = skill_observation(sim, "spin", {"angle": 0.5}, 64)  # a request with a parameter: the ranker picks too
    assert ranked.ranks(None) and ranked.ranks(asked.params) and not plain.ranks(None)
    asked_frames = free_frames("spin", asked.params, 6, False)
    chosen, p = ranked.select("spin", asked, rating, sim, decide=decide)
    assert np.allclose(chosen.A_frame_world, asked_frames[4] @ asked.A_frame_world)
    assert chosen.params == asked.params and chosen.acted_as is None  # judged by the asked angle
    assert p == pytest.approx(np.linspace(0.8, 0.3, 6)[4])
    chosen, p = plain.select("spin", asked, rating, sim)  # without a ranker the ratings pick
    assert np.allclose(chosen.A_frame_world, asked.A_frame_world) and p == pytest.approx(0.8)


def test_a_frames_file_names_its_ranker_beside_it(tmp_path):
    ranker = OptionRanker(8)
    save_ranker(tmp_path / "spin_ranker.pt", ranker, "spin", "cameras", {})
    search = FrameSearch(12, False, (0.9, 0.1), ranker_file="spin_ranker.pt", ranker=load_ranker(
        tmp_path / "spin_ranker.pt"))
    search.save(tmp_path / "spin_frames.json")
    back = FrameSearch.load(tmp_path / "spin_frames.json")
    assert back == search and back.ranker is not None and back.ranker_file == "spin_ranker.pt"
    x = _features(4)
    assert np.allclose(back.ranker.score(x), ranker.score(x))
    plain = FrameSearch(12, False)
    plain.save(tmp_path / "plain.json")
    assert FrameSearch.load(tmp_path / "plain.json").ranker is None
    text = (tmp_path / "spin_frames.json").read_text().replace('"spin_ranker.pt"', '"../spin_ranker.pt"')
    (tmp_path / "far.json").write_text(text)
    with pytest.raises(InputError, match="beside"):
        FrameSearch.load(tmp_path / "far.json")
    (tmp_path / "spin_ranker.pt").unlink()
    with pytest.raises(WeightsError, match="no option ranker"):
        FrameSearch.load(tmp_path / "spin_frames.json")


def test_the_shipped_spin_ranks_its_options_with_camera_clouds_only():
    """Spin's camera frame search carries the shipped ranker; its success models and the surface sample's search
    are the policy's own, unchanged (the ranker was fitted on camera clouds)."""
    from primitives import load_skill

    spin = load_skill("spin")
    cameras = spin.ratings("cameras")
    assert spin.rated_sensors == ("surface", "cameras") and spin.frame_search.ranker is None
    assert cameras.frame_search.ranks(None) and cameras.frame_search.ranks({"angle": 0.4})
    # with camera clouds it reports its ranker's calibrated score (chosen on validation objects, RECORD.md)
    assert cameras.frame_search.reports_ranking and cameras.searched_model is None
    assert not spin.frame_search.reports_rating
    assert cameras._success_weights == weights_file.SHIPPED_DIR / "spin_success.pt"  # the policy's own
    assert (cameras.frame_search.turns, cameras.frame_search.platt) == (spin.frame_search.turns,
                                                                       spin.frame_search.platt)
    sim = ap.Simulator(ap.load_object("mug"), seed=2)  # cameras, the default
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.3)
    seen = skill_observation(sim, "spin", None, spin.n_points)
    search = cameras.frame_search
    options = search.options("spin", seen, sim)
    ratings, decision = search.rate_and_decide(options, cameras.success_model.rate_and_decide)
    plain = search.rate(options, cameras.success_model.predict)  # the same ratings, in one pass with the decisions
    assert all(np.allclose(a, b, atol=1e-5) for a, b in zip(ratings, plain))
    ranking = search.rank("spin", options, ratings, decision)
    k = int(np.argmax([q.max() for q in ranking]))
    wanted = search.acting(options, k, int(np.argmax(ranking[k])))
    chosen, _ = search.select("spin", seen, cameras.success_model.predict, sim,  # as observe
                              decide=cameras.success_model.rate_and_decide)
    assert np.allclose(chosen.obs, wanted.obs) and chosen.acted_as == wanted.acted_as
    assert cameras.observe(sim, None).params is None  # the skill's own call goes through the ranked search


def test_a_search_with_ranker_platt_scores_its_pick_by_the_rankers_calibrated_score(tmp_path):
    """With ``ranker_platt`` the score of the pick is the ranker's own (raw from choose, scaled by calibrate, for
    every kind of request); the file keeps it; a search without it, or without its ranker, scores by the ratings."""
    from scipy.special import expit, logit

    sim = ap.Simulator(ap.load_object("cube"), seed=0, sensor="surface")
    sim.reset()
    policy = load_policy(None, "spin")

    def rating(obs):
        return np.linspace(0.8, 0.3, len(obs))

    def decide(obs):
        return rating(obs), decision_features(policy, torch.from_numpy(obs))[2].numpy()

    save_ranker(tmp_path / "spin_ranker.pt", OptionRanker(8), "spin", "cameras", {})
    ranked = FrameSearch(6, False, ranker_file="spin_ranker.pt", ranker=_Pick(4))
    reporting = replace(ranked, ranker_platt=(0.5, 0.2))
    assert reporting.reports_ranking and not ranked.reports_ranking
    for params in (None, {"angle": 0.5}):
        seen = skill_observation(sim, "spin", params, 64)
        chosen, q = reporting.select("spin", seen, rating, sim, decide=decide)
        same, p = ranked.select("spin", seen, rating, sim, decide=decide)
        assert np.allclose(chosen.A_frame_world, same.A_frame_world)  # the ranker picks as before
        assert q == pytest.approx(0.9) and p == pytest.approx(np.linspace(0.8, 0.3, 6)[4])  # _Pick's score, the rating
        assert float(reporting.calibrate(q, params is not None)) == pytest.approx(expit(0.5 * logit(0.9) + 0.2))
    reporting.save(tmp_path / "spin_frames.json")
    back = FrameSearch.load(tmp_path / "spin_frames.json")
    assert back.ranker_platt == (0.5, 0.2) and back.reports_ranking
    assert not FrameSearch.load(tmp_path / "spin_frames.json", ranked=False).reports_ranking
    ranked.save(tmp_path / "plain.json")
    assert "ranker_platt" not in (tmp_path / "plain.json").read_text()
    with pytest.raises(InputError, match="Platt"):
        FrameSearch(6, False, ranker_platt=(float("nan"), 0.0))
