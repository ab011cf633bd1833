"""Time to beat the reference: how long a training run takes to pass the analytical controller.

A run whose step 0 is the analytical controller (a hybrid residual with a zero-initialised
action net, e.g. configs/irregular_terrain_v1_gains.yaml) and whose evaluations score every
checkpoint on the same fixed tasks (``eval.same_tasks``) measures the controller on those tasks
at step 0. For each run this prints the first evaluation whose success rate is above step 0's
(or above ``--reference-success``): its learner steps, env steps and wall-clock seconds since
the step-0 evaluation, and the mean over the runs (seeds) that got there; runs that did not are
counted, not averaged.

- **Wall-clock** is the run's own: the wall times of its TensorBoard events (``tb/``), which
  include the evaluations themselves.
- **Env steps** are the learner's steps, except for ``env.decision: gait_cycle`` runs (one
  learner step per gait cycle). There they are learner steps times the env steps per cycle,
  measured in the run as the mean evaluation episode length [env steps] over the mean training
  episode length [cycles] (``rollout/ep_len_mean``) logged nearest to that evaluation. A knobs
  run's learner step is a whole episode (`agents.knobs`), as is an ``env.decision: episode``
  run's; their env steps are not logged and are shown as "-".

    python benchmarks/bench_time_to_beat.py runs/<sweep dir>            # every trial_* in it
    python benchmarks/bench_time_to_beat.py runs/a runs/b --reference-success 0.6
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from agents.pipeline.learning_curve import LearningCurve, load_learning_curve


@dataclass
class TimeToBeat:
    """One run's answer; the `beat_*` fields are None when no evaluation passed the reference."""

    run: str
    reference: float
    best: float
    evaluations: int
    beat_learner_steps: int | None
    beat_env_steps: float | None
    beat_wall_s: float | None


def tb_scalars(run_dir: Path, tag: str) -> list[tuple[int, float, float]]:
    """(step, wall time [s], value) of a TensorBoard scalar of the run (every event file in
    ``tb/``, sorted by step); [] when the run has none."""
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    rows = []
    for events in sorted((run_dir / "tb").glob("**/events.out.tfevents.*")):
        accumulator = EventAccumulator(str(events), size_guidance={"scalars": 0})
        accumulator.Reload()
        if tag in accumulator.Tags()["scalars"]:
            rows += [(e.step, e.wall_time, e.value) for e in accumulator.Scalars(tag)]
    return sorted(rows)


def _env_steps_per_learner_step(run_dir: Path, step: int, curve: LearningCurve) -> float | None:
    """1, for a gait-cycle run the env steps per cycle measured near `step`, for a knobs or
    per-episode run None (module doc)."""
    if curve.unit in ("tipping events", "episodes"):
        return None
    if curve.unit != "gait cycles":
        return 1.0
    lengths = tb_scalars(run_dir, "rollout/ep_len_mean")
    if not lengths:
        raise ValueError(f"{run_dir}: a gait-cycle run without rollout/ep_len_mean in tb/")
    nearest = min(lengths, key=lambda row: abs(row[0] - step))
    return float(np.mean(curve.lengths)) / nearest[2]


def time_to_beat(run_dir: str | Path, reference: float | None = None) -> TimeToBeat:
    """The first evaluation of `run_dir` above `reference` (default: its step-0 success)."""
    run_dir = Path(run_dir)
    curve = load_learning_curve(run_dir)
    rates = curve.success_rate
    if rates is None or curve.timesteps[0] != 0:
        raise ValueError(f"{run_dir}: needs success rates and a step-0 evaluation")
    reference = float(rates[0]) if reference is None else float(reference)
    above = np.flatnonzero(rates > reference)
    result = TimeToBeat(str(run_dir), reference, float(rates.max()), len(rates), None, None, None)
    if above.size == 0:
        return result
    step = int(curve.timesteps[above[0]])
    wall = {s: t for s, t, _ in tb_scalars(run_dir, "eval/success_rate")}
    result.beat_learner_steps = step
    per_step = _env_steps_per_learner_step(run_dir, step, curve)
    result.beat_env_steps = None if per_step is None else step * per_step
    result.beat_wall_s = wall[step] - wall[0] if {0, step} <= wall.keys() else None
    return result


def run_dirs(paths: list[str]) -> list[Path]:
    """The runs named: a run directory as it is, a sweep directory as its ``trial_*``."""
    found = []
    for path in map(Path, paths):
        trials = sorted(p for p in path.glob("trial_*") if p.is_dir())
        found += trials or [path]
    return found


def table(results: list[TimeToBeat]) -> str:
    lines = [
        "| run | reference success | best success | passed at (learner steps) | env steps | "
        "wall [s] |",
        "|---|---|---|---|---|---|",
    ]
    for r in results:
        if r.beat_learner_steps is None:
            passed = f"not within {r.evaluations} evaluations | - | -"
        else:
            wall = "-" if r.beat_wall_s is None else f"{r.beat_wall_s:.0f}"
            env_steps = "-" if r.beat_env_steps is None else f"{r.beat_env_steps:.0f}"
            passed = f"{r.beat_learner_steps} | {env_steps} | {wall}"
        lines.append(f"| {r.run} | {r.reference:.0%} | {r.best:.0%} | {passed} |")
    passed = [r for r in results if r.beat_learner_steps is not None]
    lines.append("")
    lines.append(f"{len(passed)} of {len(results)} runs passed the reference.")
    if passed:
        counted = [r.beat_env_steps for r in passed if r.beat_env_steps is not None]
        env_steps = f"{np.mean(counted):.0f} env steps" if counted else "no env-step counts"
        walls = [r.beat_wall_s for r in passed if r.beat_wall_s is not None]
        wall = f"{np.mean(walls):.0f} s" if walls else "no wall times"
        lines.append(f"Mean over them: {env_steps}, {wall}.")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", help="run directories or sweep directories")
    parser.add_argument(
        "--reference-success",
        type=float,
        default=None,
        help="the success rate to pass (default: each run's step-0 evaluation)",
    )
    args = parser.parse_args(argv)
    results = [time_to_beat(run, args.reference_success) for run in run_dirs(args.runs)]
    print(table(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
