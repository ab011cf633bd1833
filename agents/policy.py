"""The one interface every controller implements, learned or analytical.

A policy is an object with ``reset()`` (start of an episode) and ``__call__(observation) ->
action`` returning an action in the env's own action space. `evaluate.py` runs all of them the
same way. Analytical policies read the observation by name through the env's
`observation_structure`; none of them reaches into the simulator.
"""

from __future__ import annotations

import copy
import dataclasses
from typing import Any, Protocol, runtime_checkable

import gymnasium as gym
import numpy as np


@runtime_checkable
class Policy(Protocol):
    def reset(self) -> None: ...

    def __call__(self, observation: np.ndarray) -> np.ndarray: ...


class EnvBound:
    """Base of a policy that reads its env's task description (``self.env``) after each reset.

    A deep copy of the policy keeps reading the same env, unless that env was copied earlier in
    the same `copy.deepcopy` call (a wrapper holding both copies its env first): then the copy
    reads the copied env. A plain deep copy would give it an env of its own that nobody resets.
    """

    env: gym.Env

    def __deepcopy__(self, memo: dict) -> EnvBound:
        new = type(self).__new__(type(self))
        memo[id(self)] = new
        for key, value in self.__dict__.items():
            shared = key == "env"
            new.__dict__[key] = memo.get(id(value), value) if shared else copy.deepcopy(value, memo)
        return new


def settings_from_section(cls: type, section: Any) -> Any:
    """Settings dataclass `cls` from a config section: None stays None; a mapping or a
    dataclass holding (at least) `cls`'s fields gives those fields, the rest (a training
    config's own keys, such as ``zero_init_action_net``) are left out."""
    if section is None:
        return None
    names = [f.name for f in dataclasses.fields(cls)]
    if not isinstance(section, dict):
        section = {name: getattr(section, name) for name in names}
    return cls(**{name: section[name] for name in names if name in section})


class AroundLearned:
    """Base of a policy built around a learned `Policy`, ``learned``: attributes it lacks are
    the learned policy's (a loaded model's files, train_env_kwargs...); ``reset`` resets it.
    `_OWN` names the instance attributes a subclass sets itself (never looked up in
    ``learned``, so a half-built copy raises AttributeError instead of recursing)."""

    learned: Policy
    _OWN: tuple[str, ...] = ("learned",)

    def __getattr__(self, name: str) -> Any:
        if name in self._OWN:
            raise AttributeError(name)
        return getattr(self.learned, name)

    def reset(self) -> None:
        self.learned.reset()


class LearnedWithController(AroundLearned):
    """Base of a learned policy combined with an analytical controller: ``learned`` (a `Policy`)
    and ``core`` (what owns the controller); ``reset`` resets both."""

    core: Any
    _OWN = ("learned", "core")

    def reset(self) -> None:
        self.learned.reset()
        self.core.reset()


class ZeroPolicy:
    """Always the zero action (in residual mode: the env's reference motion)."""

    def __init__(self, action_space: gym.spaces.Box):
        self._action = np.zeros(action_space.shape, dtype=action_space.dtype)

    def reset(self) -> None:
        pass

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        return self._action.copy()


class RandomPolicy:
    """Uniform random actions from a seeded generator (reproducible with `seed`)."""

    def __init__(self, action_space: gym.spaces.Box, seed: int | None = None):
        self.space, self.seed = action_space, seed
        self.reset()

    def reset(self) -> None:
        self._rng = np.random.default_rng(self.seed)

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        low, high = self.space.low, self.space.high
        return self._rng.uniform(low, high).astype(self.space.dtype)


class ObservationReader:
    """Named access to a flat observation: ``reader(obs)["fasm_margin_deg"]``."""

    def __init__(self, structure: dict[str, slice]):
        self.structure = dict(structure)

    def __call__(self, observation: np.ndarray) -> dict[str, np.ndarray]:
        return {name: observation[..., sl] for name, sl in self.structure.items()}


def episode_infos(
    env: gym.Env, policy: Policy, seed: int = 0, max_steps: int | None = None
) -> list[dict]:
    """Run `policy` for one episode from ``env.reset(seed=seed)`` (at most `max_steps` steps)
    and return the infos: the reset's first, then one per step."""
    obs, info = env.reset(seed=seed)
    policy.reset()
    infos = [info]
    steps = 0
    while max_steps is None or steps < max_steps:
        obs, _, terminated, truncated, info = env.step(policy(obs))
        infos.append(info)
        steps += 1
        if terminated or truncated:
            break
    return infos
