"""PPO that scores an action value only where the env reads it (`agents.read_actions`)."""

import gymnasium as gym
import numpy as np
import pytest
import torch
from helpers.ditch_stride_runs import CONFIGS, READ_CONFIG, train_tiny
from stable_baselines3.common.policies import ActorCriticPolicy

import hexapod_envs  # noqa: F401  (registers the ids)
from agents.pipeline.cli import train_main
from agents.pipeline.training import check_env, untrained_model
from agents.pipeline.zoo import zoo_unsupported
from agents.ppo import PPOPolicy
from agents.privileged_critic import PRIVILEGED_DIM
from agents.privileged_critic_policy import PrivilegedCriticPolicy
from agents.read_actions import ReadActionsMlpPolicy, ReadActionsPrivilegedPolicy
from agents.run_files.errors import UserError
from agents.run_files.train_config import load_train_config

STRIDE_LANDING_CONFIG = CONFIGS / "ditch_crossing_v1_ppo_stride_landing.yaml"
OBS = gym.spaces.Box(-np.inf, np.inf, shape=(4,), dtype=np.float32)
ACT = gym.spaces.Box(-1.0, 1.0, shape=(3,), dtype=np.float32)


def _policies():
    """A scoring policy (action 2 read where observation 3 > 0) and a plain one, same weights."""
    torch.manual_seed(0)
    scoring = ReadActionsMlpPolicy(OBS, ACT, lambda _: 1e-3, log_std_init=-1.0)
    scoring.set_action_read_flags({2: 3})
    plain = ActorCriticPolicy(OBS, ACT, lambda _: 1e-3, log_std_init=-1.0)
    plain.load_state_dict(scoring.state_dict())
    return scoring, plain


def _batch():
    obs = torch.tensor(
        [[0.1, -0.2, 0.3, 7.1], [0.4, 0.0, -0.5, -0.14], [0.2, 0.2, 0.2, 0.0]]
    )  # flags set (a standardised 1), unset (a standardised 0), unset (raw 0)
    actions = torch.tensor([[0.1, -0.3, 0.5], [0.2, 0.2, -0.9], [-0.4, 0.0, 0.3]])
    return obs, actions


def test_a_read_value_counts_and_an_ignored_one_does_not():
    scoring, plain = _policies()
    obs, actions = _batch()
    values, log_prob, entropy = scoring.evaluate_actions(obs, actions)
    plain_values, plain_log_prob, plain_entropy = plain.evaluate_actions(obs, actions)
    torch.testing.assert_close(values, plain_values)
    torch.testing.assert_close(log_prob[0], plain_log_prob[0])  # read: every value
    torch.testing.assert_close(entropy[0], plain_entropy[0])
    normal = plain.get_distribution(obs).distribution
    first_two = normal.log_prob(actions)[:, :2].sum(dim=1)
    torch.testing.assert_close(log_prob[1:], first_two[1:])  # ignored: the first two only
    torch.testing.assert_close(entropy[1:], normal.entropy()[1:, :2].sum(dim=1))


def test_an_ignored_value_puts_nothing_into_its_gradient():
    scoring, _ = _policies()
    obs, actions = _batch()
    _, log_prob, _ = scoring.evaluate_actions(obs[1:], actions[1:])
    log_prob.sum().backward()
    assert torch.all(scoring.action_net.weight.grad[2] == 0.0)
    assert scoring.log_std.grad[2] == 0.0
    assert torch.all(scoring.action_net.weight.grad[:2] != 0.0)


def test_forward_samples_as_ever_and_scores_like_evaluate_actions():
    scoring, plain = _policies()
    obs, _ = _batch()
    torch.manual_seed(1)
    actions, values, log_prob = scoring(obs)
    torch.manual_seed(1)
    plain_actions, plain_values, _ = plain(obs)
    torch.testing.assert_close(actions, plain_actions)  # acting is unchanged
    torch.testing.assert_close(values, plain_values)
    torch.testing.assert_close(log_prob, scoring.evaluate_actions(obs, actions)[1])


def test_the_privileged_critic_form_matches_its_plain_policy_where_the_values_are_read():
    """The actor and the critic with separate features (`PrivilegedCriticPolicy`)."""
    space = gym.spaces.Box(-np.inf, np.inf, shape=(4 + PRIVILEGED_DIM,), dtype=np.float32)
    torch.manual_seed(0)
    scoring = ReadActionsPrivilegedPolicy(space, ACT, lambda _: 1e-3)
    scoring.set_action_read_flags({2: 3})
    plain = PrivilegedCriticPolicy(space, ACT, lambda _: 1e-3)
    plain.load_state_dict(scoring.state_dict())
    obs, actions = _batch()
    obs = torch.cat([obs, torch.linspace(-1, 1, PRIVILEGED_DIM).expand(3, -1)], dim=1)
    values, log_prob, _ = scoring.evaluate_actions(obs, actions)
    plain_values, plain_log_prob, _ = plain.evaluate_actions(obs, actions)
    torch.testing.assert_close(values, plain_values)
    torch.testing.assert_close(log_prob[0], plain_log_prob[0])
    per_value = plain.get_distribution(obs).distribution.log_prob(actions)
    torch.testing.assert_close(log_prob[1:], per_value[1:, :2].sum(dim=1))


def test_an_inert_value_counts_nowhere():
    scoring, plain = _policies()
    scoring.set_action_read_flags({2: 3}, inert=[0])
    obs, actions = _batch()
    _, log_prob, entropy = scoring.evaluate_actions(obs, actions)
    normal = plain.get_distribution(obs).distribution
    per_value = normal.log_prob(actions)
    torch.testing.assert_close(log_prob[0], per_value[0, 1:].sum())  # flag set: values 1, 2
    torch.testing.assert_close(log_prob[1:], per_value[1:, 1])  # flag unset: value 1 alone
    torch.testing.assert_close(entropy[1:], normal.entropy()[1:, 1])
    (-log_prob.sum()).backward()
    assert scoring.log_std.grad[0] == 0.0 and scoring.log_std.grad[1] != 0.0


def test_flags_outside_the_spaces_and_a_state_dependent_noise_are_refused():
    scoring, _ = _policies()
    with pytest.raises(ValueError, match="outside the 3 action values or the 4 observation"):
        scoring.set_action_read_flags({3: 0})
    with pytest.raises(ValueError, match="inert action values"):
        scoring.set_action_read_flags({2: 3}, inert=[3])
    with pytest.raises(ValueError, match="leave at least one"):
        scoring.set_action_read_flags({}, inert=[0, 1, 2])
    with pytest.raises(ValueError, match="both flagged and inert"):
        scoring.set_action_read_flags({2: 3}, inert=[2])
    with pytest.raises(ValueError, match="diagonal Gaussian"):
        ReadActionsMlpPolicy(OBS, ACT, lambda _: 1e-3, use_sde=True)


@pytest.mark.parametrize(
    "overrides",
    [
        ["ppo.use_sde=true"],
        ["hybrid={}"],
        ["knobs={}", "policy.critic_privileged=false"],
        ["env.decision=episode"],
    ],
)
def test_configs_that_change_the_action_or_its_noise_are_refused(overrides):
    with pytest.raises(ValueError, match="score_read_actions_only"):
        load_train_config(READ_CONFIG, overrides)


def test_the_zoo_names_the_option_it_cannot_train():
    config = load_train_config(READ_CONFIG, ["policy.critic_privileged=false"])
    assert "score_read_actions_only" in zoo_unsupported(config)


def test_a_run_trains_and_resumes_with_the_flags_and_loads_as_a_plain_policy(tmp_path, monkeypatch):
    told = []
    original = ReadActionsPrivilegedPolicy.set_action_read_flags

    def spy(self, flags, inert=()):
        told.append((dict(flags), tuple(inert)))
        original(self, flags, inert)

    monkeypatch.setattr(ReadActionsPrivilegedPolicy, "set_action_read_flags", spy)
    assert train_tiny(READ_CONFIG, tmp_path) == 0
    run_dir = tmp_path / "run"
    assert train_main(["--resume", str(run_dir), "--set", "train.total_timesteps=128"]) == 0
    env = gym.make("HexapodDitchCrossing-v1", stride_action=True)
    flag = env.unwrapped.observation_structure["stride_decision"].start + 1
    assert told == [({9: flag}, ()), ({9: flag}, ())]  # the residuals act: none inert
    policy = PPOPolicy.load(run_dir, env)
    obs, _ = env.reset(seed=0)
    assert policy(obs).shape == (10,)


def test_a_new_model_is_told_the_envs_flags():
    config = load_train_config(READ_CONFIG, ["policy.pi=[16]", "policy.vf=[16]"])
    model, _ = untrained_model(config)
    flag = model.get_env().get_attr("observation_structure")[0]["stride_decision"].start + 1
    assert isinstance(model.policy, ReadActionsPrivilegedPolicy)
    assert model.policy.action_read_flags == {9: flag}
    assert model.policy.inert_actions == ()
    model.get_env().close()


def test_a_stride_learner_per_platform_step_leaves_the_inert_residuals_out():
    config = load_train_config(STRIDE_LANDING_CONFIG, ["policy.pi=[16]", "policy.vf=[16]"])
    assert config.env.decision == "gait_cycle" and config.policy.score_read_actions_only
    model, _ = untrained_model(config)
    assert model.policy.inert_actions == tuple(range(9))  # residual ranges of 0
    model.get_env().close()


def test_an_env_that_reads_every_value_is_refused_by_name_before_a_run_starts(tmp_path, capsys):
    assert train_tiny(READ_CONFIG, tmp_path, "env.kwargs={task_distribution: train}") == 2
    assert "reads every action value on every step" in capsys.readouterr().err
    assert not (tmp_path / "run").exists()
    config = load_train_config(READ_CONFIG, ["env.kwargs={task_distribution: train}"])
    with pytest.raises(UserError, match="nothing to leave out"):
        check_env(config)  # what a sweep runs before it starts Ray
    inert = "env.kwargs={task_distribution: train, residual_limb_m: 0.0, residual_leg_m: 0.0}"
    with pytest.raises(UserError, match=r"reads none of its action values \(all inert"):
        check_env(load_train_config(READ_CONFIG, [inert]))
