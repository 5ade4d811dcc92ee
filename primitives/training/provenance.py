"""How training commands record the paths they were given, in files that may ship.

A weights file's ``info["command"]`` and its path fields say how it was made, so that anyone can make it again. A path
typed as an absolute one would carry the folders of the machine it ran on into a shipped file; :func:`recorded_path`
keeps what another checkout can use: a relative path as typed, an absolute path inside the working directory made
relative to it, and any other absolute path cut to its file name.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path


def recorded_path(value: str | os.PathLike, cwd: str | os.PathLike | None = None) -> str:
    """``value`` as a training command records it: unchanged when relative (or a name such as ``"shipped"``),
    relative to ``cwd`` (default: the working directory) when it is an absolute path inside it, else its file name.
    """
    path = Path(value)
    if not path.is_absolute():
        return str(value)
    here = Path.cwd() if cwd is None else Path(cwd)
    try:
        return str(path.resolve().relative_to(here.resolve()))
    except ValueError:
        return path.name


def recorded_paths(values: Iterable[str | os.PathLike], cwd: str | os.PathLike | None = None) -> list[str]:
    """:func:`recorded_path` of each of ``values``, in order."""
    return [recorded_path(v, cwd) for v in values]
