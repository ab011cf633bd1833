"""PPO without credit for the actions a safety override discarded (`hybrid.mask_overridden`):
the buffer's advantages, the config check, and a training run whose every action is overridden
and whose policy therefore does not move."""

import gymnasium as gym
import numpy as np
import pytest
import torch
import yaml
from helpers.stewart_hybrid_runs import STEWART, train
from stable_baselines3.common.buffers import RolloutBuffer

from agents.pipeline.override_mask import OverrideMaskedRolloutBuffer
from agents.run_files.model_files import load_ppo, ppo_custom_objects
from agents.run_files.train_config import load_train_config


def _filled(cls, rng, **kwargs):
    obs = gym.spaces.Box(-1.0, 1.0, (3,))
    act = gym.spaces.Box(-1.0, 1.0, (2,))
    buffer = cls(16, obs, act, gae_lambda=0.9, gamma=0.95, n_envs=2, **kwargs)
    for _ in range(16):
        buffer.add(
            rng.normal(size=(2, 3)),
            rng.normal(size=(2, 2)),
            rng.normal(size=2),
            rng.random(2) < 0.1,
            torch.as_tensor(rng.normal(size=(2, 1))),
            torch.as_tensor(rng.normal(size=2)),
        )
    return buffer


def test_overridden_steps_get_no_advantage_and_the_rest_are_normalised():
    plain = _filled(RolloutBuffer, np.random.default_rng(0))
    masked = _filled(OverrideMaskedRolloutBuffer, np.random.default_rng(0))
    masked.overridden[::3] = True
    last, dones = torch.zeros(2), np.zeros(2)
    plain.compute_returns_and_advantage(last, dones)
    masked.compute_returns_and_advantage(last, dones)
    np.testing.assert_array_equal(masked.returns, plain.returns)  # the value targets: unchanged
    kept = ~masked.overridden
    assert not masked.advantages[~kept].any()
    raw = plain.advantages[kept]
    np.testing.assert_allclose(masked.advantages[kept], (raw - raw.mean()) / raw.std(), rtol=1e-5)


def test_masking_without_an_override_is_refused():
    with pytest.raises(ValueError, match="hybrid.mode=safety or hybrid.safety_filter=true"):
        load_train_config(STEWART, ["hybrid.mask_overridden=true"])


def test_masking_per_gait_cycle_is_refused():
    overrides = ["hybrid.mode=safety", "hybrid.mask_overridden=true", "env.decision=gait_cycle"]
    with pytest.raises(ValueError, match="needs env.decision: step"):
        load_train_config(STEWART, overrides)


def _action_net(run):
    config = load_train_config(data=yaml.safe_load((run / "config.yaml").read_text()))
    env = gym.make("HexapodStewartTilt-v0")
    box = gym.spaces.Box(-1.0, 1.0, env.action_space.shape, env.action_space.dtype)
    objects = ppo_custom_objects(config.policy.policy_kwargs(), env.observation_space, box)
    policy = load_ppo(run / "final" / "model.zip", objects).policy
    return torch.cat([p.detach().ravel() for p in policy.action_net.parameters()])


@pytest.mark.parametrize("mask", [True, False])
def test_an_always_overridden_policy_learns_nothing_only_when_masked(tmp_path, mask):
    """With ξ = 90 deg the recovery acts at every step; masked, the action mean stays at its
    zero start; unmasked, PPO moves it on noise."""
    always = ["hybrid.mode=safety", "hybrid.threshold_deg=90", "ppo.learning_rate=1e-3"]
    run = train(tmp_path, "run", *always, f"hybrid.mask_overridden={str(mask).lower()}")
    moved = float(_action_net(run).abs().max())
    assert (moved == 0.0) if mask else (moved > 0.0)


class _FlagEveryThirdStep(gym.Wrapper):
    """Reports ``info["safety_override"]`` on every third step, counted from the env's start."""

    def __init__(self, env):
        super().__init__(env)
        self.count = 0

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self.count += 1
        return obs, reward, terminated, truncated, {**info, "safety_override": self.count % 3 == 0}


def test_the_buffer_flags_exactly_the_overridden_steps():
    """`RecordOverrides` writes each step's flag into the row SB3 stores that step's action in:
    with mixed flags, a shifted or a constant record shows."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback

    from agents.pipeline.override_mask import RecordOverrides, masked_ppo_kwargs

    class KeepFlags(BaseCallback):
        def _on_step(self) -> bool:
            return True

        def _on_rollout_end(self) -> None:
            self.flags = self.model.rollout_buffer.overridden[:, 0].copy()

    env = _FlagEveryThirdStep(gym.make("Pendulum-v1"))
    model = PPO("MlpPolicy", env, n_steps=32, batch_size=32, n_epochs=1, **masked_ppo_kwargs(True))
    keep = KeepFlags()
    model.learn(32, callback=[RecordOverrides(), keep])
    np.testing.assert_array_equal(keep.flags, [(k + 1) % 3 == 0 for k in range(32)])
