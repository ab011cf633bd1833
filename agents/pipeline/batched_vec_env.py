"""`BatchedDummyVecEnv`: SB3's `DummyVecEnv` with the worlds' physics batched on threads
(``env.vectorization: batched`` in a training config).

SB3 2.x has no adapter from a Gymnasium vector env to its `VecEnv`, and one would cost twice:
a Gymnasium vector env merges the worlds' info dicts into arrays, which SB3's list of per-env
info dicts would split again, and resets on the step after an episode ends, where SB3 resets
on the same step (``terminal_observation``). So the adapter is SB3's own `DummyVecEnv` loop
(per-env infos, same-step resets, Monitor episodes, seeding) around
`hexapod_envs.vector.BatchedPhysics`, the engine of the registered batched vector env: each
step first applies every world's action and queues its physics on the threads, then the loop
steps each world, waiting for its physics. It returns what `DummyVecEnv` returns over the same
envs, bit for bit (tests/agents/pipeline/test_batched_vec_env.py).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import gymnasium as gym
from stable_baselines3.common.vec_env import DummyVecEnv

from hexapod_envs.vector import BatchedPhysics

from .envs import EnvFactory, EnvSpec

__all__ = ["BatchedDummyVecEnv", "make_batched_vec_env"]


class BatchedDummyVecEnv(DummyVecEnv):
    """`DummyVecEnv` over `env_fns` whose physics runs on ``nthread`` threads (None: the CPUs,
    at most the number of envs). The envs' wrappers must pass actions through (Monitor, the
    time limit, reward wrappers), see `BatchedPhysics`."""

    def __init__(self, env_fns: Sequence[Callable[[], gym.Env]], nthread: int | None = None):
        super().__init__(list(env_fns))
        self.physics = BatchedPhysics([env.unwrapped for env in self.envs], nthread)

    def step_wait(self):
        with self.physics.step(range(self.num_envs), self.actions):
            return super().step_wait()

    def close(self) -> None:
        self.physics.close()
        super().close()


def make_batched_vec_env(
    spec: EnvSpec, n_envs: int, seed: int, nthread: int | None = None
) -> BatchedDummyVecEnv:
    """A `BatchedDummyVecEnv` of `n_envs` monitored copies of `spec`, seeded seed..seed+n-1
    (as `agents.pipeline.envs.make_vec_env` builds the SB3 vec envs)."""
    spec.make().close()  # fail here with a clear error
    venv = BatchedDummyVecEnv([EnvFactory(spec) for _ in range(n_envs)], nthread)
    venv.seed(seed)
    return venv
