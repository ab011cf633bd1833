"""The warm start (`agents.warm_start`): a teacher cloned into the actor before PPO, and the
ditch's clear-stride rule (`agents.upu_stride`) that teaches the stride action."""

import json
import shutil

import gymnasium as gym
import numpy as np
import pytest
import torch
from helpers.ditch_stride_runs import WARM_CONFIG, train_tiny
from stable_baselines3 import PPO
from stable_baselines3.common.policies import ActorCriticPolicy

import hexapod_envs  # noqa: F401  (registers the ids)
from agents.pipeline import training
from agents.pipeline.callbacks import CriticFirst
from agents.pipeline.cli import train_main
from agents.ppo import PPOPolicy
from agents.run_files.artifacts import WARM_START, read_meta
from agents.run_files.step0 import write_step0_model
from agents.run_files.train_config import load_train_config
from agents.upu_stride import ClearStridePolicy
from agents.warm_start import WarmStartSettings, fit_actor, teacher_data


def _stride_env(steps=60):
    return gym.make(
        "HexapodDitchCrossing-v1",
        stride_action=True,
        task_distribution="train",
        max_episode_steps=steps,
    )


def test_the_clear_stride_rule_sets_the_stride_only_when_a_step_is_decided():
    env = _stride_env()
    policy = ClearStridePolicy(env)
    decision = env.unwrapped.observation_structure["stride_decision"]
    obs, _ = env.reset(seed=0)
    values = []
    for _ in range(60):
        action = policy(obs)
        assert not action[:9].any()
        if not obs[decision][1]:
            assert action[9] == 0.0
        else:
            values.append(action[9])
        obs, *_ = env.step(action)
    assert len(values) == 2 and all(-1.0 <= v <= 0.0 for v in values)
    with pytest.raises(ValueError, match="no stride action"):
        ClearStridePolicy(gym.make("HexapodDitchCrossing-v1"))


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"teacher": "oracle"}, r"one of \['analytical', 'clear_stride'\]"),
        ({"episodes": 0}, "episodes must be an integer >= 1"),
        ({"dagger_rounds": -1}, "dagger_rounds must be an integer >= 0"),
        ({"epochs": 2.5}, "epochs must be an integer"),
        ({"learning_rate": 0}, "learning_rate must be a number > 0"),
        ({"critic_steps": -5}, "critic_steps must be an integer >= 0"),
    ],
)
def test_bad_settings_are_refused_by_name(kwargs, message):
    with pytest.raises(ValueError, match=message):
        WarmStartSettings(**kwargs)


@pytest.mark.parametrize("override", ["hybrid={}", "env.decision=episode"])
def test_a_warm_start_needs_the_envs_own_actions(override):
    with pytest.raises(ValueError, match="warm_start clones"):
        load_train_config(WARM_CONFIG, [override, "policy.score_read_actions_only=false"])


def test_the_teachers_data_marks_the_steps_that_read_the_stride():
    data = teacher_data(lambda: _stride_env(60), "clear_stride", 2, seed=5)
    assert data.observations.shape == (120, _stride_env().observation_space.shape[0])
    decides = data.observations[:, _stride_env().unwrapped.action_read_flags[9]] == 1.0
    assert decides.sum() == 4  # steps 0 and 51 of each episode
    np.testing.assert_array_equal(data.read[:, 9], decides)
    assert np.all(data.read[:, :9] == 1.0)
    assert np.all(data.actions[~decides, 9] == 0.0) and np.all(data.actions[:, :9] == 0.0)
    assert data.episodes == 2 and data.successes == 0  # 60 steps cross nothing


def test_the_fit_follows_the_values_read_and_ignores_the_others():
    torch.manual_seed(0)
    space = gym.spaces.Box(-np.inf, np.inf, shape=(3,), dtype=np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
    policy = ActorCriticPolicy(space, action_space, lambda _: 1e-3)
    rng = np.random.default_rng(0)
    x = rng.normal(size=(512, 3))
    y = np.stack([np.tanh(x[:, 0]), np.full(512, 0.5)], axis=1)
    read = np.ones_like(y)
    read[::2, 1] = 0.0
    y[::2, 1] = -0.9  # labels on ignored steps: must not pull the fit
    settings = WarmStartSettings(epochs=200, learning_rate=3e-3, batch_size=128)
    loss = fit_actor(policy, x, y, read, settings, seed=0)
    with torch.no_grad():
        mean = policy.get_distribution(torch.as_tensor(x, dtype=torch.float32)).distribution.mean
    assert loss < 1e-3
    np.testing.assert_allclose(mean[:, 1].numpy(), 0.5, atol=0.05)
    np.testing.assert_allclose(mean[:, 0].numpy(), y[:, 0], atol=0.1)


def test_a_warm_started_run_saves_its_clone_as_its_step_0(tmp_path):
    warm = "warm_start={teacher: clear_stride, episodes: 2, epochs: 3, dagger_rounds: 1}"
    assert train_tiny(WARM_CONFIG, tmp_path, warm, "env.max_episode_steps=60") == 0
    run_dir = tmp_path / "run"
    meta = read_meta(run_dir / WARM_START)
    record = meta["warm_start"]
    assert meta["kind"] == "warm_start" and meta["num_timesteps"] == 0
    assert record["teacher_episodes"] == 2 and len(record["dagger"]) == 1
    assert record["pairs"] == 240 and record["pairs_read"][9] == 8
    step0 = write_step0_model(run_dir / "final", tmp_path / "step0")
    same = (step0 / "model.zip").read_bytes() == (run_dir / WARM_START / "model.zip").read_bytes()
    assert same
    env = _stride_env()
    start, trained = PPOPolicy.load(step0, env), PPOPolicy.load(run_dir / "final", env)
    obs, _ = env.reset(seed=0)
    assert start(obs).shape == trained(obs).shape == (10,)
    json.dumps(record)  # the summary is plain data


def test_a_run_killed_after_its_warm_start_resumes_from_the_clone(tmp_path, capsys):
    warm = "warm_start={teacher: clear_stride, episodes: 1, epochs: 1, dagger_rounds: 0}"
    assert train_tiny(WARM_CONFIG, tmp_path, warm) == 0
    run_dir = tmp_path / "run"
    for saved in ("checkpoints", "final", "best"):  # as if killed before PPO saved anything
        shutil.rmtree(run_dir / saved, ignore_errors=True)
    capsys.readouterr()
    assert train_main(["--resume", str(run_dir)]) == 0
    assert f"resuming {run_dir} from {WARM_START} at 0 steps" in capsys.readouterr().out
    meta = read_meta(run_dir / "final")
    assert meta["num_timesteps"] == 64 and (run_dir / WARM_START).is_dir()


def test_the_critic_learns_alone_until_its_steps_are_collected():
    model = PPO(
        "MlpPolicy", gym.make("Pendulum-v1"), n_steps=128, batch_size=64, n_epochs=2, seed=0
    )
    policy = model.policy
    actor = [*policy.mlp_extractor.policy_net.parameters(), *policy.action_net.parameters()]
    actor.append(policy.log_std)

    def snapshot(parameters):
        return [p.detach().clone() for p in parameters]

    def same(a, b):
        return all(torch.equal(x, y) for x, y in zip(a, b, strict=True))

    actor0, critic0 = snapshot(actor), snapshot(policy.value_net.parameters())
    model.learn(256, callback=CriticFirst(257))  # two updates, both before 257 steps
    actor1, critic1 = snapshot(actor), snapshot(policy.value_net.parameters())
    assert same(actor0, actor1) and not same(critic0, critic1)
    assert all(p.requires_grad for p in actor)  # trainable again when training ends
    model.learn(128, callback=CriticFirst(257), reset_num_timesteps=False)  # 384 steps: past it
    assert not same(actor1, snapshot(actor))


def test_a_warm_start_that_fails_closes_its_envs_and_leaves_no_run(tmp_path, monkeypatch):
    closed = []
    monkeypatch.setattr(training, "close_vec_env", lambda env, **kw: closed.append(env))

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(training, "_warm_start", interrupted)
    with pytest.raises(KeyboardInterrupt):
        train_tiny(WARM_CONFIG, tmp_path)
    assert len(closed) == 2  # the training and the evaluation vec envs
    assert not (tmp_path / "run").exists()
