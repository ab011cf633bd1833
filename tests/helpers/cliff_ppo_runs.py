"""Tiny PPO runs on the cliff walk through train.py and evaluate.py (DummyVecEnv, 1024 steps,
100-step episodes): what the pipeline's end-to-end tests share."""

import json
from pathlib import Path

from agents.pipeline.cli import evaluate_main, train_main
from helpers.paths import REPO

CONFIG = str(REPO / "configs" / "cliff_walk_ppo.yaml")
TINY = [
    "vec_env.n_envs=1",
    "ppo.n_steps=256",
    "ppo.batch_size=64",
    "ppo.n_epochs=1",
    "policy.pi=[32, 32]",
    "policy.vf=[32, 32]",
    "train.total_timesteps=1024",
    "env.max_episode_steps=100",
    "eval.freq=512",
    "eval.n_episodes=1",
    "checkpoint.freq=512",
    "logging.progress_bar=false",
]


def sets(overrides):
    return [arg for o in overrides for arg in ("--set", o)]


def train(tmp, name, *extra, overrides=TINY):
    argv = ["--config", CONFIG, "--output-dir", str(tmp), "--run-name", name]
    return train_main([*argv, *sets(overrides), *extra])


def meta(path: Path) -> dict:
    return json.loads((path / "meta.json").read_text())


def evaluate(out, *policies, extra=()):
    argv = ["--envs", "HexapodCliffWalk-v0", "--episodes", "2", "--max-episode-steps", "60"]
    argv += ["--output-dir", str(out), "--no-progress", "--policies", *policies]
    return evaluate_main([*argv, *extra])
