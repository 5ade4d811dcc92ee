"""Hybrid actor-critic maps over point clouds, in plain torch (no torch_geometric).

- :class:`PointNetBackbone`: a per-point MLP, a global max-pool, and a per-point head that sees each
  point's local features and the cloud's global feature. The head's first layer is split into a
  local and a global part (``W [l; g] = W_l l + W_g g``), so the global part is computed once per
  cloud and broadcast instead of concatenated per point.
- :class:`HybridActorCritic`: on the shared backbone, an *actor map* (a motion in [-1, 1]^3 per
  point) and twin *critic maps* ``Q_k(f_i, a)`` (the value of executing motion ``a`` at point ``i``).

The contact is chosen from the critic map: ``softmax(Q / T)`` over points with epsilon-greedy
exploration in training, the argmax at evaluation (HACMan's rule).

Input per point: 9 features (position, normal, goal flow; :mod:`primitives.training.env`). Weights trained on
the first 6 alone (the seed's objective, before parameters) load through :func:`widen_input`, which
gives the goal-flow inputs zero weight: the network computes exactly what it did before.
"""

from __future__ import annotations

import torch
from torch import nn

IN_DIM = 9  # per-point input: position (3), normal (3), goal flow (3)
_FIRST_LAYER = "backbone.local.0.weight"


class PointNetBackbone(nn.Module):
    """``(B, N, in_dim)`` -> per-point features ``(B, N, feat_dim)``."""

    def __init__(self, in_dim: int = IN_DIM, local_dim: int = 128, global_dim: int = 256, feat_dim: int = 128):
        super().__init__()
        self.local = nn.Sequential(nn.Linear(in_dim, 64), nn.ReLU(), nn.Linear(64, local_dim), nn.ReLU())
        self.global_mlp = nn.Sequential(nn.Linear(local_dim, global_dim), nn.ReLU())
        self.head_local = nn.Linear(local_dim, feat_dim)
        self.head_global = nn.Linear(global_dim, feat_dim, bias=False)
        self.head = nn.Sequential(nn.ReLU(), nn.Linear(feat_dim, feat_dim), nn.ReLU())

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        local = self.local(x)
        glob = self.global_mlp(local).amax(dim=1)  # (B, global_dim)
        return self.head(self.head_local(local) + self.head_global(glob)[:, None, :])


def _mlp(in_dim: int, out_dim: int, hidden: int = 128) -> nn.Sequential:
    return nn.Sequential(nn.Linear(in_dim, hidden), nn.ReLU(), nn.Linear(hidden, hidden), nn.ReLU(),
                         nn.Linear(hidden, out_dim))


class HybridActorCritic(nn.Module):
    """Actor map and twin critic maps on a shared point-cloud backbone."""

    def __init__(self, in_dim: int = IN_DIM, feat_dim: int = 128, action_dim: int = 3):
        super().__init__()
        self.backbone = PointNetBackbone(in_dim, feat_dim=feat_dim)
        self.actor = _mlp(feat_dim, action_dim)
        self.q1 = _mlp(feat_dim + action_dim, 1)
        self.q2 = _mlp(feat_dim + action_dim, 1)

    def features(self, obs: torch.Tensor) -> torch.Tensor:
        return self.backbone(obs)

    def act_map(self, feats: torch.Tensor) -> torch.Tensor:
        """Per-point motions in [-1, 1]: ``(B, N, 3)``."""
        return torch.tanh(self.actor(feats))

    def q_maps(self, feats: torch.Tensor, actions: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Twin critic values ``(B, N)`` of executing ``actions`` (``(B, N, 3)``) at every point."""
        x = torch.cat([feats, actions], dim=-1)
        return self.q1(x).squeeze(-1), self.q2(x).squeeze(-1)

    @torch.no_grad()
    def maps(self, obs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Actor map ``(B, N, 3)`` and critic map ``min(Q1, Q2)`` ``(B, N)`` for observations."""
        feats = self.features(obs)
        actions = self.act_map(feats)
        q1, q2 = self.q_maps(feats, actions)
        return actions, torch.minimum(q1, q2)


def choose_contact(q: torch.Tensor, temperature: float, epsilon: float, generator: torch.Generator | None,
                   greedy: bool) -> torch.Tensor:
    """Contact indices ``(B,)`` from critic maps ``(B, N)``: argmax, or softmax(Q/T) with epsilon-uniform."""
    if greedy:
        return q.argmax(dim=1)
    probs = torch.softmax(q / temperature, dim=1)
    probs = (1.0 - epsilon) * probs + epsilon / q.shape[1]
    return torch.multinomial(probs, 1, generator=generator).squeeze(1)


def widen_input(state: dict[str, torch.Tensor], in_dim: int = IN_DIM) -> dict[str, torch.Tensor]:
    """A state dict whose first layer reads ``in_dim`` inputs; added inputs get zero weight."""
    w = state.get(_FIRST_LAYER)
    if w is None or w.shape[1] >= in_dim:
        return state
    state = dict(state)
    state[_FIRST_LAYER] = torch.cat([w, torch.zeros(w.shape[0], in_dim - w.shape[1], dtype=w.dtype)], dim=1)
    return state
