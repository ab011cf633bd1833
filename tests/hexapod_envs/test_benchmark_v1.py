"""The v1 benchmark: ids, safety figures in info, the success and termination rules, task
difficulty, and the headroom over the baselines on a few test tasks (docs/benchmark.md)."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401  (registers the ids)
from agents.pipeline.headroom import ConstantPolicy, headroom, run_baseline
from agents.policy import RandomPolicy, ZeroPolicy
from agents.registry import ANALYTICAL_POLICIES
from agents.tipping.gait_with_recovery import GaitWithRecoveryPolicy
from hexapod_envs.benchmark import V1_KWARGS
from hexapod_envs.envs.difficulty import DifficultySpan, task_difficulty

V0_IDS = [
    "HexapodCliffWalk-v0",
    "HexapodStewartTilt-v0",
    "HexapodIrregularTerrain-v0",
    "HexapodDitchCrossing-v0",
]
V1_IDS = sorted(V1_KWARGS)


def test_every_env_has_a_v1_id_and_v0_keeps_its_semantics():
    assert sorted(i.replace("-v0", "-v1") for i in V0_IDS) == V1_IDS
    for v0 in V0_IDS:
        assert gym.spec(v0).kwargs == {}
        v1 = gym.spec(v0.replace("-v0", "-v1"))
        assert v1.entry_point == gym.spec(v0).entry_point
        assert v1.max_episode_steps == gym.spec(v0).max_episode_steps
        assert v1.id in ANALYTICAL_POLICIES


def test_difficulty_is_a_weighted_mean_of_clipped_positions():
    spans = {"a": DifficultySpan(0.0, 10.0), "b": DifficultySpan(easy=1.0, hard=0.5, weight=3.0)}
    assert task_difficulty({"a": 5.0, "b": 1.0}, spans) == pytest.approx(0.5 / 4)
    assert task_difficulty({"a": 20.0, "b": 0.0}, spans) == 1.0  # clipped past hard
    assert task_difficulty({"a": -3.0, "b": 2.0}, spans) == 0.0  # clipped past easy
    with pytest.raises(ValueError, match="easy != hard"):
        DifficultySpan(1.0, 1.0)


@pytest.mark.parametrize(
    "env_id, kwargs",
    [
        ("HexapodStewartTilt-v1", {}),  # the "random" paper scenario draws rate, axis, stance
        ("HexapodDitchCrossing-v0", {"ditch_width_range": (0.25, 0.4)}),
    ],
)
def test_the_difficulty_rates_the_task_drawn_at_reset(env_id, kwargs):
    """Paper tasks whose values are drawn while the task is applied are rated from those draws."""
    env = gym.make(env_id, **kwargs)
    base = env.unwrapped
    for seed in range(3):
        task = env.reset(seed=seed)[1]["task"]
        drawn = {k: v for k, v in task.items() if k != "difficulty"}
        assert task["difficulty"] == task_difficulty(drawn, base.task_difficulty_spans())
    assert len({env.reset(seed=s)[1]["task"]["difficulty"] for s in range(3)}) == 3
    env.close()


@pytest.mark.parametrize("env_id", V1_IDS)
def test_test_tasks_are_at_least_as_hard_as_training_on_average(env_id):
    means = {}
    for distribution in ("train", "test"):
        env = gym.make(env_id, task_distribution=distribution)
        values = [env.reset(seed=s)[1]["task"]["difficulty"] for s in range(30)]
        env.close()
        assert all(0.0 <= v <= 1.0 for v in values)
        means[distribution] = np.mean(values)
    assert means["test"] >= means["train"], means


@pytest.mark.parametrize("env_id", V0_IDS + V1_IDS)
def test_safety_figures_in_info_track_the_episode(env_id):
    env = gym.make(env_id, task_distribution="train")
    obs, info = env.reset(seed=3)
    assert info["tipping_share"] == 0.0 and info["tipping_time_s"] == 0.0
    policy, highest, tipping = RandomPolicy(env.action_space, seed=3), info["max_tilt_deg"], 0
    for step in range(1, 40):
        obs, _, terminated, truncated, info = env.step(policy(obs))
        tipping += info["is_tipping"]
        highest = max(highest, info["tilt_deg"])
        assert info["max_tilt_deg"] == highest
        assert info["tipping_time_s"] == pytest.approx(tipping * env.unwrapped.control_dt)
        assert info["tipping_share"] == pytest.approx(tipping / step)
        if terminated or truncated:
            break
    env.close()


def test_the_cliff_v1_success_needs_the_goal_and_the_safety_figures():
    env = gym.make("HexapodCliffWalk-v1", task_distribution="test")
    s = env.unwrapped.settings
    for seed in range(3):
        obs, info = env.reset(seed=seed)
        done = False
        while not done:
            obs, _, terminated, truncated, info = env.step(np.zeros(18, dtype=np.float32))
            done = terminated or truncated
        stable = (
            info["max_tilt_deg"] <= s.success_max_tilt_deg
            and info["tipping_share"] <= s.success_max_tipping_share
        )
        walked = info["distance"] >= s.min_progress * env.unwrapped.gait.gait.body_speed * (
            info["time"] - env.unwrapped.gait.gait.stand_time
        )
        assert info["is_success"] == (stable and walked and not info["is_tipped_over"])
    env.close()


def test_a_lost_margin_ends_the_episode_after_the_set_time():
    """With ``tip_over_margin_time`` of one control period, the first step at FASM <= 0 ends
    the episode as a tip-over (random actions reach it within a few seconds)."""
    env = gym.make("HexapodCliffWalk-v1", tip_over_margin_time=0.02, task_distribution="train")
    obs, _ = env.reset(seed=0)
    policy = RandomPolicy(env.action_space, seed=0)
    for _ in range(1500):
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        if terminated or truncated:
            break
    assert terminated and info["is_tipped_over"]
    tilted = info["tilt_deg"] > env.unwrapped.settings.tip_over_angle_deg
    assert info["fasm_margin_deg"] <= 0.0 or tilted
    assert info["reward_tip_over"] < 0
    env.close()


def test_stewart_v1_landing_before_tipping_is_no_success():
    """Holding every foot on the platform from the start (a constant joint action at the hold
    posture's stance legs) lands the lifted tripod before any tipping: no success in -v1."""
    env = gym.make("HexapodStewartTilt-v1", scenario="climb", action_mode="joint")
    obs, info = env.reset(seed=0)
    base = env.unwrapped
    joints = np.asarray(base.reference_joints(), dtype=float).reshape(6, 3).copy()
    stance = [i for i, leg in enumerate(base.sensors.legs) if leg in base.stance]
    swing = [i for i, leg in enumerate(base.sensors.legs) if leg in base.swing]
    for i, j in zip(swing, stance, strict=True):
        joints[i] = joints[j]  # each lifted leg copies a stance leg's pose: its foot goes down
    action = base.action_map.to_action(joints.reshape(-1)).astype(np.float32)
    for _ in range(200):
        obs, _, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            break
    assert info["early_landing"] is True
    assert info["is_success"] is False
    env.close()


def test_the_cliff_reference_can_resume_its_gait_after_a_recovery():
    """``resume_margin_deg`` re-arms the recovery once the margin is restored and the gait walks
    on (the paper's controller holds its stance for good)."""
    kwargs = {"action_mode": "joint"}
    paper = run_baseline(
        "HexapodCliffWalk-v1", "paper", GaitWithRecoveryPolicy, [0], kwargs, "train"
    )
    resumed = []

    def resuming(env):
        resumed.append(GaitWithRecoveryPolicy(env, resume_margin_deg=0.0, resume_hold_s=0.5))
        return resumed[-1]

    run_baseline("HexapodCliffWalk-v1", "resume", resuming, [0], kwargs, "train")
    assert resumed[0].resumptions >= 1
    assert paper.episodes[0].max_tilt_deg < 1.0  # held level, standing still
    with pytest.raises(ValueError, match="resume_hold_s"):
        GaitWithRecoveryPolicy(gym.make("HexapodCliffWalk-v1"), resume_hold_s=math.nan)


@pytest.mark.slow
@pytest.mark.parametrize("env_id", V1_IDS)
def test_no_baseline_reaches_the_reference_on_benchmark_tasks(env_id):
    """The headroom targets on 8 benchmark test tasks (the full 50-task table is
    scripts/benchmark_headroom.py): random actions never succeed, and neither the zero action,
    the open-loop replay of the controller's actions nor the best of the searched constant
    actions reaches the analytical controller. The env's return ranks the analytical
    controller, the zero action and random actions in the order of their success."""
    analytical, zero, random, replay, constant = headroom(env_id, range(8), n_random_constants=2)
    assert analytical.mean_return > zero.mean_return > random.mean_return
    assert analytical.success_rate >= 0.375
    assert random.success_rate == 0.0
    assert zero.success_rate < analytical.success_rate
    assert replay.name == "open-loop replay"
    assert replay.success_rate < analytical.success_rate
    assert constant.name.startswith("constant (")
    assert constant.success_rate < analytical.success_rate


def test_constant_policy_returns_a_fresh_copy():
    policy = ConstantPolicy(np.ones(3))
    a = policy(np.zeros(5))
    a[0] = 7.0
    assert policy(np.zeros(5))[0] == 1.0
    assert isinstance(ZeroPolicy(gym.spaces.Box(-1, 1, (2,))), object)
