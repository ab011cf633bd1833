"""PPO that scores an action value only on the steps where the env reads it.

Some envs read part of the action only now and then: the ditch crossing's stride value decides
a platform step on the step's first control step and is ignored on the other 50 of 51
(`hexapod_envs.envs.ditch_crossing`, ``stride_action``). Such an env says which values these
are and which observation value flags the steps that read them (``env.action_read_flags``:
action index -> observation index of a 0/1 flag), and which values it never reads
(``env.inert_actions``: the ditch's residuals when their range is 0, as when a learner chooses
the stride alone, one decision per platform step).

PPO's likelihood ratio multiplies the likelihoods of all action values. An ignored value's
sample changes nothing that follows, so its term carries no signal; but its scores (for the mean
``(a - mu) / sigma^2``, for the log standard deviation ``(a - mu)^2 / sigma^2 - 1``), weighted
by the step's advantage, still enter the gradient: zero-mean noise, from 50 of every 51 steps
for the stride against the one step whose sample matters. An inert value's scores enter on every
step, and its drift also moves the likelihood ratio that PPO clips. Leaving an ignored value out
of the log-likelihood removes that noise and no signal, as invalid-action masking does for
discrete actions: the policy gradient stays unbiased because the value's sample is independent
of the rest of the episode. The entropy bonus (``ent_coef``) counts the value on the same steps
only. Sampling and acting are unchanged; only training differs, so a deployed model is an
ordinary SB3 policy.

A training config turns it on with ``policy.score_read_actions_only: true``; the policies here
are SB3's ``MlpPolicy`` and the asymmetric `PrivilegedCriticPolicy` with that scoring.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import torch
from stable_baselines3.common.distributions import DiagGaussianDistribution
from stable_baselines3.common.policies import ActorCriticPolicy

from .privileged_critic_policy import PrivilegedCriticPolicy


class ScoresReadActions:
    """Mixin for an SB3 `ActorCriticPolicy` with a diagonal Gaussian action distribution:
    `forward` and `evaluate_actions` count the action values of `action_read_flags` only where
    their flag in the observation is set, and the `inert_actions` nowhere. The flag is read
    from the observation the policy is given, which VecNormalize may have standardised: an
    affine map that keeps 1 above 0 and 0 at or below it, so a flag counts as set when its
    value is > 0."""

    def __init__(self, *args: Any, **kwargs: Any):
        super().__init__(*args, **kwargs)
        if not isinstance(self.action_dist, DiagGaussianDistribution):
            raise ValueError(
                "scoring only the action values read needs a diagonal Gaussian action "
                f"distribution (a Box action without gSDE), got {type(self.action_dist).__name__}"
            )
        self.action_read_flags: dict[int, int] = {}
        self.inert_actions: tuple[int, ...] = ()

    def set_action_read_flags(self, flags: Mapping[int, int], inert: Sequence[int] = ()) -> None:
        """Which action values are read only when a flag is set: action index -> observation
        index (`hexapod_envs.envs.base.HexapodEnv.action_read_flags`), and which never
        (`HexapodEnv.inert_actions`)."""
        n_actions = self.action_space.shape[0]
        n_obs = self.observation_space.shape[0]
        for action, flag in flags.items():
            if not (0 <= action < n_actions and 0 <= flag < n_obs):
                raise ValueError(
                    f"action read flag {action} -> {flag} lies outside the {n_actions} action "
                    f"values or the {n_obs} observation values"
                )
        inert = tuple(int(a) for a in inert)
        if not all(0 <= a < n_actions for a in inert) or len(set(inert)) >= n_actions:
            raise ValueError(
                f"inert action values {inert} must be among the {n_actions} action values and "
                "leave at least one that is read"
            )
        if set(inert) & set(flags):
            raise ValueError(
                f"action values {sorted(set(inert) & set(flags))} are both flagged and inert"
            )
        self.action_read_flags = {int(a): int(f) for a, f in flags.items()}
        self.inert_actions = inert

    def _latents(self, obs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        features = self.extract_features(obs)
        if self.share_features_extractor:
            return self.mlp_extractor(features)
        pi_features, vf_features = features
        return (
            self.mlp_extractor.forward_actor(pi_features),
            self.mlp_extractor.forward_critic(vf_features),
        )

    def _read_weights(self, obs: torch.Tensor, like: torch.Tensor) -> torch.Tensor:
        """1 for every action value the env reads at these observations, 0 for the others."""
        weights = torch.ones_like(like)
        for action, flag in self.action_read_flags.items():
            weights[:, action] = (obs[:, flag] > 0).to(like.dtype)
        weights[:, list(self.inert_actions)] = 0.0
        return weights

    def _scored(
        self, distribution: DiagGaussianDistribution, actions: torch.Tensor, obs: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """The log-likelihood of `actions` and the entropy, over the values read."""
        normal = distribution.distribution
        per_value = normal.log_prob(actions)
        weights = self._read_weights(obs, per_value)
        return (per_value * weights).sum(dim=1), (normal.entropy() * weights).sum(dim=1)

    def forward(
        self, obs: torch.Tensor, deterministic: bool = False
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        latent_pi, latent_vf = self._latents(obs)
        values = self.value_net(latent_vf)
        distribution = self._get_action_dist_from_latent(latent_pi)
        actions = distribution.get_actions(deterministic=deterministic)
        log_prob, _ = self._scored(distribution, actions, obs)
        return actions.reshape((-1, *self.action_space.shape)), values, log_prob

    def evaluate_actions(
        self, obs: torch.Tensor, actions: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        latent_pi, latent_vf = self._latents(obs)
        distribution = self._get_action_dist_from_latent(latent_pi)
        log_prob, entropy = self._scored(distribution, actions, obs)
        return self.value_net(latent_vf), log_prob, entropy


class ReadActionsMlpPolicy(ScoresReadActions, ActorCriticPolicy):
    """SB3's MlpPolicy that scores only the action values the env reads."""


class ReadActionsPrivilegedPolicy(ScoresReadActions, PrivilegedCriticPolicy):
    """`PrivilegedCriticPolicy` that scores only the action values the env reads."""
