"""rl-baselines3-zoo hyperparameters generated from our training configs.

rl_zoo3 trains the envs unmodified (``python -m rl_zoo3.train --algo ppo --env
HexapodCliffWalk-v0 --gym-packages hexapod_envs``; it falls back to its ``default`` PPO entry).
To train with the same hyperparameters as ``train.py``, pass the generated file with
``-conf configs/rl_zoo_hyperparams.yaml``. Regenerate it after changing a config::

    python -m agents.pipeline.zoo configs/*_ppo.yaml > configs/rl_zoo_hyperparams.yaml

A config with something the zoo has no counterpart for (a privileged critic, a wrapper that
train.py adds around the env) is left out and named in the file's header.

The zoo evaluates its ``policy_kwargs`` string itself (``activation_fn=nn.Tanh``); nothing here
evaluates strings.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import yaml

from ..run_files.schedules import Schedule
from ..run_files.train_config import TrainConfig, load_train_config

ACTIVATION_NAMES = {
    "tanh": "nn.Tanh",
    "relu": "nn.ReLU",
    "elu": "nn.ELU",
    "leaky_relu": "nn.LeakyReLU",
    "gelu": "nn.GELU",
    "silu": "nn.SiLU",
}


def _schedule(s: Schedule, key: str) -> float | str:
    if s.is_constant:
        return s.initial
    if s.final == 0.0:
        return f"lin_{s.initial!r}"
    raise ValueError(f"rl_zoo3 has no linear schedule to a non-zero final value ({key}: {s})")


def zoo_hyperparams(config: TrainConfig) -> dict[str, Any]:
    """One env's entry of a zoo hyperparameter file (PPO)."""
    ppo, pol, norm = config.ppo, config.policy, config.normalize
    entry: dict[str, Any] = {
        "n_envs": config.vec_env.n_envs,
        "n_timesteps": float(config.train.total_timesteps),
        "policy": "MlpPolicy",
    }
    env_kwargs = dict(config.env.kwargs)
    if config.env.max_episode_steps is not None:
        env_kwargs["max_episode_steps"] = config.env.max_episode_steps  # a gym.make keyword
    if env_kwargs:
        entry["env_kwargs"] = env_kwargs
    if norm.observation or norm.reward:
        entry["normalize"] = {
            "norm_obs": norm.observation,
            "norm_reward": norm.reward,
            "clip_obs": norm.clip_observation,
            "clip_reward": norm.clip_reward,
        }
    for key, value in ppo.sb3_kwargs().items():  # the same PPO arguments train.py passes
        if value is not None:
            entry[key] = _schedule(value, key) if isinstance(value, Schedule) else value
    entry["policy_kwargs"] = (
        f"dict(log_std_init={pol.log_std_init}, ortho_init={pol.ortho_init}, "
        f"activation_fn={ACTIVATION_NAMES[pol.activation]}, "
        f"net_arch=dict(pi={list(pol.pi)}, vf={list(pol.vf)}))"
    )
    return entry


def zoo_unsupported(config: TrainConfig) -> str | None:
    """Why the zoo cannot train `config` as train.py does (None: it can): a critic that sees the
    task, or a wrapper train.py adds around the env."""
    if config.policy.critic_privileged:
        return "policy.critic_privileged (the zoo's MlpPolicy has no privileged critic)"
    if config.warm_start is not None:
        return "warm_start (train.py clones a teacher into the actor first)"
    if config.policy.score_read_actions_only:
        return "policy.score_read_actions_only (the zoo's MlpPolicy scores every action value)"
    if config.env.stability_penalty:
        return "env.stability_penalty (a wrapper train.py adds)"
    if config.env.min_task_difficulty is not None:
        return "env.min_task_difficulty (a wrapper train.py adds)"
    if config.env.reward_exclude or config.env.decision != "step":
        return "env.reward_exclude or env.decision (wrappers train.py adds)"
    if config.hybrid is not None or config.knobs is not None:
        return "a hybrid or knobs section (wrappers train.py adds)"
    return None


def zoo_file(config_paths: list[str | Path]) -> str:
    """The hyperparameter file of the configs the zoo can train as train.py does; the others
    are named in its header with the reason."""
    header = (
        "# rl-baselines3-zoo hyperparameters (PPO) generated from configs/*_ppo.yaml by\n"
        "#   python -m agents.pipeline.zoo configs/*_ppo.yaml > configs/rl_zoo_hyperparams.yaml\n"
        "# Use: python -m rl_zoo3.train --algo ppo --env HexapodCliffWalk-v0 \\\n"
        "#        --gym-packages hexapod_envs -conf configs/rl_zoo_hyperparams.yaml\n"
    )
    entries = {}
    for path in sorted(config_paths):
        config = load_train_config(path)
        reason = zoo_unsupported(config)
        if reason is not None:
            header += f"# Left out: {Path(path).name}, for {reason}.\n"
            continue
        entries[config.env.id] = zoo_hyperparams(config)
    return header + yaml.safe_dump(entries, sort_keys=True, width=1000)


if __name__ == "__main__":
    sys.stdout.write(zoo_file(sys.argv[1:]))
