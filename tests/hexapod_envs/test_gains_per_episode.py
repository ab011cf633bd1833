"""GainsPerEpisode and ``env.decision: episode``: one learner step per episode of the gains mode,
the action held throughout, and the trained model run per step with its first action held."""

import gymnasium as gym
import numpy as np
import pytest
from helpers.paths import REPO

import hexapod_envs  # noqa: F401  (registers the env ids)
from hexapod_envs.wrappers import GainsPerEpisode, episode_reward, margin_scale, tilt_bound

ENV_ID = "HexapodIrregularTerrain-v1"
GAINS = {
    "action_mode": "gains",
    "task_distribution": "train",
    "gains_height_offset_m": 0.04,
    "max_episode_steps": 80,
}
ACTION = np.array([0.7, 0.5, 0.3, 0.5], dtype=np.float32)


def test_one_step_plays_the_whole_episode_with_the_action_held():
    wrapped = GainsPerEpisode(gym.make(ENV_ID, **GAINS), reward="return")
    wrapped.reset(seed=3)
    obs, reward, terminated, truncated, info = wrapped.step(ACTION)
    plain = gym.make(ENV_ID, **GAINS)
    plain.reset(seed=3)
    total, steps = 0.0, 0
    while True:
        obs_p, r, term, trunc, info_p = plain.step(ACTION)
        total, steps = total + float(r), steps + 1
        if term or trunc:
            break
    np.testing.assert_array_equal(obs, obs_p)
    assert reward == total and (terminated, truncated) == (True, False)
    assert info["episode_steps"] == steps == 80 and info["episode_truncated"] is True
    assert info["is_success"] == info_p["is_success"]


def test_the_success_reward_is_the_episodes_outcome():
    env = GainsPerEpisode(gym.make(ENV_ID, **GAINS))
    env.reset(seed=3)
    _, reward, _, _, info = env.step(ACTION)
    assert reward == float(bool(info["is_success"])) and reward in (0.0, 1.0)


def test_stable_success_grades_a_success_by_how_far_its_tilt_stayed_from_the_bound():
    success = {"is_success": True, "max_tilt_deg": 0.5}
    assert episode_reward("stable_success", success, 7.0, 2.0) == 0.75
    assert episode_reward("stable_success", {**success, "max_tilt_deg": 0.0}, 7.0, 2.0) == 1.0
    assert episode_reward("stable_success", {**success, "max_tilt_deg": 3.0}, 7.0, 2.0) == 0.0
    assert episode_reward("stable_success", {**success, "is_success": False}, 7.0, 2.0) == 0.0
    assert episode_reward("success", success, 7.0) == 1.0
    assert episode_reward("return", success, 7.0) == 7.0
    with pytest.raises(ValueError, match="tilt bound"):
        episode_reward("stable_success", success, 7.0)


def test_margin_success_grades_a_success_by_its_smallest_static_margin():
    success = {"is_success": True, "min_static_margin_m": 0.02}
    assert episode_reward("margin_success", success, 7.0, margin_scale_m=0.1) == 1.2
    low = {**success, "min_static_margin_m": -0.01}
    assert episode_reward("margin_success", low, 7.0, margin_scale_m=0.1) == 1.0
    high = {**success, "min_static_margin_m": 0.3}
    assert episode_reward("margin_success", high, 7.0, margin_scale_m=0.1) == 2.0
    failure = {**success, "is_success": False}
    assert episode_reward("margin_success", failure, 7.0, margin_scale_m=0.1) == 0.0
    with pytest.raises(ValueError, match="margin scale"):
        episode_reward("margin_success", success, 7.0)


def test_margin_success_needs_an_env_judged_by_a_static_margin():
    assert margin_scale(gym.make("HexapodDitchCrossing-v1"), "margin_success") == 0.1
    assert margin_scale(gym.make(ENV_ID), "success") is None
    with pytest.raises(ValueError, match="HexapodIrregularTerrain-v1 has none"):
        margin_scale(gym.make(ENV_ID), "margin_success")


def test_stable_success_needs_an_env_whose_success_rule_bounds_the_tilt():
    assert tilt_bound(gym.make(ENV_ID), "stable_success") == 25.0  # the -v1 blocks' bound
    assert tilt_bound(gym.make("HexapodDitchCrossing-v1"), "stable_success") == 2.0
    assert tilt_bound(gym.make(ENV_ID), "success") is None
    with pytest.raises(ValueError, match="HexapodIrregularTerrain-v0 has none"):
        tilt_bound(gym.make("HexapodIrregularTerrain-v0"), "stable_success")
    with pytest.raises(
        ValueError, match=r"one of \('success', 'stable_success', 'margin_success', 'return'\)"
    ):
        tilt_bound(gym.make(ENV_ID), "stable")


def test_other_modes_and_rewards_are_refused_by_name():
    with pytest.raises(ValueError, match="GainsPerEpisode needs action_mode='gains'"):
        GainsPerEpisode(gym.make(ENV_ID))
    with pytest.raises(
        ValueError,
        match=r"reward must be one of \('success', 'stable_success', 'margin_success', 'return'\)",
    ):
        GainsPerEpisode(gym.make(ENV_ID, **GAINS), reward="returns")


def test_env_spec_decision_episode_builds_the_wrapper():
    from agents.pipeline.envs import EnvSpec
    from agents.run_files.errors import UserError

    spec = EnvSpec(ENV_ID, dict(GAINS), gym_packages=["hexapod_envs"], decision="episode")
    env = spec.make()
    assert isinstance(env, GainsPerEpisode) and env.reward == "success"
    with pytest.raises(UserError, match="decision='episode'.*action_mode='gains'"):
        EnvSpec(ENV_ID, gym_packages=["hexapod_envs"], decision="episode").make()


def test_a_config_asks_for_the_stable_success_reward_by_name():
    from agents.pipeline.envs import EnvSpec
    from agents.run_files.configtools import from_mapping
    from agents.run_files.errors import ConfigError, UserError
    from agents.run_files.train_config import EnvConfig

    section = {"id": ENV_ID, "decision": "episode", "episode_reward": "stable_success"}
    assert from_mapping(EnvConfig, section).episode_reward == "stable_success"
    with pytest.raises(ConfigError, match="stable_success"):  # the choices, named
        from_mapping(EnvConfig, {**section, "episode_reward": "steady"})
    spec = EnvSpec(
        ENV_ID,
        dict(GAINS),
        gym_packages=["hexapod_envs"],
        decision="episode",
        episode_reward="stable_success",
    )
    env = spec.make()
    env.reset(seed=3)
    _, reward, *_, info = env.step(ACTION)
    expected = 1.0 - info["max_tilt_deg"] / 25.0 if info["is_success"] else 0.0
    assert reward == pytest.approx(expected, rel=0, abs=1e-12)
    v0 = EnvSpec(
        "HexapodIrregularTerrain-v0",
        {"action_mode": "gains"},
        gym_packages=["hexapod_envs"],
        decision="episode",
        episode_reward="stable_success",
    )
    with pytest.raises(UserError, match="HexapodIrregularTerrain-v0 has none"):
        v0.make()


def test_a_held_policy_is_asked_once_per_episode():
    from agents.ppo import HeldPerEpisode

    class Counting:
        calls = resets = 0

        def reset(self):
            self.resets += 1

        def __call__(self, observation):
            self.calls += 1
            return np.full(4, self.calls, dtype=np.float32)

    learned = Counting()
    held = HeldPerEpisode(learned)
    assert [held(np.zeros(3))[0] for _ in range(3)] == [1.0, 1.0, 1.0]
    held.reset()
    assert held(np.ones(3))[0] == 2.0 and (learned.calls, learned.resets) == (2, 1)
    assert held.calls == 2  # the learned policy's attributes show through


def test_a_per_episode_run_trains_and_evaluates_per_episode_and_plays_its_first_action(tmp_path):
    """train.py with env.decision=episode: learner steps and evaluations count episodes (one step
    each), and the saved model, loaded for the plain env, holds the action it chose at the
    episode's first observation."""
    from agents.pipeline.cli import train_main
    from agents.pipeline.learning_curve import load_learning_curve
    from agents.ppo import PPOPolicy

    overrides = [
        "ppo.n_steps=4",
        "ppo.batch_size=4",
        "ppo.n_epochs=1",
        "policy.pi=[8]",
        "policy.vf=[8]",
        "policy.log_std_init=0.0",
        "train.total_timesteps=8",
        "env.max_episode_steps=30",
        "eval.freq=8",
        "eval.n_episodes=2",
        "checkpoint.freq=8",
        "hybrid.zero_init_action_net=false",  # a learned action that follows the observation
    ]
    config = REPO / "configs" / "irregular_terrain_v1_height.yaml"
    argv = ["--config", str(config), "--output-dir", str(tmp_path), "--run-name", "episodes"]
    assert train_main([*argv, *[a for o in overrides for a in ("--set", o)]]) == 0
    run = tmp_path / "episodes"
    with np.load(run / "evaluations.npz") as log:
        assert list(log["timesteps"]) == [0, 8]
        assert (log["ep_lengths"] == 1).all()
        assert set(np.unique(log["results"])) <= {0.0, 1.0}  # success rewards
    assert load_learning_curve(run).unit == "episodes"

    env = gym.make(
        ENV_ID,
        task_distribution="test",
        action_mode="gains",
        gait_ground_search="always",
        gains_height_offset_m=0.04,
    )
    policy = PPOPolicy.load(run / "final", env)
    obs, _ = env.reset(seed=0)
    policy.reset()
    first = policy(obs)
    model = policy.learned.learned  # HybridPolicy -> HeldPerEpisode -> the PPO model
    asked_first = model(obs)
    for _ in range(5):
        obs = env.step(first)[0]
        np.testing.assert_array_equal(policy(obs), first)
    assert not np.array_equal(model(obs), asked_first)  # unheld, it would have changed
    policy.reset()  # a new episode: asked again, on its own first observation
    obs, _ = env.reset(seed=1)
    assert policy(obs).shape == (4,)


def test_an_env_without_a_time_limit_is_refused():
    """Each step plays an episode to its end: without a time limit a robot that never falls
    would never return."""
    unlimited = gym.make(ENV_ID, **GAINS).unwrapped
    with pytest.raises(ValueError, match="the env needs a time limit"):
        GainsPerEpisode(gym.wrappers.OrderEnforcing(unlimited))
    GainsPerEpisode(gym.wrappers.TimeLimit(unlimited, 10))
