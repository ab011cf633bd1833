"""Tiny train.py runs of the ditch's stride-action configs (64 PPO steps, short episodes): what
the read-actions, warm-start and stride-choice tests share."""

from pathlib import Path

from agents.pipeline.cli import train_main
from helpers.paths import REPO

CONFIGS = REPO / "configs"
READ_CONFIG = CONFIGS / "ditch_crossing_v1_ppo_stride_read.yaml"
WARM_CONFIG = CONFIGS / "ditch_crossing_v1_ppo_stride_warm.yaml"
CHOICES_CONFIG = CONFIGS / "ditch_crossing_v1_ppo_stride_choices.yaml"
STRIDES_OFF = {
    "task_distribution": "train",
    "stride_action": True,
    "residual_limb_m": 0.0,
    "residual_leg_m": 0.0,
    "max_episode_steps": 500,
}
"""The ditch env's stride action with the residuals off, 500-step episodes."""
TINY = [
    "ppo.n_steps=64",
    "ppo.batch_size=32",
    "ppo.n_epochs=1",
    "policy.pi=[16]",
    "policy.vf=[16]",
    "train.total_timesteps=64",
    "env.max_episode_steps=20",
    "eval.freq=64",
    "eval.n_episodes=1",
    "checkpoint.freq=64",
]


def train_tiny(config: Path, output_dir: Path, *overrides: str) -> int:
    """train.py on `config` with `TINY` and then `overrides`, as ``output_dir/run``."""
    argv = ["--config", str(config), "--output-dir", str(output_dir), "--run-name", "run"]
    return train_main([*argv, *(a for o in [*TINY, *overrides] for a in ("--set", o))])
