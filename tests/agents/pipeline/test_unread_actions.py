"""`ppo.score_unread_at_mean`: the action values an env did not read are stored at the
policy's mean, with the log-probabilities of the actions so changed."""

import gymnasium as gym
import numpy as np
import pytest
import torch
from stable_baselines3 import PPO

from agents.pipeline.unread_actions import ScoreUnreadAtMean
from agents.run_files.train_config import PPOConfig


class SecondValueReadEveryThirdStep(gym.Env):
    """Two action values; the second is read (and reported read) on every third step only."""

    observation_space = gym.spaces.Box(-1.0, 1.0, (3,))
    action_space = gym.spaces.Box(-1.0, 1.0, (2,))

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        return self.np_random.uniform(-1, 1, 3).astype(np.float32), {}

    def step(self, action):
        read = self.t % 3 == 0
        self.t += 1
        reward = -float(action[0] ** 2) - (float(action[1] ** 2) if read else 0.0)
        obs = self.np_random.uniform(-1, 1, 3).astype(np.float32)
        info = {"unread_actions": () if read else (1,)}
        return obs, reward, False, self.t >= 30, info


class Keep(ScoreUnreadAtMean):
    """Keeps the rollout it scored, and the rollout policy's mean and log-probabilities of the
    stored actions (before PPO's update moves the policy)."""

    def _on_rollout_end(self):
        super()._on_rollout_end()
        buffer = self.model.rollout_buffer
        self.actions, self.log_probs = buffer.actions[:, 0].copy(), buffer.log_probs[:, 0].copy()
        with torch.no_grad():
            obs = torch.as_tensor(buffer.observations[:, 0])
            dist = self.model.policy.get_distribution(obs)
            self.mean = dist.distribution.mean.numpy()
            self.recomputed = dist.log_prob(torch.as_tensor(self.actions)).numpy()


def test_unread_values_are_stored_at_the_mean_with_matching_log_probabilities():
    model = PPO("MlpPolicy", SecondValueReadEveryThirdStep(), n_steps=60, batch_size=60, seed=0)
    callback = Keep()
    model.learn(total_timesteps=60, callback=callback)
    unread = callback.unread[:, 0, 1]
    assert unread.sum() == 40 and not callback.unread[..., 0].any()  # 2 of every 3 steps
    actions, mean = callback.actions, callback.mean
    np.testing.assert_allclose(actions[unread, 1], mean[unread, 1], rtol=1e-6)
    assert np.all(actions[~unread, 1] != mean[~unread, 1])  # read: still the sample
    assert np.all(actions[:, 0] != mean[:, 0])
    np.testing.assert_allclose(callback.log_probs, callback.recomputed, rtol=1e-5)


def test_the_option_is_a_ppo_setting_and_not_an_sb3_argument():
    config = PPOConfig(score_unread_at_mean=True)
    assert "score_unread_at_mean" not in config.sb3_kwargs()
    with pytest.raises(TypeError):
        PPOConfig(score_unread=True)
