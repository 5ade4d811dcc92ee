"""Learned primitives: the seed's objectives, the one-step environment, the hybrid actor-critic,
training (``python -m primitives.train``), evaluation (``python -m primitives.evaluate``) and the
trained skills (``load_skill``)."""

from primitives import rewards


def load_skill(name: str, weights=None, success_weights=None):
    """The ``push``, ``roll`` or ``spin`` skill (see :mod:`primitives.skills`)."""
    from primitives.skills import load_skill as _load

    return _load(name, weights, success_weights)


__all__ = ["load_skill", "rewards"]
