"""The error hierarchy (affordplan.errors): every library error is an AffordplanError and a ValueError, so one except
clause catches them all and code catching ValueError loses nothing."""

from __future__ import annotations

import inspect

import pytest

import affordplan as ap
from affordplan import errors
from primitives.training.checkpoint import CheckpointError

ERRORS = [cls for _, cls in inspect.getmembers(errors, inspect.isclass) if cls.__module__ == errors.__name__]


def test_the_module_defines_the_documented_errors():
    assert {cls.__name__ for cls in ERRORS} == {"AffordplanError", "MeshError", "InputError", "GoalError",
                                                "PlanningError", "ReachabilityError", "WeightsError", "PerceptionError"}
    assert ap.errors is errors  # reachable as affordplan.errors


@pytest.mark.parametrize("cls", ERRORS + [CheckpointError], ids=lambda cls: cls.__name__)
def test_every_error_is_an_affordplan_error_and_a_value_error(cls):
    assert issubclass(cls, errors.AffordplanError) and issubclass(cls, ValueError)
    with pytest.raises(ValueError, match="what went wrong"):
        raise cls("what went wrong")
    assert cls.__doc__  # each says when it is raised


def test_the_specific_errors_are_siblings_and_a_checkpoint_error_is_a_weights_error():
    specific = [cls for cls in ERRORS if cls is not errors.AffordplanError]
    for a in specific:
        assert a.__bases__ == (errors.AffordplanError,)
        assert not any(issubclass(a, b) for b in specific if b is not a)  # catching one never catches another
    assert issubclass(CheckpointError, errors.WeightsError)
    assert not issubclass(CheckpointError, errors.InputError)


def test_library_calls_raise_them():
    with pytest.raises(errors.MeshError):
        ap.load_object("teapot")
    with pytest.raises(errors.InputError):
        ap.Box(center=(0.5, 0.0), size=(0.1, -0.1, 0.1))
    with pytest.raises(errors.AffordplanError):
        ap.load_object("cube", size=float("nan"))
