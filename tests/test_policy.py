"""Loading a policy and acting greedily (primitives.policy): the file kinds it takes and refuses, and the greedy
choice among allowed contacts."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from affordplan.errors import WeightsError
from primitives import weights_file
from primitives.networks import HybridActorCritic
from primitives.policy import greedy_action, load_policy
from primitives.training import checkpoint as ckpt


def _state(seed: int = 0) -> dict:
    torch.manual_seed(seed)
    return HybridActorCritic().state_dict()


def test_a_policy_file_loads_into_an_evaluating_network_knowing_its_sensor(tmp_path):
    state = _state()
    weights_file.save(tmp_path / "p.pt", dict(model=state), weights_file.make_meta("roll", "policy", sensor="cameras"))
    model = load_policy(tmp_path / "p.pt", "roll")
    assert not model.training and model.sensor == "cameras"
    assert all(torch.equal(model.state_dict()[k], v) for k, v in state.items())


def test_a_checkpoint_is_read_as_one_by_its_name(tmp_path):
    state = _state(1)
    ckpt.save(tmp_path / "checkpoint.pt", {"model": state, "config": {"primitive": "spin"}})
    model = load_policy(tmp_path / "checkpoint.pt", "spin")
    assert all(torch.equal(model.state_dict()[k], v) for k, v in state.items())
    assert model.sensor == "surface"  # no sensor in its metadata: the clouds of every release before 0.24
    (tmp_path / "checkpoint.pt").rename(tmp_path / "weights.pt")  # by another name it is not taken for a policy
    with pytest.raises(WeightsError, match="holds a checkpoint file, not a policy"):
        load_policy(tmp_path / "weights.pt", "spin")


def test_a_file_of_another_kind_or_shape_is_refused_with_a_weights_error(tmp_path):
    weights_file.save(tmp_path / "s.pt", dict(model={}, info={}), weights_file.make_meta("push", "success"))
    with pytest.raises(WeightsError, match="holds a success file, not a policy"):
        load_policy(tmp_path / "s.pt", "push")
    weights_file.save(tmp_path / "small.pt", dict(model=HybridActorCritic(feat_dim=32).state_dict()),
                      weights_file.make_meta("push", "policy"))
    with pytest.raises(WeightsError, match="does not fit the policy network"):
        load_policy(tmp_path / "small.pt", "push")
    with pytest.raises(WeightsError):
        load_policy(tmp_path / "missing.pt", "push")


@pytest.mark.parametrize("name", ["push", "roll", "spin"])
def test_no_file_means_the_shipped_policy(name):
    shipped = load_policy(None, name)
    again = load_policy(weights_file.SHIPPED_DIR / f"{name}.pt", name)
    assert all(torch.equal(shipped.state_dict()[k], v) for k, v in again.state_dict().items())


def test_the_greedy_action_is_the_best_allowed_contact_and_its_motion():
    torch.manual_seed(0)
    model = HybridActorCritic().eval()
    obs = np.random.default_rng(0).normal(0, 0.03, size=(64, 9)).astype(np.float32)
    idx, motion, q = greedy_action(model, obs)
    actions, q_ref = model.maps(torch.from_numpy(obs)[None])
    assert idx == int(np.argmax(q)) and np.allclose(q, q_ref[0].numpy())
    assert motion.dtype == np.float64 and np.allclose(motion, actions[0, idx].numpy())
    allowed = np.ones(64, bool)
    allowed[idx] = False  # the best is masked out: the next best is taken
    idx2, motion2, q2 = greedy_action(model, obs, allowed)
    assert idx2 != idx and idx2 == int(np.argsort(q)[-2]) and np.array_equal(q2, q)
    assert np.allclose(motion2, actions[0, idx2].numpy())
