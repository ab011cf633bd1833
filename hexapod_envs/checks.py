"""Argument checks shared by the robots, terrains, envs and env settings: one wording for every
error.

Bad input raises a ValueError that names the argument and its valid range or choices
(docs/architecture.md, "Conventions"). `check_number` checks a plain float argument of a robot,
terrain or gait; the env settings (`hexapod_envs.envs.settings`) build their field checks from
`check_real`, `within`, `range_text` and `check_choice`.
"""

from __future__ import annotations

import math
import numbers
from typing import Any


def check_number(
    name: str, value: float, *, low: float = 0.0, high: float | None = None, strict: bool = False
) -> float:
    """`value` as a float if it is finite, >= `low` (> `low` with `strict`) and <= `high` (if
    given); otherwise a ValueError that names the argument and the valid range."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = math.nan
    if not (math.isfinite(x) and within(x, low, high, strict)):
        bound = range_text(low, high, strict)
        raise ValueError(f"{name} must be a finite number {bound}, got {value!r}")
    return x


def check_real(name: str, value: Any, shown: Any) -> float:
    """`value` as a float if it is a finite real number (not a bool, string or complex);
    otherwise a ValueError naming `name` and showing `shown` (the value, or the tuple it came
    from)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} must be a real number, got {shown!r} ({type(value).__name__})")
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"{name} must be finite, got {shown!r}")
    return x


def check_choice(name: str, value: Any, choices) -> None:
    """Raise a ValueError naming `name`, the bad value and the valid choices (a flag among
    them takes a bool only: 1 is not True here; other choices, such as a name, stay valid)."""
    flags = [c for c in choices if isinstance(c, bool)]
    number_for_flag = not isinstance(value, bool) and value in flags  # 1 == True, 0.0 == False
    if value not in choices or number_for_flag:
        valid = sorted(choices, key=repr)
        raise ValueError(f"{name} must be one of {valid}, got {value!r}")


def within(x: float, low: float | None, high: float | None, strict: bool = False) -> bool:
    """Whether `x` >= `low` (> with `strict`) and <= `high`; a bound of None is no bound."""
    too_low = low is not None and (x <= low if strict else x < low)
    return not (too_low or (high is not None and x > high))


def range_text(low: float | None, high: float | None, strict: bool = False) -> str:
    """The valid range as an error message states it: ">= 0", "> 0 and <= 90"."""
    parts = []
    if low is not None:
        parts.append(f"{'>' if strict else '>='} {low:g}")
    if high is not None:
        parts.append(f"<= {high:g}")
    return " and ".join(parts)


def count_argument(low: int = 1, high: int | None = None) -> Any:
    """An argparse ``type`` for a whole number within [`low`, `high`] (a count of tasks, resets,
    repeats...): the scripts' bad counts become argparse errors that name the valid range."""
    import argparse

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or value < low or (high is not None and value > high):
            bound = f">= {low}" if high is None else f"in [{low}, {high}]"
            raise argparse.ArgumentTypeError(f"must be a whole number {bound}, got {text!r}")
        return value

    return parse
