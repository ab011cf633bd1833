"""Does the ditch env's stride action hold a crossing? Simple stride rules played through it.

`HexapodDitchCrossing-v1(stride_action=True)` builds the reference gait one platform step at a
time: the action's 10th value sets each step's stride as it begins and the legs land at the
ground under each foot (docs/results.md, "Pure PPO on the ditch crossing"). Before pure PPO is
asked to learn a stride policy, this study checks which simple rules succeed through that
action (the nine residuals stay 0):

- ``full``: every stride full (the zero action): the flat gait, landing in the ditch;
- ``random``: a uniform random stride value at every step (exploration's lower bound);
- ``planner``: the strides of the paper's planner (`plan_ditch_crossing`) for the task's ditch;
- ``greedy``: from the observation alone (``ditch_ahead``, ``stride_decision``): the longest
  stride that lands every moving foot at least the planner's band (foot radius + edge
  clearance) from both edges, else the one that lands them farthest from an edge
  (`agents.upu_stride.ClearStridePolicy`).

    python experiments/ditch_stride/rules.py [--distribution train] [--tasks 10] [--rules greedy]
        [--values 0 -0.2 -0.4 -0.6 -0.8]   # greedy among these stride values only

Prints one line per rule and task distribution (successes, tip-overs, CoG advance) and the
per-task outcomes. Findings: README.md.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
import hexapod_envs  # noqa: E402,F401
from agents.upu_stride import ClearStridePolicy, stride_value  # noqa: E402
from experiments import rule_studies  # noqa: E402
from hexapod_envs.checks import count_argument  # noqa: E402
from hexapod_envs.robots.upu.gait_plan import plan_ditch_crossing  # noqa: E402

ENV_ID = "HexapodDitchCrossing-v1"
RULES = ("full", "random", "planner", "greedy")


class StrideRule(ClearStridePolicy):
    """A policy of the stride action: residuals 0, the stride value of `rule` (``greedy``: the
    clear-stride rule it extends)."""

    def __init__(self, env: gym.Env, rule: str, seed: int = 0, values=None):
        super().__init__(env, values)
        self.rule = rule
        self.rng = np.random.default_rng(seed)
        self.plan = None

    def reset(self) -> None:
        self.plan = None

    def stride(self, ahead: np.ndarray, upper_next: bool) -> float:
        gait = self.env.online_gait
        if self.rule == "full":
            return 0.0
        if self.rule == "random":
            return float(self.rng.uniform(-1.0, 1.0))
        if self.rule == "planner":
            if self.plan is None:
                self.plan = plan_ditch_crossing(
                    self.env.params, self.env.ditch, self.env.start_x, self.env.gait_settings
                )
            k = len(gait.steps)
            if not self.plan.ok or k >= len(self.plan.steps):
                return 0.0
            return stride_value(self.plan.steps[k].stride, gait.max_stride)
        return super().stride(ahead, upper_next)


def run(rule: str, distribution: str, tasks: int, values=None) -> list[dict]:
    env = gym.make(ENV_ID, stride_action=True, task_distribution=distribution)
    policy = StrideRule(env, rule, values=values)

    def row(seed: int, info: dict) -> dict:
        return {
            "seed": seed,
            "success": bool(info["is_success"]),
            "tipped": bool(info["is_tipped_over"]),
            "distance": float(info["distance"]),
            "max_tilt": float(info["max_tilt_deg"]),
            "ditch": info["ditch"],
        }

    return rule_studies.play(env, policy, range(tasks), row)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--distribution", choices=("train", "test"), default="train")
    ap.add_argument("--tasks", type=count_argument(), default=10)
    ap.add_argument("--rules", nargs="+", choices=RULES, default=list(RULES))
    ap.add_argument(
        "--values",
        nargs="+",
        type=float,
        help="greedy only: the stride values it chooses among (default: every stride on the "
        "planner's 5 mm grid), e.g. a categorical learner's env.stride_choices",
    )
    args = ap.parse_args()
    if args.values is not None and args.rules != ["greedy"]:
        ap.error("--values applies to the greedy rule only: add --rules greedy")
    for rule in args.rules:
        rows = run(rule, args.distribution, args.tasks, args.values)
        wins = sum(r["success"] for r in rows)
        tips = sum(r["tipped"] for r in rows)
        print(
            f"{rule:8s} {args.distribution}: {wins}/{len(rows)} crossed, {tips} tip-overs; "
            + " ".join(
                f"{r['seed']}:{'S' if r['success'] else 'T' if r['tipped'] else '-'}"
                f"({r['distance']:.2f} m, {r['max_tilt']:.1f} deg)"
                for r in rows
            ),
            flush=True,
        )


if __name__ == "__main__":
    main()
