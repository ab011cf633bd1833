"""The benchmarks' per-piece timers call the env's private hooks: they must keep matching the
env skeleton's signatures (no timing assertions)."""

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the benchmarks package

import gymnasium as gym  # noqa: E402

import hexapod_envs  # noqa: E402, F401
from benchmarks.bench_irregular_terrain import env_piece_costs  # noqa: E402
from benchmarks.common import random_action_rates, replay_step_rate  # noqa: E402


def test_irregular_terrain_env_pieces_run():
    costs = env_piece_costs()
    assert len(costs) == 7 and all(math.isfinite(us) and us > 0 for us in costs.values())


def test_replay_measures_raw_physics_both_ways_and_the_env():
    with gym.make("HexapodCliffWalk-v0") as env:
        rates = replay_step_rate(env, steps=5)
    assert len(rates) == 3 and all(math.isfinite(r) and r > 0 for r in rates)


def test_random_action_rates_replay_every_episode():
    """Two episodes of 10 steps in 15: the replay covers the first whole and the second's five."""
    with gym.make("HexapodCliffWalk-v0", max_episode_steps=10) as env:
        rates = random_action_rates(env, 15)
    assert len(rates) == 2 and all(math.isfinite(r) and r > 0 for r in rates)
