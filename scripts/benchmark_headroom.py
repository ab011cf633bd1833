"""Print the v1 benchmark's headroom table: analytical, zero, random and the best constant
action on the benchmark's test tasks of every ``-v1`` env (docs/benchmark.md states the targets),
and each env's mean task difficulty on train and test.

    python scripts/benchmark_headroom.py              # 50 test tasks per env (a few minutes)
    python scripts/benchmark_headroom.py --tasks 10 --env HexapodCliffWalk-v1
"""

from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np

import hexapod_envs
from agents.pipeline.headroom import format_table, headroom
from hexapod_envs.benchmark import BENCHMARK_SEEDS, V1_KWARGS
from hexapod_envs.checks import count_argument


def mean_difficulty(env_id: str, distribution: str, n: int) -> float:
    """Mean ``info["task"]["difficulty"]`` over `n` resets (no stepping)."""
    env = gym.make(env_id, task_distribution=distribution)
    values = [env.reset(seed=s)[1]["task"]["difficulty"] for s in range(n)]
    env.close()
    return float(np.mean(values))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--tasks",
        type=count_argument(1, len(BENCHMARK_SEEDS)),
        default=len(BENCHMARK_SEEDS),
        help=f"the first N benchmark test tasks (1-{len(BENCHMARK_SEEDS)})",
    )
    parser.add_argument("--env", action="append", choices=sorted(V1_KWARGS))
    args = parser.parse_args()
    print(f"hexapod_envs {hexapod_envs.__version__}")
    for env_id in args.env or sorted(V1_KWARGS):
        rows = headroom(env_id, list(BENCHMARK_SEEDS)[: args.tasks])
        print(format_table(env_id, rows))
        train, test = (mean_difficulty(env_id, d, 200) for d in ("train", "test"))
        print(f"\nmean difficulty over 200 resets: train {train:.3f}, test {test:.3f}\n")


if __name__ == "__main__":
    main()
