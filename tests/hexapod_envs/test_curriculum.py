"""The difficulty curriculum (tasks under the level, the level raised with success) and the
minimum difficulty (the hard part of a distribution)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from hexapod_envs.curriculum import DifficultyCurriculum, MinimumDifficulty


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


def test_a_reset_that_finds_no_task_under_the_level_says_so_once():
    """The ranges may hold few tasks that easy: after max_draws the last task is kept, flagged
    in info and warned about once."""
    env = _env(level=0.0, max_draws=2)
    with pytest.warns(UserWarning, match=r"none of 2 tasks drawn had a difficulty <= 0;"):
        _, info = env.reset(seed=0)
    assert info["task_draws"] == 2 and info["task_accepted"] is False
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _, info = env.reset()
    assert info["task_accepted"] is False
    _, info = _env(level=1.0).reset(seed=0)
    assert info["task_draws"] == 1 and info["task_accepted"] is True


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


def test_a_minimum_difficulty_keeps_the_hard_tasks_reproducibly():
    def hard():
        return MinimumDifficulty(gym.make("HexapodCliffWalk-v1", task_distribution="train"), 0.6)

    env = hard()
    infos = [env.reset(seed=s)[1] for s in (3, None, None, None)]
    assert min(i["task"]["difficulty"] for i in infos) >= 0.6
    assert max(i["task_draws"] for i in infos) > 1  # easier tasks were drawn and passed over
    again = hard()
    assert [again.reset(seed=s)[1]["task"] for s in (3, None, None, None)] == [
        i["task"] for i in infos
    ]
    with pytest.raises(ValueError, match=r"minimum must be a finite number .*got 1.5"):
        MinimumDifficulty(gym.make("HexapodCliffWalk-v1", task_distribution="train"), 1.5)
    with pytest.raises(ValueError, match="MinimumDifficulty draws sampled tasks"):
        MinimumDifficulty(gym.make("HexapodCliffWalk-v1"), 0.5)


def test_the_training_config_builds_it_and_names_a_bad_value():
    from agents.pipeline.envs import EnvSpec
    from agents.run_files.errors import UserError

    kwargs = {"task_distribution": "train"}
    spec = EnvSpec("HexapodCliffWalk-v1", kwargs, min_task_difficulty=0.6)
    assert spec.make().reset(seed=0)[1]["task"]["difficulty"] >= 0.6
    with pytest.raises(UserError, match="env.min_task_difficulty on HexapodCliffWalk-v1"):
        EnvSpec("HexapodCliffWalk-v1", kwargs, min_task_difficulty=-1).make()
