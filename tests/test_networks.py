"""The hybrid actor-critic (primitives.networks): per-point maps, the contact choice, widening an older first layer."""

from __future__ import annotations

import numpy as np
import torch

from primitives.networks import HybridActorCritic, choose_contact, widen_input


def test_maps_are_per_point_and_permutation_equivariant():
    torch.manual_seed(0)
    model = HybridActorCritic().eval()
    obs = torch.randn(2, 64, 9)
    actions, q = model.maps(obs)
    assert actions.shape == (2, 64, 3) and q.shape == (2, 64)
    assert actions.abs().max() <= 1.0
    perm = torch.randperm(64)
    actions_p, q_p = model.maps(obs[:, perm])
    assert torch.allclose(q_p, q[:, perm], atol=1e-5) and torch.allclose(actions_p, actions[:, perm], atol=1e-5)


def test_contact_choice_greedy_and_exploring():
    q = torch.tensor([[0.0, 5.0, -1.0]])
    assert int(choose_contact(q, 0.1, 0.1, None, greedy=True)[0]) == 1
    gen = torch.Generator().manual_seed(0)
    picks = [int(choose_contact(q, 0.1, 0.3, gen, greedy=False)[0]) for _ in range(400)]
    assert 0.7 < np.mean(np.array(picks) == 1) < 0.9  # 1 - eps + eps/3 = 0.8


def test_the_critic_map_is_the_smaller_of_the_twin_critics_of_the_actor_s_motions():
    torch.manual_seed(2)
    model = HybridActorCritic().eval()
    obs = torch.randn(3, 32, 9)
    actions, q = model.maps(obs)
    with torch.no_grad():
        feats = model.features(obs)
        assert feats.shape == (3, 32, 128)
        q1, q2 = model.q_maps(feats, model.act_map(feats))
    assert torch.equal(q, torch.minimum(q1, q2)) and not torch.equal(q1, q2)  # two critics, apart
    one, _ = model.maps(obs[:1])
    assert torch.allclose(one[0], actions[0], atol=1e-6)  # each cloud of a batch on its own


def test_a_first_layer_read_by_fewer_inputs_is_widened_with_zero_weights():
    """A file from before the goal flow (6 inputs per point) loads into today's 9-input network and acts exactly as
    it did, whatever the goal flow."""
    torch.manual_seed(1)
    old = HybridActorCritic(in_dim=6).eval()
    new = HybridActorCritic().eval()
    new.load_state_dict(widen_input(old.state_dict()))
    obs = torch.randn(2, 32, 9)
    old_actions, old_q = old.maps(obs[..., :6])
    new_actions, new_q = new.maps(obs)
    assert torch.allclose(new_actions, old_actions, atol=1e-6) and torch.allclose(new_q, old_q, atol=1e-5)
    state = new.state_dict()
    assert widen_input(state) is state  # already wide: left alone
