"""The stacked ensemble answers what the success net answers."""

import numpy as np
import pytest
import torch

from affordplan.errors import InputError
from primitives.ensemble import StackedEnsemble
from primitives.training import success


@pytest.mark.parametrize("members,n_decision,batch,encoder", [(1, 13, 1, "cloud"), (5, 14, 1, "cloud"),
                                                              (5, 14, 7, "cloud"), (3, 13, 4, "cloud"),
                                                              (5, 14, 3, "contact"), (1, 14, 1, "contact")])
def test_stacked_ensemble_matches_the_net(members, n_decision, batch, encoder):
    torch.manual_seed(members + batch)
    net = success.SuccessNet(width=32, members=members, n_decision=n_decision, encoder=encoder).eval()
    with torch.no_grad():
        net.platt.copy_(torch.tensor([1.3, -0.2]))
    rng = np.random.default_rng(batch)
    obs = torch.from_numpy(rng.normal(0, 0.03, size=(batch, 48, 9)).astype(np.float32))
    decision = torch.from_numpy(rng.normal(0, 1.0, size=(batch, success.N_DECISION)).astype(np.float32))
    with torch.no_grad():
        expected = net(obs, decision)
    got = StackedEnsemble(net)(obs, decision)
    assert got.shape == (batch,)
    assert torch.allclose(got, expected, atol=1e-6, rtol=0)


def test_stacked_ensemble_is_a_snapshot_and_refuses_bad_shapes():
    torch.manual_seed(0)
    net = success.SuccessNet(width=16, members=2).eval()
    stacked = StackedEnsemble(net)
    obs = torch.zeros(2, 8, 9)
    decision = torch.ones(2, success.N_DECISION)
    before = stacked(obs, decision)
    with torch.no_grad():
        net.members[0].head[4].bias.add_(5.0)  # a later change to the net is not seen
    assert torch.equal(stacked(obs, decision), before)
    assert not torch.allclose(net(obs, decision), before)
    with pytest.raises(InputError):
        stacked(obs[0], decision)
    with pytest.raises(InputError):
        stacked(obs, decision[:, :5])


def test_the_shipped_models_answer_as_their_nets():
    from primitives.skills import load_skill

    rng = np.random.default_rng(0)
    obs = torch.from_numpy(rng.normal(0, 0.03, size=(3, 256, 9)).astype(np.float32))
    for name in ("push", "spin"):
        model = load_skill(name).searched_model
        _, _, decision = success.decision_features(model.policy, obs)
        with torch.no_grad():
            expected = model.net(obs, decision).numpy()
        assert np.allclose(model.predict(obs.numpy()), expected, atol=1e-6, rtol=0)



def test_member_probabilities_are_the_members_through_the_ensembles_scaling():
    """The ensemble's answer is sigmoid(a * mean member logit + b); each member's probability is sigmoid(a * its
    logit + b), so undoing the scaling and averaging gives the ensemble's answer back. One member never disagrees."""
    torch.manual_seed(0)
    net = success.SuccessNet(members=4).eval()
    net.platt[:] = torch.tensor([0.8, -0.3])
    stacked = StackedEnsemble(net)
    obs, dec = torch.randn(5, 32, 9), torch.randn(5, 14)
    members = stacked.member_probabilities(obs, dec).double()
    assert members.shape == (4, 5)
    member_logits = (torch.logit(members) + 0.3) / 0.8
    assert torch.allclose(torch.sigmoid(0.8 * member_logits.mean(0) - 0.3), stacked(obs, dec).double(), atol=1e-5)
    assert members.std(dim=0).min() > 0  # four independently initialised members disagree
    one = StackedEnsemble(success.SuccessNet(members=1).eval())
    assert torch.all(one.member_probabilities(obs, dec).std(dim=0, correction=0) == 0)
