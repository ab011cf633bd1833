"""benchmarks/bench_vector_env.py: its measuring functions run (no timing assertions)."""

import math

from benchmarks.bench_vector_env import (
    batched_rate,
    interleaving_cost,
    physics_ceiling,
    ppo_rate,
    single_rate,
)


def test_env_rates_count_steps_and_the_cpu_they_take():
    single = single_rate("HexapodStewartTilt-v1", 0.05)
    batched = batched_rate("HexapodStewartTilt-v1", 0.05, 3, nthread=2)
    assert single.rate > 0 and single.cpu_us >= single.main_us > 0
    assert batched.rate > 0 and batched.cpu_us >= batched.main_us > 0


def test_ppo_rate_splits_its_time_into_env_policy_and_update():
    row = ppo_rate("batched", 2, steps=128, rollout=64)
    assert row["rate"] > 0 and min(row["env"], row["policy"], row["update"]) > 0
    assert row["env"] + row["policy"] + row["update"] <= row["total"]


def test_physics_ceiling_times_the_worlds_physics_on_one_thread_and_on_the_threads():
    one, threaded = physics_ceiling("HexapodStewartTilt-v1", 0.05, n_worlds=2, threads=2)
    assert math.isfinite(one) and math.isfinite(threaded) and min(one, threaded) > 0


def test_interleaving_cost_times_the_same_worlds_alone_and_interleaved_and_unpatches():
    from hexapod_envs.envs.base import HexapodEnv
    from hexapod_envs.envs.stewart_tilt import StewartTiltEnv

    before = (dict(vars(StewartTiltEnv)), HexapodEnv._simulate, HexapodEnv.reset)
    alone, interleaved = interleaving_cost("HexapodStewartTilt-v1", n_worlds=2, steps=3)
    assert math.isfinite(alone) and math.isfinite(interleaved) and min(alone, interleaved) > 0
    assert (dict(vars(StewartTiltEnv)), HexapodEnv._simulate, HexapodEnv.reset) == before
