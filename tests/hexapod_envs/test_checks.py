"""The shared argument checks: finite numbers in range pass as floats, the rest name themselves."""

import math
import re

import numpy as np
import pytest

from hexapod_envs.checks import check_choice, check_number, check_real, range_text, within


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


def test_the_settings_checks_share_the_wording():
    assert within(0.0, 0.0, None) and not within(0.0, 0.0, None, strict=True)
    assert not within(2.0, None, 1.0) and within(-5.0, None, 1.0)
    assert range_text(0.0, 90.0, strict=True) == "> 0 and <= 90"
    assert check_real("x", np.float64(2.0), 2.0) == 2.0
    with pytest.raises(ValueError, match=r"x must be a real number, got \(1, 'a'\) \(str\)"):
        check_real("x", "a", (1, "a"))
    with pytest.raises(ValueError, match=r"flag must be one of \[False, True\], got 1"):
        check_choice("flag", 1, (True, False))
    flag_or_name = (False, True, "stop")  # a flag with a named third value (clock_action)
    check_choice("clock_action", "stop", flag_or_name)
    check_choice("clock_action", False, flag_or_name)
    for number in (1, 0.0, np.int64(1)):
        with pytest.raises(ValueError, match=r"must be one of \['stop', False, True\]"):
            check_choice("clock_action", number, flag_or_name)


def test_a_count_argument_takes_whole_numbers_in_range_and_names_the_range():
    import argparse

    from hexapod_envs.checks import count_argument

    assert count_argument()("3") == 3 and count_argument(0)("0") == 0
    for parse, text, bound in (
        (count_argument(), "0", ">= 1"),
        (count_argument(1, 50), "51", "in [1, 50]"),
        (count_argument(), "2.5", ">= 1"),
    ):
        with pytest.raises(argparse.ArgumentTypeError, match=rf"whole number {re.escape(bound)}"):
            parse(text)
