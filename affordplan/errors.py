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
