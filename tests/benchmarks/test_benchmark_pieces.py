"""The benchmarks' per-piece timers call the env's private hooks: they must keep matching the
env skeleton's signatures (no timing assertions)."""

import math
import re

import gymnasium as gym

import hexapod_envs  # noqa: F401
from benchmarks.bench_irregular_terrain import (
    env_piece_costs,
    print_training_task_rates,
)
from benchmarks.common import (
    STEP_PIECES,
    random_action_rates,
    replay_step_rate,
    step_profile,
)


def test_irregular_terrain_env_pieces_run():
    costs = env_piece_costs()
    assert len(costs) == 7 and all(math.isfinite(us) and us > 0 for us in costs.values())


def test_training_task_rates_print_the_env_and_its_bare_physics(capsys):
    print_training_task_rates(steps=5)
    lines = capsys.readouterr().out.splitlines()
    assert [line.split(",")[0] for line in lines] == ["ramp", "blocks"]
    for line in lines:
        rates = [float(x) for x in re.findall(r"(?:env|physics) ([0-9.]+)", line)]
        assert len(rates) == 2 and all(rate > 0 for rate in rates), line


def test_replay_measures_raw_physics_both_ways_and_the_env():
    with gym.make("HexapodCliffWalk-v0") as env:
        rates = replay_step_rate(env, steps=5)
    assert len(rates) == 3 and all(math.isfinite(r) and r > 0 for r in rates)


def test_random_action_rates_replay_every_episode():
    """Two episodes of 10 steps in 15: the replay covers the first whole and the second's five."""
    with gym.make("HexapodCliffWalk-v0", max_episode_steps=10) as env:
        rates = random_action_rates(env, 15)
    assert len(rates) == 2 and all(math.isfinite(r) and r > 0 for r in rates)


def test_step_profile_times_every_hook_of_the_step_and_restores_them():
    """Every hook HexapodEnv.step calls is timed (a hook the step stopped calling would read
    0), across an episode's end, and the env's own methods are back afterwards."""
    with gym.make("HexapodCliffWalk-v0", max_episode_steps=4) as env:
        profile = step_profile(env, 10)
        base = env.unwrapped
        assert not set(STEP_PIECES) & set(vars(base))
    assert list(profile) == [name.lstrip("_") for name in STEP_PIECES] + ["rest"]
    assert all(math.isfinite(us) and us > 0 for us in profile.values())
