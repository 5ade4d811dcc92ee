"""A searched success model's Platt scaling refitted on other objects' rollouts (primitives.training.recalibrate)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from primitives.success_model import N_DECISION, SuccessNet
from primitives.training import recalibrate
from primitives.training.success import Rollouts


def _rollouts(net: SuccessNet, n: int, objects: int, spread: float, offset: float,
              seed: int) -> tuple[Rollouts, float]:
    """``n`` rollouts of ``objects`` objects whose outcomes follow ``sigmoid(a z + offset)`` of ``net``'s raw logit
    ``z``, with ``a`` set so that ``a z`` spreads by ``spread`` (one standard deviation); returns them and ``a``."""
    rng = np.random.default_rng(seed)
    obs = rng.normal(0.0, 0.03, size=(n, 32, 9)).astype(np.float16)
    decision = rng.normal(0.0, 1.0, size=(n, N_DECISION)).astype(np.float32)
    with torch.no_grad():
        z = net.logit(torch.from_numpy(obs.astype(np.float32)), torch.from_numpy(decision)).numpy()
    a = spread / z.std()
    p = 1.0 / (1.0 + np.exp(-(a * z + offset)))
    return Rollouts(obs, decision, rng.random(n) < p, np.arange(n) % objects, np.zeros(n, dtype=bool)), a


def _net() -> SuccessNet:
    torch.manual_seed(0)
    net = SuccessNet(width=16, members=2).eval()
    with torch.no_grad():
        net.platt.copy_(torch.tensor([1.0, 0.0]))
    return net


def test_the_refitted_scaling_recovers_the_one_the_outcomes_follow_and_leaves_the_net_alone():
    net = _net()
    data, a = _rollouts(net, 4000, 8, spread=2.0, offset=-0.5, seed=3)  # outcomes from about 0.1 to 0.8
    obs, decision = torch.from_numpy(data.obs[:5].astype(np.float32)), torch.from_numpy(data.decision[:5])
    with torch.no_grad():
        before = net(obs, decision).clone()
    result = recalibrate.recalibrate(net, data)
    assert result.platt[0] == pytest.approx(a, rel=0.15) and result.platt[1] == pytest.approx(-0.5, abs=0.15)
    with torch.no_grad():
        assert torch.equal(net(obs, decision), before)  # the caller decides what to keep
    report = result.report(data.success)
    assert report["in_sample"]["ece"] < report["before"]["ece"]  # the net's own (1, 0) was wrong
    assert report["leave_one_object_out"]["ece"] < report["before"]["ece"]
    assert not np.array_equal(result.leave_one_object_out, result.in_sample)  # each object scored without itself
    # a scaling with a > 0 keeps the order: the ranking (AUROC) is the net's own
    assert report["in_sample"]["auroc"] == pytest.approx(report["before"]["auroc"], abs=1e-9)


def test_rollouts_of_one_object_cannot_be_judged_without_themselves():
    net = _net()
    data, _ = _rollouts(net, 50, 1, spread=1.0, offset=0.0, seed=0)
    with pytest.raises(ValueError, match="at least 2 objects"):
        recalibrate.recalibrate(net, data)


def test_calibrate_refuses_held_out_test_objects_with_exit_2(tmp_path, capsys):
    assert recalibrate.main(["push", "--objects", "housekeep:unseen", "--out", str(tmp_path)]) == 2
    assert "held out" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())  # refused before anything was written
