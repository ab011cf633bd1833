"""A trained SB3 PPO model as a `Policy`: loads the model and its VecNormalize statistics.

``PPOPolicy.load(path, env)`` accepts a model file, a model directory or a run directory (see
`agents.run_files.artifacts`). It checks that the model was trained for this env id (from the
resolved ``config.yaml`` saved next to it) and that the observation and action shapes match,
and raises `agents.run_files.errors.UserError` (a ValueError) with a clear message otherwise.
Observations are normalised with the saved statistics (frozen) before the network sees them.
Nothing in the model files is unpickled unless the caller passes ``trust_pickle=True``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from .hybrid import from_run_config
from .knob_wiring import knobs_observation_space, knobs_policy
from .knobs import KnobSettings
from .knobs import settings_from_config as knob_settings
from .policy import AroundLearned, Policy
from .privileged_critic import pad_observation, privileged_space
from .run_files.artifacts import ModelFiles, find_model, other_env_error, read_meta
from .run_files.errors import UserError
from .run_files.model_files import NormalizationStats, load_ppo, load_stats, ppo_custom_objects
from .run_files.train_config import load_train_config


class PPOPolicy:
    """Deterministic (by default) actions of a PPO model on raw env observations."""

    def __init__(
        self,
        model: Any,
        stats: NormalizationStats | None,
        files: ModelFiles | None = None,
        deterministic: bool = True,
        train_env_kwargs: dict[str, Any] | None = None,
        privileged_critic: bool = False,
    ):
        self.model, self.stats, self.files = model, stats, files
        self.deterministic = deterministic
        self.train_env_kwargs = dict(train_env_kwargs or {})
        self.privileged_critic = privileged_critic
        """The model's observation ends with the critic's privileged values
        (`agents.privileged_critic`): the sensor observation is padded with zeros, which its
        actor ignores."""

    @classmethod
    def load(
        cls,
        path: str | Path,
        env: gym.Env,
        deterministic: bool = True,
        device: str = "cpu",
        trust_pickle: bool = False,
    ) -> Policy:
        """The model at `path` as a policy for `env`, loaded without unpickling anything (see
        `agents.run_files.model_files`; pickled files of older runs only with ``trust_pickle``).
        A hybrid run's model comes back combined with `env`'s analytical controller as in
        training (`agents.hybrid.HybridPolicy`), a knobs run's as the controller it tunes
        (`agents.knob_wiring.knobs_policy`)."""
        files = find_model(path)
        config = files.training_config()
        env_id = env.spec.id if env.spec is not None else None
        if config is None:
            raise UserError(
                f"cannot verify the model at {files.model}: no config.yaml next to it to tell "
                "which env it was trained for"
            )
        trained_for = (config.get("env") or {}).get("id")
        if trained_for != env_id:
            raise other_env_error(files, trained_for, env_id)
        train_config = load_train_config(data=config)
        privileged = train_config.policy.critic_privileged
        meta = read_meta(files.directory)
        try:
            knobs = knob_settings(config.get("knobs"))
        except ValueError as exc:
            raise UserError(f"cannot use the model at {files.model}: {exc}") from None
        observation_space = env.observation_space
        if knobs is not None:
            observation_space = knobs_observation_space(env, knobs)
        action_space = env.action_space if knobs is None else knobs.action_space
        choices, clearances = _stride_choices(env, config, files)
        if choices is not None:
            action_space = choices.action_space
        if clearances is not None:
            observation_space = clearances.observation_space
        if privileged:
            observation_space = privileged_space(observation_space)
        for what, key, env_space in (
            ("observation", "observation_shape", observation_space),
            ("action", "action_shape", action_space),
        ):
            if key in meta and tuple(meta[key]) != env_space.shape:
                raise UserError(
                    f"the model at {files.model} expects {what} shape {tuple(meta[key])}, "
                    f"but {env_id} (with these kwargs) has {env_space.shape}"
                )
        policy_kwargs = train_config.policy.policy_kwargs()
        if config.get("hybrid") is not None:  # the learned action of a hybrid lies in [-1, 1]
            shape, dtype = env.action_space.shape, env.action_space.dtype
            action_space = gym.spaces.Box(-1.0, 1.0, shape=shape, dtype=dtype)
        objects = ppo_custom_objects(
            policy_kwargs, observation_space, action_space, privileged_critic=privileged
        )
        model = load_ppo(files.model, objects, trust_pickle, device=device)
        stats = load_stats(files.directory, trust_pickle, train_config.normalize.observation)
        train_kwargs = (config.get("env") or {}).get("kwargs") or {}
        policy = cls(model, stats, files, deterministic, train_kwargs, privileged)
        if choices is not None:
            return ChosenStride(policy, choices, clearances)
        return _as_trained(policy, env, config, knobs)

    def reset(self) -> None:
        pass

    def seed_episode(self, seed: int) -> None:
        """Sample the actions of the episode run with `seed` from that seed (``deterministic``
        False), so that its result does not depend on the episodes run before it; an evaluation
        calls this before each episode. The sampling draws from torch's global generator."""
        if self.deterministic:
            return
        import torch

        torch.manual_seed(seed)
        if self.model.use_sde:
            self.model.policy.reset_noise()

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        obs = np.asarray(observation)
        if obs.dtype.kind not in "fiu":
            raise UserError(
                f"observation of dtype {obs.dtype} given to a PPO policy; expected real numbers"
            )
        if self.privileged_critic:
            obs = pad_observation(obs)
        if self.stats is not None:
            obs = self.stats.normalize_obs(obs)
        action, _ = self.model.predict(obs, deterministic=self.deterministic)
        return action


def _as_trained(
    policy: PPOPolicy, env: gym.Env, config: dict[str, Any], knobs: KnobSettings | None
) -> Any:
    """The policy as its run used it: a hybrid run's ``hybrid`` config section re-creates the
    combination with the env's analytical controller (`agents.hybrid.from_run_config`), a knobs
    run's settings (its ``knobs`` section) the controller it tunes
    (`agents.knob_wiring.knobs_policy`),
    and a run that decided once per episode (``env.decision: episode``) holds its first action
    (`HeldPerEpisode`)."""
    learned: Policy = policy
    if (config.get("env") or {}).get("decision") == "episode":
        learned = HeldPerEpisode(policy)
    try:
        if knobs is not None:
            return knobs_policy(policy, env, knobs)
        return from_run_config(learned, env, config)
    except ValueError as exc:
        raise UserError(f"cannot use the model at {policy.files.model}: {exc}") from None


def _stride_choices(env: gym.Env, config: dict[str, Any], files: ModelFiles) -> tuple[Any, Any]:
    """A model trained with ``env.stride_choices``: (`hexapod_envs.wrappers.StrideChoices` on
    `env`, which turns its choices into `env`'s actions; `StrideClearances` on `env` if it
    trained with ``env.stride_clearances``, else None); (None, None) for any other model."""
    section = config.get("env") or {}
    values = section.get("stride_choices")
    if values is None:
        return None, None
    from hexapod_envs.wrappers import StrideChoices, StrideClearances

    try:
        choices = StrideChoices(env, values)
        clearances = StrideClearances(env, values) if section.get("stride_clearances") else None
    except ValueError as exc:
        raise UserError(f"cannot use the model at {files.model}: {exc}") from None
    return choices, clearances


class ChosenStride(AroundLearned):
    """A learned `Policy` of stride choices (a model trained with ``env.stride_choices``) as a
    policy of the plain ditch env: each choice becomes the env's action through `choices` (a
    `hexapod_envs.wrappers.StrideChoices`); with `clearances` (a `StrideClearances`), the
    learned policy sees the observation as it trained on it. Attributes it lacks are the learned
    policy's."""

    _OWN = ("learned", "choices", "clearances")

    def __init__(self, learned: Policy, choices: Any, clearances: Any = None):
        self.learned, self.choices, self.clearances = learned, choices, clearances

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        if self.clearances is not None:
            observation = self.clearances.observation(np.asarray(observation))
        return self.choices.action(self.learned(observation))


class HeldPerEpisode(AroundLearned):
    """A learned `Policy` asked once per episode, at its first observation, whose action is then
    held: a model trained with ``env.decision: episode`` (`hexapod_envs.wrappers.GainsPerEpisode`)
    run at every step of the plain env. Attributes it lacks are the learned policy's."""

    _OWN = ("learned", "_action")

    def __init__(self, learned: Policy):
        self.learned = learned
        self._action: np.ndarray | None = None

    def reset(self) -> None:
        self.learned.reset()
        self._action = None

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        if self._action is None:
            self._action = np.array(self.learned(observation))
        return self._action.copy()
