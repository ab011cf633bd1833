"""The analytical controller on HexapodIrregularTerrain-v1 with its torso-height reference raised
by a constant: success and torso contacts on hard training tasks.

Most of the paper's controller's failures on the v1 test tasks are torso contacts with the
blocks. The scan runs the controller in the env's gains mode (the paper's blocks gains) with the
body-height knob (`gains_height_offset_m`) held at each offset, on the first `--tasks` training
tasks from seed 1000 on whose difficulty is at least `--min-difficulty` (training tasks only: the
scan picks a setting, the test tasks judge it), and prints per offset the successes, the episodes
with a torso contact and the median distance.

    python experiments/athena_posture/height_reference_scan.py [--offsets 0 0.01 0.02 0.03]
        [--tasks 40] [--min-difficulty 0.55] [--json results.json]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # run as a script from anywhere

import hexapod_envs  # noqa: E402, F401  (registers the ids)
from agents.athena_policy import PAPER_GAINS  # noqa: E402

ENV_ID = "HexapodIrregularTerrain-v1"
RANGE_M = 0.05
"""The knob's range here (the setting's largest): an offset of x m is the action x / RANGE_M."""
FIRST_SEED = 1000
MAX_SEEDS_PER_TASK = 100
"""Seeds tried per task wanted before giving up (a difficulty no training task reaches)."""


def hard_train_seeds(count: int, min_difficulty: float) -> list[int]:
    """The first `count` training-task seeds from `FIRST_SEED` whose task difficulty is at least
    `min_difficulty` (the env draws the task at reset, before any physics)."""
    env = gym.make(ENV_ID, task_distribution="train")
    seeds, seed, last = [], FIRST_SEED, FIRST_SEED + MAX_SEEDS_PER_TASK * count
    while len(seeds) < count and seed < last:
        _, info = env.reset(seed=seed)
        if info["task"]["difficulty"] >= min_difficulty:
            seeds.append(seed)
        seed += 1
    env.close()
    if len(seeds) < count:
        raise SystemExit(
            f"only {len(seeds)} of seeds {FIRST_SEED}-{last - 1} give a training task of "
            f"difficulty >= {min_difficulty}; lower --min-difficulty (the hardest are about 0.85)"
        )
    return seeds


def episode(offset_m: float, seed: int, max_steps: int | None = None) -> dict:
    """One episode of the paper's blocks gains with the height reference raised by `offset_m`."""
    env = gym.make(
        ENV_ID,
        task_distribution="train",
        action_mode="gains",
        gains_height_offset_m=RANGE_M,
        max_episode_steps=max_steps,
    )
    action = np.array([*PAPER_GAINS["blocks"], offset_m / RANGE_M], dtype=np.float32)
    env.reset(seed=seed)
    done = False
    while not done:
        _, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
    env.close()
    return {
        "seed": seed,
        "success": bool(info["is_success"]),
        "tipped_over": bool(info["is_tipped_over"]),
        "torso_contact": info["torso_collisions"] > 0,
        "distance_m": float(info["distance"]),
    }


def scan(
    offsets: list[float], seeds: list[int], max_steps: int | None = None
) -> dict[float, list[dict]]:
    """Offset [m] -> the episodes on `seeds`."""
    return {offset: [episode(offset, seed, max_steps) for seed in seeds] for offset in offsets}


def table(results: dict[float, list[dict]]) -> str:
    """A Markdown table: per offset, successes, torso contacts, tip-overs, median distance."""
    lines = [
        "| height offset [m] | successes | torso contact | tip-overs | median distance [m] |",
        "|---|---|---|---|---|",
    ]
    for offset, episodes in results.items():
        n = len(episodes)
        count = {k: sum(e[k] for e in episodes) for k in ("success", "torso_contact")}
        count["tipped_over"] = sum(e["tipped_over"] for e in episodes)
        lines.append(
            f"| {offset:+.3f} | {count['success']}/{n} | {count['torso_contact']}/{n} | "
            f"{count['tipped_over']}/{n} | {np.median([e['distance_m'] for e in episodes]):.2f} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--offsets", type=float, nargs="+", default=[0.0, 0.01, 0.02, 0.03])
    parser.add_argument("--tasks", type=int, default=40)
    parser.add_argument("--min-difficulty", type=float, default=0.55)
    parser.add_argument("--max-steps", type=int, default=None, help="episode limit (tests)")
    parser.add_argument("--json", type=Path, default=None, help="write the episodes here")
    args = parser.parse_args(argv)
    for offset in args.offsets:
        if abs(offset) > RANGE_M:
            parser.error(f"--offsets must lie within ±{RANGE_M} m, got {offset}")
    seeds = hard_train_seeds(args.tasks, args.min_difficulty)
    results = scan(args.offsets, seeds, args.max_steps)
    print(f"{ENV_ID}, {len(seeds)} training tasks with difficulty >= {args.min_difficulty}")
    print(table(results))
    if args.json is not None:
        args.json.write_text(json.dumps({str(k): v for k, v in results.items()}, indent=1))


if __name__ == "__main__":
    main()
