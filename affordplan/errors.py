"""Exceptions raised by affordplan.

Every error the library raises on bad input derives from :class:`AffordplanError`, which is a
:class:`ValueError`, so callers can catch one type and lose nothing else.
"""

from __future__ import annotations


class AffordplanError(ValueError):
    """Base class of every affordplan error."""


class MeshError(AffordplanError):
    """A mesh cannot be loaded or made physical (unreadable, empty, non-finite, zero volume)."""


class InputError(AffordplanError):
    """A numeric argument is malformed: wrong shape, NaN or infinite, out of its documented range."""


class GoalError(AffordplanError):
    """A goal or start cannot be reached by construction (in an obstacle, off the workspace, ...)."""


class PlanningError(AffordplanError):
    """No plan was found within the budget; the message names why."""


class ReachabilityError(AffordplanError):
    """The pusher cannot reach the requested contact."""


class WeightsError(AffordplanError):
    """A weights or checkpoint file is missing, damaged, unsafe (it would run code to load), or made for another
    skill, kind of model or sensor; the message names which."""


class PerceptionError(AffordplanError):
    """The sensor cannot see the object (hidden behind obstacles or the arm from every camera)."""
