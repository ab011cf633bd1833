"""Argument checks shared by the robots, terrains and envs: one wording for every error."""

from __future__ import annotations

import math


def check_number(name: str, value: float, *, low: float = 0.0, strict: bool = False) -> float:
    """`value` as a float if it is finite and >= `low` (> `low` with `strict`); otherwise a
    ValueError that names the argument and the valid range."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = math.nan
    if not (math.isfinite(x) and (x > low if strict else x >= low)):
        bound = f"{'>' if strict else '>='} {low:g}"
        raise ValueError(f"{name} must be a finite number {bound}, got {value!r}")
    return x
