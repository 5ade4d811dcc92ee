"""Learned primitives: the seed's objectives, and (in later releases) policies and skills."""

from primitives import rewards

__all__ = ["rewards"]
