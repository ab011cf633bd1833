"""A categorical stride learner (``env.stride_choices``) trains, loads as a policy of the plain
ditch env and starts at the full stride."""

import gymnasium as gym
import numpy as np
import pytest
from helpers.ditch_stride_runs import CHOICES_CONFIG, train_tiny

import hexapod_envs  # noqa: F401  (registers the ids)
from agents.export import actor_module, export_model
from agents.pipeline.training import untrained_model
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
    """The run's config says the model saw each choice's clearance: the loaded policy appends
    them to the plain env's observation; without that key the shapes disagree, by name."""
    assert train_tiny(CHOICES_CONFIG, tmp_path, "env.stride_clearances=true") == 0
    env = gym.make("HexapodDitchCrossing-v1", **load_train_config(CHOICES_CONFIG).env.kwargs)
    policy = PPOPolicy.load(tmp_path / "run", env)
    assert isinstance(policy, ChosenStride) and policy.clearances is not None
    obs, _ = env.reset(seed=0)
    assert policy.clearances.observation(obs).shape == (obs.size + 5,)
    assert policy(obs)[STRIDE_ACTION] in np.float32(
        load_train_config(CHOICES_CONFIG).env.stride_choices
    )
    for config in (tmp_path / "run").rglob("config.yaml"):  # the run's and each model's
        config.write_text(config.read_text().replace("clearances: true", "clearances: false"))
    with pytest.raises(UserError, match=r"expects observation shape \(\d+,\)"):
        PPOPolicy.load(tmp_path / "run", env)
