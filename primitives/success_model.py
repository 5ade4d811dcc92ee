"""A skill's success model at query time: ``P(success | cloud, params)`` from the policy's observation and decision.

The model and its choices are described where it is fitted, :mod:`primitives.training.success`; this module is
what answering a query needs: the network, the policy-decision features and the shipped file's loader.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import numpy as np
import torch
from torch import nn

from affordplan.errors import InputError, WeightsError
from primitives import weights_file
from primitives.ensemble import StackedEnsemble
from primitives.networks import HybridActorCritic
from primitives.observation import OBS_DIM

N_DECISION = 14  # policy-decision features, see decision_features (files fitted before 0.20 use the first 13)
CONTRAST_TURNS = 12  # turns about the vertical of frame-contrast rollouts, as the shipped frame searches try


def decision_features(policy: HybridActorCritic, obs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """The policy's greedy decision on a batch ``(B, N, 9)`` and its summary ``(B, 14)``.

    Returns ``(index (B,), motion (B, 3), features (B, 14))``; the features are the chosen Q, the
    map's max minus its mean, its std, a softmax-entropy, the contact's observation (position,
    normal), the motion, and the motion line's lever arm: the distance in the table plane from the cloud's
    centroid (the observation's origin) to the line through the contact along the motion, in cm. A push whose
    line passes more than a centimetre from the centroid turns the object about it.
    """
    actions, q = policy.maps(obs)
    idx = q.argmax(dim=1)
    rows = torch.arange(len(idx))
    q_max = q[rows, idx]
    probs = torch.softmax(q / 0.1, dim=1)
    entropy = -(probs * torch.log(probs + 1e-12)).sum(dim=1) / np.log(q.shape[1])
    motion = actions[rows, idx]
    contact = obs[rows, idx, :2]
    along = motion[:, :2] / motion[:, :2].norm(dim=1, keepdim=True).clamp_min(1e-6)
    lever = (contact[:, 0] * along[:, 1] - contact[:, 1] * along[:, 0]).abs() * 100.0
    feats = torch.cat([torch.stack([q_max, q_max - q.mean(dim=1), q.std(dim=1), entropy], dim=1),
                       obs[rows, idx, :6] * torch.tensor([10, 10, 10, 1, 1, 1.0]), motion, lever[:, None]], dim=1)
    return idx, motion, feats


ENCODERS = ("cloud", "contact")  # what a success net's members read, see SuccessNet
_CLOUD_DIM, _CONTACT_DIM = OBS_DIM, 13


def contact_frame_input(obs: torch.Tensor, decision: torch.Tensor) -> torch.Tensor:
    """The cloud as the policy's fingertip meets it: per point ``(B, N, 13)`` from observations ``(B, N, 9)`` and
    decision features ``(B, >= 13)`` (:func:`decision_features`: the contact at columns 4-6 in dm, the motion at
    10-12).

    In the *contact frame* (origin at the contact, x along the motion's horizontal direction, z up): the point's
    position (dm), its normal, its goal flow (in 5 cm), and its distance to the contact (dm); then its position in
    the goal frame (dm), as the cloud encoder reads it. A motion with no horizontal part leaves the goal frame's
    axes.
    """
    contact = decision[:, 4:7] / 10.0
    along = decision[:, 10:12]
    norm = along.norm(dim=1, keepdim=True)
    along = torch.where(norm > 1e-6, along / norm.clamp_min(1e-6), torch.tensor([1.0, 0.0]))
    R = torch.stack([along, torch.stack([-along[:, 1], along[:, 0]], dim=1)], dim=1)  # rows: along, across
    rel = obs[..., :3] - contact[:, None, :]
    turned = [torch.einsum("bij,bnj->bni", R, obs[..., k:k + 2] if k else rel[..., :2]) for k in (0, 3, 6)]
    return torch.cat([turned[0] * 10.0, rel[..., 2:3] * 10.0, turned[1], obs[..., 5:6], turned[2] * 20.0,
                      obs[..., 8:9] * 20.0, rel.norm(dim=-1, keepdim=True) * 10.0, obs[..., :3] * 10.0], dim=-1)


def member_input(encoder: str, obs: torch.Tensor, decision: torch.Tensor) -> torch.Tensor:
    """What a success net's members read for ``encoder`` (:data:`ENCODERS`): the scaled observation
    (:meth:`SuccessNet.scaled`, ``(B, N, 9)``) or the contact frame (:func:`contact_frame_input`, ``(B, N, 13)``)."""
    return contact_frame_input(obs, decision) if encoder == "contact" else SuccessNet.scaled(obs)


class _Member(nn.Module):
    """One PointNet of the ensemble: logit from scaled points ``(B, N, 9)`` and decision features
    ``(B, n_decision)``."""

    def __init__(self, in_dim: int, width: int, n_decision: int = N_DECISION):
        super().__init__()
        self.points = nn.Sequential(nn.Linear(in_dim, width), nn.ReLU(), nn.Linear(width, 2 * width), nn.ReLU())
        self.head = nn.Sequential(nn.Linear(4 * width + n_decision, 2 * width), nn.ReLU(),
                                  nn.Linear(2 * width, width), nn.ReLU(), nn.Linear(width, 1))

    def forward(self, x: torch.Tensor, decision: torch.Tensor) -> torch.Tensor:
        h = self.points(x)
        return self.head(torch.cat([h.amax(dim=1), h.mean(dim=1), decision], dim=1)).squeeze(-1)


class SuccessNet(nn.Module):
    """Logit of success from an observation ``(B, N, 9)`` and decision features ``(B, >= n_decision)``.

    The mean logit of ``members`` independently initialised and trained PointNets (a deep ensemble: it ranks
    outcomes better than any one member), then one Platt scaling of that mean. ``n_decision``: how many of
    :func:`decision_features` it reads, the first ones (13 for files fitted before the lever arm was added).
    ``encoder``: what the members' point MLP reads: ``"cloud"``, the observation (:meth:`scaled`), or
    ``"contact"``, the cloud seen from the policy's contact along its motion (:func:`contact_frame_input`), which
    lets a max-pool over points weigh the geometry ahead of the fingertip. A file's encoder is read from its
    first layer's width (9 or 13).
    """

    def __init__(self, width: int = 64, members: int = 1, n_decision: int = N_DECISION, encoder: str = "cloud"):
        super().__init__()
        if members < 1:
            raise InputError(f"an ensemble needs at least one member, got {members}")
        if encoder not in ENCODERS:
            raise InputError(f"unknown encoder {encoder!r}; expected one of {ENCODERS}")
        self.n_decision = n_decision
        self.encoder = encoder
        in_dim = _CONTACT_DIM if encoder == "contact" else _CLOUD_DIM
        self.members = nn.ModuleList(_Member(in_dim, width, n_decision) for _ in range(members))
        # Platt scaling, fitted after training: p = sigmoid(a * logit + b).
        self.register_buffer("platt", torch.tensor([1.0, 0.0]))

    @staticmethod
    def scaled(obs: torch.Tensor) -> torch.Tensor:
        """The members' input: observation features at about unit scale (positions in dm, flow in 5 cm)."""
        return obs * torch.tensor([10, 10, 10, 1, 1, 1, 20, 20, 20.0])

    def member_input(self, obs: torch.Tensor, decision: torch.Tensor) -> torch.Tensor:
        """What the members' point MLP reads, ``(B, N, 9)`` or ``(B, N, 13)`` (see ``encoder``)."""
        return member_input(self.encoder, obs, decision)

    def logit(self, obs: torch.Tensor, decision: torch.Tensor) -> torch.Tensor:
        x = self.member_input(obs, decision)
        decision = decision[:, :self.n_decision]
        return torch.stack([m(x, decision) for m in self.members]).mean(dim=0)

    def forward(self, obs: torch.Tensor, decision: torch.Tensor) -> torch.Tensor:
        """Calibrated probability of success ``(B,)``."""
        return torch.sigmoid(self.platt[0] * self.logit(obs, decision) + self.platt[1])

    @classmethod
    def from_state_dict(cls, state: dict) -> SuccessNet:
        """A net of as many members as ``state`` holds; files from before ensembles hold one, unprefixed."""
        if any(k.startswith(("points.", "head.")) for k in state):
            state = {(k if k == "platt" else f"members.0.{k}"): v for k, v in state.items()}
        members = 1 + max(int(k.split(".")[1]) for k in state if k.startswith("members."))
        width, in_dim = state["members.0.points.0.weight"].shape
        net = cls(width=width, members=members, n_decision=state["members.0.head.0.weight"].shape[1] - 4 * width,
                  encoder="contact" if in_dim == _CONTACT_DIM else "cloud")
        net.load_state_dict(state)
        return net


class SuccessModel:
    """A skill's policy and its success model, answering queries on observations.

    Queries go through a :class:`~primitives.ensemble.StackedEnsemble` of ``net``, built here: a snapshot of the
    net's weights, so build the model after training the net, not before.
    """

    def __init__(self, policy: HybridActorCritic, net: SuccessNet):
        self.policy = policy.eval()
        self.net = net.eval()
        self._stacked = StackedEnsemble(self.net)

    @torch.no_grad()
    def predict(self, obs: np.ndarray) -> np.ndarray:
        """P(success) for observations ``(N, 9)`` or ``(B, N, 9)``."""
        return self._per_observation(obs, lambda x, d: self._stacked(x, d))

    @torch.no_grad()
    def rate_and_decide(self, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """P(success) ``(B,)`` for observations ``(B, N, 9)`` and the policy's decision features ``(B, 14)``
        (:func:`decision_features`) it read them with, from one pass of the policy."""
        x = torch.as_tensor(np.asarray(obs, dtype=np.float32))
        _, _, d = decision_features(self.policy, x)
        return self._stacked(x, d).numpy(), d.numpy()

    @torch.no_grad()
    def spread(self, obs: np.ndarray) -> np.ndarray:
        """The members' disagreement on P(success) for observations ``(N, 9)`` or ``(B, N, 9)``: the standard
        deviation of their calibrated probabilities (0 for a one-member net). Low on observations like those the
        model was fitted on, higher where they did not settle the answer; it is not itself a probability."""
        return self._per_observation(
            obs, lambda x, d: self._stacked.member_probabilities(x, d).std(dim=0, correction=0))

    def _per_observation(self, obs: np.ndarray,
                         answer: Callable[[torch.Tensor, torch.Tensor], torch.Tensor]) -> np.ndarray:
        """``answer(observations (B, N, 9), the policy's decision features)`` for ``(N, 9)`` or ``(B, N, 9)``."""
        x = torch.as_tensor(np.asarray(obs, dtype=np.float32))
        single = x.ndim == 2
        x = x[None] if single else x
        _, _, d = decision_features(self.policy, x)
        out = answer(x, d).numpy()
        return out[0] if single else out


def load_success_net(skill: str, path: str | os.PathLike | None = None, sensor: str | None = None) -> SuccessNet:
    """A success net from ``path`` or the shipped ``weights/{skill}_success.pt`` (fitted to ``sensor``'s clouds where
    one is shipped for it: :func:`primitives.weights_file.rating_path`).

    Raises:
        WeightsError: missing, damaged or unsafe file, or one for another skill or kind of model.
    """
    path = Path(path) if path else weights_file.rating_path(skill, "success", sensor)
    payload, _ = weights_file.load(path, kind="success", skill=skill)
    try:
        net = SuccessNet.from_state_dict(payload["model"])
    except Exception as exc:  # a state dict of the right kind but the wrong shapes
        raise WeightsError(f"success model {path} does not fit the network ({type(exc).__name__}: "
                           f"{str(exc).splitlines()[0][:200] if str(exc) else ''})") from exc
    return net.eval()
