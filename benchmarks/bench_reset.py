"""Reset cost of every env id and task distribution: what a learner waits for between episodes.

Each row is `resets` calls of ``env.reset(seed=s)`` on fresh seeds (after one warm-up reset that
builds the model and compiles the kernels), timed one by one: median and worst [ms]. The issue's
target is no reset over 20 ms.

    python benchmarks/bench_reset.py                 # every id, 20 resets per row
    python benchmarks/bench_reset.py --resets 50 --envs HexapodDitchCrossing-v0
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np

import hexapod_envs  # noqa: F401

TARGET_MS = 20.0
"""Issue 46's bound on one reset [ms]."""


def reset_times_ms(env_id: str, distribution: str, resets: int) -> np.ndarray:
    """Wall time of each of `resets` resets on seeds 1.. (seed 0 warms up) [ms]."""
    env = gym.make(env_id, task_distribution=distribution)
    env.reset(seed=0)
    times = []
    for seed in range(1, resets + 1):
        t0 = time.perf_counter()
        env.reset(seed=seed)
        times.append(1e3 * (time.perf_counter() - t0))
    env.close()
    return np.array(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resets", type=int, default=20)
    ids = sorted(k for k in gym.registry if k.startswith("Hexapod"))
    parser.add_argument("--envs", nargs="*", default=ids, choices=ids)
    args = parser.parse_args()
    print("| env id | distribution | median [ms] | worst [ms] | <= 20 ms |")
    print("|---|---|---|---|---|")
    for env_id in args.envs:
        for distribution in ("paper", "train", "test"):
            t = reset_times_ms(env_id, distribution, args.resets)
            ok = "met" if t.max() <= TARGET_MS else "missed"
            print(
                f"| {env_id} | {distribution} | {np.median(t):.1f} | {t.max():.1f} | {ok} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
