"""A task's difficulty as one number in [0, 1], from the task parameters that make it hard.

Each env names the parameters that make its task hard and, for each, the value at which it is
easy and the value at which it is hard (a `DifficultySpan`; the hard value may be the smaller
one, as for friction). A task's difficulty is the weighted mean of its parameters' positions
between easy (0) and hard (1), each clipped to [0, 1]. The envs put it in
``info["task"]["difficulty"]``, so that a report can plot success against difficulty and a test
can check that the held-out test tasks are at least as hard as the training tasks.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass


@dataclass(frozen=True)
class DifficultySpan:
    """One task parameter's contribution: its value when the task is easy and when it is hard
    (in the parameter's own unit), and its weight in the mean."""

    easy: float
    hard: float
    weight: float = 1.0

    def __post_init__(self) -> None:
        if self.easy == self.hard:
            raise ValueError(f"a difficulty span needs easy != hard, got {self.easy!r} twice")
        if not self.weight > 0:
            raise ValueError(f"a difficulty weight must be > 0, got {self.weight!r}")

    def position(self, value: float) -> float:
        """Where `value` lies from easy (0) to hard (1), clipped to [0, 1]."""
        x = (float(value) - self.easy) / (self.hard - self.easy)
        return min(1.0, max(0.0, x))


def task_difficulty(task: Mapping[str, object], spans: Mapping[str, DifficultySpan]) -> float:
    """The weighted mean of the spans' positions of the task's values (keys of `spans` missing
    from `task` are a KeyError: an env declares spans for its own task keys only)."""
    total = sum(span.weight for span in spans.values())
    return sum(span.weight * span.position(task[key]) for key, span in spans.items()) / total
