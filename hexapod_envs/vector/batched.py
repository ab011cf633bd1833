"""`BatchedVectorEnv`: N hexapod worlds whose physics runs on threads, returning exactly what N
single envs return.

Each world is an ordinary env instance (its own `MjModel`, `MjData`, task, controllers and
`np_random`), wrapped as ``gym.make`` wraps it (the time limit). A vector step:

1. on the calling thread, every stepping world validates its action; then, world by world, it
   applies the action (the servo commands, residual filters and gait controllers:
   `HexapodEnv._apply_action`)
2. and queues that world's control period of physics (its own `HexapodEnv._simulate`,
   ATHENA's contact checks included) on ``nthread`` threads, so the first worlds' physics
   starts while later actions are applied; MuJoCo releases the GIL inside ``mj_step``, so the
   worlds' physics runs in parallel (a world that no thread has started when the calling
   thread needs it runs on the calling thread);
3. meanwhile the calling thread runs Gymnasium's `SyncVectorEnv.step`, which steps every world
   as usual with its action application and physics replaced, for this one call, by phase 1
   and by waiting for its physics: world k's measurement, tip-over, success, reward,
   observation and info run while later worlds' physics goes on. The time limit and the
   autoreset (any `AutoresetMode`) are Gymnasium's own code; the vector info dict is built
   once after the worlds have stepped (`hexapod_envs.vector.infos.merge_infos`), equal to
   Gymnasium's world-by-world merge (which the same-step autoreset keeps).

So the results are bit-identical to `SyncVectorEnv` over ``gym.make(id)`` envs with the same
seeds (tests/hexapod_envs/test_vector_env.py), whatever the thread count: each world runs its
own code on its own data, and only the order in which the worlds' pieces run changes.

Why not `mujoco.rollout` (MuJoCo 4.0): a rollout is stateless by design. It loads each world's
state into a per-thread scratch `MjData`, zeroes ``qacc_warmstart`` unless given and returns
neither it nor the derived fields (contacts, ``xmat``, the sensors' intermediate values) that
the envs read after a step, clears the warning counters the envs read as instability and
stops stepping a world on a warning, where ``mj_step`` goes on (MuJoCo's rollout.cc). The PGS
solver starts from the warm start, so worlds stepped through rollouts would not carry the
single env's warm start from one control period to the next. `mujoco.batch` keeps its own
`MjData` per simulation, which would have to be copied into each env's data in and out of
every step, and ATHENA's contact checks within a period would be reimplemented.

What the threads buy, and what caps it (the calling thread's share of a step, caches that go
cold between a world's turns): benchmarks/README.md, ``bench_vector_env.py``.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ThreadPoolExecutor, wait
from contextlib import contextmanager
from functools import partial
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, SyncVectorEnv
from gymnasium.vector.utils import iterate

from ..envs.base import HexapodEnv
from .infos import merge_infos

__all__ = ["BatchedPhysics", "BatchedVectorEnv"]


class BatchedPhysics:
    """The worlds' physics on ``nthread`` threads, between their Python: the engine of
    `BatchedVectorEnv`, and of any vector env that steps each world through its wrappers in
    turn (SB3's `DummyVecEnv` loop, `agents.pipeline.batched_vec_env`).

    ``with physics.step(stepping, actions): <step each world in turn>``: on entry the worlds in
    `stepping` validate and apply their actions and their physics is queued on the threads; in
    the block, each world's next `_apply_action` is skipped (after a check that the action
    reaching it is the one applied: the wrappers between the vector env and the world must pass
    actions through, as `TimeLimit`, `OrderEnforcing` and SB3's `Monitor` do) and its next
    `_simulate` waits for its physics. A world whose step raises leaves no physics running and
    no replacement behind, and every world of that step must be reset before it steps again
    (some had their physics run without the rest of their step)."""

    def __init__(self, worlds: Sequence[gym.Env], nthread: int | None = None):
        self.worlds = list(worlds)
        """The worlds' env instances (each unwrapped env: its model, data, task, rng)."""
        for world in self.worlds:
            if not isinstance(world, HexapodEnv):
                raise TypeError(
                    "batched physics steps hexapod_envs worlds (HexapodEnv), got "
                    f"{type(world).__name__}; use a SyncVectorEnv or an SB3 vec env for others"
                )
        if nthread is None:
            nthread = min(len(self.worlds), os.cpu_count() or 1)
        if not isinstance(nthread, int | np.integer) or isinstance(nthread, bool) or nthread < 0:
            raise ValueError(f"nthread must be an integer >= 0, got {nthread!r}")
        self.nthread = int(nthread)
        """Threads that run the worlds' physics (0: the calling thread runs it)."""
        self._pool = ThreadPoolExecutor(self.nthread) if self.nthread else None
        self._running: list[Future] = []

    @contextmanager
    def step(self, stepping: Sequence[int], actions: Sequence[np.ndarray]) -> Iterator[None]:
        """Phases 1 and 2 of the worlds `stepping` (see the class docstring)."""
        worlds = self.worlds
        # Validate every action before any world changes: a bad action leaves all worlds alone.
        applied = {i: worlds[i]._validate_action(actions[i]).copy() for i in stepping}
        try:
            physics = self._start(stepping)
            for i in stepping:
                _replace_once(worlds[i], "_apply_action", partial(_check_action, i, applied[i]))
                _replace_once(worlds[i], "_simulate", physics[i])
            yield
        except BaseException:
            wait(self._running)  # no world's physics may run on after an error
            for i in stepping:  # some worlds ran physics without their step's bookkeeping
                worlds[i]._needs_reset = True
            raise
        finally:
            self._running = []
            for i in stepping:
                for name in ("_apply_action", "_simulate"):
                    worlds[i].__dict__.pop(name, None)

    def _start(self, worlds: Sequence[int]) -> dict[int, Callable[[], bool]]:
        """Apply each of `worlds`' action and queue its control period of physics (its own
        `_simulate`) on the threads at once, in world order, so that the first worlds' physics
        runs while the later actions are applied; world -> a call that waits for it and returns
        whether it stayed stable. Without threads the call runs the physics itself."""
        physics = {}
        for i in worlds:
            world = self.worlds[i]
            world._apply_action(world._action)
            if self._pool is None:
                physics[i] = world._simulate
            else:
                future = self._pool.submit(world._simulate)
                self._running.append(future)
                physics[i] = partial(_take, future, world._simulate)
        return physics

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown()
            self._pool = None


class BatchedVectorEnv(SyncVectorEnv):
    """N hexapod worlds stepped together, the physics on ``nthread`` threads (see the module
    docstring). The constructor takes `SyncVectorEnv`'s arguments and ``nthread``: the threads
    that run the worlds' physics while the calling thread runs the rest of the step (default:
    the CPUs, at most N; 0 runs everything on the calling thread, as `SyncVectorEnv`).
    ``gym.make_vec(id, num_envs=N, vectorization_mode="vector_entry_point", nthread=...)``
    builds one for a registered id (`hexapod_envs.vector.make_batched`)."""

    def __init__(
        self,
        env_fns: Sequence[Callable[[], gym.Env]],
        nthread: int | None = None,
        copy: bool = True,
        autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP,
    ):
        self._collected_infos: list[tuple[dict, int]] | None = None
        super().__init__(env_fns, copy=copy, autoreset_mode=autoreset_mode)
        self.physics = BatchedPhysics([env.unwrapped for env in self.envs], nthread)

    @property
    def worlds(self) -> list[gym.Env]:
        """The worlds' env instances (unwrapped)."""
        return self.physics.worlds

    def step(self, actions):
        """`SyncVectorEnv.step` with the physics of the worlds that step (not those that
        autoreset now) batched (`BatchedPhysics.step`), and the vector info built once."""
        stepping = [
            i
            for i in range(self.num_envs)
            if self.autoreset_mode != AutoresetMode.NEXT_STEP or not self._autoreset_envs[i]
        ]
        # Each world's info is merged after every world has stepped: its values must not
        # change once returned (the hexapod envs return fresh ones). With the same-step
        # autoreset a world resets within the step after giving its final info, which a reset
        # may change in place: those steps keep Gymnasium's merge, world by world.
        collect = self.autoreset_mode != AutoresetMode.SAME_STEP
        self._collected_infos = [] if collect else None
        try:
            with self.physics.step(stepping, list(iterate(self.action_space, actions))):
                observations, rewards, terminations, truncations, infos = super().step(actions)
        finally:
            collected, self._collected_infos = self._collected_infos, None
        if collect:
            infos = merge_infos(collected, self.num_envs, self._add_info)
        return observations, rewards, terminations, truncations, infos

    def _add_info(self, vector_infos: dict, env_info: dict, env_num: int) -> dict:
        """In a step, collect each world's info for `merge_infos`; elsewhere (the reset, the
        same-step autoreset) Gymnasium's merge."""
        if self._collected_infos is None:
            return super()._add_info(vector_infos, env_info, env_num)
        self._collected_infos.append((env_info, env_num))
        return vector_infos

    def close_extras(self, **kwargs: Any) -> None:
        super().close_extras(**kwargs)
        self.physics.close()


def _take(future: Future, simulate: Callable[[], bool]) -> bool:
    """A world's physics when the calling thread needs it: if no thread has started it yet,
    the calling thread runs it itself rather than wait idle."""
    if future.cancel():
        return simulate()
    return future.result()


def _check_action(world: int, applied: np.ndarray, action: np.ndarray) -> None:
    """The replacement of a world's `_apply_action` in a batched step: the action reaching the
    world must be the one applied before its physics ran."""
    if not np.array_equal(action, applied):
        raise RuntimeError(
            f"world {world}: a wrapper changed the action between the vector env and the env; "
            "batched physics applies the vector env's action before the world steps, so it "
            "needs wrappers that pass actions through (not a hybrid policy or GainsPerCycle)"
        )


def _replace_once(world: gym.Env, name: str, replacement: Callable) -> None:
    """Shadow the method `name` of `world` for its next call only."""

    def once(*args):
        del world.__dict__[name]
        return replacement(*args)

    world.__dict__[name] = once
