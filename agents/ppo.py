"""A trained SB3 PPO model as a `Policy`: loads the model and its VecNormalize statistics.

``PPOPolicy.load(path, env)`` accepts a model file, a model directory or a run directory (see
`agents.pipeline.artifacts`). It checks that the model was trained for this env id (from the
resolved ``config.yaml`` saved next to it) and that the observation and action shapes match,
and raises `agents.pipeline.errors.UserError` (a ValueError) with a clear message otherwise.
Observations are normalised with the saved statistics (frozen) before the network sees them.
"""

from __future__ import annotations

import pickle
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from .pipeline.artifacts import ModelFiles, find_model
from .pipeline.errors import UserError
from .policy import Policy

# Schedules are only needed to keep training; replacing them makes loading independent of them.
_INFERENCE_OBJECTS = {
    "learning_rate": 0.0,
    "lr_schedule": lambda _: 0.0,
    "clip_range": lambda _: 0.0,
}


class PPOPolicy:
    """Deterministic (by default) actions of a PPO model on raw env observations."""

    def __init__(
        self,
        model: Any,
        vec_normalize: Any | None,
        files: ModelFiles | None = None,
        deterministic: bool = True,
        train_env_kwargs: dict[str, Any] | None = None,
    ):
        self.model, self.vec_normalize, self.files = model, vec_normalize, files
        self.deterministic = deterministic
        self.train_env_kwargs = dict(train_env_kwargs or {})

    @classmethod
    def load(
        cls, path: str | Path, env: gym.Env, deterministic: bool = True, device: str = "cpu"
    ) -> Policy:
        """The model at `path` as a policy for `env`; a hybrid run's model comes back combined
        with `env`'s analytical controller as in training (`agents.hybrid.HybridPolicy`)."""
        from stable_baselines3 import PPO

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
            raise UserError(
                f"the model at {files.model} was trained for {trained_for}, not {env_id}"
            )
        try:
            model = PPO.load(files.model, device=device, custom_objects=_INFERENCE_OBJECTS)
        except (ValueError, KeyError, OSError, RuntimeError) as exc:
            raise UserError(f"cannot load the PPO model {files.model}: {exc}") from None
        for what, model_space, env_space in (
            ("observation", model.observation_space, env.observation_space),
            ("action", model.action_space, env.action_space),
        ):
            if model_space.shape != env_space.shape:
                raise UserError(
                    f"the model at {files.model} expects {what} shape {model_space.shape}, "
                    f"but {env_id} (with these kwargs) has {env_space.shape}"
                )
        vec_normalize = None
        if files.vec_normalize is not None:
            with open(files.vec_normalize, "rb") as fh:
                vec_normalize = pickle.load(fh)  # VecNormalize without its venv: stats only
            vec_normalize.training = False
        train_kwargs = (config.get("env") or {}).get("kwargs") or {}
        policy = cls(model, vec_normalize, files, deterministic, train_kwargs)
        return _as_trained(policy, env, config)

    def reset(self) -> None:
        pass

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        obs = np.asarray(observation)
        if self.vec_normalize is not None:
            obs = self.vec_normalize.normalize_obs(obs)
        action, _ = self.model.predict(obs, deterministic=self.deterministic)
        return action


def _as_trained(policy: PPOPolicy, env: gym.Env, config: dict[str, Any]) -> Any:
    """The policy as its run used it: a hybrid run's ``hybrid`` config section re-creates the
    combination with the env's analytical controller (`agents.hybrid.from_run_config`)."""
    from .hybrid import from_run_config

    try:
        return from_run_config(policy, env, config)
    except ValueError as exc:
        raise UserError(f"cannot use the model at {policy.files.model}: {exc}") from None
