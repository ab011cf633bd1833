"""experiments/ditch_stride/reward_landscape.py: a platform step's reward against its stride."""

import numpy as np
import pytest
from helpers.paths import REPO

from agents.pipeline.training import env_spec
from agents.run_files.train_config import load_train_config
from experiments.ditch_stride.reward_landscape import GRID, platform_step_reward

CONFIG = REPO / "configs/ditch_crossing_v1_ppo_stride_foothold.yaml"


def test_a_replayed_stride_earns_what_the_learner_is_paid_and_leaves_the_env_alone():
    spec = env_spec(load_train_config(CONFIG))
    env = spec.make()
    env.reset(seed=101)
    before = env.unwrapped.data.qpos.copy()
    grid = [platform_step_reward(env, value) for value in GRID]
    np.testing.assert_array_equal(env.unwrapped.data.qpos, before)
    assert env.unwrapped.stride_due
    # Far from the ditch the longer stride walks farther in the same time: it earns more.
    assert grid == sorted(grid, reverse=True) and grid[0] > grid[-1] + 5.0
    action = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)
    action[-1] = GRID[3]
    _, reward, *_ = env.step(action)  # the learner's step: one platform step
    assert reward == pytest.approx(grid[3], rel=1e-12)
