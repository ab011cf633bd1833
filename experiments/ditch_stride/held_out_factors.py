"""Which of the test ditches' held-out factors breaks a learnt stride policy?

The benchmark's test ditches lie beyond the training ranges in four factors at once (wider,
deeper, farther ahead, more slippery: `DITCH_TEST` against `DITCH_TRAIN`). This script plays a
trained stride model and full strides (its step 0, the zero action of the stride action) on the
training ranges with one factor at a time taken from the test ranges, on the same tasks for
both, and prints successes and tip-overs per factor ("none": the training ranges).

    python experiments/ditch_stride/held_out_factors.py \\
        runs/study_ditch_crossing_v1_ppo_stride_choices/seed_2/best --tasks 50

Findings: reports/study_ditch_crossing_v1_ppo_stride_choices/README.md.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
import hexapod_envs  # noqa: E402,F401
from agents.ppo import PPOPolicy  # noqa: E402
from agents.run_files.artifacts import find_model  # noqa: E402
from experiments.rule_studies import play_episode  # noqa: E402
from hexapod_envs.checks import count_argument  # noqa: E402
from hexapod_envs.envs.ditch_crossing import DITCH_TEST, DITCH_TRAIN  # noqa: E402

FACTORS = ("none", "width", "depth", "start_x", "friction")
FIRST_SEED = 1000
"""The tasks: training-distribution seeds from here (apart from the runs' evaluation seeds)."""


def ranges_with(factor: str) -> dict[str, tuple[float, float]]:
    """The training ranges with `factor`'s range from the test ranges ("none": unchanged)."""
    ranges = {f: getattr(DITCH_TRAIN, f) for f in FACTORS[1:]}
    if factor != "none":
        ranges[factor] = getattr(DITCH_TEST, factor)
    return ranges


def play(env: gym.Env, policy, seeds) -> tuple[int, int]:
    """(successes, tip-overs) of `policy` on the tasks of `seeds`."""
    infos = [play_episode(env, policy, seed) for seed in seeds]
    return sum(i["is_success"] for i in infos), sum(i["is_tipped_over"] for i in infos)


class FullStrides:
    """Every stride full, residuals 0: the zero action of the stride action."""

    def reset(self) -> None:
        pass

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        return np.zeros(10, dtype=np.float32)


def factor_rows(model: str, factors, tasks: int) -> list[dict]:
    """One row per factor: the model's and full strides' successes and tip-overs."""
    kwargs = dict((find_model(model).training_config() or {})["env"]["kwargs"])
    kwargs.pop("landing_weight", None)  # a shaping term: the outcomes do not depend on it
    seeds = range(FIRST_SEED, FIRST_SEED + tasks)
    rows = []
    for factor in factors:
        env = gym.make(
            "HexapodDitchCrossing-v1",
            **{**kwargs, "task_distribution": "train", "train_ranges": ranges_with(factor)},
        )
        policy = PPOPolicy.load(model, env)
        rows.append(
            {
                "factor": factor,
                "policy": play(env, policy, seeds),
                "full": play(env, FullStrides(), seeds),
            }
        )
        env.close()
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("model", help="a trained stride model (model, run or best/ directory)")
    ap.add_argument("--tasks", type=count_argument(), default=50)
    ap.add_argument("--factors", nargs="+", choices=FACTORS, default=list(FACTORS))
    args = ap.parse_args()
    for row in factor_rows(args.model, args.factors, args.tasks):
        (pw, pt), (fw, ft) = row["policy"], row["full"]
        print(
            f"{row['factor']:8s} policy {pw}/{args.tasks} crossed ({pt} tip-overs), "
            f"full strides {fw}/{args.tasks} ({ft})",
            flush=True,
        )


if __name__ == "__main__":
    main()
