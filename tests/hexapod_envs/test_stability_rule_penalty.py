"""StabilityRulePenalty and ``env.stability_penalty``: per-step penalties that mirror a -v1
success rule's bounds on the time spent tipping and the largest tilt."""

from types import SimpleNamespace

import gymnasium as gym
import numpy as np
import pytest
from helpers.paths import REPO

import hexapod_envs  # noqa: F401  (registers the env ids)
from agents.pipeline.training import env_spec
from agents.run_files.errors import ConfigError
from agents.run_files.train_config import load_train_config
from hexapod_envs.wrappers import StabilityRulePenalty

CONFIG = REPO / "configs" / "irregular_terrain_v1_ppo.yaml"


def test_the_terms_count_the_tipping_steps_and_the_reward_carries_them():
    # a 3 deg success bound (the env's is 25) that the zero action's 6 deg sag passes
    kwargs = {"task_distribution": "train", "max_episode_steps": 60, "success_max_tilt_deg": 3.0}
    wrapped = StabilityRulePenalty(gym.make("HexapodIrregularTerrain-v1", **kwargs), 2.5)
    plain = gym.make("HexapodIrregularTerrain-v1", **kwargs)
    wrapped.reset(seed=1000)
    plain.reset(seed=1000)
    tipping_steps = tilted_steps = 0
    for _ in range(60):
        _, reward, *_, info = wrapped.step(np.zeros(18))
        _, plain_reward, *_, plain_info = plain.step(np.zeros(18))
        tipping_steps += bool(plain_info["is_tipping"])
        assert info["reward_rule_tipping"] == -2.5 * bool(plain_info["is_tipping"])
        tilted_steps += plain_info["tilt_deg"] > 3.0
        assert info["reward_rule_tilt"] == -2.5 * (plain_info["tilt_deg"] > 3.0)
        assert info["reward_rule_early_landing"] == 0.0  # the rule has no swing phase here
        expected = plain_reward + info["reward_rule_tipping"] + info["reward_rule_tilt"]
        assert reward == pytest.approx(expected, abs=1e-9)
    assert wrapped.tilt_bound_deg == 3.0
    # the zero action sags onto the blocks: both terms are exercised
    assert tipping_steps > 0 and 0 < tilted_steps < 60


class _Scripted(gym.Env):
    """Steps through given (is_tipping, tilt_deg) pairs with reward 1."""

    observation_space = gym.spaces.Box(-1.0, 1.0, (1,))
    action_space = gym.spaces.Box(-1.0, 1.0, (1,))

    def __init__(self, states, tipping_share=0.1):
        self.states = list(states)
        self.settings = SimpleNamespace(
            success_max_tilt_deg=8.0, success_max_tipping_share=tipping_share
        )

    def reset(self, *, seed=None, options=None):
        return np.zeros(1, np.float32), {}

    def step(self, action):
        tipping, tilt = self.states.pop(0)
        info = {"is_tipping": tipping, "tilt_deg": tilt}
        return np.zeros(1, np.float32), 1.0, False, False, info


def test_the_tilt_term_pays_only_past_the_bound():
    env = StabilityRulePenalty(_Scripted([(False, 7.9), (False, 8.0), (True, 8.1), (True, 3.0)]), 1)
    env.reset()
    rewards = [env.step(np.zeros(1))[1] for _ in range(4)]
    assert rewards == [1.0, 1.0, -1.0, 0.0]


def test_tipping_costs_nothing_where_the_rule_does_not_bound_it():
    """The Stewart tilt's rule bounds the tilt but not the time below xi (every stance on the
    tilted platform is below it after the recovery): only the tilt term applies there."""
    env = StabilityRulePenalty(_Scripted([(True, 1.0), (True, 9.0)], tipping_share=None), 1.0)
    env.reset()
    assert [env.step(np.zeros(1))[1] for _ in range(2)] == [1.0, 0.0]
    stewart = StabilityRulePenalty(gym.make("HexapodStewartTilt-v1"), 1.0)
    assert not stewart.bounds_tipping and stewart.tilt_bound_deg == 2.5


def test_an_early_landing_costs_every_step_from_the_landing_where_the_rule_keeps_the_swing():
    """The Stewart tilt's rule keeps the lifted tripod up until the robot first tips: a policy
    standing on six feet from the start pays on every step from its landing."""
    kwargs = {"landing_action": True, "residual_scale": 0.05}
    wrapped = StabilityRulePenalty(gym.make("HexapodStewartTilt-v1", **kwargs), 3.0)
    assert wrapped.bounds_swing
    wrapped.reset(seed=0)
    action = np.r_[np.zeros(18), 1.0].astype(np.float32)
    terms = []
    for _ in range(100):
        info = wrapped.step(action)[4]
        terms.append(info["reward_rule_early_landing"])
        assert terms[-1] == -3.0 * info["early_landing"]
    assert terms[0] == 0.0 and terms[-1] == -3.0
    scripted = StabilityRulePenalty(_Scripted([(False, 0.0)]), 1.0)
    assert not scripted.bounds_swing


def test_bad_uses_are_named():
    with pytest.raises(ValueError, match="HexapodCliffWalk-v0 has no success tilt bound"):
        StabilityRulePenalty(gym.make("HexapodCliffWalk-v0"), 1.0)
    for weight in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="must be > 0"):
            StabilityRulePenalty(_Scripted([]), weight)


def test_the_training_config_wraps_the_env_and_checks_the_weight():
    config = load_train_config(CONFIG, ["env.max_episode_steps=5"])
    assert config.env.stability_penalty == 2.0
    env = env_spec(config).make()
    wrappers = []
    while isinstance(env, gym.Wrapper):
        wrappers.append(type(env).__name__)
        env = env.env
    assert "StabilityRulePenalty" in wrappers
    with pytest.raises((ConfigError, ValueError), match="stability_penalty must be a number >= 0"):
        load_train_config(CONFIG, ["env.stability_penalty=-1"])
    batched = load_train_config(CONFIG, ["env.vectorization=batched"])  # each env is wrapped
    assert batched.env.stability_penalty == 2.0


def _cliff_return(progress_weight, stop_at):
    """A flat cliff walk with the one-way stop at step `stop_at` (None: never): the summed
    reward and progress terms, and whether the episode met the success rule."""
    env = StabilityRulePenalty(
        gym.make("HexapodCliffWalk-v1", terrain="flat", clock_action="stop"), 2.0, progress_weight
    )
    env.reset(seed=0)
    action = np.zeros(19, dtype=np.float32)
    total = progress = 0.0
    for step in range(1500):
        action[18] = -1.0 if step == stop_at else 0.0
        _, reward, terminated, truncated, info = env.step(action)
        total += reward
        progress += info.get("reward_rule_progress", 0.0)
        assert info.get("reward_rule_progress", 0.0) == -progress_weight * info["behind_pace"]
        if terminated or truncated:
            return total, progress, info["is_success"]
    raise AssertionError("the time limit should have ended the episode")


def test_the_progress_term_charges_the_walking_steps_behind_the_rules_pace():
    """On flat ground a stop that leaves the robot short of half the reference distance fails
    the rule and pays on every step from when it falls behind; a late stop and walking on do
    not (the few steps of the gait's start, when the body lags the pace, cost all alike)."""
    walk, walk_progress, walk_success = _cliff_return(2.0, None)
    late, late_progress, late_success = _cliff_return(2.0, 1000)
    early, early_progress, early_success = _cliff_return(2.0, 600)
    assert walk_success and late_success and not early_success
    assert walk_progress == late_progress > -20.0  # a handful of steps at the start
    assert early_progress < -500.0  # hundreds of steps behind, each charged 2
    assert walk > late > early
    plain_early, none, _ = _cliff_return(0.0, 600)
    assert none == 0.0 and plain_early - early == pytest.approx(-early_progress)


def test_the_progress_term_needs_a_pace_and_the_config_the_stability_penalty():
    with pytest.raises(ValueError, match="HexapodStewartTilt-v1 has no pace"):
        StabilityRulePenalty(gym.make("HexapodStewartTilt-v1"), 1.0, 1.0)
    with pytest.raises(ValueError, match="progress-rule penalty weight must be a number >= 0"):
        StabilityRulePenalty(gym.make("HexapodCliffWalk-v1"), 1.0, -1.0)
    cliff = REPO / "configs" / "cliff_walk_v1_ppo_stop.yaml"
    config = load_train_config(cliff, ["env.max_episode_steps=5"])
    env = env_spec(config).make()
    while not isinstance(env, StabilityRulePenalty):
        env = env.env
    assert env.progress_weight == config.env.progress_penalty > 0
    with pytest.raises((ConfigError, ValueError), match="set env.stability_penalty > 0 too"):
        load_train_config(cliff, ["env.stability_penalty=0"])
    with pytest.raises((ConfigError, ValueError), match="progress_penalty must be a number >= 0"):
        load_train_config(cliff, ["env.progress_penalty=-2"])
