"""What a controller may know about an env's task (`TaskDescription`), declared by the env."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

__all__ = ["TaskDescription"]


@dataclasses.dataclass(frozen=True)
class TaskDescription:
    """What a controller may know about the env's task, declared by the env (instead of reading
    its attributes): robot, action mapping, timing, stability criterion, the episode's course
    and the reference gait. Per-step information comes through the observation.

    The course (and for some envs the reference) changes at every reset with a sampled task:
    a controller reads ``env.unwrapped.task_description`` on its first call after a reset."""

    robot: Any
    """The robot's parameters (frozen dataclass of its `params` module)."""
    action_mode: str
    control_dt: float
    """Control period [s]."""
    joint_low: tuple[float, ...]
    """Joint (command) target at action -1, per action entry, robot units ("joint" mode)."""
    joint_high: tuple[float, ...]
    """Joint (command) target at action +1."""
    tipping_threshold_deg: float
    stability_criterion: str
    course: Mapping[str, Any]
    """The episode's task parameters (`info["task"]`, read-only)."""
    reference: Mapping[str, Any]
    """Env-specific reference gait and timing (see the env's `_reference_description`)."""
    observation_structure: Mapping[str, slice]
    """Name -> slice of every piece of the flat observation (what a controller reads)."""

    def __reduce__(self):
        """Deep-copied and pickled with plain dicts in place of the read-only mappings (neither
        `copy.deepcopy` nor pickle takes a mappingproxy), which the copy makes read-only again."""
        fields = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        fields.update({name: dict(fields[name]) for name in _READ_ONLY})
        return _task_description, (fields,)


_READ_ONLY = ("course", "reference", "observation_structure")


def _task_description(fields: dict[str, Any]) -> TaskDescription:
    read_only = {name: MappingProxyType(fields[name]) for name in _READ_ONLY}
    return TaskDescription(**{**fields, **read_only})
