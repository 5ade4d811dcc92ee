"""Learned primitives: the seed's objectives, the one-step environment, the hybrid actor-critic,
training (``python -m primitives.train``), evaluation (``python -m primitives.evaluate``) and the
trained skills (``load_skill``, ``load_skills``)."""

from primitives import rewards


def load_skill(name: str, weights=None, success_weights=None, frame_search=True, searched=True, weights_dir=None):
    """The ``push``, ``roll`` or ``spin`` skill (see :func:`primitives.skills.load_skill`)."""
    from primitives.skills import load_skill as _load

    return _load(name, weights, success_weights, frame_search, searched, weights_dir)


def load_skills(weights_dir=None):
    """All three skills, ``{"push": Skill, ...}`` (see :func:`primitives.skills.load_skills`)."""
    from primitives.skills import load_skills as _load

    return _load(weights_dir)


__all__ = ["load_skill", "load_skills", "rewards"]
