"""A categorical stride learner (``env.stride_choices``) trains, loads as a policy of the plain
ditch env and starts at the full stride."""

from dataclasses import replace

import gymnasium as gym
import numpy as np
import pytest
import torch
from helpers.ditch_stride_runs import CHOICES_CONFIG, train_tiny
from stable_baselines3.common.utils import obs_as_tensor

import hexapod_envs  # noqa: F401  (registers the ids)
from agents.export import actor_module, export_model
from agents.pipeline.training import env_spec, untrained_model
from agents.ppo import ChosenStride, PPOPolicy
from agents.run_files.errors import UserError
from agents.run_files.train_config import load_train_config
from hexapod_envs.envs.ditch_crossing import STRIDE_ACTION

SMALL = ["policy.pi=[16]", "policy.vf=[16]"]


@pytest.mark.parametrize(
    ("overrides", "named"),
    [
        (["policy.score_read_actions_only=true"], "policy.score_read_actions_only: true"),
        (["ppo.use_sde=true"], "ppo.use_sde: true"),
        (["env.decision=step"], "env.decision: step (use gait_cycle)"),
        (["hybrid={}"], "a hybrid section"),
    ],
)
def test_configs_that_need_the_envs_own_action_are_refused_by_name(overrides, named):
    with pytest.raises(ValueError, match="does not go with") as error:
        load_train_config(CHOICES_CONFIG, overrides)
    assert named in str(error.value)


def test_choices_that_do_not_start_at_the_full_stride_are_refused():
    with pytest.raises(ValueError, match=r"must start with 0.0, the full stride.*\[-0.5, 0.0\]"):
        load_train_config(CHOICES_CONFIG, ["env.stride_choices=[-0.5, 0.0]"])


def test_an_untrained_model_chooses_the_full_stride_and_samples_every_value():
    config = load_train_config(CHOICES_CONFIG, SMALL)
    model, _ = untrained_model(config)
    venv = model.get_env()
    obs = venv.reset()
    assert model.action_space == gym.spaces.Discrete(5)
    assert model.predict(obs, deterministic=True)[0].tolist() == [0]  # the full stride
    sampled = {int(model.predict(obs, deterministic=False)[0][0]) for _ in range(60)}
    assert sampled == set(range(5))
    with pytest.raises(UserError, match="Discrete action space"):
        actor_module(model, None)  # ONNX export: Gaussian actions only
    venv.close()


def test_a_run_trains_and_loads_as_a_policy_of_the_plain_env_only(tmp_path):
    assert train_tiny(CHOICES_CONFIG, tmp_path) == 0
    config = load_train_config(CHOICES_CONFIG)
    env = gym.make("HexapodDitchCrossing-v1", **config.env.kwargs)
    policy = PPOPolicy.load(tmp_path / "run", env)
    assert isinstance(policy, ChosenStride)
    obs, _ = env.reset(seed=0)
    action = policy(obs)
    assert action.shape == (STRIDE_ACTION + 1,) and not np.any(action[:STRIDE_ACTION])
    assert np.isclose(config.env.stride_choices, action[STRIDE_ACTION]).sum() == 1
    with pytest.raises(UserError, match=r"chooses among stride values \(env.stride_choices"):
        export_model(tmp_path / "run", tmp_path / "actor.onnx")
    assert not (tmp_path / "actor.onnx").exists()
    residuals = gym.make("HexapodDitchCrossing-v1", task_distribution="train", stride_action=True)
    with pytest.raises(UserError, match="residual_limb_m=0 and residual_leg_m=0"):
        PPOPolicy.load(tmp_path / "run", residuals)


def test_clearances_need_stride_choices():
    with pytest.raises(ValueError, match="env.stride_clearances .* needs env.stride_choices"):
        load_train_config(CHOICES_CONFIG, ["env.stride_choices=null", "env.stride_clearances=true"])


def test_a_run_with_clearances_loads_seeing_them(tmp_path):
    """The run's config says the model saw each choice's clearance: on the plain env the loaded
    policy's actor gets exactly the training env's observation (clearances inside the
    privileged critic's values, which the actor ignores); without that key the shapes
    disagree, by name."""
    assert train_tiny(CHOICES_CONFIG, tmp_path, "env.stride_clearances=true") == 0
    config = load_train_config(CHOICES_CONFIG, ["env.stride_clearances=true"])
    env = gym.make("HexapodDitchCrossing-v1", **config.env.kwargs)
    training = replace(env_spec(config), decision="step").make()  # as the evaluations run
    policy = PPOPolicy.load(tmp_path / "run", env)
    assert isinstance(policy, ChosenStride) and policy.clearances is not None
    learned = policy.learned
    with torch.no_grad():  # a tiny run's logits barely move: make every actor input count
        torch.manual_seed(0)
        learned.model.policy.action_net.weight.normal_()
    seen, chosen = [], []  # what the actor got and chose through the load path
    predict = learned.model.predict

    def recorded(obs, **kwargs):
        seen.append(obs)
        chosen.append(predict(obs, **kwargs)[0])
        return chosen[-1], None

    learned.model.predict = recorded
    obs, _ = env.reset(seed=3)
    obs_training, _ = training.reset(seed=3)
    assert policy.clearances.observation(obs).shape == (obs.size + 5,)
    for _ in range(60):
        action = policy(obs)
        assert action[STRIDE_ACTION] in np.float32(config.env.stride_choices)
        logits = [
            learned.model.policy.get_distribution(obs_as_tensor(o[None], "cpu")).distribution.logits
            for o in (seen[-1], learned.stats.normalize_obs(obs_training))
        ]
        np.testing.assert_array_equal(*(x.detach().numpy() for x in logits))
        obs = env.step(action)[0]
        obs_training = training.step(int(chosen[-1]))[0]
    for config_file in (tmp_path / "run").rglob("config.yaml"):  # the run's and each model's
        text = config_file.read_text().replace("clearances: true", "clearances: false")
        config_file.write_text(text)
    with pytest.raises(UserError, match=r"expects observation shape \(\d+,\)"):
        PPOPolicy.load(tmp_path / "run", env)
