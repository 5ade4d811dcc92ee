"""The shared argument checks: what each accepts and the message each refusal carries."""

import math

import numpy as np
import pytest

from affordplan.checks import is_finite, is_whole, require_probability, require_whole
from affordplan.errors import InputError


@pytest.mark.parametrize("value", [0, 7, np.int64(3), np.uint8(2)])
def test_is_whole_accepts_python_and_numpy_integers(value):
    assert is_whole(value)


@pytest.mark.parametrize("value", [True, False, 1.0, np.float64(2.0), "3", None])
def test_is_whole_refuses_bools_floats_and_strings(value):
    assert not is_whole(value)


@pytest.mark.parametrize("value", [0, -2.5, np.float32(1.5), np.int32(4)])
def test_is_finite_accepts_finite_reals(value):
    assert is_finite(value)


@pytest.mark.parametrize("value", [math.nan, math.inf, -np.inf, True, "1", None, 1j])
def test_is_finite_refuses_nan_inf_bools_and_non_reals(value):
    assert not is_finite(value)


def test_require_whole_names_the_setting_its_least_and_the_value():
    require_whole("--steps", 1, 1)
    require_whole("EnvConfig.model_cache", np.int64(0), 0)
    with pytest.raises(InputError, match=r"^--steps must be a whole number >= 1, got 0$"):
        require_whole("--steps", 0, 1)
    with pytest.raises(InputError, match=r"n_points must be a whole number >= 16, got 8\.0"):
        require_whole("n_points", 8.0, 16)
    with pytest.raises(InputError, match=r"got True"):
        require_whole("workers", True, 0)


@pytest.mark.parametrize("value", [-0.01, 1.5, math.nan, math.inf, None, False])
def test_require_probability_refuses_values_outside_the_unit_interval(value):
    with pytest.raises(InputError, match=r"^--epsilon is a probability in \[0, 1\], got "):
        require_probability("--epsilon", value)


@pytest.mark.parametrize("value", [0, 0.0, 0.5, 1, np.float32(1.0)])
def test_require_probability_accepts_the_closed_unit_interval(value):
    require_probability("--epsilon", value)
