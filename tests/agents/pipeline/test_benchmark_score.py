"""Normalised benchmark scores (0 = random actions, 100 = the analytical controller) and their
IQM across envs."""

from __future__ import annotations

import numpy as np
import pytest

from agents.pipeline.benchmark_score import (
    env_scale,
    env_scores,
    iqm_intervals,
    normalised,
    score_matrices,
)


def test_the_scale_runs_from_random_to_analytical():
    assert env_scale({"random": 0.1, "analytical": 0.6}) == (0.1, 0.6)
    assert normalised(0.6, (0.1, 0.6)) == 100.0
    assert normalised(0.1, (0.1, 0.6)) == 0.0
    assert normalised(0.85, (0.1, 0.6)) == pytest.approx(150.0)
    # no scale: a reference missing, or the controller no better than random actions
    assert env_scale({"analytical": 0.5}) is None
    assert env_scale({"random": 0.5, "analytical": 0.5}) is None


def test_score_matrices_leave_out_envs_without_a_scale():
    successes = {
        "A": {"random": [0, 0, 0, 0], "analytical": [1, 1, 0, 0], "ppo": [1, 1, 1, 0]},
        "B": {"random": [1, 1, 0, 0], "analytical": [1, 0, 0, 0], "ppo": [0, 0, 0, 0]},
    }
    matrices, envs = score_matrices(successes)
    assert envs == ["A"]
    assert matrices["ppo"].shape == (4, 1)
    assert matrices["ppo"].mean() == pytest.approx(150.0)  # 3/4 against 2/4 above 0
    assert matrices["analytical"].mean() == pytest.approx(100.0)


def test_env_scores_keep_a_policy_that_ran_on_some_envs_only():
    """A learned agent shipped for some envs gets its score there, though no IQM."""
    successes = {
        "A": {"analytical": [1, 1], "random": [0, 0], "knobs": [1, 0]},
        "B": {"analytical": [1, 0], "random": [0, 0]},
        "C": {"analytical": [0, 0], "random": [0, 0], "knobs": [1, 1]},  # no scale
    }
    scores = env_scores(successes)
    assert scores["knobs"] == {"A": 50.0}
    assert scores["analytical"] == {"A": 100.0, "B": 100.0}
    assert "knobs" not in score_matrices(successes)[0]


def test_the_iqm_of_per_env_scores_with_an_interval_that_holds_it():
    successes = {
        env: {
            "random": [0] * 8,
            "analytical": [1] * 4 + [0] * 4,
            "ppo": [1] * k + [0] * (8 - k),
        }
        for env, k in (("A", 2), ("B", 4), ("C", 6), ("D", 8))
    }
    matrices, envs = score_matrices(successes)
    intervals = iqm_intervals(matrices, reps=300)
    iqm, low, high = intervals["ppo"]
    # per-env scores 50, 100, 150, 200: the IQM is the mean of the middle two
    assert iqm == pytest.approx(125.0)
    assert low <= iqm <= high and high - low > 0
    assert intervals["analytical"][:1] == (100.0,)
    assert intervals["random"] == (0.0, 0.0, 0.0)
    assert np.isfinite(list(intervals["ppo"])).all()
