"""Reset cost of every env id and task distribution: what a learner waits for between episodes.

Each row is `resets` calls of ``env.reset(seed=s)`` on fresh seeds (after one warm-up reset that
builds the model and compiles the kernels), timed one by one: median and worst wall time [ms], and
the median and worst CPU time of the process [ms], which a loaded machine inflates far less (a
reset runs on one thread). The verdict against the target (no reset over 20 ms) reads the worst
CPU time; the wall times are the ones to quote from an idle machine (the load is printed first).

    python benchmarks/bench_reset.py                 # every id, 20 resets per row
    python benchmarks/bench_reset.py --resets 50 --envs HexapodDitchCrossing-v0
"""

from __future__ import annotations

import argparse
import os
import time

import gymnasium as gym
import numpy as np

import hexapod_envs  # noqa: F401
from hexapod_envs.checks import count_argument

TARGET_MS = 20.0
"""The bound on one reset [ms] (times in the table are in ms)."""


def reset_times_ms(env_id: str, distribution: str, resets: int) -> tuple[np.ndarray, np.ndarray]:
    """Wall and CPU time of each of `resets` resets on seeds 1.. (seed 0 warms up) [ms]."""
    env = gym.make(env_id, task_distribution=distribution)
    env.reset(seed=0)
    wall, cpu = [], []
    for seed in range(1, resets + 1):
        t0, c0 = time.perf_counter(), time.process_time()
        env.reset(seed=seed)
        wall.append(1e3 * (time.perf_counter() - t0))
        cpu.append(1e3 * (time.process_time() - c0))
    env.close()
    return np.array(wall), np.array(cpu)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resets", type=count_argument(), default=20)
    ids = sorted(k for k in gym.registry if k.startswith("Hexapod"))
    parser.add_argument("--envs", nargs="*", default=ids, choices=ids)
    args = parser.parse_args()
    print(f"load average (1, 5, 15 min): {os.getloadavg()}, {os.cpu_count()} cores")
    print(
        "| env id | distribution | wall median | wall worst | CPU median | CPU worst | <= 20 ms |"
    )
    print("|---|---|---|---|---|---|---|")
    for env_id in args.envs:
        for distribution in ("paper", "train", "test"):
            t, cpu = reset_times_ms(env_id, distribution, args.resets)
            ok = "met" if cpu.max() <= TARGET_MS else "missed"
            print(
                f"| {env_id} | {distribution} | {np.median(t):.1f} | {t.max():.1f} "
                f"| {np.median(cpu):.1f} | {cpu.max():.1f} | {ok} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
