"""Training checkpoints: atomic writes (a temporary file in the same folder, then renamed over the old one) in the
safe weights format (:mod:`primitives.weights_file`).

A run killed at any moment leaves either the previous checkpoint or the new one, never a torn file. A damaged,
truncated or unsafe file raises :class:`CheckpointError` with the path, not an unpickling traceback.
"""

from __future__ import annotations

from pathlib import Path

from affordplan.errors import WeightsError
from primitives import weights_file


class CheckpointError(WeightsError):
    """A checkpoint file is missing, truncated, unsafe or not a checkpoint."""


def save(path: str | Path, payload: dict, meta: dict | None = None) -> None:
    """Write ``payload`` atomically to ``path`` with ``meta`` (:func:`primitives.weights_file.save`; by default a
    checkpoint of the skill ``payload["config"]["primitive"]`` names)."""
    if meta is None:
        skill = payload.get("config", {}).get("primitive", "push")
        meta = weights_file.make_meta(skill, "checkpoint")
    weights_file.save(path, payload, meta)


def load(path: str | Path, skill: str | None = None) -> dict:
    """The payload of the training checkpoint ``path`` (for ``skill`` when given), read safely.

    Raises:
        CheckpointError: missing, damaged, unsafe, no metadata, or another kind or skill.
    """
    try:
        payload, meta = weights_file.load(path, kind="checkpoint", skill=skill)
    except WeightsError as exc:
        raise CheckpointError(str(exc)) from exc
    if "model" not in payload:
        raise CheckpointError(f"{path} is not an affordplan checkpoint (no model)")
    payload["meta"] = meta
    return payload
