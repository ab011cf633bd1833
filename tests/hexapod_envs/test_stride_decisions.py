"""One learner step per platform step: the ditch crossing's stride action with the residuals off,
through `GainsPerCycle` (``env.decision: gait_cycle``)."""

import copy

import gymnasium as gym
import numpy as np
import pytest
from helpers.ditch_stride_runs import STRIDES_OFF
from helpers.paths import REPO

import hexapod_envs  # noqa: F401  (registers the env ids)
from agents.upu_stride import ClearStridePolicy
from hexapod_envs.envs.ditch_crossing import STRIDE_ACTION
from hexapod_envs.wrappers import GainsPerCycle

ENV_ID = "HexapodDitchCrossing-v1"
STRIDES = STRIDES_OFF


def _rule_with_noise(env: gym.Env):
    """The clear-stride rule where the observation says the stride is read, random values
    everywhere else (the nine residual values always, the stride value on the other control
    steps): the plain env must ignore all of those to follow the wrapped env."""
    rule, rng = ClearStridePolicy(env), np.random.default_rng(0)
    flag = env.unwrapped.observation_layout.slices["stride_decision"].start + 1

    def act(obs: np.ndarray) -> np.ndarray:
        action = rng.uniform(-1, 1, STRIDE_ACTION + 1).astype(np.float32)
        if obs[flag] == 1.0:
            action[STRIDE_ACTION] = rule(obs)[STRIDE_ACTION]
        return action

    return act


def _run(env: gym.Env, seed: int) -> tuple[np.ndarray, float, list[int], dict]:
    policy = _rule_with_noise(env)
    obs, _ = env.reset(seed=seed)
    total, steps = 0.0, []
    while True:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        total += reward
        steps.append(info.get("cycle_steps", 1))
        if terminated or truncated:
            return obs, total, steps, info


def test_a_stride_policy_acts_the_same_per_platform_step_and_per_control_step():
    """The env reads only the stride, on a platform step's first control step: the wrapped and
    the plain env follow the same trajectory, with the same summed reward. On training task 2
    the rule shortens strides near the ditch within the first 10 platform steps."""
    wrapped, plain = GainsPerCycle(gym.make(ENV_ID, **STRIDES)), gym.make(ENV_ID, **STRIDES)
    obs_w, return_w, steps, info_w = _run(wrapped, seed=2)
    obs_p, return_p, _, info_p = _run(plain, seed=2)
    np.testing.assert_array_equal(obs_w, obs_p)
    assert return_w == pytest.approx(return_p, rel=1e-12)
    assert info_w["distance"] == info_p["distance"] > 0.3
    strides = [
        [step.stride for step in env.unwrapped.online_gait.steps] for env in (wrapped, plain)
    ]
    assert strides[0] == strides[1] and min(strides[0]) < 0.15
    # 5.1 s a platform step at 10 Hz: 51 control steps, the last one cut by the time limit.
    assert len(steps) == 10 and steps[:-1] == [51] * 9 and sum(steps) == 500


def test_the_stride_is_read_on_a_platform_steps_first_control_step_only():
    env = gym.make(ENV_ID, **STRIDES).unwrapped
    env.reset(seed=0)
    flag = env.observation_layout.slices["stride_decision"].start + 1
    short = np.zeros(env.action_space.shape, dtype=np.float32)
    short[STRIDE_ACTION] = -0.5
    assert env.stride_due
    obs, *_ = env.step(short)
    assert not env.stride_due and obs[flag] == 0.0
    for _ in range(50):
        obs, *_ = env.step(np.zeros_like(short))  # a full stride, ignored: not a decision
    assert env.stride_due and obs[flag] == 1.0
    assert env.online_gait.steps[-1].stride == pytest.approx(0.08)


def test_residuals_and_other_envs_are_refused_by_name():
    residuals = "residual_limb_m=0 and residual_leg_m=0.*got 0.05 and 0.16"
    with pytest.raises(ValueError, match=residuals):
        GainsPerCycle(gym.make(ENV_ID, task_distribution="train", stride_action=True))
    with pytest.raises(ValueError, match="stride_action=True and the residuals off.*DitchCrossing"):
        GainsPerCycle(gym.make(ENV_ID))


def test_the_config_builds_one_learner_step_per_platform_step():
    from agents.pipeline.envs import EnvSpec
    from agents.run_files.artifacts import learner_step_unit
    from agents.run_files.configtools import to_mapping
    from agents.run_files.train_config import load_train_config

    config = load_train_config(REPO / "configs" / "ditch_crossing_v1_ppo_stride_decisions.yaml")
    section = config.env
    spec = EnvSpec(
        section.id, dict(section.kwargs), gym_packages=["hexapod_envs"], decision=section.decision
    )
    env = spec.make()
    env.reset(seed=0)
    *_, info = env.step(np.zeros(env.action_space.shape, dtype=np.float32))
    assert info["cycle_steps"] == 51
    assert learner_step_unit(to_mapping(config)) == "platform steps"


def test_a_deep_copy_of_the_wrapper_steps_its_own_env_to_its_own_next_decision():
    """A copy (e.g. for a look-ahead) plays one whole platform step of its own env; the original
    does not move."""
    env = GainsPerCycle(gym.make(ENV_ID, **STRIDES))
    env.reset(seed=1)
    before = env.unwrapped.data.qpos.copy()
    twin = copy.deepcopy(env)
    _, _, _, _, info = twin.step(np.zeros(STRIDE_ACTION + 1, dtype=np.float32))
    assert info["cycle_steps"] > 40 and twin.unwrapped.stride_due
    np.testing.assert_array_equal(env.unwrapped.data.qpos, before)
