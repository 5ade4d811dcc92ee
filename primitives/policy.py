"""Loading a trained policy and acting with it greedily (run time: what skills and evaluation share)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import torch

from affordplan.errors import WeightsError
from primitives.networks import HybridActorCritic, widen_input
from primitives.weights_file import load, policy_path


def load_policy(weights: str | os.PathLike | None, primitive: str, sensor: str | None = None) -> HybridActorCritic:
    """The ``primitive``'s policy from a ``policy.pt`` / ``checkpoint.pt`` file, or the shipped weights (with
    ``sensor``, the shipped policy for that sensor's clouds: :func:`primitives.weights_file.policy_path`).

    The returned module's ``sensor`` attribute names the clouds it was trained on (its file's metadata:
    ``"cameras"`` or ``"surface"``).

    Raises:
        WeightsError: missing, damaged or unsafe file, or one for another skill or kind of model.
    """
    path = Path(weights) if weights else policy_path(primitive, sensor)
    if path.is_file() and path.name.startswith("checkpoint"):
        payload, meta = load(path, kind="checkpoint", skill=primitive)
    else:
        payload, meta = load(path, kind="policy", skill=primitive)
    model = HybridActorCritic()
    try:
        model.load_state_dict(widen_input(payload["model"]))
    except (KeyError, RuntimeError, TypeError) as exc:
        raise WeightsError(f"{path} does not fit the policy network ({str(exc).splitlines()[0][:200]})") from exc
    model.eval()
    model.sensor = str(meta.get("sensor", "surface"))
    return model


def greedy_action(model: HybridActorCritic, obs: np.ndarray,
                  allowed: np.ndarray | None = None) -> tuple[int, np.ndarray, np.ndarray]:
    """Deterministic action: ``(contact index, motion, critic map)``.

    ``allowed``: an optional boolean mask over the points; the contact is the best allowed one.
    """
    actions, q = model.maps(torch.from_numpy(obs)[None])
    scores = q[0] if allowed is None else torch.where(torch.from_numpy(np.asarray(allowed, dtype=bool)), q[0],
                                                      torch.tensor(-torch.inf))
    idx = int(scores.argmax())
    return idx, actions[0, idx].numpy().astype(np.float64), q[0].numpy()
