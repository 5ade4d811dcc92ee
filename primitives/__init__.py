"""Learned primitives: the seed's objectives, the one-step environment, the hybrid actor-critic,
training (``python -m primitives.train``), evaluation (``python -m primitives.evaluate``) and the
trained skills (``load_skill``, ``load_skills``), and calls of them that re-observe between strokes
(:mod:`primitives.strokes`: ``push_to``, ``spin_by``, ``roll_to``).

Skill names (:data:`SKILLS`, typed :data:`SkillName`) and their parameters as typed values
(:class:`PushParams`, :class:`SpinParams`, :class:`RollParams`; see :mod:`primitives.params`).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from primitives import rewards
from primitives.params import SKILLS, ParamsLike, PushParams, RollParams, SkillName, SpinParams, as_params

if TYPE_CHECKING:
    from primitives.frames import FrameSearch
    from primitives.skills import Skill


def load_skill(name: SkillName, weights: str | os.PathLike | None = None,
               success_weights: str | os.PathLike | None = None, frame_search: FrameSearch | bool = True,
               searched: bool = True, weights_dir: str | os.PathLike | None = None) -> Skill:
    """The ``push``, ``roll`` or ``spin`` skill (see :func:`primitives.skills.load_skill`)."""
    from primitives.skills import load_skill as _load

    return _load(name, weights, success_weights, frame_search, searched, weights_dir)


def load_skills(weights_dir: str | os.PathLike | None = None) -> dict[SkillName, Skill]:
    """All three skills, ``{"push": Skill, "roll": ..., "spin": ...}`` (see :func:`primitives.skills.load_skills`)."""
    from primitives.skills import load_skills as _load

    return _load(weights_dir)


__all__ = ["SKILLS", "ParamsLike", "PushParams", "RollParams", "SkillName", "SpinParams", "as_params", "load_skill",
           "load_skills", "rewards"]
