"""Learned primitives: the seed's objectives, the one-step environment, the hybrid actor-critic,
training (``python -m primitives.train``) and evaluation (``python -m primitives.evaluate``)."""

from primitives import rewards

__all__ = ["rewards"]
