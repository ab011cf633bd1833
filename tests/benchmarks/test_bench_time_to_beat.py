"""The time-to-beat benchmark reads a run's evaluation log and TensorBoard events."""

import numpy as np
import pytest
import yaml
from torch.utils.tensorboard import SummaryWriter

from benchmarks.bench_time_to_beat import main, run_dirs, time_to_beat


def _run(path, rates, decision="step", cycle_lengths=None):
    """A run directory: evaluations every 1000 learner steps with these success rates (10 tasks
    of 200 env steps each), TensorBoard events 30 s apart."""
    path.mkdir(parents=True)
    steps = np.arange(len(rates)) * 1000
    successes = np.array([[i < round(10 * r) for i in range(10)] for r in rates], dtype=float)
    np.savez(
        path / "evaluations.npz",
        timesteps=steps,
        results=np.zeros((len(rates), 10)),
        ep_lengths=np.full((len(rates), 10), 200),
        successes=successes,
    )
    (path / "config.yaml").write_text(yaml.safe_dump({"env": {"decision": decision}}))
    writer = SummaryWriter(str(path / "tb" / "PPO_1"))
    for i, (step, rate) in enumerate(zip(steps, rates, strict=True)):
        writer.add_scalar("eval/success_rate", rate, int(step), walltime=1000.0 + 30 * i)
        if cycle_lengths is not None:
            writer.add_scalar("rollout/ep_len_mean", cycle_lengths, int(step), walltime=1000.0)
    writer.close()
    return path


def test_the_first_evaluation_above_step_zero(tmp_path):
    run = _run(tmp_path / "a", [0.5, 0.5, 0.7, 0.9])
    result = time_to_beat(run)
    assert result.reference == 0.5 and result.best == 0.9
    assert (result.beat_learner_steps, result.beat_env_steps, result.beat_wall_s) == (
        2000,
        2000,
        60.0,
    )
    assert time_to_beat(run, reference=0.8).beat_learner_steps == 3000
    never = time_to_beat(run, reference=0.9)
    assert never.beat_learner_steps is None and never.beat_wall_s is None


def test_gait_cycle_runs_count_env_steps_per_cycle(tmp_path):
    run = _run(tmp_path / "c", [0.2, 0.4], decision="gait_cycle", cycle_lengths=4.0)
    assert time_to_beat(run).beat_env_steps == 1000 * 200 / 4.0


def test_per_episode_runs_have_no_env_step_count(tmp_path):
    run = _run(tmp_path / "e", [0.2, 0.4], decision="episode")
    result = time_to_beat(run)
    assert result.beat_learner_steps == 1000 and result.beat_env_steps is None


def test_a_sweep_directory_means_its_trials_and_the_table_counts_them(tmp_path, capsys):
    _run(tmp_path / "sweep" / "trial_00000", [0.5, 0.6])
    _run(tmp_path / "sweep" / "trial_00001", [0.5, 0.5])
    assert [p.name for p in run_dirs([str(tmp_path / "sweep")])] == ["trial_00000", "trial_00001"]
    assert main([str(tmp_path / "sweep")]) == 0
    out = capsys.readouterr().out
    assert "not within 2 evaluations" in out and "1 of 2 runs passed" in out
    assert "Mean over them: 1000 env steps, 30 s." in out


def test_a_run_without_a_step_zero_evaluation_is_refused(tmp_path):
    run = _run(tmp_path / "a", [0.5, 0.6])
    data = dict(np.load(run / "evaluations.npz"))
    data["timesteps"] = data["timesteps"] + 500
    np.savez(run / "evaluations.npz", **data)
    with pytest.raises(ValueError, match="step-0"):
        time_to_beat(run)
