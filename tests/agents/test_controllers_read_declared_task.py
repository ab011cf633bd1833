"""The analytical controllers know the task only through the env's declared task description
(`env.unwrapped.task_description`) and the observation: built on an env whose `unwrapped`
exposes nothing else, each runs whole episodes (the heavy-duty ones into their tipping
recovery) and chooses the same actions as on the real env."""

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from agents.registry import ANALYTICAL_ENV_KWARGS, analytical_policy


class _DeclaredOnly:
    """`env.unwrapped` stand-in exposing only the task description."""

    def __init__(self, base):
        self._base = base

    @property
    def task_description(self):
        return self._base.task_description

    def __getattr__(self, name):
        raise AttributeError(f"a controller read env.unwrapped.{name}")


class _Env:
    def __init__(self, env):
        self.spec, self.action_space, self.observation_space = (
            env.spec,
            env.action_space,
            env.observation_space,
        )
        self.unwrapped = _DeclaredOnly(env.unwrapped)


@pytest.mark.parametrize("env_id", sorted(k for k in gym.registry if k.startswith("Hexapod")))
def test_controller_reads_only_the_task_description_and_observation(env_id):
    kwargs = {**ANALYTICAL_ENV_KWARGS.get(env_id, {}), "task_distribution": "train"}
    env, twin = gym.make(env_id, **kwargs), gym.make(env_id, **kwargs)
    declared, full = analytical_policy(_Env(env)), analytical_policy(twin)
    recovering = 0
    for episode in range(2):  # the second episode has another sampled task
        obs, _ = env.reset(seed=episode)
        twin.reset(seed=episode)
        declared.reset()
        full.reset()
        while True:
            action = declared(obs)
            np.testing.assert_array_equal(action, full(obs))
            recovering += getattr(getattr(declared, "controller", None), "active", False)
            obs, _, terminated, truncated, _ = env.step(action)
            twin.step(action)
            if terminated or truncated:
                break
    if hasattr(getattr(declared, "controller", None), "active"):  # the tipping recovery
        assert recovering > 0
    env.close()
    twin.close()
