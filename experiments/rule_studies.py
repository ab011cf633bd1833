"""What the rule studies share (`cliff_stop`, `stewart_landing`): play scripted policies on the
tasks of a distribution, one row of outcomes per task, and a command line that prints each
policy's summary and writes the rows as JSON."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable, Sequence
from pathlib import Path

import gymnasium as gym
import numpy as np

Rows = list[dict]


def play(env: gym.Env, act: Callable, seeds: range, row: Callable[[int, dict], dict]) -> Rows:
    """One episode per seed with policy `act` (`play_episode`); `row(seed, info)` of each
    episode's last info. Closes `env`."""
    try:
        return [row(seed, play_episode(env, act, seed)) for seed in seeds]
    finally:
        env.close()


def play_episode(env: gym.Env, act: Callable, seed: int) -> dict:
    """The last info of one episode of policy `act` (its ``reset()`` called first) from
    ``env.reset(seed=seed)``."""
    obs, _ = env.reset(seed=seed)
    act.reset()
    while True:
        obs, _, terminated, truncated, info = env.step(act(np.asarray(obs)))
        if terminated or truncated:
            return info


def outcome(seed: int, info: dict) -> dict:
    """The outcome every rule study records of an episode's last info: success, tip-over and the
    largest tilt [deg]; a study adds its own keys."""
    return {
        "seed": seed,
        "success": bool(info["is_success"]),
        "tipped_over": bool(info["is_tipped_over"]),
        "max_tilt_deg": float(info["max_tilt_deg"]),
    }


def counts(rows: Rows) -> str:
    """``"<s> of <n> successes, <t> tip-overs"``, the start of every study's summary line."""
    successes = sum(r["success"] for r in rows)
    return f"{successes} of {len(rows)} successes, {sum(r['tipped_over'] for r in rows)} tip-overs"


def main(
    description: str,
    policies: Sequence[str],
    run: Callable[[str, str, range], Rows],
    summary: Callable[[Rows], str],
    default_seeds: tuple[int, int],
    default_distribution: str,
    argv: list[str] | None = None,
) -> dict[str, Rows]:
    """The command line of a rule study: ``--distribution``, ``--seeds A B``, ``--policies``
    and ``--json``; prints ``<policy>: <summary(rows)>`` per policy."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--distribution", default=default_distribution, choices=("train", "test"))
    parser.add_argument("--seeds", nargs=2, type=int, default=default_seeds, metavar=("A", "B"))
    parser.add_argument("--policies", nargs="+", default=list(policies), choices=policies)
    parser.add_argument("--json", type=Path, help="write every task's outcome here")
    args = parser.parse_args(argv)
    out = {}
    for policy in args.policies:
        rows = out[policy] = run(policy, args.distribution, range(*args.seeds))
        print(f"{policy}: {summary(rows)}", flush=True)
    if args.json:
        args.json.write_text(json.dumps(out, indent=1) + "\n")
    return out
