"""Training on the batched vector env (``env.vectorization: batched``): the SB3 adapter returns
what DummyVecEnv returns, the config key is checked, and a run trains, evaluates, saves and
resumes on it."""

from __future__ import annotations

import io
import zipfile

import numpy as np
import pytest
import torch
from helpers.cliff_ppo_runs import CONFIG, TINY, meta, train
from stable_baselines3.common.vec_env import DummyVecEnv

from agents.pipeline.batched_vec_env import BatchedDummyVecEnv, make_batched_vec_env
from agents.pipeline.cli import train_main
from agents.pipeline.envs import EnvFactory, EnvSpec
from agents.run_files.errors import ConfigError
from agents.run_files.train_config import load_train_config

TIPPING = EnvSpec(
    "HexapodStewartTilt-v1",
    {"task_distribution": "train", "tilt_start_time": 0.2},
    max_episode_steps=150,
    gym_packages=["hexapod_envs"],
)
"""Held on a tripod on a platform that starts tilting at once: episodes end by tipping over
(within about 200 steps) and by the time limit."""


def _same(a, b, where):
    if isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for key in a:
            if key != "t":  # Monitor's episode wall-clock time
                _same(a[key], b[key], f"{where}[{key!r}]")
    elif isinstance(a, np.ndarray):
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f") and a.dtype == b.dtype, where
    elif isinstance(a, list | tuple):
        assert len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            _same(x, y, f"{where}[{k}]")
    else:
        assert a == b or (a != a and b != b), where


WALKING = EnvSpec(
    "HexapodCliffWalk-v1",
    {"task_distribution": "train"},
    max_episode_steps=60,
    gym_packages=["hexapod_envs"],
    privileged_critic=True,
    stability_penalty=0.5,
    progress_penalty=0.2,
)
"""The v1 PPO configs' wrappers: the task appended for the critic, the stability rule's
penalties (a reward wrapper that reads each step's info)."""


@pytest.mark.parametrize("spec", [TIPPING, WALKING], ids=["tipping", "privileged_penalised"])
def test_adapter_returns_what_dummy_vec_env_returns(spec):
    batched = make_batched_vec_env(spec, 3, seed=5, nthread=2)
    dummy = DummyVecEnv([EnvFactory(spec) for _ in range(3)])
    dummy.seed(5)
    _same(batched.reset(), dummy.reset(), "reset")
    rng = np.random.default_rng(0)
    dones = 0
    for k in range(320):
        actions = rng.uniform(-1, 1, (3, 18)).astype(np.float32)
        got, expected = batched.step(actions), dummy.step(actions)
        _same(got, expected, f"step {k}")
        dones += int(got[2].sum())
    assert dones >= 3  # same-step resets with terminal observations and Monitor episodes
    assert any("episode" in info for info in got[3]) or dones
    batched.close()
    dummy.close()


def test_adapter_refuses_envs_that_are_not_hexapod_worlds():
    with pytest.raises(TypeError, match="hexapod_envs worlds"):
        BatchedDummyVecEnv([lambda: __import__("gymnasium").make("Pendulum-v1")])


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        (["env.vectorization=threads"], "valid: ['vec_env', 'batched']"),
        (["env.vectorization=batched", "vec_env.physics_threads=-1"], "physics_threads"),
        (["env.vectorization=batched", "env.decision=gait_cycle"], "env.decision: step"),
        (["env.vectorization=batched", "vec_env.type=subprocess"], "does not apply"),
    ],
)
def test_the_vectorization_key_is_checked(overrides, message):
    with pytest.raises((ConfigError, ValueError), match=message.replace("[", r"\[")):
        load_train_config(CONFIG, overrides)


def test_batched_vectorization_refuses_a_hybrid_policy():
    with pytest.raises(ValueError, match="no hybrid section"):
        load_train_config(CONFIG, ["env.vectorization=batched", "hybrid.mode=residual"])


def _policy_weights(run_dir) -> dict[str, torch.Tensor]:
    with zipfile.ZipFile(run_dir / "final" / "model.zip") as archive:
        return torch.load(io.BytesIO(archive.read("policy.pth")), weights_only=True)


def test_a_batched_run_trains_the_same_policy_as_dummy_vec_env_and_resumes(tmp_path):
    two = [*TINY, "vec_env.n_envs=2"]
    assert train(tmp_path, "dummy", overrides=[*two, "vec_env.type=dummy"]) == 0
    batched = [*two, "env.vectorization=batched", "vec_env.physics_threads=2"]
    assert train(tmp_path, "batched", overrides=batched) == 0
    # The same transitions train the same policy: two DummyVecEnv runs in one process differ by
    # up to 3e-7 (the first training of a process; later ones are bit-identical), while one
    # different transition changes the gradient of every minibatch that holds it.
    expected, got = _policy_weights(tmp_path / "dummy"), _policy_weights(tmp_path / "batched")
    assert expected.keys() == got.keys()
    for name in expected:
        torch.testing.assert_close(got[name], expected[name], rtol=0, atol=1e-5, msg=name)
    run_dir = tmp_path / "batched"
    assert (run_dir / "best").is_dir() and (run_dir / "checkpoints").is_dir()
    argv = ["--resume", str(run_dir), "--set", "train.total_timesteps=1536"]
    assert train_main(argv) == 0
    assert meta(run_dir / "final")["num_timesteps"] == 1536
    # how the envs run may change on resuming (what they are may not)
    argv = ["--resume", str(run_dir), "--set", "train.total_timesteps=2048"]
    assert train_main([*argv, "--set", "env.vectorization=vec_env"]) == 0
    assert meta(run_dir / "final")["num_timesteps"] == 2048
    assert train_main([*argv[:2], "--set", "env.max_episode_steps=50"]) == 2
