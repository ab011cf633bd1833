"""What a stride policy chooses where the clear-stride rule shortens the stride.

A learner of the ditch's stride action that does not beat its starting point (full strides) may
not have moved at all, or may have moved the wrong way. Along the clear-stride rule's own
crossings (`agents.upu_stride.ClearStridePolicy`), this script asks a policy for its stride
value at every decision, the rule driving, and compares the two: at the decisions where the
rule takes the full stride and at those where it shortens it (where a crossing is won or lost).

    python experiments/ditch_stride/policy_strides.py \\
        runs/study_ditch_crossing_v1_ppo_stride_landing/seed_0/best --seeds 100 101 102 103 104

One line per policy: how many of the rule's full-stride decisions the policy shortens, and at
the shortened ones the rule's mean value, the policy's mean value, their correlation and the
mean absolute difference (stride values: 0 the full 160 mm, -0.5 half of it). Findings:
README.md.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Iterable
from typing import NamedTuple

import gymnasium as gym
import numpy as np

from agents.ppo import PPOPolicy
from agents.upu_stride import ClearStridePolicy
from hexapod_envs.envs.ditch_crossing import STRIDE_ACTION

STRIDE_ENV = dict(
    task_distribution="train", stride_action=True, residual_limb_m=0.0, residual_leg_m=0.0
)
"""The stride learners' env (`configs/ditch_crossing_v1_ppo_stride_*.yaml`): the stride alone."""

FULL = -0.005
"""Stride values above this are the full stride (the rule's values are 0 or well below)."""


class Strides(NamedTuple):
    """A policy's stride values against the rule's at the rule's decisions."""

    full: np.ndarray
    """The policy's values where the rule takes the full stride."""
    rule_short: np.ndarray
    """The rule's values where it shortens the stride."""
    policy_short: np.ndarray
    """The policy's values at those decisions."""


def compare(policy: Callable[[np.ndarray], np.ndarray], env: gym.Env, seeds: Iterable[int]):
    """The policy's stride value (clipped to the full stride at 0) at each decision of the
    rule's episodes on training tasks `seeds`, the rule driving."""
    rule = ClearStridePolicy(env)
    full, rule_short, policy_short = [], [], []
    for seed in seeds:
        obs, _ = env.reset(seed=seed)
        done = False
        while not done:
            action = rule(obs)
            if env.unwrapped.stride_due:
                ours = float(np.clip(np.asarray(policy(obs))[STRIDE_ACTION], -1.0, 0.0))
                if action[STRIDE_ACTION] > FULL:
                    full.append(ours)
                else:
                    rule_short.append(float(action[STRIDE_ACTION]))
                    policy_short.append(ours)
            obs, _, terminated, truncated, _ = env.step(action)
            done = terminated or truncated
    return Strides(np.array(full), np.array(rule_short), np.array(policy_short))


def summary(strides: Strides) -> str:
    full, rule, ours = strides
    corr = np.corrcoef(rule, ours)[0, 1] if ours.std() > 0 and rule.std() > 0 else float("nan")
    return (
        f"rule full: {len(full)}, policy shortens {int((full <= FULL).sum())} | rule shortens: "
        f"{len(rule)}, rule mean {rule.mean():+.3f}, policy mean {ours.mean():+.3f}, "
        f"correlation {corr:+.2f}, mean |difference| {np.abs(rule - ours).mean():.3f}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("models", nargs="+", help="model files, model folders or run folders")
    ap.add_argument("--seeds", type=int, nargs="+", default=[100, 101, 102, 103, 104])
    args = ap.parse_args()
    env = gym.make("HexapodDitchCrossing-v1", **STRIDE_ENV)
    for model in args.models:
        print(model, "|", summary(compare(PPOPolicy.load(model, env), env, args.seeds)))


if __name__ == "__main__":
    main()
