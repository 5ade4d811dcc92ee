"""Success models at run time (primitives.success_model): loading nets (ensembles and older single nets), answering
single and batched queries, the decision features (the lever arm) and the contact-frame input."""

import numpy as np
import pytest
import torch

from primitives import success_model, weights_file
from primitives.networks import HybridActorCritic
from primitives.training import success


def test_a_single_net_file_from_before_ensembles_loads(tmp_path):
    torch.manual_seed(0)
    net = success_model.SuccessNet()
    net.platt.copy_(torch.tensor([0.9, 0.1]))
    legacy = {k.removeprefix("members.0."): v for k, v in net.state_dict().items()}  # the old key names
    assert "points.0.weight" in legacy
    weights_file.save(tmp_path / "old.pt", dict(model=legacy, info={}), weights_file.make_meta("push", "success"))
    loaded = success_model.load_success_net("push", tmp_path / "old.pt")
    obs = torch.from_numpy(np.random.default_rng(0).normal(0, 0.03, size=(4, 32, 9)).astype(np.float32))
    dec = torch.zeros(4, success_model.N_DECISION)
    with torch.no_grad():
        assert len(loaded.members) == 1 and torch.allclose(loaded(obs, dec), net(obs, dec))


def test_model_answers_single_and_batched_queries(tmp_path):
    torch.manual_seed(0)
    model = success_model.SuccessModel(HybridActorCritic(), success_model.SuccessNet())
    obs = np.random.default_rng(0).normal(0, 0.03, size=(3, 64, 9)).astype(np.float32)
    p = model.predict(obs)
    assert p.shape == (3,) and np.all((p > 0) & (p < 1))
    assert model.predict(obs[1]) == pytest.approx(p[1], abs=1e-6)
    success.save(model.net, tmp_path / "s.pt", {}, skill="push")
    assert torch.equal(success_model.load_success_net("push", tmp_path / "s.pt").platt, model.net.platt)
    (tmp_path / "bad.pt").write_bytes(b"not a checkpoint")
    from affordplan.errors import WeightsError

    with pytest.raises(WeightsError):
        success_model.load_success_net("push", tmp_path / "bad.pt")
    with pytest.raises(WeightsError):
        success_model.load_success_net("push", tmp_path / "missing.pt")


class _FixedPolicy:
    """Stands in for a policy whose greedy decision is point ``index`` with ``motion``."""

    def __init__(self, index: int, motion):
        self.index, self.motion = index, torch.tensor(motion, dtype=torch.float32)

    def maps(self, obs):
        q = torch.zeros(obs.shape[:2])
        q[:, self.index] = 1.0
        return self.motion.expand(*obs.shape[:2], 3).clone(), q


def test_the_lever_arm_feature_is_the_motion_lines_distance_from_the_centroid():
    """The last decision feature: a push along +x through a contact 2 cm to the side of the cloud's centroid (the
    observation's origin) has a 2 cm lever arm; along +y through the same contact, 5 cm."""
    obs = torch.zeros(1, 8, 9)
    obs[0, 3, :3] = torch.tensor([-0.05, 0.02, 0.03])  # 5 cm behind the centroid, 2 cm to its left, 3 cm up
    _, _, along_x = success_model.decision_features(_FixedPolicy(3, [1.0, 0.0, -0.2]), obs)
    _, _, along_y = success_model.decision_features(_FixedPolicy(3, [0.0, 0.7, 0.0]), obs)
    assert along_x.shape == (1, success_model.N_DECISION)
    assert along_x[0, -1].item() == pytest.approx(2.0, abs=1e-4)  # cm
    assert along_y[0, -1].item() == pytest.approx(5.0, abs=1e-4)
    _, _, still = success_model.decision_features(_FixedPolicy(3, [0.0, 0.0, -1.0]), obs)  # straight down: no line
    assert torch.isfinite(still).all()


def test_a_model_fitted_before_the_lever_arm_reads_only_its_thirteen_features(tmp_path):
    from primitives import weights_file

    # a file fitted before the lever arm (as roll's were until 0.24): its head reads 13 decision features
    old = success_model.SuccessNet(members=2, n_decision=13)
    weights_file.save(tmp_path / "old.pt", {"model": old.state_dict(), "info": {}},
                      weights_file.make_meta("roll", "success"))
    net = success_model.load_success_net("roll", tmp_path / "old.pt")
    assert net.n_decision == 13
    obs = torch.randn(3, 256, 9) * 0.03
    dec = torch.randn(3, success_model.N_DECISION)
    other = dec.clone()
    other[:, 13:] = 1e3
    with torch.no_grad():
        assert torch.equal(net(obs, dec), net(obs, other))


def test_the_shipped_push_model_reads_the_lever_arm():
    from primitives.skills import load_skill

    net = load_skill("push").success_model.net  # 0.20's push files were fitted with the lever arm
    assert net.n_decision == success_model.N_DECISION == 14
    obs = torch.randn(3, 256, 9) * 0.03
    dec = torch.randn(3, success_model.N_DECISION)
    other = dec.clone()
    other[:, 13] += 5.0  # the line 5 cm further from the centroid
    with torch.no_grad():
        assert not torch.allclose(net(obs, dec), net(obs, other))


def test_the_contact_frame_sees_the_cloud_from_the_fingertip():
    """Points are placed relative to the contact with x along the motion: the contact itself at the origin, a
    point 1 cm ahead of it at x = 0.1 dm; turning the whole scene about the vertical changes nothing in the contact
    frame, only the goal-frame positions the encoder also reads."""
    rng = np.random.default_rng(3)
    obs = rng.normal(0, 0.03, size=(1, 16, 9)).astype(np.float32)
    obs[0, 1, :3] = obs[0, 0, :3] + [0.0, 0.01, 0.0]  # 1 cm from the contact along +y
    decision = np.zeros((1, success_model.N_DECISION), np.float32)
    decision[0, 4:7] = 10 * obs[0, 0, :3]  # the contact, in dm as decision_features gives it
    decision[0, 10:13] = [0.0, 0.7, -0.2]  # the motion: along +y, a little down
    x = success_model.contact_frame_input(torch.from_numpy(obs), torch.from_numpy(decision))[0]
    assert x.shape == (16, 13)
    assert torch.allclose(x[0, :3], torch.zeros(3), atol=1e-6) and float(x[0, 9]) == pytest.approx(0.0, abs=1e-6)
    assert torch.allclose(x[1, :3], torch.tensor([0.1, 0.0, 0.0]), atol=1e-6)
    assert float(x[1, 9]) == pytest.approx(0.1, abs=1e-6)
    c, s = np.cos(0.7), np.sin(0.7)
    Rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]], np.float32)
    turned_obs = np.einsum("ij,bnkj->bnki", Rz, obs.reshape(1, 16, 3, 3)).reshape(1, 16, 9)
    turned_dec = decision.copy()
    turned_dec[0, 4:7] = Rz @ decision[0, 4:7]
    turned_dec[0, 10:13] = Rz @ decision[0, 10:13]
    y = success_model.contact_frame_input(torch.from_numpy(turned_obs), torch.from_numpy(turned_dec))[0]
    assert torch.allclose(y[:, :10], x[:, :10], atol=1e-5)
    assert not torch.allclose(y[:, 10:], x[:, 10:], atol=1e-3)
