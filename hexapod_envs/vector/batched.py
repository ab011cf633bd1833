"""`BatchedVectorEnv`: N hexapod worlds whose physics runs on threads, returning exactly what N
single envs return.

Each world is an ordinary env instance (its own `MjModel`, `MjData`, task, controllers and
`np_random`), wrapped as ``gym.make`` wraps it (the time limit). A vector step:

1. on the calling thread, every stepping world validates its action; then, world by world, it
   applies the action (the servo commands, residual filters and gait controllers:
   `HexapodEnv._apply_action`)
2. and its control period of physics starts on another thread while later actions are
   applied. Where the period is plain MuJoCo steps (the cliff walk, the Stewart tilt, the
   ditch crossing: `BatchedPhysics.compiled`), the worlds are split in contiguous shares: each
   of ``nthread - 1`` helper threads steps its share in one compiled call that holds no GIL
   (`hexapod_envs.vector.compiled_steps`), handed over once its share's actions are applied,
   and the calling thread steps the first share itself, sized every step so that the helpers
   finish when the calling thread reaches their worlds. Otherwise (ATHENA's contact checks
   within a period) a pool of ``nthread`` threads runs each world's own `_simulate`, and MuJoCo
   releases the GIL inside each ``mj_step`` (a world that no thread has started when the
   calling thread needs it runs on the calling thread);
3. meanwhile the calling thread runs Gymnasium's `SyncVectorEnv.step`, which steps every world
   as usual with its action application and physics replaced, for this one call, by phase 1
   and by waiting for its physics: world k's measurement, tip-over, success, reward,
   observation and info run while later worlds' physics goes on. The time limit and the
   autoreset (any `AutoresetMode`) are Gymnasium's own code; the vector info dict is built
   once after the worlds have stepped (`hexapod_envs.vector.infos.merge_infos`), equal to
   Gymnasium's world-by-world merge (which the same-step autoreset keeps).

So the results are bit-identical to `SyncVectorEnv` over ``gym.make(id)`` envs with the same
seeds (tests/hexapod_envs/test_vector_env.py), whatever the thread count and the split: each
world runs its own code on its own data, and only the order in which the worlds' pieces run
changes.

Why not `mujoco.rollout` (MuJoCo 4.0): a rollout is stateless by design. It loads each world's
state into a per-thread scratch `MjData`, zeroes ``qacc_warmstart`` unless given and returns
neither it nor the derived fields (contacts, ``xmat``, the sensors' intermediate values) that
the envs read after a step, clears the warning counters the envs read as instability and
stops stepping a world on a warning, where ``mj_step`` goes on (MuJoCo's rollout.cc). The PGS
solver starts from the warm start, so worlds stepped through rollouts would not carry the
single env's warm start from one control period to the next. `mujoco.batch` keeps its own
`MjData` per simulation, which would have to be copied into each env's data in and out of
every step, and ATHENA's contact checks within a period would be reimplemented.

What the threads buy, and what caps it: every world's step outside the physics runs on the
calling thread, so the batched env pays off on few cores and SubprocVecEnv, which runs a Python
per process, overtakes it on many; and cores run the worlds' physics side by side less than
linearly (benchmarks/README.md, ``bench_vector_env.py``).
"""

from __future__ import annotations

import os
import platform
import threading
import time
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
from ..envs.physics import SENSORS_OFF
from .compiled_steps import compiled_steps_available, run_control_periods
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
        """Threads that step the worlds' physics. With `compiled` periods the calling thread is
        one of them (it steps a share between its Python, so 1 runs all physics on the calling
        thread, after the actions); otherwise a pool of ``nthread`` threads beside the calling
        thread. 0: the calling thread steps each world within the world's own step."""
        self.compiled = (
            self.nthread > 0
            and all(_plain_periods(world) for world in self.worlds)
            and compiled_steps_available()
        )
        """The worlds' control periods are plain MuJoCo steps, run in shares of worlds by
        `run_control_periods` without the GIL: the calling thread runs the first share between
        its Python and ``nthread - 1`` helper threads the rest. Otherwise (ATHENA's contact
        checks within a period) a pool of ``nthread`` threads runs each world's `_simulate`."""
        helpers = self.nthread - 1 if self.compiled else self.nthread
        self._pool = ThreadPoolExecutor(helpers) if helpers else None
        self._running: list[Future] = []
        self._own_share = 1.0 / max(self.nthread, 1)
        """The calling thread's share of the worlds in the compiled mode, tuned every step so
        that the helpers finish their worlds when the calling thread reaches them."""
        n = len(self.worlds)
        self._models, self._datas, self._flags, self._nsteps, self._done = period_arrays(n)
        self._compiled_worlds = 0
        """Worlds of the step in progress run compiled (their flags are ``_done[:n]``)."""

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
            if not (_STORES_IN_ORDER and self._physics_over()):  # flags alone prove it here
                wait(self._running)
        except BaseException:
            wait(self._running)  # no world's physics may run on after an error
            for i in stepping:  # some worlds ran physics without their step's bookkeeping
                worlds[i]._needs_reset = True
            raise
        finally:
            self._running, self._compiled_worlds = [], 0
            for i in stepping:
                for name in ("_apply_action", "_simulate"):
                    worlds[i].__dict__.pop(name, None)

    def _physics_over(self) -> bool:
        """Whether every world's physics of this step is over (the compiled worlds' flags: a
        helper may still be taking the GIL back to finish its future), so that the next step
        may rewrite what the threads read."""
        if self._compiled_worlds:
            return bool(self._done[: self._compiled_worlds].all())
        return all(future.done() for future in self._running)

    def _start(self, worlds: Sequence[int]) -> dict[int, Callable[[], bool]]:
        """Apply each of `worlds`' action and queue its control period of physics (its own
        `_simulate`) on the threads at once, in world order, so that the first worlds' physics
        runs while the later actions are applied; world -> a call that waits for it and returns
        whether it stayed stable. Without threads the call runs the physics itself."""
        if self.compiled and all(_plain_periods(self.worlds[i]) for i in worlds):
            return self._start_compiled(worlds)
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

    def _start_compiled(self, worlds: Sequence[int]) -> dict[int, Callable[[], bool]]:
        """`_start` in the compiled mode: the helpers' shares (the last worlds) first, each
        handed over as soon as its actions are applied, then the calling thread's share (the
        first worlds), whose physics it runs before returning."""
        order = list(worlds)
        n, helpers = len(order), self.nthread - 1
        if n == 0:  # every world autoresets this step
            return {}
        self._compiled_worlds = n
        # At least one world for the helpers: their timing is what tunes the split.
        own = n if helpers == 0 else min(n - 1, max(0, round(self._own_share * n)))
        bounds = [own + (n - own) * h // helpers for h in range(helpers + 1)] if helpers else []
        args = (self._models, self._datas, self._flags, self._nsteps, self._done)
        expected = {}
        for k, i in enumerate(order):
            load_period(args, k, self.worlds[i])
        shares = {}
        for start, stop in zip(bounds[:-1], bounds[1:], strict=False):
            for k in range(start, stop):
                expected[k] = self._apply(order[k])
            if stop > start:
                started = threading.Event()
                future = self._pool.submit(_run_share, started, *args, start, stop)
                self._running.append(future)
                started.wait()  # the helper's share runs without the GIL from here
                shares[range(start, stop)] = future
        for k in range(own):
            expected[k] = self._apply(order[k])
        run_control_periods(*args, 0, own)
        balance = _Balance(self, shares, own, len(order))
        physics = {}
        for k, i in enumerate(order):
            stable = partial(self.worlds[i]._stayed_stable_to, expected[k])
            physics[i] = stable if k < own else partial(balance.wait, k, stable)
        return physics

    def _apply(self, i: int) -> float:
        """Apply world `i`'s action; the time [s] its control period must reach."""
        world = self.worlds[i]
        world._apply_action(world._action)
        return world.data.time + world.control_dt

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown()
            self._pool = None


class BatchedVectorEnv(SyncVectorEnv):
    """N hexapod worlds stepped together, the physics on ``nthread`` threads (see the module
    docstring). The constructor takes `SyncVectorEnv`'s arguments and ``nthread``: the threads
    that step the worlds' physics (default: the CPUs, at most N; 0 runs everything on the
    calling thread, as `SyncVectorEnv`; see `BatchedPhysics.nthread`).
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


class _Balance:
    """The calling thread's waits for the helpers' worlds in a compiled step, and the split
    they move by one world a step: the helpers all done when the calling thread reaches their
    first world waited idle (a smaller own share next step); the calling thread waiting for
    them (for the last world, or for the whole shares where flags are not trusted) means a
    larger one.

    Where stores reach other cores in program order (x86-64), a world's flag in
    ``BatchedPhysics._done`` says that its physics is done and its data visible, so the calling
    thread goes on with it while the helper steps the rest of its share; elsewhere it waits for
    the helpers' whole shares (the futures' locks order the memory). A wait for a world spins
    for 0.5 ms, then sleeps between looks."""

    def __init__(self, physics: BatchedPhysics, shares: dict[range, Future], first: int, stop: int):
        self._physics, self._shares = physics, shares
        self._first, self._stop = first, stop
        self._reached = False

    def wait(self, k: int, stable: Callable[[], bool]) -> bool:
        physics, done = self._physics, self._physics._done
        step = 1.0 / len(physics.worlds)
        if not self._reached:
            self._reached = True
            if done[self._first : self._stop].all():
                physics._own_share = max(0.0, physics._own_share - step)
            elif not _STORES_IN_ORDER:
                physics._own_share = min(1.0, physics._own_share + step)
        if _STORES_IN_ORDER and done[k]:
            return stable()
        share = next(future for worlds, future in self._shares.items() if k in worlds)
        if _STORES_IN_ORDER:
            if k == self._stop - 1:
                physics._own_share = min(1.0, physics._own_share + step)
            spin_until = time.perf_counter() + _SPIN_S
            while not done[k] and not share.done():
                # sleep(0) lets another thread run; later sleeps free the core too
                time.sleep(0.0 if time.perf_counter() < spin_until else _POLL_S)
            if done[k]:
                return stable()
        share.result()  # a helper's error reaches the caller here
        return stable()


_SPIN_S = 5e-4
"""How long a wait for a helper's world spins (yielding the core at each look) before it
sleeps between looks [s]: a world's physics takes 0.1-1 ms."""

_POLL_S = 5e-5
"""The sleep between looks after the spin [s] (Linux's timer slack makes it about 0.1 ms)."""

_STORES_IN_ORDER = platform.machine().lower() in ("x86_64", "amd64")
"""Other cores see a thread's stores in the order it made them (x86-64's memory model)."""


def period_arrays(n: int) -> tuple[np.ndarray, ...]:
    """Empty arrays of `run_control_periods` for `n` worlds: models, datas, flags, nsteps,
    done (see `load_period`)."""
    return (
        np.zeros(n, np.int64),
        np.zeros(n, np.int64),
        np.zeros((n, 2), np.int32),
        np.zeros(n, np.int64),
        np.zeros(n, np.int8),
    )


def load_period(arrays: Sequence[np.ndarray], k: int, world: HexapodEnv) -> None:
    """Row `k` of `run_control_periods`' arrays (models, datas, flags, nsteps, done) for one
    control period of `world`: its model's and data's addresses, the flags of the period's steps
    (the sensors off before the last, unless they keep a history), its steps, not done."""
    models, datas, flags, nsteps, done = arrays
    models[k], datas[k] = world.model._address, world.data._address
    own_flags = world.model.opt.disableflags
    flags[k] = own_flags if world._sensors_every_step else own_flags | SENSORS_OFF
    flags[k, 1] = own_flags
    nsteps[k] = world.n_substeps
    done[k] = 0


def _run_share(started: threading.Event, *args) -> None:
    """A helper's share of a compiled step: signal that it runs, then step its worlds."""
    started.set()
    run_control_periods(*args)


def _plain_periods(world: HexapodEnv) -> bool:
    """The world's control period is `HexapodEnv`'s plain MuJoCo steps (no override of the
    period's physics, on its class or replacing it on the instance)."""
    cls = type(world)
    return (
        cls._simulate is HexapodEnv._simulate
        and cls._run_physics is HexapodEnv._run_physics
        and cls._step_sensing_last is HexapodEnv._step_sensing_last
        and not {"_simulate", "_run_physics", "_step_sensing_last"} & world.__dict__.keys()
    )


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
