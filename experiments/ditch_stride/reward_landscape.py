"""What one stride earns: the learner's reward of a platform step against its stride value.

A PPO learner of the ditch's stride action, one decision per platform step (``env.decision:
gait_cycle``), sees each decision's reward: the summed rewards of that platform step's ~51
control steps in its training config's env (reward terms excluded, stability penalty, foothold
term). Along the clear-stride rule's own crossing (`agents.upu_stride.ClearStridePolicy`), this
script replays every decision from a copy of the env with each stride value of a grid and prints
the platform step's reward for each: the landscape a Gaussian policy's gradient climbs.

    python experiments/ditch_stride/reward_landscape.py \\
        --config configs/ditch_crossing_v1_ppo_stride_foothold.yaml --seeds 100 101 104

One line per decision: the task seed, the decision's index, the rule's stride value and reward,
then the reward of each grid value (0 = the full stride). Findings: README.md.
"""

from __future__ import annotations

import argparse
import copy

import numpy as np

from agents.pipeline.training import env_spec
from agents.run_files.train_config import load_train_config
from agents.upu_stride import ClearStridePolicy
from hexapod_envs.envs.ditch_crossing import STRIDE_ACTION
from hexapod_envs.wrappers import GainsPerCycle

GRID = (0.0, -0.1, -0.2, -0.3, -0.4, -0.5, -0.6, -0.7)
"""Stride values tried at each decision: the full stride (160 mm) down to 30 % of it."""


def platform_step_reward(env: GainsPerCycle, stride_value: float) -> float:
    """The learner's reward of the next platform step with `stride_value`, played on a copy of
    `env` (at a decision); `env` itself does not move."""
    twin = copy.deepcopy(env)
    action = np.zeros(twin.action_space.shape, dtype=twin.action_space.dtype)
    action[STRIDE_ACTION] = stride_value
    reward = twin.step(action)[1]
    twin.close()
    return float(reward)


def landscape(config: str, seed: int) -> list[tuple[int, float, float, list[float]]]:
    """Per decision of the rule's episode on training task `seed`: (index, the rule's stride
    value, its reward, the rewards of `GRID`)."""
    spec = env_spec(load_train_config(config))
    spec.privileged_critic = False  # the rule reads the sensor observation
    env = spec.make()
    if not isinstance(env, GainsPerCycle):
        raise SystemExit(f"{config}: needs env.decision: gait_cycle on the stride action")
    rule = ClearStridePolicy(env)
    obs, _ = env.reset(seed=seed)
    rows = []
    while True:
        grid = [platform_step_reward(env, value) for value in GRID]
        action = rule(obs)
        obs, reward, terminated, truncated, _ = env.step(action)
        rows.append((len(rows), float(action[STRIDE_ACTION]), float(reward), grid))
        if terminated or truncated:
            env.close()
            return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", default="configs/ditch_crossing_v1_ppo_stride_foothold.yaml")
    ap.add_argument("--seeds", type=int, nargs="+", default=[100, 101, 104])
    args = ap.parse_args()
    print("seed decision | rule: value reward | reward at " + " ".join(f"{v:+.1f}" for v in GRID))
    for seed in args.seeds:
        for index, value, reward, grid in landscape(args.config, seed):
            cells = " ".join(f"{r:7.1f}" for r in grid)
            print(f"{seed:4d} {index:3d} | {value:+.2f} {reward:7.1f} | {cells}")


if __name__ == "__main__":
    main()
