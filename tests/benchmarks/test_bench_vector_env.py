"""benchmarks/bench_vector_env.py: its measuring functions run (no timing assertions)."""

from benchmarks.bench_vector_env import batched_rate, ppo_rate, single_rate


def test_env_rates_count_steps_of_single_and_batched_envs():
    assert single_rate("HexapodStewartTilt-v1", 0.05) > 0
    assert batched_rate("HexapodStewartTilt-v1", 0.05, 3, nthread=2) > 0


def test_ppo_rate_splits_its_time_into_env_policy_and_update():
    row = ppo_rate("batched", 2, steps=128, rollout=64)
    assert row["rate"] > 0 and min(row["env"], row["policy"], row["update"]) > 0
    assert row["env"] + row["policy"] + row["update"] <= row["total"]
