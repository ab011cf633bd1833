"""Learned recovery knobs (agents.knobs): the action's meaning, the per-event env, the policy on
the plain env, and a training run that loads back as that policy."""

import gymnasium as gym
import numpy as np
import pytest
from helpers.paths import REPO

import hexapod_envs  # noqa: F401  (registers the ids)
from agents.export import load_actor
from agents.knobs import KNOB_RANGES, KnobPolicy, KnobSettings, KnobsPerEvent, knob_values
from agents.pipeline.cli import train_main
from agents.pipeline.envs import EnvSpec
from agents.ppo import PPOPolicy
from agents.registry import analytical_policy
from agents.run_files.errors import UserError
from agents.run_files.train_config import load_train_config
from agents.tipping.controller import RecoveryConfig, TippingRecoveryPolicy

STEWART = "HexapodStewartTilt-v1"
LIMIT = 500  # control steps: every test task's event comes before (about steps 150-400)


def _stewart():
    return gym.make(STEWART, task_distribution="test", max_episode_steps=LIMIT)


def _episode(env, policy, seed):
    """(return, last info) of one episode of `policy` on `env`."""
    obs, _ = env.reset(seed=seed)
    policy.reset()
    total, done = 0.0, False
    while not done:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        total, done = total + reward, terminated or truncated
    return total, info


class _Constant:
    """A learned policy that always answers the same action."""

    def __init__(self, action):
        self.action = np.asarray(action, dtype=np.float32)
        self.calls = 0

    def reset(self):
        pass

    def __call__(self, observation):
        self.calls += 1
        return self.action


def test_zero_is_the_controllers_setting_and_one_the_ranges_ends():
    default = RecoveryConfig()
    names = ("rho", "kappa", "t_min")
    assert knob_values(default, names, [0, 0, 0]) == {"rho": 0.9, "kappa": 0.7, "t_min": 0.5}
    high = knob_values(default, names, [1, 1, 1])
    low = knob_values(default, names, [-1, -1, -1])
    for name in names:
        assert (low[name], high[name]) == pytest.approx(KNOB_RANGES[name])
    assert knob_values(default, ("rho",), [-0.5])["rho"] == pytest.approx(0.65)
    assert knob_values(default, ("rho",), [3.0]) == knob_values(default, ("rho",), [1.0])
    outside = RecoveryConfig(t_max=5.0)  # above the knob's range 1.5-4.0: the range widens to it
    assert knob_values(outside, ("t_max",), [1.0]) == {"t_max": 5.0}
    assert knob_values(outside, ("t_max",), [-1.0]) == {"t_max": 1.5}
    with pytest.raises(ValueError, match="one per knob"):
        knob_values(default, names, [0.0, np.nan, 0.0])


def test_bad_settings_name_the_valid_choices():
    with pytest.raises(ValueError, match="rho"):
        KnobSettings(names=("rhoo",))
    with pytest.raises(ValueError, match="reward"):
        KnobSettings(reward="distance")
    with pytest.raises(ValueError, match="event_margin_deg"):
        KnobSettings(event_margin_deg=-1.0)
    with pytest.raises(UserError, match="has none"):
        EnvSpec("HexapodIrregularTerrain-v1", knobs=KnobSettings()).make()
    with pytest.raises(ValueError, match="knobs"):
        load_train_config(
            data={
                "env": {"id": STEWART},
                "knobs": {"names": ["rho"]},
                "hybrid": {"mode": "residual"},
            }
        )


def test_the_zero_action_replays_the_analytical_controller():
    """The learner is asked on the step the controller judges tipping; its one step spans the
    rest of the episode and ends it as terminated (no value to bootstrap after the outcome);
    with a = 0 the env's episode is the analytical controller's, step for step."""
    env = KnobsPerEvent(_stewart(), KnobSettings())
    env.reset(seed=3)
    before = env._steps
    assert env.core.base.controller.phase == "monitor"
    _, reward, terminated, truncated, info = env.step(np.zeros(3, dtype=np.float32))
    assert (terminated, truncated) == (True, False)
    assert info["env_truncated"] and not info["env_terminated"]  # stood to the time limit
    judged = env.core.base.controller.diagnostics["judgment_time"]
    assert judged == pytest.approx(before * env.unwrapped.control_dt)
    assert 0 < before < info["env_steps"] == LIMIT

    raw = _stewart()
    total, last = _episode(raw, analytical_policy(raw), seed=3)
    assert info["episode_return"] == pytest.approx(total, rel=0, abs=1e-9)
    assert reward == float(last["is_success"])
    assert info["knobs"] == {"rho": 0.9, "kappa": 0.7, "t_min": 0.5}


def test_the_knobs_act_as_the_same_settings_given_at_construction():
    """Setting the knobs at the judgment is the controller built with those settings, and
    another setting changes the episode."""
    action = [-0.5, 0.5, 1.0]  # exact in float32, the learned action's dtype
    settings = KnobSettings()
    values = knob_values(RecoveryConfig(), settings.names, action)
    env = _stewart()
    tuned, _ = _episode(env, KnobPolicy(_Constant(action), env, settings), seed=4)
    built = TippingRecoveryPolicy(env, RecoveryConfig(threshold_deg=20.0, **values))
    assert _episode(env, built, seed=4)[0] == pytest.approx(tuned, rel=0, abs=1e-9)
    assert _episode(env, analytical_policy(env), seed=4)[0] != pytest.approx(tuned, abs=1e-3)


def test_the_policy_asks_once_at_the_event_and_matches_the_training_env():
    action = [-0.6, 0.3, 0.5]
    env = KnobsPerEvent(_stewart(), KnobSettings(reward="return"))
    env.reset(seed=5)
    _, after_event, *_, info = env.step(np.asarray(action, dtype=np.float32))

    raw = _stewart()
    learned = _Constant(action)
    policy = KnobPolicy(learned, raw, KnobSettings())
    total, _ = _episode(raw, policy, seed=5)
    assert learned.calls == 1
    assert policy.core.values == info["knobs"]
    assert policy.core.base.controller.config.rho == pytest.approx(0.9 - 0.6 * 0.5)
    assert total == pytest.approx(info["episode_return"], rel=0, abs=1e-9)
    assert after_event < info["episode_return"]  # the steps before the event are not the learner's
    policy.reset()
    assert policy.core.base.controller.config == RecoveryConfig(threshold_deg=20.0)


def test_a_knobs_run_trains_and_loads_as_the_controller_it_tunes(tmp_path):
    overrides = [
        "ppo.n_steps=4",
        "ppo.batch_size=4",
        "ppo.n_epochs=1",
        "train.total_timesteps=8",
        "eval.freq=4",
        "eval.n_episodes=1",
        "checkpoint.freq=0",
        f"env.max_episode_steps={LIMIT}",
    ]
    config = str(REPO / "configs" / "stewart_tilt_v1_knobs.yaml")
    argv = ["--config", config, "--output-dir", str(tmp_path)]
    argv += ["--run-name", "run", *[a for o in overrides for a in ("--set", o)]]
    assert train_main(argv) == 0
    env = _stewart()
    policy = PPOPolicy.load(tmp_path / "run", env)
    assert isinstance(policy, KnobPolicy)
    _episode(env, policy, seed=0)
    assert policy.core.decided and set(policy.core.values) == {"rho", "kappa", "t_min"}
    actor, actor_env, _ = load_actor(tmp_path / "run")
    obs, _ = actor_env.reset(seed=0)
    assert actor(obs).shape == (3,)
    actor_env.close()


def test_episodes_without_a_judgment_are_skipped_and_too_many_are_an_error():
    short = gym.make(STEWART, task_distribution="test", max_episode_steps=20)  # ends before
    env = KnobsPerEvent(short, KnobSettings(), max_skipped=2)
    with pytest.raises(RuntimeError, match="3 episodes in a row ended without a tipping judgment"):
        env.reset(seed=0)
    with pytest.raises(RuntimeError, match="reset"):
        KnobsPerEvent(_stewart(), KnobSettings()).step(np.zeros(3, dtype=np.float32))
