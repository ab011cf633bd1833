"""Does a trained model beat its own step-0 policy? Paired evaluation on fixed tasks.

For each model: rebuild its step-0 policy (`agents.run_files.step0`: the model with its actor's
zero-initialised output layer zeroed again, or a warm-started run's ``warm_start/`` model), then
evaluate both on the same tasks of the
training env (its config's env id, kwargs and minimum task difficulty; `--distribution train`
by default: the tasks training drew from) with `evaluate.py`, the step-0 policy as the
reference. Each model's suite and report go to
``<output-dir>/<env id>__<model name>__<distribution>/`` (the rebuilt step-0 model is removed
after its evaluation); one line per model gives the success counts, tip-overs, the paired 95 %
intervals of the success and return differences and the verdict of `verdict`.
``<output-dir>/summary.json`` keeps every model's figures, keyed by the model path given, then
the task distribution, with the SHA-256 of its model.zip; a rerun replaces the entry.

    python scripts/check_step0.py models/HexapodIrregularTerrain-v0/ppo [more models] \
        --episodes 50 --seed 1000 --output-dir reports/step0_check
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shutil
import sys
from pathlib import Path

from agents.pipeline.cli import evaluate_main
from agents.run_files.artifacts import find_model
from agents.run_files.configtools import dump_yaml
from agents.run_files.errors import UserError
from agents.run_files.step0 import write_step0_model
from agents.run_files.train_config import load_train_config

STEP0_DIR, REPORT_DIR, SUMMARY_FILE = "step0_model", "report", "summary.json"


def suite_for(model: Path, step0: Path, args: argparse.Namespace, out_dir: Path) -> dict:
    """The evaluation suite (`agents.pipeline.eval_config`) of one model against its step 0."""
    config = load_train_config(data=find_model(model).training_config())
    kwargs = {**config.env.kwargs, "task_distribution": args.distribution}
    env = {"id": config.env.id, "kwargs": kwargs, "max_episode_steps": config.env.max_episode_steps}
    if config.env.min_task_difficulty is not None:  # the part of the distribution it trained on
        env["min_task_difficulty"] = config.env.min_task_difficulty
    trained, start = f"ppo:{model}", f"ppo:{step0}"
    return {
        "title": f"{model} against its step-0 policy",
        "envs": [env],
        "policies": [start, trained],
        "references": [start],
        "episodes": args.episodes,
        "seed": args.seed,
        "output_dir": str(out_dir),
        "missing_models": "error",
        "gym_packages": config.env.gym_packages,
    }


def _comparison(env: dict, metric: str, challenger: str) -> dict:
    return next(
        c for c in env["comparisons"] if c["metric"] == metric and c["challenger"] == challenger
    )


def verdict(success: dict, episode_return: dict) -> str:
    """Success decides; where its paired interval includes 0 and the trained model succeeds at
    least as often, the return (what the learner maximised) decides."""
    if success["resolved"] and success["interval"][0] > 0:
        return "beats its step 0 (success)"
    not_lower = success["challenger_value"] >= success["baseline_value"]
    if not_lower and episode_return["resolved"] and episode_return["interval"][0] > 0:
        return "beats its step 0 (return; success not lower)"
    return "does not beat its step 0"


def check_record(model: Path, metrics: dict) -> dict:
    """The figures of one check: success and tip-over counts, paired intervals, verdict, and the
    checked model file's SHA-256 (a check belongs to these weights only)."""
    ((env_id, env),) = metrics["envs"].items()
    start, trained = metrics["policies"]

    def count(name: str, key: str) -> int:
        return sum(bool(e.get(key)) for e in env["policies"][name]["episodes"])

    success = _comparison(env, "success", trained)
    episode_return = _comparison(env, "episode_return", trained)
    return {
        "env_id": env_id,
        "model_sha256": hashlib.sha256(find_model(model).model.read_bytes()).hexdigest(),
        "tasks": len(env["policies"][trained]["episodes"]),
        "seeds": metrics["seeds"],
        "successes": {"step0": count(start, "success"), "trained": count(trained, "success")},
        "tip_overs": {
            "step0": count(start, "tipped_over"),
            "trained": count(trained, "tipped_over"),
        },
        "success_interval": success["interval"],
        "return_change": episode_return["challenger_value"] - episode_return["baseline_value"],
        "return_interval": episode_return["interval"],
        "verdict": verdict(success, episode_return),
    }


def summary_line(model: str, record: dict) -> str:
    (s0, s1), (t0, t1) = (
        (record[k]["step0"], record[k]["trained"]) for k in ("successes", "tip_overs")
    )
    n = record["tasks"]

    def interval(key: str, digits: int) -> str:
        found = record[key]  # None: fewer than two paired tasks
        return "n/a" if found is None else ", ".join(f"{x:+.{digits}f}" for x in found)

    return (
        f"{model} on {record['env_id']}: step 0 {s0}/{n} successes ({t0} tip-overs), trained "
        f"{s1}/{n} ({t1}); success {(s1 - s0) / n:+.3f} [{interval('success_interval', 3)}], "
        f"return {record['return_change']:+.1f} [{interval('return_interval', 1)}]: "
        f"{record['verdict']}"
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("models", nargs="+", type=Path, help="model or run directories")
    parser.add_argument("--episodes", type=int, default=50, help="tasks per policy (50)")
    parser.add_argument("--seed", type=int, default=1000, help="first task seed (1000)")
    parser.add_argument(
        "--distribution", default="train", help="task_distribution of the tasks (train)"
    )
    parser.add_argument("--output-dir", type=Path, default=Path("reports/step0_check"))
    args = parser.parse_args(argv)
    if args.episodes < 2:
        parser.error(
            f"--episodes must be >= 2 (a paired interval needs two tasks), got {args.episodes}"
        )
    summary_path = args.output_dir / SUMMARY_FILE
    summary = json.loads(summary_path.read_text()) if summary_path.is_file() else {}
    for model in args.models:
        try:
            name = "__".join([*find_model(model).directory.parts[-2:], args.distribution])
            out_dir = args.output_dir / name
            out_dir.mkdir(parents=True, exist_ok=True)
            step0 = write_step0_model(model, out_dir / STEP0_DIR)
        except UserError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
        suite_path = out_dir / "suite.yaml"
        suite_path.write_text(dump_yaml(suite_for(model, step0, args, out_dir / REPORT_DIR)))
        try:
            code = evaluate_main(["--config", str(suite_path), "--force"])
        finally:
            shutil.rmtree(step0)  # rebuilt from the model by the next run; the report is the record
        if code != 0:
            return code
        metrics = json.loads((out_dir / REPORT_DIR / "metrics.json").read_text())
        record = check_record(model, metrics)
        summary.setdefault(str(model), {})[args.distribution] = record
        summary_path.write_text(json.dumps(summary, indent=2, sort_keys=True) + "\n")
        print(summary_line(str(model), record), flush=True)
    print("\nsummary (" + str(summary_path) + "):")
    for model, records in sorted(summary.items()):
        for distribution, record in sorted(records.items()):
            print(f"[{distribution}] {summary_line(model, record)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
