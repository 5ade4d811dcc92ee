"""Ranking one start's options by what the policy would do in each: the option ranker of a frame search.

A frame search (:mod:`primitives.frames`) rates every option of a start (each free frame of the request, and of
each stand-in request) with the goal-frame success model and acts in the likeliest. That model was fitted to tell
starts apart, not one start's options: on household objects and camera clouds it ranks a start's options little
better than chance (spin, the seed's objective: within-start AUROC 0.63 on ``housekeep:validation``), although
some option of almost every start succeeds.

An :class:`OptionRanker` is fitted to that question alone, on every option of training starts executed from the
same simulator state (:mod:`primitives.training.ranker`). It reads, per option, the policy's greedy decision in
that option's frame (:func:`primitives.success_model.decision_features`: the critic's value and sharpness, the
contact, its normal, the motion and its lever arm), the success model's rating, what the option asks for, and the
cloud's extents; and each of these *minus its mean over the start's options*, so that what sets one option apart
from its siblings is an input of its own (:func:`option_features`). An ensemble of small MLPs (the mean of their
logits) turns them into a probability of success. The search then acts in the option it rates highest; the score it
reports stays the success model's calibrated rating of that option (:meth:`primitives.frames.FrameSearch.choose`),
so the calibrations downstream keep their meaning.

Units: contact positions in dm (as the decision features carry them), angles in radians, extents in dm.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import torch
from torch import nn

from affordplan.errors import InputError, WeightsError
from primitives import weights_file
from primitives.success_model import N_DECISION

N_OPTION = N_DECISION + 7  # per option: decision features, rating logit, |request|, two flags, three extents
N_FEATURES = 2 * N_OPTION  # and each minus its mean over the start's options


def cloud_extents(points: np.ndarray) -> np.ndarray:
    """The standard deviations of a cloud ``(N, 3)`` (metres) along its principal axes, largest first, in dm: the
    same in every frame a search tries (turns and mirrors leave them unchanged)."""
    pts = np.asarray(points, dtype=float)
    cov = np.cov((pts - pts.mean(axis=0)).T)
    return np.sqrt(np.clip(np.sort(np.linalg.eigvalsh(cov))[::-1], 0.0, None)) * 10.0


def request_size(skill: str, params: dict | None) -> float:
    """How much a request asks for, one number the ranker reads: a spin's ``|angle|`` (radians); 0 for the seed's
    objective and for push and roll (their requests are told apart by the frame and the goal flow)."""
    if params is None or skill != "spin":
        return 0.0
    return abs(float(params["angle"]))


def option_features(decision: np.ndarray, rating: np.ndarray, request: np.ndarray, parameterised: np.ndarray,
                    stand_in: np.ndarray, extents: np.ndarray) -> np.ndarray:
    """The ranker's input ``(m, N_FEATURES)`` for the ``m`` options of one start.

    ``decision``: ``(m, >= N_DECISION)`` decision features of the policy in each option's frame; ``rating``:
    ``(m,)`` the success model's raw rating; ``request``: ``(m,)`` :func:`request_size` of each option's request;
    ``parameterised``: ``(m,)`` whether its request has a parameter; ``stand_in``: ``(m,)`` whether it is a
    stand-in request (:mod:`primitives.frames`); ``extents``: ``(3,)`` :func:`cloud_extents` of the start's cloud.
    """
    decision = np.asarray(decision, dtype=np.float64)[:, :N_DECISION]
    m = len(decision)
    p = np.clip(np.asarray(rating, dtype=np.float64), 1e-6, 1.0 - 1e-6)
    columns = [decision, np.log(p / (1.0 - p))[:, None], np.asarray(request, dtype=np.float64)[:, None],
               np.asarray(parameterised, dtype=np.float64)[:, None], np.asarray(stand_in, dtype=np.float64)[:, None],
               np.broadcast_to(np.asarray(extents, dtype=np.float64), (m, 3))]
    x = np.concatenate(columns, axis=1)
    if x.shape != (m, N_OPTION):
        raise InputError(f"option features of {m} options came out {x.shape}, expected ({m}, {N_OPTION})")
    return np.concatenate([x, x - x.mean(axis=0, keepdims=True)], axis=1).astype(np.float32)


class OptionRanker(nn.Module):
    """P(success) of each option from :func:`option_features`: standardised inputs, an ensemble of MLPs, the mean
    of their logits.

    ``mean`` and ``scale`` standardise the features (fitted with the nets); ``width``: hidden units per layer;
    ``members``: MLPs, each trained from its own initialisation (fitted on 600 training starts of spin, five
    members picked a succeeding option of 400 other household starts on 0.683, one on 0.658;
    :mod:`primitives.training.ranker`).
    """

    def __init__(self, width: int = 64, members: int = 1):
        super().__init__()
        if width < 1 or members < 1:
            raise InputError(f"an option ranker needs a positive width and member count, got {width} and {members}")
        self.register_buffer("mean", torch.zeros(N_FEATURES))
        self.register_buffer("scale", torch.ones(N_FEATURES))
        self.nets = nn.ModuleList(
            nn.Sequential(nn.Linear(N_FEATURES, width), nn.ReLU(), nn.Linear(width, width), nn.ReLU(),
                          nn.Linear(width, 1))
            for _ in range(members))

    @property
    def width(self) -> int:
        return self.nets[0][0].out_features

    def standardise(self, features: torch.Tensor) -> torch.Tensor:
        """Features ``(m, N_FEATURES)`` as every member reads them: less ``mean``, over ``scale``."""
        return (features - self.mean) / self.scale

    def member_logits(self, features: torch.Tensor) -> torch.Tensor:
        """Each member's logits ``(members, m)`` of features ``(m, N_FEATURES)``."""
        z = self.standardise(features)
        return torch.stack([net(z).squeeze(-1) for net in self.nets])

    def forward(self, features: torch.Tensor) -> torch.Tensor:
        """Logits ``(m,)`` of features ``(m, N_FEATURES)``: the members' mean."""
        return self.member_logits(features).mean(dim=0)

    @torch.no_grad()
    def score(self, features: np.ndarray) -> np.ndarray:
        """P(success) ``(m,)`` of each option, from :func:`option_features`."""
        return torch.sigmoid(self(torch.as_tensor(np.asarray(features, dtype=np.float32)))).numpy()


def save_ranker(path: str | os.PathLike, ranker: OptionRanker, skill: str, sensor: str, info: dict) -> None:
    """Write ``ranker`` as an affordplan weights file of kind ``ranker`` (``info``: how it was made)."""
    weights_file.save(path, dict(model=ranker.state_dict(), width=ranker.width, members=len(ranker.nets), info=info),
                      weights_file.make_meta(skill, "ranker", sensor=sensor))


def load_ranker(path: str | os.PathLike, skill: str | None = None) -> OptionRanker:
    """The option ranker in ``path`` (for ``skill``, where given).

    Raises:
        WeightsError: missing, damaged or unsafe file, another kind or skill, or weights that do not fit.
    """
    payload, _ = weights_file.load(Path(path), kind="ranker", skill=skill)
    try:
        ranker = OptionRanker(int(payload["width"]), int(payload["members"]))
        ranker.load_state_dict(payload["model"])
    except Exception as exc:  # the right kind of file, the wrong shapes
        raise WeightsError(f"option ranker {path} does not fit the network ({type(exc).__name__})") from exc
    return ranker.eval()
