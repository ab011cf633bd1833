"""PPO that scores the action values an env did not read at their mean.

Some actions are read only at certain steps: the ditch crossing's stride value
(`stride_action`) sets a platform step's stride on the step's first control step and is ignored
on the other 50. PPO still scores the sampled noise of every ignored value with its step's
advantage; that noise changed nothing, so it only adds variance to the policy gradient, about
50 samples of it to every one that decided something. An env says which action indices it did
not read in ``info["unread_actions"]`` (a tuple of indices, empty when it read them all).

With ``ppo.score_unread_at_mean: true`` the training run records them (`ScoreUnreadAtMean`),
and at the end of each rollout sets those entries of the stored actions to the policy's mean
and recomputes the stored log-probabilities: an unread value then contributes no sampled noise
to the gradient of the policy's mean (its term pulls the mean toward where it was, like PPO's
clipping). The env saw the clipped sample and ignored it, so the stored transitions stay true
to what happened; the values, returns and advantages are untouched.
"""

from __future__ import annotations

import numpy as np
import torch
from stable_baselines3.common.callbacks import BaseCallback

INFO_KEY = "unread_actions"
"""The info key: the indices of the action values the env ignored at that step."""


class ScoreUnreadAtMean(BaseCallback):
    """Records each step's unread action indices (`INFO_KEY`) of every env, and at the end of
    the rollout replaces those stored action values by the policy's mean and the stored
    log-probabilities by the ones of the actions so changed."""

    def _on_rollout_start(self) -> None:
        buffer = self.model.rollout_buffer
        self.unread = np.zeros(buffer.actions.shape, dtype=bool)
        """(n_steps, n_envs, action dim): True where the env did not read the value."""

    def _on_step(self) -> bool:
        row = self.model.rollout_buffer.pos  # the row SB3 adds this step to, after callbacks
        for env, info in enumerate(self.locals["infos"]):
            indices = list(info.get(INFO_KEY, ()))
            if indices:
                self.unread[row, env, indices] = True
        return True

    def _on_rollout_end(self) -> None:
        rows = self.unread.any(axis=-1)
        if not rows.any():
            return
        buffer, policy = self.model.rollout_buffer, self.model.policy
        with torch.no_grad():
            obs = torch.as_tensor(buffer.observations[rows], device=policy.device)
            dist = policy.get_distribution(obs)
            actions = buffer.actions[rows]
            mean = dist.distribution.mean.cpu().numpy()
            unread = self.unread[rows]
            actions[unread] = mean[unread]
            log_prob = dist.log_prob(torch.as_tensor(actions, device=policy.device))
        buffer.actions[rows] = actions
        buffer.log_probs[rows] = log_prob.cpu().numpy()
