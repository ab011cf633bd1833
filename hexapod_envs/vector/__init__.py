"""Batched vector envs: N worlds of one hexapod env, their physics on threads
(`BatchedVectorEnv`), registered as each id's Gymnasium ``vector_entry_point``:

>>> import gymnasium as gym, hexapod_envs
>>> envs = gym.make_vec("HexapodCliffWalk-v1", num_envs=8, vectorization_mode="vector_entry_point")

The entry points below build the worlds as ``gym.make`` does (the env class with the id's
keyword arguments, under its time limit); ``nthread`` (the threads that step the physics, the
calling thread among them where the periods run compiled; default: the CPUs) and
``autoreset_mode`` go to `BatchedVectorEnv`, the other keyword arguments to each world.
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


def _entry_point(name: str, env_entry_point: str) -> Callable[..., BatchedVectorEnv]:
    def make(
        num_envs: int = 1, *, max_episode_steps: int | None = None, **kwargs: Any
    ) -> BatchedVectorEnv:
        if max_episode_steps is None:  # as gym.make reads None: the registered time limit
            max_episode_steps = _registered_limit(f"{__name__}:{name}")
        return make_batched(
            env_entry_point, num_envs, max_episode_steps=max_episode_steps, **kwargs
        )

    make.__doc__ = (
        f"`make_batched` of {env_entry_point}; ``max_episode_steps=None`` is the time limit "
        "of the ids registered with this vector entry point, as ``gym.make`` reads it."
    )
    return make


def _registered_limit(vector_entry_point: str) -> int | None:
    """The time limit shared by the ids registered with `vector_entry_point` (None: none)."""
    limits = {
        spec.max_episode_steps
        for spec in gym.registry.values()
        if spec.vector_entry_point == vector_entry_point
    }
    if len(limits) > 1:
        raise ValueError(
            f"the ids registered with {vector_entry_point} have different time limits "
            f"({sorted(limits, key=repr)}); pass a number as max_episode_steps"
        )
    return limits.pop() if limits else None


cliff_walk = _entry_point("cliff_walk", "hexapod_envs.envs.cliff_walk:CliffWalkEnv")
stewart_tilt = _entry_point("stewart_tilt", "hexapod_envs.envs.stewart_tilt:StewartTiltEnv")
irregular_terrain = _entry_point(
    "irregular_terrain", "hexapod_envs.envs.irregular_terrain:IrregularTerrainEnv"
)
ditch_crossing = _entry_point("ditch_crossing", "hexapod_envs.envs.ditch_crossing:DitchCrossingEnv")
