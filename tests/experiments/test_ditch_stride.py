"""experiments/ditch_stride/rules.py: stride rules through the ditch env's stride action."""

import gymnasium as gym
import numpy as np
import pytest

from agents.upu_stride import ClearStridePolicy
from experiments.ditch_stride.policy_strides import STRIDE_ENV, compare, summary
from experiments.ditch_stride.rules import ENV_ID, StrideRule, run


def test_the_greedy_rule_reads_the_observation_and_crosses_where_full_strides_tip():
    greedy = run("greedy", "train", 2)  # training ditches 0 and 1: the full stride tips on both
    full = run("full", "train", 2)
    assert [r["success"] for r in greedy] == [True, True]
    assert [r["tipped"] for r in full] == [True, True]


def test_the_greedy_rule_among_a_few_values_chooses_only_those_and_crosses():
    """Among a categorical learner's five values (env.stride_choices): training ditches 0 and
    1 crossed; on ditch 1 every stride is one of the values' (full, 80 % and 60 % of it)."""
    values = [0.0, -0.2, -0.4, -0.6, -0.8]
    assert [r["success"] for r in run("greedy", "train", 2, values)] == [True, True]
    env = gym.make(ENV_ID, stride_action=True, task_distribution="train")
    policy = StrideRule(env, "greedy", values=values)
    obs, _ = env.reset(seed=1)
    done = False
    while not done:
        obs, _, terminated, truncated, _ = env.step(policy(obs))
        done = terminated or truncated
    strides = np.array([s.stride for s in env.unwrapped.online_gait.steps])
    np.testing.assert_allclose(np.unique(strides.round(9)), [0.096, 0.128, 0.16], atol=1e-9)
    for bad in ([], [0.0, 0.5]):
        with pytest.raises(ValueError, match=r"a non-empty list in \[-1, 0\]"):
            ClearStridePolicy(env, bad)


def test_a_rule_sets_the_stride_value_only_when_a_step_is_decided():
    env = gym.make(ENV_ID, stride_action=True, task_distribution="train")
    policy = StrideRule(env, "random", seed=1)
    obs, _ = env.reset(seed=0)
    decision = env.unwrapped.observation_structure["stride_decision"]
    for _ in range(60):
        action = policy(obs)
        assert action.shape == (10,) and not action[:9].any()
        assert (action[9] != 0) == bool(obs[decision][1])  # a random value is never exactly 0
        obs, *_ = env.step(action)
    assert np.all([-1 <= s.stride / 0.16 - 1 <= 0 for s in env.unwrapped.online_gait.steps])


def test_policy_strides_compares_a_policy_with_the_rule_at_the_rules_decisions():
    env = gym.make(ENV_ID, **STRIDE_ENV)
    rule = compare(ClearStridePolicy(env), env, [101])
    assert len(rule.rule_short) >= 3 and len(rule.full) >= 5
    np.testing.assert_array_equal(rule.policy_short, rule.rule_short)  # the rule against itself
    np.testing.assert_allclose(rule.full, 0.0, atol=1e-12)  # the rule's full strides, rounded
    zero = compare(lambda obs: np.zeros(10, dtype=np.float32), env, [101])
    np.testing.assert_array_equal(zero.rule_short, rule.rule_short)  # the same decisions
    assert (zero.policy_short == 0.0).all()
    assert "policy shortens 0" in summary(zero)


def test_held_out_factors_changes_one_range_and_plays_both_policies(tmp_path):
    from helpers.ditch_stride_runs import CHOICES_CONFIG, train_tiny

    from experiments.ditch_stride.held_out_factors import factor_rows, ranges_with
    from hexapod_envs.envs.ditch_crossing import DITCH_TEST, DITCH_TRAIN

    wide = ranges_with("width")
    assert wide["width"] == DITCH_TEST.width and wide["depth"] == DITCH_TRAIN.depth
    assert ranges_with("none")["width"] == DITCH_TRAIN.width
    assert train_tiny(CHOICES_CONFIG, tmp_path) == 0
    (row,) = factor_rows(str(tmp_path / "run"), ["width"], 1)
    assert row["factor"] == "width" and len(row["policy"]) == len(row["full"]) == 2
    assert row["full"] == (0, 1)  # full strides tip over on this task (a test-range width)
