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
those allow on 2 free cores (1 / CPU for the single env; 1 / max(main, CPU / 2) with the
physics threads): the figure a loaded machine cannot show. Each env also gets its step profile
(`common.step_profile`: physics against the env's Python, µs per step) and the ceiling of any
batching on this machine: 16 worlds' physics alone (their `_simulate`, no other Python) on one
thread and on the 2 threads, the rate against one env that a batched env with no Python cost
would reach at that scaling (from the step profile: its physics and Python), and the CPU per
world step that the 1.8 x target allows with both cores fully used.

PPO rows: configs/cliff_walk_ppo.yaml on HexapodCliffWalk-v1 with the same rollout size
(`--rollout` steps over all envs) and `--ppo-steps` steps: SubprocVecEnv(2), the batched
DummyVecEnv adapter with 2 envs (``env.vectorization: batched``, the same config) and with 8
envs, each split into the time spent stepping the envs, the rest of the rollout (policy
inference, buffers) and the PPO update.

Run: python benchmarks/bench_vector_env.py [--seconds 2] [--rounds 2] [--ppo-steps 8192]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
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

ENV_IDS = ("HexapodCliffWalk-v1", "HexapodStewartTilt-v1", "HexapodIrregularTerrain-v1")
KWARGS = {"task_distribution": "train"}
THREADS = 2
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


def subproc_rate(env_id: str, seconds: float, n_envs: int = 2) -> Rate:
    spec = EnvSpec(env_id, dict(KWARGS), gym_packages=["hexapod_envs"])
    venv = make_vec_env(spec, n_envs, seed=0, subprocess=True)
    return _vec_rate(venv, n_envs, seconds, venv.action_space, local=False)


def batched_rate(env_id: str, seconds: float, n_envs: int, nthread: int = THREADS) -> Rate:
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


def physics_ceiling(env_id: str, seconds: float, n_worlds: int = 16) -> tuple[float, float]:
    """The batching's ceiling on this machine: µs of wall time per world and control period of
    the physics alone (each world's `_simulate`, no other Python), `n_worlds` worlds in turn on
    the calling thread, and split between `THREADS` threads. Each round restores every world to
    the state it had after 50 random-action steps, so both figures step the same states."""
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

    def periods(share: list) -> None:
        for world, state, spec, _ in share:
            mujoco.mj_setState(world.model, world.data, state, spec)
            world._simulate()

    def per_world(run: Callable[[], None]) -> float:
        rounds, start = 0, time.perf_counter()
        while (elapsed := time.perf_counter() - start) < seconds:
            run()
            rounds += 1
        return elapsed / (rounds * n_worlds) * 1e6

    with ThreadPoolExecutor(THREADS) as pool:
        shares = [worlds[k::THREADS] for k in range(THREADS)]
        threaded = per_world(lambda: list(pool.map(periods, shares)))
    one = per_world(lambda: periods(worlds))
    for *_, env in worlds:
        env.close()
    return one, threaded


CONFIGS = {
    "single": single_rate,
    f"subproc {THREADS}": subproc_rate,
    "batched 8, 0 threads": lambda env_id, s: batched_rate(env_id, s, 8, nthread=0),
    f"batched 8, {THREADS} threads": lambda env_id, s: batched_rate(env_id, s, 8),
    f"batched 16, {THREADS} threads": lambda env_id, s: batched_rate(env_id, s, 16),
}


def env_rates(seconds: float, rounds: int) -> dict[tuple[str, str], Rate]:
    """Per (env id, configuration), the configurations taken in turn `rounds` times: the best
    rate and the lowest CPU figures (the machine is shared: interference slows a run down and
    inflates its CPU time through the caches)."""
    best: dict[tuple[str, str], Rate] = {}
    for env_id in ENV_IDS:
        for r in range(rounds):
            for name, measure in CONFIGS.items():
                got = measure(env_id, seconds)
                old = best.setdefault((env_id, name), got)
                best[(env_id, name)] = Rate(
                    max(old.rate, got.rate),
                    min(old.cpu_us, got.cpu_us),
                    min(old.main_us, got.main_us),
                )
            print(f"measured {env_id}, round {r + 1}", file=sys.stderr)
    return best


def ppo_rate(vectorization: str, n_envs: int, steps: int, rollout: int) -> dict[str, float]:
    """PPO on configs/cliff_walk_ppo.yaml (HexapodCliffWalk-v1): env steps per second of
    `model.learn`, and its seconds split into env stepping, the rest of the rollouts and the
    updates."""
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    config = load_train_config(ROOT / "configs" / "cliff_walk_ppo.yaml")
    torch.set_num_threads(config.train.num_threads)  # as train.py runs it
    spec = EnvSpec("HexapodCliffWalk-v1", dict(config.env.kwargs), gym_packages=["hexapod_envs"])
    if vectorization == "batched":
        venv = make_batched_vec_env(spec, n_envs, seed=0, nthread=THREADS)
    else:
        venv = make_vec_env(spec, n_envs, seed=0, subprocess=True)
    ppo = config.ppo.sb3_kwargs()
    ppo["n_steps"] = rollout // n_envs
    ppo["batch_size"] = min(ppo["batch_size"], rollout)
    norm = VecNormalize(venv, gamma=ppo["gamma"])
    model = PPO("MlpPolicy", norm, policy_kwargs=config.policy.policy_kwargs(), seed=0, **ppo)
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
    profile_steps: int,
) -> list[tuple]:
    """The env table; returns the ratios the targets judge (batched / single, / subproc).

    "CPU" is this process's CPU per env step (all threads), "main" the calling thread's; the
    "2 free cores" bound is what those CPU figures allow when nothing else runs: 1 / CPU for
    the single env (one core), 1 / max(main, CPU / 2) with the physics threads."""
    print(
        f"\n{'env (training tasks)':28s} {'configuration':22s} {'steps/s':>8s} {'/ single':>9s} "
        f"{'/ subproc':>10s} {'CPU µs':>7s} {'main µs':>8s} {'2 free cores':>13s} {'/ single':>9s}"
    )
    judged = []
    for env_id in ENV_IDS:
        single, subproc = rates[(env_id, "single")], rates[(env_id, f"subproc {THREADS}")]
        single_bound = 1e6 / single.cpu_us
        for name in CONFIGS:
            r = rates[(env_id, name)]
            threads = int(name.split(", ")[1].split()[0]) if ", " in name else 0
            bound = 1e6 / max(r.main_us, r.cpu_us / max(1, min(threads, 2)))
            if np.isnan(r.cpu_us):  # subprocess envs: their CPU is not this process's
                bound = float("nan")
            print(
                f"{env_id:28s} {name:22s} {r.rate:8.0f} {r.rate / single.rate:9.2f} "
                f"{r.rate / subproc.rate:10.2f} {r.cpu_us:7.0f} {r.main_us:8.0f} "
                f"{bound:13.0f} {bound / single_bound:9.2f}"
            )
            if name.startswith("batched") and not name.endswith("0 threads"):
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
        print(
            f"  physics alone, 16 worlds in turn: {one:.0f} µs per world and control period on "
            f"1 thread, {threaded:.0f} on {THREADS} threads ({scaling:.2f} x); a batched env "
            f"whose Python cost nothing would reach {(physics + python) / physics * scaling:.2f}"
            f" x one env (the profiled step / its physics split {scaling:.2f} ways), and "
            f"{SINGLE_TARGET} x needs the whole step of a world within "
            f"{2e6 / single.rate / SINGLE_TARGET:.0f} µs of CPU with both cores fully used"
        )
    return judged


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=2.0, help="per env measurement")
    parser.add_argument("--rounds", type=int, default=2, help="env measurements per config")
    parser.add_argument("--profile-steps", type=int, default=1000)
    parser.add_argument("--ppo-steps", type=int, default=8192)
    parser.add_argument("--rollout", type=int, default=1024, help="PPO rollout, all envs")
    args = parser.parse_args()

    rates = env_rates(args.seconds, args.rounds)
    ceilings = {}
    for env_id in ENV_IDS:  # the lowest of the rounds (interference only slows a run down)
        runs = [physics_ceiling(env_id, args.seconds) for _ in range(args.rounds)]
        ceilings[env_id] = (min(one for one, _ in runs), min(two for _, two in runs))
    ppo = {
        f"subproc {THREADS}": ppo_rate("subproc", 2, args.ppo_steps, args.rollout),
        "batched 2": ppo_rate("batched", 2, args.ppo_steps, args.rollout),
        "batched 8": ppo_rate("batched", 8, args.ppo_steps, args.rollout),
    }
    cores = len(os.sched_getaffinity(0))
    print(
        f"\n{cores} usable cores (shared); physics threads of the batched env: {THREADS}; "
        f"best of {args.rounds} rounds of {args.seconds:g} s"
    )
    judged = print_env_rows(rates, ceilings, args.profile_steps)

    print(
        f"\nPPO, configs/cliff_walk_ppo.yaml on HexapodCliffWalk-v1, {args.ppo_steps} steps, "
        f"rollout {args.rollout} steps over all envs"
    )
    print(
        f"{'vec env':12s} {'steps/s':>8s} {'/ subproc':>10s} {'env s':>7s} {'policy s':>9s} "
        f"{'update s':>9s}"
    )
    base = ppo[f"subproc {THREADS}"]["rate"]
    for name, row in ppo.items():
        print(
            f"{name:12s} {row['rate']:8.0f} {row['rate'] / base:10.2f} {row['env']:7.2f} "
            f"{row['policy']:9.2f} {row['update']:9.2f}"
        )

    worst_single = min(s for s, _ in judged)
    worst_subproc = min(p for _, p in judged)
    ppo_best = max(ppo["batched 2"]["rate"], ppo["batched 8"]["rate"]) / base
    print(
        f"issue 46's targets: batched >= {SINGLE_TARGET} x single (lowest {worst_single:.2f}): "
        f"{verdict(worst_single, SINGLE_TARGET)}; >= {SUBPROC_TARGET} x subproc 2 (lowest "
        f"{worst_subproc:.2f}): {verdict(worst_subproc, SUBPROC_TARGET)}; PPO >= "
        f"{SUBPROC_TARGET} x subproc 2 (best {ppo_best:.2f}): "
        f"{verdict(ppo_best, SUBPROC_TARGET)}"
    )


if __name__ == "__main__":
    main()
