"""A categorical stride learner (``env.stride_choices``) trains, loads as a policy of the plain
ditch env and starts at the full stride."""

import gymnasium as gym
import numpy as np
import pytest
from helpers.ditch_stride_runs import CHOICES_CONFIG, train_tiny

import hexapod_envs  # noqa: F401  (registers the ids)
from agents.export import actor_module
from agents.pipeline.training import untrained_model
from agents.ppo import ChosenStride, PPOPolicy
from agents.run_files.errors import UserError
from agents.run_files.train_config import load_train_config
from hexapod_envs.envs.ditch_crossing import STRIDE_ACTION

SMALL = ["policy.pi=[16]", "policy.vf=[16]"]


@pytest.mark.parametrize(
    "overrides",
    [
        ["policy.score_read_actions_only=true"],
        ["ppo.use_sde=true"],
        ["env.decision=episode"],
        ["hybrid={}"],
    ],
)
def test_configs_that_need_the_envs_own_action_are_refused(overrides):
    with pytest.raises(ValueError, match="stride_choices replaces the env's action"):
        load_train_config(CHOICES_CONFIG, overrides)


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
    assert action[STRIDE_ACTION] in config.env.stride_choices
    residuals = gym.make("HexapodDitchCrossing-v1", task_distribution="train", stride_action=True)
    with pytest.raises(UserError, match="residual_limb_m=0 and residual_leg_m=0"):
        PPOPolicy.load(tmp_path / "run", residuals)
