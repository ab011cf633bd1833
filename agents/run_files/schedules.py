"""Hyperparameter schedules for SB3 (learning rate, clip range) without ``eval`` of strings.

Accepted config values:

| value | meaning |
|---|---|
| ``3.0e-4`` or ``"3e-4"`` | constant |
| ``"lin_3e-4"`` | linear from 3e-4 at the start to 0 at the end (rl-zoo's spelling) |
| ``{type: linear, initial: 3.0e-4, final: 1.0e-5}`` | linear between the two values |
| ``{type: constant, initial: 3.0e-4}`` | constant |

SB3 calls a schedule with ``progress_remaining`` going from 1 (start) to 0 (end of training).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .configtools import from_mapping, parse_float
from .errors import ConfigError

SCHEDULE_TYPES = ("constant", "linear")


@dataclass(frozen=True)
class Schedule:
    """``initial`` at progress_remaining = 1, ``final`` at 0, linear in between (or constant)."""

    type: str = "constant"
    initial: float = 0.0
    final: float = 0.0

    def __post_init__(self):
        if self.type not in SCHEDULE_TYPES:
            raise ValueError(f"schedule type {self.type!r} is not valid; valid: {SCHEDULE_TYPES}")

    def __call__(self, progress_remaining: float) -> float:
        if self.type == "constant":
            return self.initial
        return self.final + (self.initial - self.final) * progress_remaining

    @property
    def is_constant(self) -> bool:
        return self.type == "constant"

    def to_yaml(self) -> Any:
        if self.is_constant:
            return self.initial
        if self.final == 0.0:
            return f"lin_{self.initial!r}"
        return {"type": self.type, "initial": self.initial, "final": self.final}


def parse_schedule(value: Any, where: str) -> Schedule:
    """Parse one of the forms in the module docstring; ConfigError naming `where` otherwise."""
    if isinstance(value, Schedule):
        return value
    if isinstance(value, dict):
        spec = from_mapping(Schedule, value, where)
        if spec.type == "constant" and "final" in value:
            raise ConfigError(f"{where}: a constant schedule takes only 'initial'")
        return spec
    if isinstance(value, str) and value.startswith("lin_"):
        return Schedule("linear", parse_float(value[4:], where), 0.0)
    try:
        return Schedule("constant", parse_float(value, where))
    except ConfigError:
        raise ConfigError(
            f"{where}: expected a number, 'lin_<number>' or "
            f"{{type: linear|constant, initial: <number>, final: <number>}}, got {value!r}"
        ) from None


def parse_optional_schedule(value: Any, where: str) -> Schedule | None:
    return None if value is None else parse_schedule(value, where)
