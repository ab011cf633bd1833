"""Tiny hybrid runs on the Stewart tilt through train.py (256 steps, 64-step episodes): what the
hybrid pipeline's tests share."""

from pathlib import Path

from agents.pipeline.cli import train_main
from helpers.paths import REPO

STEWART = str(REPO / "configs" / "stewart_tilt_hybrid.yaml")
TINY = [
    "vec_env.n_envs=1",
    "ppo.n_steps=128",
    "ppo.batch_size=64",
    "ppo.n_epochs=1",
    "policy.pi=[16, 16]",
    "policy.vf=[16, 16]",
    "train.total_timesteps=256",
    "env.max_episode_steps=64",
    "eval.freq=128",
    "eval.n_episodes=2",
    "checkpoint.freq=0",
    "logging.progress_bar=false",
    "logging.tensorboard=false",
]


def train(tmp: Path, name: str, *overrides: str, config: str = STEWART) -> Path:
    argv = ["--config", config, "--output-dir", str(tmp), "--run-name", name]
    for o in [*TINY, *overrides]:
        argv += ["--set", o]
    assert train_main(argv) == 0
    return tmp / name
