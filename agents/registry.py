"""Reference (analytical) controller of each env id: ``env id -> factory (env) -> Policy``.

`evaluate.py` runs the policy named ``analytical`` through this table. Add an entry when an env
gets its controller: the value is ``"module:attribute"`` (imported only when used, so the table
costs nothing to import) or any callable taking the env and returning a `Policy`.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable

import gymnasium as gym

from .policy import Policy

PolicyFactory = Callable[[gym.Env], Policy]

ANALYTICAL_POLICIES: dict[str, str | PolicyFactory] = {
    "HexapodCliffWalk-v0": "agents.tipping.gait_with_recovery:GaitWithRecoveryPolicy",
    "HexapodDitchCrossing-v0": "agents.upu_gait:UpuGaitPolicy",
    "HexapodIrregularTerrain-v0": "agents.athena_policy:analytical_policy",
    "HexapodStewartTilt-v0": "agents.tipping.controller:TippingRecoveryPolicy",
}


ANALYTICAL_ENV_KWARGS: dict[str, dict] = {
    "HexapodCliffWalk-v0": {"action_mode": "joint"},
    "HexapodDitchCrossing-v0": {"action_mode": "joint"},
    "HexapodIrregularTerrain-v0": {"action_mode": "joint"},
}
"""Env kwargs an evaluation gives each controller on top of the suite's: the action mode in which
its commands are applied as computed. In the default residual modes the recovery's, the posture
controller's and the gate-waiting planner's targets exceed the residual's range and are clipped
(see each controller's module docstring); the Stewart-tilt env's residual_scale of 2 already
reaches every target."""

# The v1 benchmark's references are the papers' controllers (docs/benchmark.md).
for _v0 in list(ANALYTICAL_POLICIES):
    ANALYTICAL_POLICIES[_v0.replace("-v0", "-v1")] = ANALYTICAL_POLICIES[_v0]
    if _v0 in ANALYTICAL_ENV_KWARGS:
        ANALYTICAL_ENV_KWARGS[_v0.replace("-v0", "-v1")] = ANALYTICAL_ENV_KWARGS[_v0]


def register_analytical(env_id: str, factory: str | PolicyFactory) -> None:
    """Add or replace the analytical controller of `env_id` (e.g. from a user's own package)."""
    ANALYTICAL_POLICIES[env_id] = factory


def analytical_factory(env_id: str) -> PolicyFactory:
    """The factory of `env_id`; ValueError listing the env ids that have one."""
    try:
        entry = ANALYTICAL_POLICIES[env_id]
    except KeyError:
        raise ValueError(
            f"no analytical controller registered for {env_id!r}; registered: "
            f"{sorted(ANALYTICAL_POLICIES)} (add one in agents/registry.py)"
        ) from None
    return load_factory(entry)


def load_factory(entry: str | PolicyFactory) -> PolicyFactory:
    """A ``"module:attribute"`` entry, imported; a callable as it is."""
    if isinstance(entry, str):
        module, _, attribute = entry.partition(":")
        return getattr(importlib.import_module(module), attribute)
    return entry


def analytical_policy(env: gym.Env) -> Policy:
    """The analytical controller for `env` (looked up by ``env.spec.id``)."""
    if env.spec is None:
        raise ValueError("env has no spec (create it with gymnasium.make) to look its id up")
    return analytical_factory(env.spec.id)(env)
