"""`BatchedVectorEnv`: N hexapod worlds whose physics runs on threads, returning exactly what N
single envs return.

Each world is an ordinary env instance (its own `MjModel`, `MjData`, task, controllers and
`np_random`), wrapped as ``gym.make`` wraps it (the time limit). A vector step:

1. on the calling thread, every stepping world validates its action and applies it (the
   servo commands, residual filters and gait controllers: `HexapodEnv._apply_action`);
2. the control period's physics of those worlds (each world's own `HexapodEnv._simulate`,
   ATHENA's contact checks included) is queued, in world order, on ``nthread`` threads;
   MuJoCo releases the GIL inside ``mj_step``, so the worlds' physics runs in parallel;
3. meanwhile the calling thread runs Gymnasium's `SyncVectorEnv.step`, which steps every world
   as usual with its action application and physics replaced, for this one call, by phase 1
   and by waiting for its physics: world k's measurement, tip-over, success, reward,
   observation and info run while later worlds' physics goes on. The time limit, the
   autoreset (any `AutoresetMode`) and the vector info dict are Gymnasium's own code.

So the results are bit-identical to `SyncVectorEnv` over ``gym.make(id)`` envs with the same
seeds (tests/hexapod_envs/test_vector_env.py), whatever the thread count: each world runs its
own code on its own data, and only the order in which the worlds' pieces run changes.

Why not `mujoco.rollout` (MuJoCo 4.0): a rollout is stateless by design. It loads each world's
state into a per-thread scratch `MjData`, zeroes ``qacc_warmstart`` unless given and returns
neither it nor the derived fields (contacts, ``xmat``, the sensors' intermediate values) that
the envs read after a step, clears the warning counters the envs read as instability and
stops stepping a world on a warning, where ``mj_step`` goes on. The PGS solver starts from the
warm start, so a world stepped through a rollout drifts from the single env. `mujoco.batch`
keeps its own `MjData` per simulation, which would have to be copied into each env's data in
and out of every step, and ATHENA's contact checks within a period would be reimplemented.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor, wait
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, SyncVectorEnv
from gymnasium.vector.utils import iterate

__all__ = ["BatchedVectorEnv"]


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
        super().__init__(env_fns, copy=copy, autoreset_mode=autoreset_mode)
        self.worlds = [env.unwrapped for env in self.envs]
        """The worlds' env instances (each unwrapped env: its model, data, task, rng)."""
        if nthread is None:
            nthread = min(self.num_envs, os.cpu_count() or 1)
        if not isinstance(nthread, int | np.integer) or isinstance(nthread, bool) or nthread < 0:
            raise ValueError(f"nthread must be an integer >= 0, got {nthread!r}")
        self.nthread = int(nthread)
        """Threads that run the worlds' physics (0: the calling thread runs it)."""
        self._pool = ThreadPoolExecutor(self.nthread) if self.nthread else None
        self._running: list[Future] = []

    def step(self, actions):
        """Phase 1 on the calling thread for the worlds that step (not those that autoreset
        now), their physics started on the threads, then `SyncVectorEnv.step` with each world's
        action application done and its physics awaited."""
        stepping = [
            i
            for i in range(self.num_envs)
            if self.autoreset_mode != AutoresetMode.NEXT_STEP or not self._autoreset_envs[i]
        ]
        single = list(iterate(self.action_space, actions))
        # Validate every action before any world changes: a bad action leaves all worlds alone.
        valid = {i: self.worlds[i]._validate_action(single[i]) for i in stepping}
        for i in stepping:
            self.worlds[i]._apply_action(valid[i])
        physics = self._start_physics(stepping)
        try:
            for i in stepping:
                _replace_once(self.worlds[i], "_apply_action", lambda action: None)
                _replace_once(self.worlds[i], "_simulate", physics[i])
            return super().step(actions)
        except BaseException:
            wait(self._running)  # no world's physics may run on after an error
            raise
        finally:  # and no replacement stays behind
            self._running = []
            for i in stepping:
                for name in ("_apply_action", "_simulate"):
                    self.worlds[i].__dict__.pop(name, None)

    def _start_physics(self, worlds: list[int]) -> dict[int, Callable[[], bool]]:
        """Start one control period of physics of each of `worlds` (its own `_simulate`) on
        the threads, in world order; world -> a call that waits for it and returns whether it
        stayed stable. Without threads the call runs the physics itself."""
        if self._pool is None:
            return {i: self.worlds[i]._simulate for i in worlds}
        self._running = [self._pool.submit(self.worlds[i]._simulate) for i in worlds]
        return {i: future.result for i, future in zip(worlds, self._running, strict=True)}

    def close_extras(self, **kwargs: Any) -> None:
        super().close_extras(**kwargs)
        if self._pool is not None:
            self._pool.shutdown()
            self._pool = None


def _replace_once(world: gym.Env, name: str, replacement: Callable) -> None:
    """Shadow the method `name` of `world` for its next call only."""

    def once(*args):
        del world.__dict__[name]
        return replacement(*args)

    world.__dict__[name] = once
