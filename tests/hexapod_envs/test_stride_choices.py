"""The ditch crossing's stride action as a choice among stride values (`StrideChoices`) and
each choice's landing clearance in the observation (`StrideClearances`)."""

import gymnasium as gym
import numpy as np
import pytest
from helpers.ditch_stride_runs import STRIDES_OFF

import hexapod_envs  # noqa: F401  (registers the env ids)
from agents.upu_stride import ClearStridePolicy
from hexapod_envs.envs.ditch_crossing import STRIDE_ACTION
from hexapod_envs.robots.upu.gait_plan import edge_clearance
from hexapod_envs.wrappers import GainsPerCycle, StrideChoices, StrideClearances

ENV_ID = "HexapodDitchCrossing-v1"
STRIDES = STRIDES_OFF
VALUES = [0.0, -0.2, -0.4, -0.6, -0.8]


def test_a_choice_walks_as_its_stride_value_on_the_plain_env():
    """Choices 3, 0, 1, 4, 2, ... per platform step through the wrapper (one learner step per
    platform step) and the same stride values as Box actions on the plain env: one trajectory."""
    chosen = GainsPerCycle(StrideChoices(gym.make(ENV_ID, **STRIDES), VALUES))
    plain = gym.make(ENV_ID, **STRIDES)
    assert chosen.action_space == gym.spaces.Discrete(5)
    chosen.reset(seed=4)
    obs_p, _ = plain.reset(seed=4)
    flag = plain.unwrapped.observation_layout.slices["stride_decision"].start + 1
    done, k, decided = False, 0, []
    while not done:
        choice = [3, 0, 1, 4, 2][k % 5]
        obs_c, _, term, trunc, _ = chosen.step(choice)
        k += 1
        done = term or trunc
    k, done = 0, False
    while not done:
        action = np.zeros(STRIDE_ACTION + 1, dtype=np.float32)
        if obs_p[flag] == 1.0:
            action[STRIDE_ACTION] = VALUES[[3, 0, 1, 4, 2][k % 5]]
            decided.append(action[STRIDE_ACTION])
            k += 1
        obs_p, _, term, trunc, _ = plain.step(action)
        done = term or trunc
    np.testing.assert_array_equal(obs_c, obs_p)
    strides = [s.stride for s in chosen.unwrapped.online_gait.steps]
    assert strides == [s.stride for s in plain.unwrapped.online_gait.steps]
    assert len(decided) >= 7 and len(set(np.round(strides, 6))) >= 3  # the room caps some


def test_a_choice_maps_to_the_stride_value_with_the_residuals_at_0():
    env = StrideChoices(gym.make(ENV_ID, **STRIDES), VALUES)
    expected = np.zeros(STRIDE_ACTION + 1, dtype=np.float32)
    expected[STRIDE_ACTION] = -0.6
    np.testing.assert_array_equal(env.action(np.int64(3)), expected)
    np.testing.assert_array_equal(env.action(np.array([0])), np.zeros_like(expected))
    with pytest.raises(ValueError, match=r"stride choice 5 is not in 0\.\.4"):
        env.action(5)


@pytest.mark.parametrize(
    ("kwargs", "values", "match"),
    [
        ({}, VALUES, "stride_action=True, got HexapodDitchCrossing-v1"),
        ({"stride_action": True}, VALUES, "residual_limb_m=0 and residual_leg_m=0"),
        (STRIDES, [0.0, 0.5], r"lie in \[-1, 0\]"),
        (STRIDES, [0.0, float("nan")], r"lie in \[-1, 0\]"),
        (STRIDES, [0.0, -0.2, 0.0], "must differ"),
        (STRIDES, [0.0], "at least 2 values"),
    ],
)
def test_other_envs_residuals_and_bad_values_are_refused_by_name(kwargs, values, match):
    env = gym.make(ENV_ID, **kwargs)
    with pytest.raises(ValueError, match=match):
        StrideChoices(env, values)


def test_the_clearances_follow_the_observation_and_rank_choices_as_the_rule_does():
    """On a test ditch the clear-stride rule drives: the wrapped observation is the plain one
    and one value per choice in [-0.3, 0.3] m; the chosen value's is where the env then plans
    the moving feet (world frame, its own ditch), and the rule takes the longest choice whose
    value is >= 0 (every foot clear), or the largest value where none is."""
    kwargs = {**STRIDES, "task_distribution": "test", "max_episode_steps": None}
    env = StrideClearances(gym.make(ENV_ID, **kwargs), VALUES)
    plain = env.env
    rule = ClearStridePolicy(plain, values=VALUES)
    n = plain.observation_space.shape[0]
    assert env.observation_space.shape == (n + 5,)
    obs, _ = env.reset(seed=1)
    flag = plain.unwrapped.observation_layout.slices["stride_decision"].start + 1
    base = plain.unwrapped
    done, decisions, shortened = False, 0, 0
    while not done:
        assert env.observation_space.contains(obs)
        clearances, action = obs[n:], rule(obs[:n])
        np.testing.assert_array_equal(clearances, env.clearances(obs[:n]))
        decided = obs[flag] == 1.0
        if decided:
            upper_next = obs[env._decision][0] > 0.5
            strides, _ = env.geometry.candidates(obs[env._ahead], upper_next, VALUES)
            clear = np.flatnonzero(clearances >= 0)
            expected = strides[clear].max() if clear.size else strides[np.argmax(clearances)]
            stride = env.geometry.max_stride * (1.0 + action[STRIDE_ACTION])
            assert stride == pytest.approx(expected, abs=1e-6)
            decisions += 1
            shortened += expected < strides[0]
        obs, _, term, trunc, _ = env.step(action)
        done = term or trunc
        if decided:  # the env has just planned the step
            step, d = base.online_gait.steps[-1], base.ditch
            feet = step.end_x + env.geometry.feet_x[step.moving]
            planned = edge_clearance(
                feet, d.start_x, d.end_x, base.edge_band, d.depth <= base.params.leg_extend
            )
            k = int(np.argmin(np.abs(strides - step.stride)))
            assert clearances[k] == pytest.approx(
                np.clip(planned.min() - base.edge_band, -0.3, 0.3), abs=1e-6
            )
    assert decisions >= 15 and shortened >= 2


@pytest.mark.parametrize(
    ("kwargs", "values", "match"),
    [
        ({}, VALUES, "StrideClearances needs HexapodDitchCrossing-\\* with stride_action=True"),
        (STRIDES, [0.0, 0.5], r"lie in \[-1, 0\]"),
    ],
)
def test_clearances_refuse_other_envs_and_bad_values_by_name(kwargs, values, match):
    with pytest.raises(ValueError, match=match):
        StrideClearances(gym.make(ENV_ID, **kwargs), values)
