"""The difficulty curriculum: tasks under the level, the level raised with success."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from hexapod_envs.curriculum import DifficultyCurriculum


def _env(**kwargs):
    return DifficultyCurriculum(
        gym.make("HexapodCliffWalk-v1", task_distribution="train"), **kwargs
    )


def test_resets_draw_tasks_under_the_level_reproducibly():
    env = _env(level=0.4)
    levels = []
    for seed in (0, None, None, None):
        _, info = env.reset(seed=seed)
        levels.append(info["task"]["difficulty"])
        assert info["curriculum_level"] == 0.4
    assert max(levels) <= 0.4
    again = _env(level=0.4)
    assert [again.reset(seed=s)[1]["task"]["difficulty"] for s in (0, None, None, None)] == levels
    plain = gym.make("HexapodCliffWalk-v1", task_distribution="train")
    spread = [plain.reset(seed=s)[1]["task"]["difficulty"] for s in range(20)]
    assert max(spread) > 0.4  # without it the same env draws harder tasks


def test_the_level_rises_after_a_successful_window_and_falls_after_a_failing_one():
    env = _env(level=0.3, step=0.1, window=2, promote_at=1.0, demote_at=0.5)
    for success in (True, True):
        env._record(success)
    assert env.level == pytest.approx(0.4)
    for success in (False, False):
        env._record(success)
    assert env.level == pytest.approx(0.3)
    env.reset(seed=1)
    _, _, _, _, info = env.step(np.zeros(18, dtype=np.float32))
    assert info["curriculum_level"] == pytest.approx(0.3)


def test_bad_settings_are_named():
    with pytest.raises(ValueError, match="level"):
        _env(level=1.5)
    with pytest.raises(ValueError, match="demote_at < promote_at"):
        _env(promote_at=0.2, demote_at=0.5)
    with pytest.raises(ValueError, match='task_distribution="train"'):
        DifficultyCurriculum(gym.make("HexapodCliffWalk-v1"))
