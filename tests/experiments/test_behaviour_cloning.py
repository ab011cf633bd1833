"""The cloning study's machinery on a few steps (not its findings)."""

import gymnasium as gym
import numpy as np

import hexapod_envs  # noqa: F401  (registers the ids)
from agents.registry import analytical_factory
from experiments.behaviour_cloning.clone import Clone, episode


def test_pairs_are_the_controllers_labels_and_the_clone_fits_them():
    env = gym.make("HexapodStewartTilt-v1", task_distribution="train", max_episode_steps=30)
    expert = analytical_factory("HexapodStewartTilt-v1")(env)
    pairs = []
    episode(env, expert, 0, None, pairs)
    assert len(pairs) == 30
    x, y = (np.array(v) for v in zip(*pairs, strict=True))
    assert x.shape == (30, env.observation_space.shape[0]) and np.abs(y).max() <= 1.0
    clone = Clone(x.shape[1], y.shape[1], seed=0)
    first = clone.fit(x, y, epochs=1, noise=0.0)
    assert clone.fit(x, y, epochs=200, noise=0.0) < first
    labelled = []
    episode(env, expert, 0, clone, labelled)  # the clone drives, the controller labels
    assert 0 < len(labelled) <= 30 and np.all(np.abs(clone(x[0])) <= 1.0)
