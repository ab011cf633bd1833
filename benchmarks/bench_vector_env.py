"""The batched vector env's throughput: env steps per second of `hexapod_envs.vector` (N worlds,
their physics on 2 threads) beside one single env and SB3's SubprocVecEnv(2), on the cliff walk,
the Stewart tilt and ATHENA's block bed; then PPO training steps per second on the batched env
beside SubprocVecEnv(2), measured in one run.

Env rows: the -v1 ids on their training tasks with random actions, resets included (time limit
and tip-overs). "single" is ``gym.make(id)``; "subproc 2" SB3's SubprocVecEnv of 2 monitored
envs (the training pipeline's default with 2 envs); "batched N" ``gym.make_vec(id, N,
vectorization_mode="vector_entry_point", nthread=2)``; "batched 8, 0 threads" the same code
with the physics on the calling thread (Gymnasium's SyncVectorEnv loop: what the vector
machinery costs). Configurations are measured in turn, `--rounds` times, best of the rounds
(the machine is shared: interference only slows a run down). Beside the rates, this process's
CPU per env step (all threads, and the calling thread's: not for subprocess envs) and the rate
those allow on free cores (1 / CPU for the single env; 1 / max(main, CPU / threads) with the
physics threads): the figure a loaded machine cannot show. Each env also gets its step profile
(`common.step_profile`: physics against the env's Python, µs per step) and the ceiling of any
batching on this machine: the largest batch's worlds' physics alone (no other Python) on one
thread and on the physics threads as the batched env runs it (compiled shares, or a thread
pool for ATHENA); the same worlds' trajectories stepped alone and interleaved (what
interleaving costs the physics); the rate against one env that a batched env with no Python
cost would reach (one env's step over the interleaved physics split at that scaling), and the
CPU per world step that the 1.8 x target allows with those cores fully used.

PPO rows: configs/cliff_walk_ppo.yaml on HexapodCliffWalk-v1 with the same rollout size
(`--rollout` steps over all envs) and `--ppo-steps` steps: SubprocVecEnv(2), the batched
DummyVecEnv adapter with 2 envs (``env.vectorization: batched``, the same config) and with 8
envs, each split into the time spent stepping the envs, the rest of the rollout (policy
inference, buffers) and the PPO update.

On a machine with more cores, ``--threads 16 --worlds 64 --subproc 16 --ppo-steps 0`` gives
the same env rows with 64 worlds on 16 physics threads against SubprocVecEnv(16); ``taskset -c
0,1`` before the command holds the 2-core rows to two of its cores.

Run: python benchmarks/bench_vector_env.py [--seconds 2] [--rounds 2] [--ppo-steps 8192]
  [--threads 2] [--worlds 8,16] [--subproc 2]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections import defaultdict
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from pathlib import Path
from typing import NamedTuple

import gymnasium as gym
import mujoco
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run as a script from anywhere

import hexapod_envs  # noqa: E402, F401  (registers the ids)
from agents.pipeline.batched_vec_env import make_batched_vec_env  # noqa: E402
from agents.pipeline.envs import EnvSpec, make_vec_env  # noqa: E402
from agents.run_files.train_config import load_train_config  # noqa: E402
from benchmarks.common import step_profile, verdict  # noqa: E402
from hexapod_envs.vector import BatchedPhysics  # noqa: E402
from hexapod_envs.vector.batched import load_period, period_arrays  # noqa: E402
from hexapod_envs.vector.compiled_steps import run_control_periods  # noqa: E402

ENV_IDS = ("HexapodCliffWalk-v1", "HexapodStewartTilt-v1", "HexapodIrregularTerrain-v1")
KWARGS = {"task_distribution": "train"}
SINGLE_TARGET = 1.8
"""Issue 46's target: batched env steps per second >= 1.8 x one single env (2 cores)."""
SUBPROC_TARGET = 1.2
"""Issue 46's targets: batched >= 1.2 x SubprocVecEnv(2), env steps and PPO steps per second."""


class Rate(NamedTuple):
    """One measurement: env steps per second, and this process's CPU per env step."""

    rate: float
    cpu_us: float
    """CPU time of all this process's threads per env step [µs] (NaN for subprocess envs,
    whose stepping runs in other processes)."""
    main_us: float
    """CPU time of the calling thread per env step [µs]."""


def _timed(step: Callable[[], int], seconds: float, local: bool = True) -> Rate:
    """Repeated `step()` calls (each returns the env steps it made) over at least `seconds`:
    the rate and the CPU per step (`local`: the stepping runs in this process)."""
    steps, start = 0, time.perf_counter()
    cpu, main = time.process_time(), time.thread_time()
    while (elapsed := time.perf_counter() - start) < seconds:
        steps += step()
    main = (time.thread_time() - main) / steps * 1e6  # the process's window holds the thread's
    cpu = (time.process_time() - cpu) / steps * 1e6 if local else float("nan")
    return Rate(steps / elapsed, cpu, main)


ACTION_SCALE = 0.1
"""Random actions uniform in this share of the action range around its centre: small enough
that episodes mostly run to the time limit, so every configuration resets at about the same
rate (a reset on the training tasks rebuilds the model and settles: as much as 10-60 steps),
and the figures compare stepping rather than the luck of the draws."""


def _actions(space: gym.Space, rows: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    mid, half = (space.high + space.low) / 2, (space.high - space.low) / 2 * ACTION_SCALE
    return rng.uniform(mid - half, mid + half, (rows, *space.shape)).astype(space.dtype)


def single_rate(env_id: str, seconds: float) -> Rate:
    env = gym.make(env_id, **KWARGS)
    actions = _actions(env.action_space, 4096, 0)
    env.reset(seed=0)
    env.step(actions[0])  # loads the compiled kernels (start-up, not stepping)
    k = [0]

    def step() -> int:
        _, _, terminated, truncated, _ = env.step(actions[k[0] % len(actions)])
        k[0] += 1
        if terminated or truncated:
            env.reset()
        return 1

    rate = _timed(step, seconds)
    env.close()
    return rate


def subproc_rate(env_id: str, seconds: float, n_envs: int) -> Rate:
    spec = EnvSpec(env_id, dict(KWARGS), gym_packages=["hexapod_envs"])
    venv = make_vec_env(spec, n_envs, seed=0, subprocess=True)
    return _vec_rate(venv, n_envs, seconds, venv.action_space, local=False)


def batched_rate(env_id: str, seconds: float, n_envs: int, nthread: int) -> Rate:
    envs = gym.make_vec(
        env_id, n_envs, vectorization_mode="vector_entry_point", nthread=nthread, **KWARGS
    )
    envs.reset(seed=0)
    return _vec_rate(envs, n_envs, seconds, envs.single_action_space)


def _vec_rate(envs, n_envs: int, seconds: float, space: gym.Space, local: bool = True) -> Rate:
    """Env steps per second of a vec env (SB3's or Gymnasium's) with random actions."""
    actions = _actions(space, 1024 * n_envs, 1).reshape(1024, n_envs, *space.shape)
    envs.reset()
    envs.step(actions[0])  # the workers load their compiled kernels
    k = [0]

    def step() -> int:
        envs.step(actions[k[0] % len(actions)])
        k[0] += 1
        return n_envs

    rate = _timed(step, seconds, local)
    envs.close()
    return rate


def physics_ceiling(
    env_id: str, seconds: float, n_worlds: int, threads: int
) -> tuple[float, float]:
    """The batching's ceiling on this machine: µs of wall time per world and control period of
    the physics alone (no other Python), `n_worlds` worlds in turn on the calling thread and
    split between `threads` threads, both as the batched env runs them: in compiled shares that
    hold no GIL where the worlds' periods are plain MuJoCo steps (`BatchedPhysics.compiled`),
    else each world's `_simulate` (on a thread pool for the threads). Each round restores every
    world to the state it had after 50 random-action steps (each thread its own worlds), so both
    figures step the same states."""
    worlds = []
    for seed in range(n_worlds):
        env = gym.make(env_id, **KWARGS)
        env.reset(seed=seed)
        for action in _actions(env.action_space, 50, seed):
            env.step(action)
        world = env.unwrapped
        spec = mujoco.mjtState.mjSTATE_INTEGRATION
        state = np.empty(mujoco.mj_stateSize(world.model, spec))
        mujoco.mj_getState(world.model, world.data, state, spec)
        worlds.append((world, state, spec, env))

    def restore(share: list) -> None:
        for world, state, spec, _ in share:
            mujoco.mj_setState(world.model, world.data, state, spec)

    def periods(share: list) -> None:
        restore(share)
        for world, *_ in share:
            world._simulate()

    def per_world(run: Callable[[], None]) -> float:
        rounds, start = 0, time.perf_counter()
        while (elapsed := time.perf_counter() - start) < seconds:
            run()
            rounds += 1
        return elapsed / (rounds * n_worlds) * 1e6

    engine = BatchedPhysics([world for world, *_ in worlds], threads)
    compiled = engine.compiled
    engine.close()
    with ThreadPoolExecutor(threads) as pool:
        if compiled:
            arrays = period_arrays(n_worlds)
            for k, (world, *_) in enumerate(worlds):
                load_period(arrays, k, world)
            bounds = [n_worlds * k // threads for k in range(threads + 1)]

            def compiled_share(start: int, stop: int) -> None:
                restore(worlds[start:stop])
                run_control_periods(*arrays, start, stop)

            compiled_share(0, 1)  # loads the compiled kernel (start-up, not stepping)
            threaded = per_world(lambda: list(pool.map(compiled_share, bounds[:-1], bounds[1:])))
            one = per_world(lambda: compiled_share(0, n_worlds))
        else:
            shares = [worlds[k::threads] for k in range(threads)]
            threaded = per_world(lambda: list(pool.map(periods, shares)))
            one = per_world(lambda: periods(worlds))
    for *_, env in worlds:
        env.close()
    return one, threaded


def interleaving_cost(env_id: str, n_worlds: int, steps: int) -> tuple[float, float]:
    """What interleaving worlds costs their physics, before any thread: mean µs of a control
    period's physics (`_simulate`) of the same `n_worlds` worlds on the same trajectories (seeds
    0..n-1, the same actions), each world alone (its own env stepped `steps` times in a row)
    and the worlds interleaved as the batched env with 0 threads steps them (each world's
    physics on the calling thread within its own step, the other worlds' steps between). The
    difference is the caches: a world stepped alone finds its model, data and the env's Python
    objects where its last step left them. The first step of each world and the resets' settling
    periods are not counted."""
    alone, periods = [], []
    for i in range(n_worlds):
        with gym.make(env_id, **KWARGS) as env, _timing_simulate(env.unwrapped) as times:
            if i == 0:
                actions = _actions(env.action_space, steps * n_worlds, 2)
                actions = actions.reshape(steps, n_worlds, -1)
            env.reset(seed=i)
            for k in range(steps):
                _, _, terminated, truncated, _ = env.step(actions[k, i])
                if terminated or truncated:
                    break
        periods.append(len(times[id(env.unwrapped)]))
        alone += times[id(env.unwrapped)][1:]
    envs = gym.make_vec(
        env_id, n_worlds, vectorization_mode="vector_entry_point", nthread=0, **KWARGS
    )
    envs.reset(seed=0)
    with _timing_simulate(envs.envs[0].unwrapped) as times:
        for k in range(steps):
            envs.step(actions[k])
    # each world's periods up to where it ended alone (the vector env goes on after an autoreset)
    interleaved = [
        t for i, e in enumerate(envs.envs) for t in times[id(e.unwrapped)][1 : periods[i]]
    ]
    envs.close()
    return float(np.mean(alone)) * 1e6, float(np.mean(interleaved)) * 1e6


@contextmanager
def _timing_simulate(world: gym.Env) -> Iterator[dict[int, list[float]]]:
    """Times the `_simulate` calls of `world`'s class inside its steps [s], per world (``id``
    of the unwrapped env); the calls of a reset (its settling periods) are left out. Patched
    on the class: the batched env replaces each world's instance attributes for every step."""
    cls, times, resetting = type(world), defaultdict(list), set()
    simulate, reset = cls._simulate, cls.reset

    def timed_simulate(self):
        start = time.perf_counter()
        try:
            return simulate(self)
        finally:
            if id(self) not in resetting:
                times[id(self)].append(time.perf_counter() - start)

    def marked_reset(self, *args, **kwargs):
        resetting.add(id(self))
        try:
            return reset(self, *args, **kwargs)
        finally:
            resetting.discard(id(self))

    with _patched(cls, "_simulate", timed_simulate), _patched(cls, "reset", marked_reset):
        yield times


@contextmanager
def _patched(cls: type, name: str, replacement: Callable) -> Iterator[None]:
    """`cls.<name>` replaced for the block, then restored as it was (own or inherited)."""
    own, original = name in vars(cls), getattr(cls, name)
    setattr(cls, name, replacement)
    try:
        yield
    finally:
        if own:
            setattr(cls, name, original)
        else:
            delattr(cls, name)


class Setup(NamedTuple):
    """What the env rows compare: the batched env's physics threads and sizes, and the number of
    SubprocVecEnv workers (the issue's 2-core rows: 2 threads, 8 and 16 worlds, 2 workers)."""

    threads: int = 2
    worlds: tuple[int, ...] = (8, 16)
    subproc: int = 2

    def configs(self) -> dict[str, Callable[[str, float], Rate]]:
        """Configuration name -> its measurement (env id, seconds) -> Rate."""
        configs = {
            "single": single_rate,
            f"subproc {self.subproc}": lambda env_id, s: subproc_rate(env_id, s, self.subproc),
            f"batched {self.worlds[0]}, 0 threads": lambda env_id, s: batched_rate(
                env_id, s, self.worlds[0], nthread=0
            ),
        }
        for n in self.worlds:
            configs[f"batched {n}, {self.threads} threads"] = lambda env_id, s, n=n: batched_rate(
                env_id, s, n, self.threads
            )
        return configs


def env_rates(seconds: float, rounds: int, setup: Setup) -> dict[tuple[str, str], Rate]:
    """Per (env id, configuration), the configurations taken in turn `rounds` times: the best
    rate and the lowest CPU figures (the machine is shared: interference slows a run down and
    inflates its CPU time through the caches)."""
    best: dict[tuple[str, str], Rate] = {}
    for env_id in ENV_IDS:
        for r in range(rounds):
            for name, measure in setup.configs().items():
                got = measure(env_id, seconds)
                old = best.setdefault((env_id, name), got)
                best[(env_id, name)] = Rate(
                    max(old.rate, got.rate),
                    min(old.cpu_us, got.cpu_us),
                    min(old.main_us, got.main_us),
                )
            print(f"measured {env_id}, round {r + 1}", file=sys.stderr)
    return best


def ppo_rate(
    vectorization: str, n_envs: int, steps: int, rollout: int, threads: int = 2
) -> dict[str, float]:
    """PPO on configs/cliff_walk_ppo.yaml (HexapodCliffWalk-v1) as train.py runs it (its torch
    threads and device): env steps per second of `model.learn`, and its seconds split into env
    stepping, the rest of the rollouts and the updates. `threads`: the batched env's physics
    threads."""
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    config = load_train_config(ROOT / "configs" / "cliff_walk_ppo.yaml")
    torch.set_num_threads(config.train.num_threads)  # as train.py runs it
    spec = EnvSpec("HexapodCliffWalk-v1", dict(config.env.kwargs), gym_packages=["hexapod_envs"])
    if vectorization == "batched":
        venv = make_batched_vec_env(spec, n_envs, seed=0, nthread=threads)
    else:
        venv = make_vec_env(spec, n_envs, seed=0, subprocess=True)
    ppo = config.ppo.sb3_kwargs()
    ppo["n_steps"] = rollout // n_envs
    ppo["batch_size"] = min(ppo["batch_size"], rollout)
    norm = VecNormalize(venv, gamma=ppo["gamma"])
    model = PPO(
        "MlpPolicy",
        norm,
        policy_kwargs=config.policy.policy_kwargs(),
        seed=0,
        device=config.train.device,
        **ppo,
    )
    norm.reset()
    norm.step(np.zeros((n_envs, *venv.action_space.shape), dtype=np.float32))  # warm up
    seconds = {"env": 0.0, "update": 0.0, "rollout": 0.0}
    _time_calls(venv, "step_wait", seconds, "env")
    _time_calls(model, "train", seconds, "update")
    _time_calls(model, "collect_rollouts", seconds, "rollout")
    start = time.perf_counter()
    model.learn(steps)
    total = time.perf_counter() - start
    venv.close()
    return {
        "rate": model.num_timesteps / total,
        "env": seconds["env"],
        "policy": seconds["rollout"] - seconds["env"],
        "update": seconds["update"],
        "total": total,
    }


def _time_calls(obj, name: str, seconds: dict[str, float], key: str) -> None:
    method = getattr(obj, name)

    def timed(*args, **kwargs):
        start = time.perf_counter()
        try:
            return method(*args, **kwargs)
        finally:
            seconds[key] += time.perf_counter() - start

    setattr(obj, name, timed)


def print_env_rows(
    rates: dict[tuple[str, str], Rate],
    ceilings: dict[str, tuple[float, float]],
    interleaving: dict[str, tuple[float, float]],
    profile_steps: int,
    setup: Setup,
) -> list[tuple]:
    """The env table; returns the ratios the targets judge (batched / single, / subproc).

    "CPU" is this process's CPU per env step (all threads), "main" the calling thread's; the
    "free cores" bound is what those CPU figures allow when nothing else runs: 1 / CPU for
    the single env (one core), 1 / max(main, CPU / threads) with the physics threads (as many
    cores as threads, at most the usable ones)."""
    cores = len(os.sched_getaffinity(0))
    print(
        f"\n{'env (training tasks)':28s} {'configuration':22s} {'steps/s':>8s} {'/ single':>9s} "
        f"{'/ subproc':>10s} {'CPU µs':>7s} {'main µs':>8s} {'free cores':>11s} {'/ single':>9s}"
    )
    judged = []
    worlds = max(setup.worlds)
    for env_id in ENV_IDS:
        single = rates[(env_id, "single")]
        subproc = rates[(env_id, f"subproc {setup.subproc}")]
        single_bound = 1e6 / single.cpu_us
        for name in setup.configs():
            r = rates[(env_id, name)]
            threads = int(name.split(", ")[1].split()[0]) if ", " in name else 0
            bound = 1e6 / max(r.main_us, r.cpu_us / max(1, min(threads, cores)))
            if np.isnan(r.cpu_us):  # subprocess envs: their CPU is not this process's
                bound = float("nan")
            print(
                f"{env_id:28s} {name:22s} {r.rate:8.0f} {r.rate / single.rate:9.2f} "
                f"{r.rate / subproc.rate:10.2f} {r.cpu_us:7.0f} {r.main_us:8.0f} "
                f"{bound:11.0f} {bound / single_bound:9.2f}"
            )
            if name.startswith("batched") and threads > 0:
                judged.append((r.rate / single.rate, r.rate / subproc.rate))
        with gym.make(env_id, **KWARGS) as env:
            profile = step_profile(env, profile_steps)
        physics = profile.pop("simulate")
        python = sum(profile.values())
        print(
            f"  {env_id} step profile (single env): physics {physics:.0f} µs, the env's "
            f"Python {python:.0f} µs per step"
        )
        one, threaded = ceilings[env_id]
        scaling = one / threaded
        alone, interleaved = interleaving[env_id]
        print(
            f"  physics alone, {worlds} worlds in turn: {one:.0f} µs per world and control period"
            f" on 1 thread, {threaded:.0f} on {setup.threads} threads ({scaling:.2f} x)"
        )
        print(
            f"  the same trajectories' physics, each world alone {alone:.0f} µs a control period,"
            f" {worlds} worlds interleaved {interleaved:.0f} µs ({interleaved / alone:.2f} x); a "
            f"batched env whose Python cost nothing would reach "
            f"{1e6 / single.rate * scaling / interleaved:.2f} x one env (one env's step / the "
            f"interleaved physics split {scaling:.2f} ways), and {SINGLE_TARGET} x needs the "
            f"whole step of a world within "
            f"{setup.threads * 1e6 / single.rate / SINGLE_TARGET:.0f} µs of CPU with "
            f"{setup.threads} cores fully used"
        )
    return judged


def _positive(text: str) -> int:
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"takes an integer >= 1, got {text!r}")
    return int(text)


def _worlds(text: str) -> tuple[int, ...]:
    sizes = tuple(int(n) for n in text.split(","))
    if not sizes or min(sizes) < 1:
        raise argparse.ArgumentTypeError(f"--worlds takes sizes >= 1 like 8,16, got {text!r}")
    return sizes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=2.0, help="per env measurement")
    parser.add_argument("--rounds", type=int, default=2, help="env measurements per config")
    parser.add_argument("--profile-steps", type=int, default=1000)
    parser.add_argument("--interleave-steps", type=int, default=100, help="steps a world")
    parser.add_argument("--ppo-steps", type=int, default=8192, help="0: no PPO rows")
    parser.add_argument("--rollout", type=int, default=1024, help="PPO rollout, all envs")
    parser.add_argument(
        "--threads", type=_positive, default=2, help="the batched env's physics threads"
    )
    parser.add_argument("--worlds", type=_worlds, default=(8, 16), help="batched sizes, as 8,16")
    parser.add_argument("--subproc", type=_positive, default=2, help="SubprocVecEnv workers")
    args = parser.parse_args()
    setup = Setup(args.threads, args.worlds, args.subproc)

    rates = env_rates(args.seconds, args.rounds, setup)
    ceilings, interleaving = {}, {}
    for env_id in ENV_IDS:  # the lowest of the rounds (interference only slows a run down)
        runs = [
            physics_ceiling(env_id, args.seconds, max(setup.worlds), setup.threads)
            for _ in range(args.rounds)
        ]
        ceilings[env_id] = (min(one for one, _ in runs), min(two for _, two in runs))
        runs = [
            interleaving_cost(env_id, max(setup.worlds), args.interleave_steps)
            for _ in range(args.rounds)
        ]
        interleaving[env_id] = (min(one for one, _ in runs), min(many for _, many in runs))
    ppo = {}
    if args.ppo_steps > 0:
        ppo = {
            f"subproc {setup.subproc}": ppo_rate(
                "subproc", setup.subproc, args.ppo_steps, args.rollout
            ),
            "batched 2": ppo_rate("batched", 2, args.ppo_steps, args.rollout, setup.threads),
            "batched 8": ppo_rate("batched", 8, args.ppo_steps, args.rollout, setup.threads),
        }
    cores = len(os.sched_getaffinity(0))
    print(
        f"\n{cores} usable cores (shared); physics threads of the batched env: {setup.threads}; "
        f"best of {args.rounds} rounds of {args.seconds:g} s"
    )
    judged = print_env_rows(rates, ceilings, interleaving, args.profile_steps, setup)
    worst_single = min(s for s, _ in judged)
    worst_subproc = min(p for _, p in judged)
    targets = [
        f"batched >= {SINGLE_TARGET} x single (lowest {worst_single:.2f}): "
        f"{verdict(worst_single, SINGLE_TARGET)}",
        f">= {SUBPROC_TARGET} x subproc {setup.subproc} (lowest {worst_subproc:.2f}): "
        f"{verdict(worst_subproc, SUBPROC_TARGET)}",
    ]

    if ppo:
        print(
            f"\nPPO, configs/cliff_walk_ppo.yaml on HexapodCliffWalk-v1, {args.ppo_steps} steps,"
            f" rollout {args.rollout} steps over all envs"
        )
        print(
            f"{'vec env':12s} {'steps/s':>8s} {'/ subproc':>10s} {'env s':>7s} {'policy s':>9s} "
            f"{'update s':>9s}"
        )
        base = ppo[f"subproc {setup.subproc}"]["rate"]
        for name, row in ppo.items():
            print(
                f"{name:12s} {row['rate']:8.0f} {row['rate'] / base:10.2f} {row['env']:7.2f} "
                f"{row['policy']:9.2f} {row['update']:9.2f}"
            )
        ppo_best = max(ppo["batched 2"]["rate"], ppo["batched 8"]["rate"]) / base
        targets.append(
            f"PPO >= {SUBPROC_TARGET} x subproc {setup.subproc} (best {ppo_best:.2f}): "
            f"{verdict(ppo_best, SUBPROC_TARGET)}"
        )
    scope = "issue 46's targets" if setup == Setup() else "issue 46's 2-core targets, here"
    print(f"{scope}: " + "; ".join(targets))


if __name__ == "__main__":
    main()
