"""Learned ditch-planner knobs (agents.plan_knobs): the action's meaning, the fallback to the
env's own settings, the per-episode env, the policy on the plain env, and a training run that
loads back and exports as that policy."""

import json

import gymnasium as gym
import numpy as np
import pytest
from helpers.paths import REPO

import hexapod_envs  # noqa: F401  (registers the ids)
from agents.knobs import PLANNER_KNOB_RANGES, KnobSettings, knob_values
from agents.pipeline.cli import train_main
from agents.pipeline.envs import EnvSpec
from agents.plan_knobs import (
    PlanKnobCore,
    PlanKnobPolicy,
    PlanKnobsPerEpisode,
    course_features,
    resolved_settings,
)
from agents.ppo import PPOPolicy
from agents.registry import analytical_policy
from agents.run_files.artifacts import learner_step_unit
from agents.run_files.errors import UserError
from agents.run_files.train_config import load_train_config
from hexapod_envs.robots.upu.gait_plan import GaitSettings
from hexapod_envs.robots.upu.params import UpuParams

DITCH = "HexapodDitchCrossing-v1"
NAMES = ("edge_clearance", "min_margin")


def _ditch(distribution="train"):
    return gym.make(DITCH, task_distribution=distribution, action_mode="joint")


def _episode(env, policy, seed):
    """(return, steps, last info) of one episode of `policy` on `env`."""
    obs, _ = env.reset(seed=seed)
    policy.reset()
    total, steps, done = 0.0, 0, False
    while not done:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        total, steps, done = total + reward, steps + 1, terminated or truncated
    return total, steps, info


class _Constant:
    """A learned policy that always answers the same action, recording what it was shown."""

    def __init__(self, action):
        self.action = np.asarray(action, dtype=np.float32)
        self.seen = []

    def reset(self):
        pass

    def __call__(self, observation):
        self.seen.append(np.array(observation))
        return self.action


def test_zero_is_the_envs_setting_and_one_the_ranges_ends():
    default = resolved_settings(GaitSettings(), UpuParams())
    assert (default.lift, default.max_stride) == pytest.approx((0.08, 0.16))
    names = tuple(PLANNER_KNOB_RANGES)
    zero = knob_values(default, names, np.zeros(4), PLANNER_KNOB_RANGES)
    assert zero == pytest.approx(
        {"edge_clearance": 0.02, "min_margin": 0.01, "max_stride": 0.16, "lift": 0.08}
    )
    high = knob_values(default, names, np.ones(4), PLANNER_KNOB_RANGES)
    low = knob_values(default, names, -np.ones(4), PLANNER_KNOB_RANGES)
    for name in names:
        assert (low[name], high[name]) == pytest.approx(PLANNER_KNOB_RANGES[name])
    half = knob_values(default, NAMES, [-0.5, 0.5], PLANNER_KNOB_RANGES)
    assert half == pytest.approx({"edge_clearance": 0.01, "min_margin": 0.02})


def test_knob_names_come_from_one_controller_and_errors_name_the_choices():
    assert KnobSettings(names=NAMES).controller == "planner"
    assert KnobSettings().controller == "recovery"
    with pytest.raises(ValueError, match="edge_clearance.*rho|rho.*edge_clearance"):
        KnobSettings(names=("rho", "min_margin"))
    with pytest.raises(UserError, match="the ditch crossing"):
        EnvSpec("HexapodStewartTilt-v1", knobs=KnobSettings(names=NAMES)).make()
    with pytest.raises(UserError, match="terrain='ditch'"):
        EnvSpec(
            DITCH,
            kwargs={"terrain": "flat", "action_mode": "joint"},
            knobs=KnobSettings(names=NAMES),
        ).make()
    with pytest.raises(UserError, match="action_mode='joint'"):
        EnvSpec(DITCH, knobs=KnobSettings(names=NAMES)).make()  # the default residual mode
    with pytest.raises(ValueError, match="critic_privileged"):
        load_train_config(
            data={
                "env": {"id": DITCH, "kwargs": {"action_mode": "joint"}},
                "knobs": {"names": list(NAMES)},
                "policy": {"critic_privileged": True},
            }
        )
    assert learner_step_unit({"knobs": {"names": list(NAMES)}}) == "episodes"
    assert learner_step_unit({"knobs": {"names": ["rho"]}}) == "tipping events"


def test_settings_without_a_plan_fall_back_to_the_envs_own():
    """Test ditch 11 (0.53 m wide) has a plan with the env's 10 mm margin but none with 20 mm:
    the planner keeps its own settings. A ditch refused either way keeps the learned ones."""
    env = _ditch("test")
    core = PlanKnobCore(env, KnobSettings(names=NAMES))
    env.reset(seed=11)
    core.reset()
    assert core.set_knobs([0.0, 0.5]) == pytest.approx({"edge_clearance": 0.02, "min_margin": 0.02})
    assert core.fallback and core.base.settings == core.default and core.base.status == "ok"
    core.set_knobs([0.0, 0.0])
    assert not core.fallback and core.base.status == "ok"
    env.reset(seed=4)  # refused by the env's own settings too
    core.reset()
    core.set_knobs([0.0, 0.5])
    assert not core.fallback and core.base.status != "ok"
    assert core.base.settings.min_margin == pytest.approx(0.02)


def test_the_zero_action_replays_the_analytical_controller():
    """The learner sees the course, and its one step walks the whole episode and ends it as
    terminated; with a = 0 the env's episode is the analytical controller's, step for step."""
    env = PlanKnobsPerEpisode(_ditch(), KnobSettings(names=NAMES))
    features, _ = env.reset(seed=3)
    task = env.unwrapped.task_description
    assert features == pytest.approx(
        [task.course["ditch_start_x"], task.course["ditch_width"], task.course["ditch_depth"]],
        abs=1e-6,
    )
    assert env.observation_space.contains(features)
    _, reward, terminated, truncated, info = env.step(np.zeros(2, dtype=np.float32))
    assert (terminated, truncated) == (True, False)
    assert info["knobs"] == pytest.approx({"edge_clearance": 0.02, "min_margin": 0.01})
    assert not info["planner_fallback"]

    raw = _ditch()
    total, steps, last = _episode(raw, analytical_policy(raw), seed=3)
    assert info["episode_return"] == pytest.approx(total, rel=0, abs=1e-9)
    assert info["env_steps"] == steps
    assert reward == float(last["is_success"]) == 1.0


def test_the_stable_success_reward_grades_the_crossing_by_its_largest_tilt():
    env = PlanKnobsPerEpisode(_ditch(), KnobSettings(names=NAMES, reward="stable_success"))
    env.reset(seed=3)
    _, reward, *_, info = env.step(np.zeros(2, dtype=np.float32))
    assert info["is_success"] and 0.0 < info["max_tilt_deg"] < 2.0  # -v1's bound: 2 deg
    assert reward == pytest.approx(1.0 - info["max_tilt_deg"] / 2.0, rel=0, abs=1e-12)


def test_the_margin_success_reward_grades_the_crossing_by_its_smallest_static_margin():
    rewards = {}
    for margin in (0.0, 0.5):  # the env's 10 mm, then 20 mm (min_margin's range: 0-30 mm)
        env = PlanKnobsPerEpisode(_ditch(), KnobSettings(names=NAMES, reward="margin_success"))
        env.reset(seed=3)
        _, reward, *_, info = env.step(np.array([0.0, margin], dtype=np.float32))
        assert info["is_success"] and not info["planner_fallback"]
        assert reward == pytest.approx(1.0 + info["min_static_margin_m"] / 0.1, rel=0, abs=1e-12)
        rewards[margin] = reward
    assert rewards[0.5] > rewards[0.0] + 0.03  # the planned margin is the crossing's (+5 mm)


def test_a_course_blind_policy_sees_zeros_in_training_and_on_the_plain_env():
    settings = KnobSettings(names=NAMES, course=False)
    env = PlanKnobsPerEpisode(_ditch(), settings)
    features, _ = env.reset(seed=6)
    np.testing.assert_array_equal(features, np.zeros(3, dtype=np.float32))
    np.testing.assert_array_equal(env.step(np.zeros(2, dtype=np.float32))[0], features)
    raw = _ditch()
    learned = _Constant([0.25, 0.5])
    policy = PlanKnobPolicy(learned, raw, settings)
    _episode(raw, policy, seed=6)
    assert len(learned.seen) == 1 and not learned.seen[0].any()
    with pytest.raises(ValueError, match="knobs.course: false is for the ditch planner"):
        KnobSettings(course=False)  # the recovery's knobs
    with pytest.raises(ValueError, match="knobs.course must be true or false"):
        KnobSettings(names=NAMES, course="no")


def test_margin_success_is_refused_where_no_static_margin_grades_the_outcome():
    with pytest.raises(ValueError, match="the recovery's knobs take"):
        KnobSettings(reward="margin_success")
    with pytest.raises(ValueError, match=r"env.episode_reward: \"margin_success\""):
        load_train_config(
            data={
                "env": {
                    "id": "HexapodIrregularTerrain-v1",
                    "kwargs": {"action_mode": "gains"},
                    "decision": "episode",
                    "episode_reward": "margin_success",
                }
            }
        )


def test_the_policy_asks_once_with_the_course_and_matches_the_training_env():
    action = [-0.25, 0.5]  # exact in float32
    env = PlanKnobsPerEpisode(_ditch(), KnobSettings(names=NAMES, reward="return"))
    features, _ = env.reset(seed=6)
    _, reward, *_, info = env.step(np.asarray(action, dtype=np.float32))
    assert reward == info["episode_return"]

    raw = _ditch()
    learned = _Constant(action)
    policy = PlanKnobPolicy(learned, raw, KnobSettings(names=NAMES))
    total, _, _ = _episode(raw, policy, seed=6)
    assert len(learned.seen) == 1 and learned.seen[0] == pytest.approx(features)
    assert policy.core.values == info["knobs"]
    assert total == pytest.approx(info["episode_return"], rel=0, abs=1e-9)
    other, _, _ = _episode(raw, analytical_policy(raw), seed=6)
    assert other != pytest.approx(total, abs=1e-3)  # the settings changed the walk
    policy.reset()
    assert policy.core.base.settings == policy.core.default


def test_course_features_follow_the_sampled_ditch():
    env = _ditch("test")
    widths = set()
    for seed in range(3):
        env.reset(seed=seed)
        ahead, width, depth = course_features(env)
        assert 0.4 <= width <= 0.55 and 0.12 <= depth <= 0.15 and ahead > 0
        widths.add(float(width))
    assert len(widths) == 3


def test_a_planner_knobs_run_trains_loads_and_exports(tmp_path):
    pytest.importorskip("onnx")
    from agents.export import export_model

    overrides = [
        "ppo.n_steps=2",
        "ppo.batch_size=2",
        "ppo.n_epochs=1",
        "train.total_timesteps=2",
        "eval.freq=2",
        "eval.n_episodes=1",
        "checkpoint.freq=0",
        "env.max_episode_steps=60",
    ]
    config = str(REPO / "configs" / "ditch_crossing_v1_knobs.yaml")
    argv = ["--config", config, "--output-dir", str(tmp_path)]
    argv += ["--run-name", "run", *[a for o in overrides for a in ("--set", o)]]
    assert train_main(argv) == 0
    env = _ditch("test")
    policy = PPOPolicy.load(tmp_path / "run", env)
    assert isinstance(policy, PlanKnobPolicy)
    obs, _ = env.reset(seed=0)
    policy.reset()
    env.step(policy(obs))
    assert set(policy.core.values) == set(NAMES)
    exported = export_model(tmp_path / "run", tmp_path / "actor.onnx")
    card = json.loads(exported.card_json.read_text())
    assert card["observation"]["shape"] == [3]
    assert "planner knobs model" in card["action"]["exported"]
