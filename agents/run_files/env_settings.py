"""The training env's resolved settings, recorded with every run and model directory, and
compared with the env a model is later evaluated or resumed on.

Why: a run's ``config.yaml`` holds only the env kwargs it was given; every other setting is a
default of the code that trained it. When a default changes later (ATHENA's physics step went
from 2 ms to 2.5 ms), comparing kwargs cannot see it, and an agent is silently evaluated, or
its training resumed, under other physics than it learned on. So a run writes
``env_settings.yaml``: every field of ``env.unwrapped.settings`` (the env's typed settings,
see `hexapod_envs.envs.settings`) with the defaults filled in, into the run directory and into
every model directory it saves. Envs of other packages have no typed settings: nothing is
recorded for them and the evaluation falls back to comparing kwargs.

What the record covers is the settings dataclass: a setting left at None for the env to derive
at construction (the ditch env's gait timing, ATHENA's per-terrain swing height) is recorded as
None, and robot constants that are no settings (e.g. the heavy-duty servo stiffness in
``HeavyDutyParams``) are not recorded; a change of those is not detected.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import gymnasium as gym

from .configtools import dump_yaml, load_yaml, to_mapping
from .model_files import atomic_write_text

SETTINGS_FILE = "env_settings.yaml"

RENDERING = ("render_mode", "width", "height", "camera_name")
"""Settings that change no physics."""

NOT_COMPARED = ("task_distribution", "train_ranges", "test_ranges", *RENDERING)
"""Settings whose differences are no mismatch for an evaluation: the task distribution and its
ranges are the evaluation's own choice (a held-out distribution is its point)."""

_HEADER = "# The training env's settings, defaults filled in (agents/run_files/env_settings.py)\n"

REWARD = "reward"
"""The nested reward scales: they change returns, not what the agent meets."""


def resolved_settings(env: gym.Env) -> dict[str, Any] | None:
    """Every setting of `env` (defaults filled in) as plain YAML types (tuples as lists: what a
    YAML round trip gives back); None for an env without typed settings."""
    settings = getattr(env.unwrapped, "settings", None)
    if settings is None or not dataclasses.is_dataclass(settings):
        return None
    return to_mapping(settings)


def write_settings(directory: str | Path, settings: dict[str, Any] | None) -> None:
    """Write ``env_settings.yaml`` into `directory` (nothing for None)."""
    if settings is not None:
        atomic_write_text(Path(directory) / SETTINGS_FILE, _HEADER + dump_yaml(settings))


def read_settings(directory: str | Path | None) -> dict[str, Any] | None:
    """The settings recorded in `directory`; None when it has none (older runs, other envs)."""
    if directory is None:
        return None
    path = Path(directory) / SETTINGS_FILE
    return load_yaml(path) if path.is_file() else None


def differences(
    trained: dict[str, Any], current: dict[str, Any], ignore: tuple[str, ...] = NOT_COMPARED
) -> dict[str, tuple[Any, Any]]:
    """``{setting: (trained, current)}`` for every setting not in `ignore` that differs; the
    fields of a nested mapping as ``<setting>.<field>`` (e.g. ``reward.rate_weight``). A setting
    that exists on one side only (added or removed since the training) shows as None on the
    other."""
    out = {}
    for key in _keys(trained, current):
        if key in ignore:
            continue
        a, b = trained.get(key), current.get(key)
        if isinstance(a, dict) and isinstance(b, dict):
            out.update({f"{key}.{k}": v for k, v in differences(a, b, ()).items()})
        elif a != b:
            out[key] = (a, b)
    return out


def _keys(a: dict[str, Any], b: dict[str, Any]) -> list[str]:
    return [*a, *(k for k in b if k not in a)]


def _is_reward(key: str) -> bool:
    return key.startswith(f"{REWARD}.")


def reward_only(found: dict[str, tuple[Any, Any]]) -> bool:
    """Whether every difference of `differences` is a reward scale: those change the returns,
    not what the agent meets or does."""
    return all(_is_reward(key) for key in found)


def describe(found: dict[str, tuple[Any, Any]], reward_note: str = "change returns only") -> str:
    """The differences as ``"physics_dt: 0.002 -> 0.0025; reward terms (change returns only):
    reward.rate_weight: 5.0 -> 0.5"``."""
    env_part = {k: v for k, v in found.items() if not _is_reward(k)}
    reward = {k: v for k, v in found.items() if _is_reward(k)}
    parts = []
    if env_part:
        parts.append(", ".join(f"{k}: {a!r} -> {b!r}" for k, (a, b) in env_part.items()))
    if reward:
        terms = ", ".join(f"{k}: {a!r} -> {b!r}" for k, (a, b) in reward.items())
        parts.append(f"reward terms ({reward_note}): {terms}")
    return "; ".join(parts)
