"""The cloning study's machinery on a few steps (not its findings)."""

import gymnasium as gym
import numpy as np

import hexapod_envs  # noqa: F401  (registers the ids)
from agents.registry import analytical_factory
from experiments.behaviour_cloning.clone import Clone, episode, with_ditch_and_time


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


def test_the_task_inputs_are_the_ditch_ahead_of_the_cog_and_the_time():
    env = gym.make("HexapodDitchCrossing-v1", task_distribution="train", max_episode_steps=5)
    expert = analytical_factory("HexapodDitchCrossing-v1")(env)
    pairs = []
    info = episode(env, expert, 0, None, pairs, with_ditch_and_time, noise=0.5)
    x = np.array([p[0] for p in pairs])
    n_obs = env.observation_space.shape[0]
    assert x.shape == (5, n_obs + 4)
    ditch = info["ditch"]
    assert np.allclose(x[:, n_obs + 1] - x[:, n_obs], ditch["width"])  # far edge - near edge
    assert np.all(x[:, n_obs + 2] == ditch["depth"])
    np.testing.assert_allclose(x[:, -1] * 150.0, 0.1 * np.arange(5))  # the episode time [s]
    assert 0.0 < x[0, n_obs] < 1.0  # the near edge ahead of the CoG, as the task draws it
