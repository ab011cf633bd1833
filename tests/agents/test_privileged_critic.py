"""The asymmetric actor-critic: what the critic sees, and that the actor does not see it."""

import gymnasium as gym
import numpy as np
import pytest
import torch
from helpers.cliff_ppo_runs import TINY, train
from stable_baselines3 import PPO

import hexapod_envs  # noqa: F401  (registers the ids)
from agents.export import export_model
from agents.pipeline.cli import train_main
from agents.ppo import PPOPolicy
from agents.privileged_critic import (
    PRIVILEGED_DIM,
    TASK_SLOTS,
    PrivilegedObservation,
    pad_observation,
    task_code,
)
from agents.privileged_critic_policy import PrivilegedCriticPolicy


def _cliff(limit=1500):
    env = gym.make("HexapodCliffWalk-v1", task_distribution="train")
    return PrivilegedObservation(env, limit)


def test_the_observation_ends_with_the_task_and_the_elapsed_share():
    env = _cliff(limit=4)
    n = env.env.observation_space.shape[0]
    assert env.observation_space.shape == (n + PRIVILEGED_DIM,)
    obs, info = env.reset(seed=3)
    task = info["task"]
    keys = sorted(task)
    assert env.task_keys == keys
    np.testing.assert_array_equal(obs[n : n + len(keys)], [task_code(task[k]) for k in keys])
    assert obs[n + keys.index("cliff_x")] == pytest.approx(task["cliff_x"])
    assert np.all(obs[n + len(keys) : n + TASK_SLOTS] == 0.0)
    shares = [obs[-1]]
    for _ in range(4):
        obs = env.step(np.zeros(18))[0]
        shares.append(obs[-1])
    np.testing.assert_allclose(shares, [0.0, 0.25, 0.5, 0.75, 1.0])
    second, info = env.reset(seed=4)
    assert second[-1] == 0.0
    assert second[n + keys.index("cliff_x")] == pytest.approx(info["task"]["cliff_x"])


def test_task_codes():
    assert task_code(True) == 1.0 and task_code(2) == 2.0 and task_code(float("nan")) == 0.0
    assert task_code("left") != task_code("right")
    assert 0.0 <= task_code("left") < 1.0
    assert task_code((1, 2)) == 0.0


def test_bad_settings_are_refused():
    env = gym.make("HexapodCliffWalk-v1")
    with pytest.raises(ValueError, match="time limit"):
        PrivilegedObservation(env, 0)
    wrapped = PrivilegedObservation(env, 10)
    too_many = {f"p{i}": 1.0 for i in range(TASK_SLOTS + 1)}
    wrapped.env.reset = lambda **kw: (np.zeros(env.observation_space.shape), {"task": too_many})
    with pytest.raises(ValueError, match="room for"):
        wrapped.reset()


def test_the_actor_ignores_the_privileged_values_and_the_critic_reads_them():
    env = _cliff()
    model = PPO(PrivilegedCriticPolicy, env, n_steps=64, batch_size=32, seed=0)
    obs = np.zeros(env.observation_space.shape)  # raw observations would saturate the tanh layers
    obs[:5] = 0.3
    other = obs.copy()
    other[-PRIVILEGED_DIM:] += np.linspace(0.1, 0.5, PRIVILEGED_DIM)
    policy = model.policy
    means, values = [], []
    with torch.no_grad():
        for o in (obs, other):  # one call each: a batch may round its rows differently
            batch = torch.as_tensor(o[None])
            means.append(policy.get_distribution(batch).distribution.mean)
            values.append(policy.predict_values(batch).item())
    torch.testing.assert_close(means[0], means[1], rtol=0, atol=0)
    assert values[0] != values[1]
    reference = PPO("MlpPolicy", env, n_steps=64, batch_size=32, seed=0).policy
    assert policy.state_dict().keys() == reference.state_dict().keys()
    padded = pad_observation(obs[:-PRIVILEGED_DIM])
    assert padded.shape == obs.shape and np.all(padded[-PRIVILEGED_DIM:] == 0.0)


def test_a_run_with_the_privileged_critic_trains_on_the_batched_env(tmp_path):
    """The task is appended inside each env's wrappers, which the batched adapter steps as
    DummyVecEnv does (their transitions compared: tests/agents/pipeline)."""
    batched = ["env.vectorization=batched", "vec_env.n_envs=2", "vec_env.physics_threads=2"]
    assert train(tmp_path, "run", overrides=[*TINY, "policy.critic_privileged=true", *batched]) == 0
    assert (tmp_path / "run" / "final" / "model.zip").is_file()


def test_a_run_trains_resumes_loads_and_exports_with_the_privileged_critic(tmp_path):
    """train.py with policy.critic_privileged, then --resume, PPOPolicy on the raw env (padded
    with zeros) and the ONNX actor (which takes the sensor observation)."""
    assert train(tmp_path, "run", overrides=[*TINY, "policy.critic_privileged=true"]) == 0
    run_dir = tmp_path / "run"
    resumed = ["--resume", str(run_dir), "--set", "train.total_timesteps=1536"]
    assert train_main(resumed) == 0
    env = gym.make("HexapodCliffWalk-v0")
    policy = PPOPolicy.load(run_dir, env)
    assert policy.privileged_critic
    obs, _ = env.reset(seed=0)
    padded = policy.stats.normalize_obs(pad_observation(obs))
    expected, _ = policy.model.predict(padded, deterministic=True)
    np.testing.assert_array_equal(policy(obs), expected)
    onnxruntime = pytest.importorskip("onnxruntime")
    exported = export_model(run_dir, tmp_path / "actor.onnx")
    session = onnxruntime.InferenceSession(str(exported.onnx))
    (action,) = session.run(None, {"observation": obs[None].astype(np.float64)})
    np.testing.assert_allclose(action[0], expected, rtol=0, atol=1e-5)
