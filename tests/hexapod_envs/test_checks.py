"""The shared argument check: finite numbers in range pass as floats, the rest name themselves."""

import math

import numpy as np
import pytest

from hexapod_envs.checks import check_number


def test_in_range_values_come_back_as_floats():
    assert check_number("x", 0) == 0.0 and isinstance(check_number("x", 0), float)
    assert check_number("x", np.float32(2.5), strict=True) == 2.5
    assert check_number("x", 1.0, low=1.0) == 1.0


@pytest.mark.parametrize(
    ("value", "strict", "bound"),
    [(-1e-9, False, ">= 0"), (0.0, True, "> 0"), (math.inf, False, ">= 0"), ("a", False, ">= 0")],
)
def test_out_of_range_values_name_the_argument_and_the_bound(value, strict, bound):
    with pytest.raises(ValueError, match=f"servo_kp must be a finite number {bound}, got"):
        check_number("servo_kp", value, strict=strict)
