"""An asymmetric actor-critic: the critic also sees the task, the actor only the sensors.

On the benchmark's task distributions every reset draws a new terrain, payload and friction
(``info["task"]``), which the sensor observation shows only indirectly. A value function that
cannot tell the tasks apart predicts their average return, so its advantages carry the task's
luck as noise. Giving the critic privileged information that the robot will not have is the
usual remedy in legged-robot learning (asymmetric actor-critic, Pinto et al. 2018): the critic
is used only in training, so the deployed actor needs nothing the robot lacks.

- `PrivilegedObservation` appends `PRIVILEGED_DIM` values to the env's observation: the task's
  parameters (`task_vector`) and the elapsed share of the episode's time limit (the value of a
  state depends on how much of the episode is left).
- `agents.privileged_critic_policy.PrivilegedCriticPolicy` is SB3's ``MlpPolicy`` with
  separate actor and critic feature extractors; the actor's zeroes the appended values, so the
  action depends on the sensor observation alone and a deployed policy can be given zeros
  there (`pad_observation`).

A training config turns it on with ``policy.critic_privileged: true`` (docs/training.md).
"""

from __future__ import annotations

import zlib
from typing import Any

import gymnasium as gym
import numpy as np

PRIVILEGED_DIM = 16
"""Values appended to the observation: `TASK_SLOTS` task parameters, then the time share."""
TASK_SLOTS = PRIVILEGED_DIM - 1


def task_code(value: Any) -> float:
    """One task parameter as a number: numbers as they are, booleans 0/1, a string (the cliff's
    side, the Stewart stance) as a fixed code in [0, 1) from its CRC-32 (distinct strings get
    distinct inputs; VecNormalize rescales them like any other input), anything else 0."""
    if isinstance(value, bool | np.bool_):
        return float(value)
    if isinstance(value, int | float | np.integer | np.floating):
        return float(value) if np.isfinite(value) else 0.0
    if isinstance(value, str):
        return zlib.crc32(value.encode()) / 2.0**32
    return 0.0


def task_vector(task: dict[str, Any], keys: list[str]) -> np.ndarray:
    """`TASK_SLOTS` values: the task's parameters in the order of `keys` (missing ones 0), then
    zeros."""
    vector = np.zeros(TASK_SLOTS)
    for i, key in enumerate(keys):
        vector[i] = task_code(task.get(key))
    return vector


def privileged_space(space: gym.spaces.Space) -> gym.spaces.Box:
    """The observation space of `PrivilegedObservation` around an env with `space` (a flat
    Box; ValueError otherwise)."""
    if not isinstance(space, gym.spaces.Box) or len(space.shape) != 1:
        raise ValueError(f"the privileged critic needs a flat Box observation, got {space}")
    low = np.concatenate([space.low, np.full(PRIVILEGED_DIM, -np.inf)])
    high = np.concatenate([space.high, np.full(PRIVILEGED_DIM, np.inf)])
    return gym.spaces.Box(low, high, dtype=space.dtype)


class PrivilegedObservation(gym.Wrapper):
    """The env's observation with `PRIVILEGED_DIM` values appended for the critic: the task's
    parameters (``info["task"]`` at reset, its keys in the sorted order of the first reset) and
    the elapsed share of `max_episode_steps` (0 at reset, 1 at the time limit).

    Args:
        env: a hexapod env (its reset info has a ``task`` dict).
        max_episode_steps: the episode's time limit in env steps (> 0).
    """

    def __init__(self, env: gym.Env, max_episode_steps: int):
        super().__init__(env)
        if not max_episode_steps or max_episode_steps <= 0:
            raise ValueError(
                f"the privileged critic needs the episode's time limit in steps, got "
                f"{max_episode_steps!r}"
            )
        self.observation_space = privileged_space(env.observation_space)
        self.max_episode_steps = int(max_episode_steps)
        self.task_keys: list[str] | None = None
        self._task = np.zeros(TASK_SLOTS)
        self._steps = 0

    def reset(self, **kwargs: Any):
        obs, info = self.env.reset(**kwargs)
        task = info.get("task") or {}
        if self.task_keys is None:
            if len(task) > TASK_SLOTS:
                raise ValueError(
                    f"the task has {len(task)} parameters; the privileged critic has room for "
                    f"{TASK_SLOTS}: {sorted(task)}"
                )
            self.task_keys = sorted(task)
        self._task, self._steps = task_vector(task, self.task_keys), 0
        return self._with_privileged(obs), info

    def step(self, action: Any):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._steps += 1
        return self._with_privileged(obs), reward, terminated, truncated, info

    def _with_privileged(self, obs: np.ndarray) -> np.ndarray:
        share = min(self._steps / self.max_episode_steps, 1.0)
        extra = np.append(self._task, share)
        return np.concatenate([obs, extra]).astype(self.observation_space.dtype)


def pad_observation(observation: np.ndarray) -> np.ndarray:
    """A sensor observation (batched or not) padded with the `PRIVILEGED_DIM` zeros a
    `PrivilegedCriticPolicy` expects; its actor ignores them."""
    obs = np.asarray(observation)
    pad = np.zeros(obs.shape[:-1] + (PRIVILEGED_DIM,), dtype=obs.dtype)
    return np.concatenate([obs, pad], axis=-1)
