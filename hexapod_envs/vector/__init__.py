"""Batched vector envs: N worlds of one hexapod env, their physics on threads
(`BatchedVectorEnv`), registered as each id's Gymnasium ``vector_entry_point``:

>>> import gymnasium as gym, hexapod_envs
>>> envs = gym.make_vec("HexapodCliffWalk-v1", num_envs=8, vectorization_mode="vector_entry_point")

The entry points below build the worlds as ``gym.make`` does (the env class with the id's
keyword arguments, under its time limit); ``nthread`` (the threads of the physics, default: the
CPUs) and ``autoreset_mode`` go to `BatchedVectorEnv`, the other keyword arguments to each
world.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import gymnasium as gym
from gymnasium.envs.registration import load_env_creator
from gymnasium.vector import AutoresetMode
from gymnasium.wrappers import OrderEnforcing, TimeLimit

from .batched import BatchedPhysics, BatchedVectorEnv

__all__ = [
    "BatchedPhysics",
    "BatchedVectorEnv",
    "cliff_walk",
    "ditch_crossing",
    "irregular_terrain",
    "make_batched",
    "stewart_tilt",
]


def make_batched(
    entry_point: str,
    num_envs: int = 1,
    *,
    max_episode_steps: int | None = None,
    nthread: int | None = None,
    autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP,
    **kwargs: Any,
) -> BatchedVectorEnv:
    """`num_envs` worlds of the env class at `entry_point` ("module:Class") built with
    `kwargs`, each under ``TimeLimit(max_episode_steps)`` as ``gym.make`` builds it."""
    env_class = load_env_creator(entry_point)

    def world() -> gym.Env:
        env = OrderEnforcing(env_class(**kwargs))
        return env if max_episode_steps is None else TimeLimit(env, max_episode_steps)

    return BatchedVectorEnv([world] * num_envs, nthread=nthread, autoreset_mode=autoreset_mode)


def _entry_point(env_entry_point: str) -> Callable[..., BatchedVectorEnv]:
    def make(num_envs: int = 1, **kwargs: Any) -> BatchedVectorEnv:
        return make_batched(env_entry_point, num_envs, **kwargs)

    make.__doc__ = f"`make_batched` of {env_entry_point}."
    return make


cliff_walk = _entry_point("hexapod_envs.envs.cliff_walk:CliffWalkEnv")
stewart_tilt = _entry_point("hexapod_envs.envs.stewart_tilt:StewartTiltEnv")
irregular_terrain = _entry_point("hexapod_envs.envs.irregular_terrain:IrregularTerrainEnv")
ditch_crossing = _entry_point("hexapod_envs.envs.ditch_crossing:DitchCrossingEnv")
