"""The SB3 policy of the asymmetric actor-critic (`agents.privileged_critic`): the actor sees
the observation without its privileged values, the critic all of it."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import torch
from stable_baselines3.common.policies import ActorCriticPolicy
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor

from .privileged_critic import PRIVILEGED_DIM


class SensorOnly(BaseFeaturesExtractor):
    """The flat observation with its last `PRIVILEGED_DIM` values set to 0 (the actor's view)."""

    def __init__(self, observation_space: gym.spaces.Box):
        n = int(np.prod(observation_space.shape))
        super().__init__(observation_space, features_dim=n)
        if n <= PRIVILEGED_DIM:
            raise ValueError(f"an observation of {n} values holds no sensor part")
        mask = torch.ones(n)
        mask[n - PRIVILEGED_DIM :] = 0.0
        self.register_buffer("mask", mask, persistent=False)  # the state dict stays MlpPolicy's

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        return torch.flatten(observations, start_dim=1) * self.mask


class PrivilegedCriticPolicy(ActorCriticPolicy):
    """SB3's MlpPolicy whose actor sees the observation without the privileged values (the
    critic sees all of it); the same keyword arguments, the same weights."""

    def __init__(self, *args: Any, **kwargs: Any):
        kwargs["share_features_extractor"] = False
        super().__init__(*args, **kwargs)
        self.pi_features_extractor = self.features_extractor = SensorOnly(self.observation_space)
