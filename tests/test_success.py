"""Fitting success models (primitives.training.success): metrics, calibration and fitting on synthetic rollouts,
ensembles, frame-searched and frame-contrast rollouts, the commands, shipped models answering through the skills."""

import json
from pathlib import Path

import numpy as np
import pytest
import torch

from affordplan.errors import InputError
from primitives import weights_file
from primitives.frames import FrameSearch
from primitives.training import success


def test_metrics_on_known_values():
    y = np.array([1, 1, 0, 0], bool)
    assert success.auroc(np.array([0.9, 0.8, 0.2, 0.1]), y) == 1.0
    assert success.auroc(np.array([0.1, 0.2, 0.8, 0.9]), y) == 0.0
    assert success.auroc(np.full(4, 0.5), y) == 0.5
    assert success.brier(np.array([1.0, 0.0]), np.array([1, 1])) == 0.5
    # Two bins: predictions 0.15 (measured 0) and 0.85 (measured 1), half the samples each.
    assert success.ece(np.array([0.15, 0.15, 0.85, 0.85]), y[::-1]) == pytest.approx(0.15)


def _synthetic(n: int, rng: np.random.Generator) -> success.Rollouts:
    """Clouds whose success depends on the goal flow's x: pushes towards +x succeed 90 %, others 10 %."""
    obs = rng.normal(0, 0.03, size=(n, 32, 9)).astype(np.float32)
    direction = rng.uniform(-np.pi, np.pi, size=n)
    obs[:, :, 6] = 0.05 * np.cos(direction)[:, None]
    obs[:, :, 7] = 0.05 * np.sin(direction)[:, None]
    obs[:, :, 8] = 0
    p_true = np.where(np.cos(direction) > 0, 0.9, 0.1)
    y = rng.random(n) < p_true
    return success.Rollouts(obs.astype(np.float16), np.zeros((n, success.N_DECISION), np.float32), y,
                            rng.integers(0, 50, size=n), np.ones(n, bool))


def test_a_reliability_diagram_wraps_a_long_title_and_shows_the_metrics(tmp_path):
    rng = np.random.default_rng(0)
    p = rng.random(200)
    y = rng.random(200) < p
    title = "push success model, frame search, housekeep:unseen, cameras"
    path = tmp_path / "reliability.png"
    heading = success.plot_reliability(p, y, path, title)
    *lines, figures = heading.split("\n")
    assert " ".join(lines) == title and len(lines) == 2
    assert all(len(line) <= success.RELIABILITY_TITLE_CHARS for line in lines)
    assert figures.startswith(f"ECE {success.metrics(p, y)['ece']:.3f}") and figures.endswith("(n=200)")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_fit_learns_and_calibrates_on_synthetic_rollouts():
    torch.set_num_threads(1)
    rng = np.random.default_rng(0)
    net, info = success.fit(_synthetic(1500, rng), seed=0, epochs=8, progress=False)
    test = _synthetic(1000, rng)
    with torch.no_grad():
        p = net(torch.from_numpy(test.obs.astype(np.float32)), torch.from_numpy(test.decision)).numpy()
    m = success.metrics(p, test.success)
    assert m["auroc"] > 0.8  # the best possible here is ~0.9
    assert m["ece"] < 0.08
    assert abs(m["mean_prediction"] - m["success_rate"]) < 0.05


def test_an_ensemble_averages_its_members_and_round_trips(tmp_path):
    torch.set_num_threads(1)
    rng = np.random.default_rng(1)
    net, info = success.fit(_synthetic(1200, rng), seed=0, epochs=6, members=2, progress=False)
    assert len(net.members) == 2 and info["members"] == 2
    test = _synthetic(600, rng)
    obs, dec = torch.from_numpy(test.obs.astype(np.float32)), torch.from_numpy(test.decision)
    with torch.no_grad():
        x = success.SuccessNet.scaled(obs)
        mean_logit = (net.members[0](x, dec) + net.members[1](x, dec)) / 2
        assert torch.allclose(net.logit(obs, dec), mean_logit)
        assert not torch.allclose(net.members[0](x, dec), net.members[1](x, dec))  # trained apart
        p = net(obs, dec).numpy()
    assert success.metrics(p, test.success)["auroc"] > 0.8
    success.save(net, tmp_path / "e.pt", info, skill="push")
    again = success.load_success_net("push", tmp_path / "e.pt")
    with torch.no_grad():
        assert np.allclose(again(obs, dec).numpy(), p)


def test_shipped_success_models_load_and_answer():
    import affordplan as ap
    from primitives import load_skill

    sim = ap.Simulator(ap.load_object("cube"), seed=0)
    sim.reset(0, (0.5, 0.0), 0.0)
    for name, params in (("push", {"direction": 0.0}), ("spin", {"angle": 0.5}), ("roll", {"target": 1})):
        p = load_skill(name).success_probability(sim, params)
        assert 0.0 < p < 1.0


def test_frame_searched_rollouts_keep_the_goal_frame_view():
    """What a searched success model learns from: the goal-frame observation and decision the skill started from,
    and the outcome of acting in the frame the search picked from it."""
    from primitives.frames import FrameSearch, reframe_obs
    from primitives.skills import load_skill

    model = load_skill("spin", frame_search=False).success_model
    search = FrameSearch(4, False)
    rating, data = success.collect_frame_search(model, "spin", 3, search, "train", n_objects=3, seed=1,
                                                p_params=1.0, progress=False)
    assert rating.shape == (3,) and len(data) == 3 and data.parameterised.all()
    obs = torch.from_numpy(data.obs.astype(np.float32))
    _, _, decision = success.decision_features(model.policy, obs)
    assert torch.allclose(decision, torch.from_numpy(data.decision), atol=0.05)  # fp16-stored clouds
    best = [model.predict(reframe_obs(o, search.frames("spin", {}))).max() for o in data.obs.astype(np.float32)]
    assert np.allclose(best, rating, atol=0.02)
    # the same rollouts in every frame the search tries: the decision there, the outcome unchanged
    views = success.FrameViews.of(data, model.policy, "spin", search, progress=False)
    assert views.frames.shape == (3, 4, 3, 3) and np.all(views.count == 4)
    assert np.allclose(views.decision[:, 0], data.decision, atol=0.05)  # fp16-stored clouds, as above
    seen = torch.from_numpy(reframe_obs(data.obs[1].astype(np.float32), search.frames("spin", {}))[2:3])
    assert np.allclose(views.decision[1, 2], success.decision_features(model.policy, seen)[2][0].numpy(), atol=1e-5)
    data.group[:] = [1, 2, 3]  # one rollout per object: two to train on, one to calibrate
    net, info = success.fit(data, epochs=1, views=views, calib_fraction=0.34, progress=False)
    assert info["frame_views"] and (info["train"], info["calibration"]) == (2, 1)


def test_parallel_collection_splits_the_rollouts_and_worker_0_keeps_the_seed():
    """``--workers 2``: two processes, each its share of the rollouts from its own seed; worker 0's share is what
    one in-process collector with the same seed gathers first."""
    from primitives.skills import load_skill

    policy = load_skill("push", frame_search=False).success_model.policy
    parts = success.collect_parallel(success.collect, (policy, "push"), 5, seed=3, workers=2, progress=False,
                                     split="train", n_objects=4)
    assert [len(p) for p in parts] == [3, 2]
    data = success.Rollouts.concat(parts)
    assert len(data) == 5 and data.obs.shape[1:] == parts[0].obs.shape[1:]
    alone = success.collect(policy, "push", 3, "train", n_objects=4, seed=3, progress=False)
    assert np.array_equal(alone.obs, parts[0].obs) and np.array_equal(alone.success, parts[0].success)
    assert not np.array_equal(parts[1].obs, alone.obs[:2])  # worker 1 draws other starts
    with pytest.raises(InputError):
        success.collect_parallel(success.collect, (policy, "push"), 5, seed=3, workers=0)


def test_frames_command_calibrates_the_stand_ins_on_seed_objective_rollouts(tmp_path, capsys):
    """``success frames --stand-ins N``: the frames' calibration as before, then rollouts of the seed's objective
    acting through the stand-ins, on which ``platt_stand_ins`` is fitted; the file records how."""
    from primitives.frames import FrameSearch

    rc = success.main(["frames", "push", "--turns", "1", "--rollouts", "30", "--stand-ins", "4",
                       "--stand-in-rollouts", "40", "--seed", "2", "--out", str(tmp_path), "--json"])
    assert rc == 0
    search = FrameSearch.load(tmp_path / "frames.json")
    assert search.stand_ins == 4 and search.platt_stand_ins != (1.0, 0.0)
    info = search.info
    assert info["stand_in_rollouts"] == 40 and info["stand_in_calibrated"]["n"] == 40
    assert 0.0 <= info["stand_in_success_rate"] <= 1.0
    assert "--stand-ins 4 --stand-in-rollouts 40 --seed 2" in info["command"]
    # the calibrated mean matches the success rate it was fitted on (Platt scaling with an intercept)
    assert info["stand_in_calibrated"]["mean_prediction"] == pytest.approx(info["stand_in_success_rate"], abs=0.02)
    # bad counts are refused before any rollout is collected
    assert success.main(["frames", "push", "--turns", "12", "--stand-ins", "18", "--out", str(tmp_path / "b")]) == 2
    assert "multiple of turns" in capsys.readouterr().err and not (tmp_path / "b").exists()  # nothing written
    with pytest.raises(SystemExit):
        success.main(["frames", "push", "--stand-ins", "24", "--stand-in-rollouts", "0"])


def test_frame_contrast_rollouts_execute_one_start_in_several_frames():
    """``collect_contrast``: each start is restored and executed once per drawn frame; the stored observation is
    the start seen in that frame, with the policy's decision there."""
    from primitives.frames import reframe_obs
    from primitives.skills import load_skill

    policy = load_skill("spin", frame_search=False).success_model.policy
    search = FrameSearch(4, False)
    data = success.collect_contrast(policy, "spin", 6, search, 3, "train", n_objects=3, seed=1, p_params=1.0,
                                    progress=False)
    assert len(data) == 6 and data.parameterised.all()
    assert data.group[0] == data.group[1] == data.group[2]  # one start, three frames
    obs = data.obs.astype(np.float32)
    turned = reframe_obs(obs[0], search.frames("spin", {}))  # the first start in each of the four frames
    for i in (1, 2):
        assert not np.allclose(obs[i], obs[0], atol=1e-2)  # frames drawn without replacement
        assert min(np.abs(t - obs[i]).max() for t in turned) < 2e-3  # fp16-stored clouds
    _, _, decision = success.decision_features(policy, torch.from_numpy(obs))
    stored = torch.from_numpy(data.decision)
    assert torch.allclose(decision[:, :13], stored[:, :13], atol=0.05)
    assert torch.allclose(decision[:, 13], stored[:, 13], atol=0.2)  # the lever arm is in cm, the others ~dm
    again = success.collect_contrast(policy, "spin", 6, search, 3, "train", n_objects=3, seed=1, p_params=1.0,
                                     progress=False)
    assert np.array_equal(again.obs, data.obs) and np.array_equal(again.success, data.success)
    assert success.contrast_starts(data.obs).tolist() == [0, 0, 0, 1, 1, 1]  # read back from the clouds alone


def test_contrast_starts_are_runs_of_one_cloud_turned_or_mirrored():
    """A cloud turned about the vertical or mirrored keeps its heights, so it is the same start; the next cloud, or
    the same cloud again after another, starts a new one."""
    from scipy.spatial.transform import Rotation

    from primitives.frames import reframe_obs

    rng = np.random.default_rng(0)
    a, b = rng.normal(0, 0.03, size=(2, 64, 9)).astype(np.float32)
    turned = reframe_obs(a, np.stack([Rotation.from_euler("z", 0.7).as_matrix(), np.diag([1.0, -1.0, 1.0])]))
    shuffled = a[rng.permutation(64)]  # the point order is not what makes a start
    obs = np.stack([a, turned[0], turned[1], shuffled, b, b, a]).astype(np.float16)
    assert success.contrast_starts(obs).tolist() == [0, 0, 0, 0, 1, 1, 2]
    assert success.contrast_starts(obs[:0]).tolist() == []


def test_pairwise_rank_loss_counts_the_pairs_within_a_start():
    """``softplus(z_fail - z_success)`` over one start's pairs, averaged; pairs across starts or of equal labels do
    not count, and its gradient raises the successful rollout's logit."""
    logit = torch.tensor([2.0, 0.0, -1.0, 5.0, 3.0], requires_grad=True)
    label = torch.tensor([1.0, 0.0, 0.0, 1.0, 1.0])
    start = torch.tensor([0, 0, 0, 1, 1])
    loss = success.pairwise_rank_loss(logit, label, start)
    expected = (torch.nn.functional.softplus(torch.tensor(-2.0)) + torch.nn.functional.softplus(torch.tensor(-3.0))) / 2
    assert loss.item() == pytest.approx(expected.item())
    loss.backward()
    assert logit.grad[0] < 0 < logit.grad[1] and logit.grad[3] == logit.grad[4] == 0
    assert success.pairwise_rank_loss(logit, label, torch.arange(5)).item() == 0.0  # no start with two labels


def _contrast_synthetic(n_starts: int, rng: np.random.Generator) -> success.Rollouts:
    """Starts of 12 rollouts each, one cloud turned about the vertical; a start-level feature (the cloud's mean
    height) sets whether a start is hard (10 % succeed) or easy (90 %), and within a start the rollouts whose goal
    flow points to +x succeed more often (+30 points)."""
    from scipy.spatial.transform import Rotation

    from primitives.frames import reframe_obs

    obs, y, group = [], [], []
    for s in range(n_starts):
        cloud = rng.normal(0, 0.03, size=(32, 9)).astype(np.float32)
        easy = rng.random() < 0.5
        cloud[:, 2] += 0.03 if easy else -0.03
        cloud[:, 6:9] = [0.05, 0.0, 0.0]
        turns = rng.uniform(-np.pi, np.pi, size=12)
        obs.extend(reframe_obs(cloud, Rotation.from_euler("z", turns[:, None]).as_matrix()))
        for turn in turns:
            p = (0.75 if easy else 0.05) + (0.2 if np.cos(turn) > 0 else 0.0)
            y.append(rng.random() < p), group.append(s % 40)
    n = len(y)
    return success.Rollouts(np.stack(obs).astype(np.float16), np.zeros((n, success.N_DECISION), np.float32),
                            np.array(y), np.array(group), np.ones(n, bool))


def test_a_ranking_loss_orders_one_starts_rollouts_and_keeps_the_calibration():
    """``fit(rank_weight=...)`` on frame-contrast rollouts ranks one start's rollouts by what decides among them
    (the goal flow's direction) and, Platt-scaled, stays calibrated across starts."""
    torch.set_num_threads(1)
    rng = np.random.default_rng(4)
    net, info = success.fit(_contrast_synthetic(150, rng), seed=0, epochs=8, progress=False, rank_weight=1.0)
    assert info["rank_weight"] == 1.0
    test = _contrast_synthetic(60, rng)
    with torch.no_grad():
        p = net(torch.from_numpy(test.obs.astype(np.float32)), torch.from_numpy(test.decision)).numpy()
    towards_x = test.obs[:, 0, 6].astype(np.float32) > 0
    start = success.contrast_starts(test.obs)
    within = [success.auroc(p[start == s], towards_x[start == s]) for s in np.unique(start)
              if 0 < towards_x[start == s].sum() < 12]
    assert np.mean(within) > 0.9  # the order within a start follows the flow
    m = success.metrics(p, test.success)
    assert m["auroc"] > 0.8 and m["ece"] < 0.1
    with pytest.raises(InputError):
        success.fit(_contrast_synthetic(2, rng), epochs=1, progress=False, rank_weight=float("nan"))


def test_smoothed_labels_share_the_outcomes_of_a_decision_and_its_neighbours(tmp_path):
    """``collect_contrast(neighbours=True)``: the same rollouts and outcomes as without, each with the share of
    it and its four neighbours that succeed as its label (so at least 1/5 where it succeeded, at most 4/5 where
    it failed); the label is what ``fit`` reads, survives a save, a subset and a concat, and ``--neighbours`` needs
    ``--contrast``."""
    from primitives.skills import load_skill

    policy = load_skill("spin", frame_search=False).success_model.policy
    search = FrameSearch(4, False)
    args = (policy, "spin", 12, search, 3, "train")
    plain = success.collect_contrast(*args, n_objects=3, seed=2, p_params=1.0, progress=False)
    data = success.collect_contrast(*args, n_objects=3, seed=2, p_params=1.0, progress=False, neighbours=True)
    assert plain.target is None and data.target is not None
    assert np.array_equal(plain.obs, data.obs) and np.array_equal(plain.success, data.success)
    assert np.allclose(data.target * 5, np.round(data.target * 5))
    assert (data.target[data.success] >= 0.2).all() and (data.target[~data.success] <= 0.8).all()
    assert 0 < data.target.mean() < 1 and not np.array_equal(data.target, data.success.astype(np.float32))
    assert np.array_equal(data.labels(), data.target) and np.array_equal(plain.labels(), plain.success)
    data.save(tmp_path / "r.npz")
    back = success.Rollouts.load(tmp_path / "r.npz")
    assert np.array_equal(back.target, data.target)
    assert np.array_equal(back.subset(back.success).target, data.target[data.success])
    assert np.array_equal(success.Rollouts.concat([back, back]).target, np.tile(data.target, 2))
    assert success.Rollouts.concat([back, plain]).target is None
    with pytest.raises(SystemExit):
        success.main(["train", "spin", "--neighbours", "--out", str(tmp_path / "no")])
    assert not (tmp_path / "no").exists()


def test_fit_reads_the_smoothed_labels():
    """A model fitted to labels that say the opposite of the outcomes learns the labels."""
    torch.set_num_threads(1)
    rng = np.random.default_rng(3)
    data = _synthetic(1500, rng)
    towards_x = data.obs[:, 0, 6].astype(np.float32) > 0
    data.target = np.where(towards_x, 0.1, 0.9).astype(np.float32)  # the outcomes favour +x, the labels -x
    net, _ = success.fit(data, seed=0, epochs=6, progress=False)
    test = _synthetic(400, rng)
    with torch.no_grad():
        z = net.logit(torch.from_numpy(test.obs.astype(np.float32)), torch.from_numpy(test.decision)).numpy()
    assert success.auroc(z, test.obs[:, 0, 6].astype(np.float32) < 0) > 0.95


class _Twice(FrameSearch):
    """A frame search whose 'free frames' are the goal frame twice."""

    def frames(self, skill, params):
        return np.stack([np.eye(3), np.eye(3)])


def test_frame_contrast_rollouts_restore_the_start_before_each_frame():
    """The same frame twice from one start: the same outcome both times, and the outcome one goal-frame rollout
    of the same start has (the start is restored, not left where the first try moved it)."""
    from primitives.skills import load_skill

    policy = load_skill("spin", frame_search=False).success_model.policy
    data = success.collect_contrast(policy, "spin", 8, _Twice(turns=1), 2, "train", n_objects=3, seed=5, p_params=1.0,
                                    progress=False)
    plain = success.collect(policy, "spin", 4, "train", n_objects=3, seed=5, p_params=1.0, progress=False)
    assert np.array_equal(data.obs[0::2], data.obs[1::2]) and np.array_equal(data.success[0::2], data.success[1::2])
    assert np.array_equal(data.obs[0::2], plain.obs) and np.array_equal(data.success[0::2], plain.success)
    assert data.success.any()  # a spin that succeeded moved the object: the second try started over


def test_train_command_fits_on_frame_contrast_rollouts(tmp_path, capsys):
    """``success train SKILL --contrast K``: the rollouts are frame-contrast ones (cached under their own name), and
    the model file records how it was made; ``--contrast`` with ``--frames`` or below 0 is refused."""
    rc = success.main(["train", "spin", "--contrast", "3", "--rollouts", "30", "--epochs", "1", "--seed", "1",
                       "--out", str(tmp_path), "--json"])
    assert rc == 0
    info = weights_file.load(tmp_path / "success.pt", kind="success")[0]["info"]
    assert info["contrast"] == 3 and "--rollouts 30 --seed 1 --epochs 1 --members 1 --contrast 3" in info["command"]
    data = success.Rollouts.load(tmp_path / "train_contrast3_rollouts_30_1.npz")
    assert len(data) == 30 == info["train"] + info["calibration"]
    assert len(np.unique(data.group)) < 30  # several rollouts per start
    for bad in (["--contrast", "3", "--frames", "shipped"], ["--contrast", "-1"]):
        with pytest.raises(SystemExit):
            success.main(["train", "spin", *bad, "--out", str(tmp_path / "no")])
    assert not (tmp_path / "no").exists()
    # The same rollouts (from the cache) read by a contact-frame encoder: the file says so and loads as one.
    rc = success.main(["train", "spin", "--contrast", "3", "--rollouts", "30", "--epochs", "1", "--seed", "1",
                       "--encoder", "contact", "--out", str(tmp_path), "--json"])
    assert rc == 0
    info = weights_file.load(tmp_path / "success.pt", kind="success")[0]["info"]
    assert info["encoder"] == "contact" and info["command"].endswith("--encoder contact")
    assert success.load_success_net("spin", tmp_path / "success.pt").encoder == "contact"
    # The cached rollouts again, fitted with the ranking loss and read through --rollouts-from (twice, concatenated).
    cache = str(tmp_path / "train_contrast3_rollouts_30_1.npz")
    out = tmp_path / "ranked"
    rc = success.main(["train", "spin", "--rollouts-from", cache, cache, "--rank-weight", "0.5", "--epochs", "1",
                       "--seed", "1", "--out", str(out), "--json"])
    assert rc == 0
    info = weights_file.load(out / "success.pt", kind="success")[0]["info"]
    assert info["rank_weight"] == 0.5 and info["rollouts"] == 60 == info["train"] + info["calibration"]
    name = Path(cache).name  # a folder outside the working directory is not recorded (primitives.training.provenance)
    assert info["rollouts_from"] == [name, name] and info["command"].endswith(f"--rollouts-from {name} {name}")
    assert str(tmp_path) not in json.dumps(info)
    assert "--rollouts " not in info["command"]  # the files, not a count, say what was fitted
    assert list(out.glob("*.npz")) == []  # nothing collected, nothing cached
    for bad in (["--rank-weight", "1"], ["--contrast", "3", "--rank-weight", "-1"],
                ["--rollouts-from", str(tmp_path / "missing.npz")]):
        with pytest.raises(SystemExit):
            success.main(["train", "spin", *bad, "--out", str(tmp_path / "no")])
    assert not (tmp_path / "no").exists()
    broken = tmp_path / "broken.npz"
    broken.write_bytes(b"not a zip")
    assert success.main(["train", "spin", "--rollouts-from", str(broken), "--out", str(tmp_path / "b"), "--json"]) == 2
    assert "broken.npz is not a rollouts file" in capsys.readouterr().err
    np.savez(broken, obs=np.zeros(3))  # a real archive without the columns
    with pytest.raises(InputError, match="not a rollouts file .*no decision, success, group, parameterised"):
        success.Rollouts.load(broken)
    single = tmp_path / "single.npy"
    np.save(single, np.zeros(3))  # numpy's, but one array
    with pytest.raises(InputError, match="single.npy is not a rollouts file"):
        success.Rollouts.load(single)


def test_frame_contrast_rollouts_may_act_as_the_stand_in_requests():
    """With a search that has stand-ins, a start with the seed's objective is also executed as if asked for each
    drawn stand-in request, judged by that request's own criterion (a parameterised rollout); starts with a
    parameter keep their own free frames."""
    from primitives.frames import reframe_obs
    from primitives.skills import load_skill

    policy = load_skill("push", frame_search=False).success_model.policy
    search = FrameSearch(2, True, stand_ins=4)  # the seed's 4 frames and 4 directions x 2 mirrors: 12 options
    data = success.collect_contrast(policy, "push", 12, search, 12, "train", n_objects=3, seed=2, p_params=0.0,
                                    progress=False)
    assert len(np.unique(data.group)) == 1  # one start (one object), all twelve options
    assert data.parameterised.sum() == 8  # the four directions in both mirrors, judged as asked
    flows = np.abs(data.obs[:, :, 6:].astype(np.float32)).max(axis=(1, 2))
    assert (flows[~data.parameterised] == 0).all() and (flows[data.parameterised] > 0).all()
    seed_frames = data.obs[~data.parameterised].astype(np.float32)
    turned = reframe_obs(seed_frames[0], search.frames("push", None))
    assert all(min(np.abs(t - o).max() for t in turned) < 2e-3 for o in seed_frames)
    asked = success.collect_contrast(policy, "push", 4, search, 12, "train", n_objects=3, seed=2, p_params=1.0,
                                     progress=False)
    assert asked.parameterised.all()
    mirrored = reframe_obs(asked.obs[0].astype(np.float32), search.frames("push", {}))[1]
    assert np.abs(mirrored - asked.obs[1]).max() < 2e-3  # a direction's options: its two mirror frames
    with pytest.raises(SystemExit):
        success.main(["train", "push", "--contrast-stand-ins", "24"])  # needs --contrast


def test_a_bad_stand_in_count_for_contrast_is_refused_before_anything_is_written(tmp_path, capsys):
    out = tmp_path / "no"
    assert success.main(["train", "push", "--contrast", "2", "--contrast-stand-ins", "18", "--out", str(out)]) == 2
    assert "multiple of turns" in capsys.readouterr().err and not out.exists()


def test_a_contact_encoder_learns_round_trips_and_answers_as_its_stacked_form(tmp_path):
    torch.set_num_threads(1)
    rng = np.random.default_rng(4)
    net, info = success.fit(_synthetic(1200, rng), seed=0, epochs=6, members=2, progress=False, encoder="contact")
    assert net.encoder == "contact" and info["encoder"] == "contact"
    test = _synthetic(600, rng)
    obs, dec = torch.from_numpy(test.obs.astype(np.float32)), torch.from_numpy(test.decision)
    with torch.no_grad():
        p = net(obs, dec).numpy()
    assert success.metrics(p, test.success)["auroc"] > 0.8
    success.save(net, tmp_path / "c.pt", info, skill="spin")
    again = success.load_success_net("spin", tmp_path / "c.pt")
    assert again.encoder == "contact"
    with torch.no_grad():
        assert np.allclose(again(obs, dec).numpy(), p)
    from primitives.ensemble import StackedEnsemble

    assert np.allclose(StackedEnsemble(again)(obs, dec).numpy(), p, atol=1e-6)
    with pytest.raises(InputError):
        success.SuccessNet(encoder="voxels")


@pytest.mark.parametrize("objects", ["test", "housekeep:unseen", "train+housekeep:unseen_class_thick",
                                     "housekeep:training+housekeep:unseen_instance",
                                     "train+housekeep/clamp_050_medium_clamp_M",
                                     "some/where/clamp_050_medium_clamp_M.obj"])
def test_fitting_refuses_held_out_objects_and_evaluating_takes_them(objects):
    from primitives.training.env import check_objects

    with pytest.raises(InputError, match="held out"):
        check_objects(objects, fitting=True)
    check_objects(objects, fitting=False)
    check_objects("train+housekeep:training", fitting=True)
    with pytest.raises(InputError, match="housekeep split"):
        check_objects("housekeep:nope", fitting=False)


def test_single_training_meshes_are_not_held_out():
    from affordplan.objects import housekeep
    from primitives.training.env import check_objects, held_out

    name = housekeep.names("training")[0]
    assert not held_out(f"housekeep/{name}") and not held_out("cube") and not held_out(f"meshes/{name}.obj")
    check_objects(f"train+housekeep/{name}", fitting=True)


def test_searched_rollouts_act_with_the_frame_search_and_ratings_of_the_asked_sensor(tmp_path, monkeypatch):
    """``train --frames shipped --sensor cameras`` collects with the camera frame search (spin's: ranked) and
    the success model for camera clouds, as the skill acts on a camera simulator, not with the files beside the
    policy."""
    asked, real_search = {}, success.load_frame_search

    class Stop(Exception):
        pass

    def frame_search(skill, frames, sensor=None, ranked=True):
        asked["frames"] = sensor
        search = real_search(skill, frames, sensor, ranked)
        asked["ranked"] = search.ranker is not None
        return search

    def success_net(skill, weights=None, sensor=None):
        asked["model"] = sensor
        raise Stop  # before any rollout

    monkeypatch.setattr(success, "load_frame_search", frame_search)
    monkeypatch.setattr(success, "load_success_net", success_net)
    with pytest.raises(Stop):
        success.main(["train", "spin", "--frames", "shipped", "--sensor", "cameras", "--rollouts", "1",
                      "--out", str(tmp_path)])
    assert asked == {"frames": "cameras", "ranked": True, "model": "cameras"}


def test_train_command_records_a_collection_of_full_motion_spins(tmp_path):
    """``--full-motion``: the spins by an angle collected run their full motion (as plans execute them); the model
    file records it, in its info and in the command that remakes it."""
    rc = success.main(["train", "spin", "--rollouts", "12", "--epochs", "1", "--seed", "2", "--full-motion",
                       "--out", str(tmp_path), "--json"])
    assert rc == 0
    info = weights_file.load(tmp_path / "success.pt", kind="success")[0]["info"]
    assert info["full_motion"] is True and info["command"].endswith("--full-motion")
