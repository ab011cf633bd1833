"""Env keyword arguments as policies see them: which settings say how an action is read or what
the observation holds, and an env's default settings.

Shared by `agents.hybrid` (a hybrid model is combined only with the env settings it was trained
with) and the evaluation (`agents.pipeline.evaluation`: a policy is evaluated with the settings
it was built for); Gymnasium only, no hexapod env imported.
"""

from __future__ import annotations

import dataclasses
import inspect
from typing import Any

import gymnasium as gym

POLICY_SETTINGS = (
    "action_mode",
    "residual_scale",
    "residual_filter_tau",
    "residual_limb_m",
    "residual_leg_m",
    "gait_ground_search",
    "terrain_scan",
    "foot_scan",
    "gains_height_offset_m",
    "clock_action",
    "landing_action",
    "stride_action",
)
"""Env kwargs that say how an action is read or what the observation holds (not which task is
posed): a policy is evaluated with the ones it was built for, on the suite's task."""


def registered_defaults(env_id: str) -> dict[str, Any]:
    """Keyword defaults of the registered env class and the registration's kwargs."""
    spec = gym.spec(env_id)
    creator = gym.envs.registration.load_env_creator(spec.entry_point)
    defaults = class_defaults(creator) if isinstance(creator, type) else {}
    return {**defaults, **spec.kwargs}


def class_defaults(cls: type) -> dict[str, Any]:
    """Default settings of an env class: the fields of its settings dataclass (the hexapod
    envs' ``Settings``), else the keyword defaults of its constructors along its MRO."""
    settings = getattr(cls, "Settings", None)
    if dataclasses.is_dataclass(settings):
        return {
            f.name: f.default
            for f in dataclasses.fields(settings)
            if f.default is not dataclasses.MISSING
        }
    defaults: dict[str, Any] = {}
    for klass in reversed(cls.__mro__):
        init = klass.__dict__.get("__init__")
        if init is None:
            continue
        try:
            params = inspect.signature(init).parameters.values()
        except (TypeError, ValueError):
            continue
        defaults.update({p.name: p.default for p in params if p.default is not p.empty})
    return defaults


def constructor_defaults(env: gym.Env) -> dict[str, Any]:
    """Keyword defaults of the env class's constructors along its MRO, plus registered kwargs."""
    defaults = class_defaults(type(env.unwrapped))
    if env.spec is not None and env.spec.id in gym.registry:
        defaults.update(gym.spec(env.spec.id).kwargs)
    return defaults
