"""Atomic checkpoints: written to a temporary file in the same folder, then renamed over the old one.

A run killed at any moment leaves either the previous checkpoint or the new one, never a torn file.
A damaged or truncated file raises :class:`CheckpointError` with the path, not an unpickling
traceback.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import torch

from affordplan.errors import AffordplanError


class CheckpointError(AffordplanError):
    """A checkpoint file is missing, truncated or not a checkpoint."""


def save(path: str | Path, payload: dict) -> None:
    """Write ``payload`` atomically to ``path``; temporary files left by a killed earlier write are removed."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    for stale in path.parent.glob(f"{path.name}*.tmp"):  # a run killed mid-write leaves one behind
        stale.unlink(missing_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            torch.save(payload, f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def load(path: str | Path) -> dict:
    path = Path(path)
    if not path.exists():
        raise CheckpointError(f"no checkpoint at {path}")
    try:
        payload = torch.load(path, map_location="cpu", weights_only=False)
    except Exception as exc:  # torch raises several types for damaged files
        raise CheckpointError(f"checkpoint {path} is damaged or truncated ({type(exc).__name__}: {exc})") from exc
    if not isinstance(payload, dict) or "model" not in payload:
        raise CheckpointError(f"{path} is not an affordplan checkpoint")
    return payload
