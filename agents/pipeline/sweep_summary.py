"""The summaries of a sweep directory, read from its trials' run directories alone.

``summary.csv`` / ``summary.md``: one row per trial (overrides, budget, steps trained, best
evaluation of the sweep's metric, wall time, node); ``best_config.yaml``: the resolved training
config of the best trial. Each trial's ``trial.json`` (written by the trial) holds its overrides,
its attempts (node id, IP, hostname, pid, start, seconds) and its summed wall time.
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ..run_files.artifacts import CONFIG_FILE, latest_model_dir, read_meta
from ..run_files.configtools import load_yaml
from ..run_files.errors import UserError
from .learning_curve import EVALUATIONS_FILE, load_learning_curve
from .sweep_config import SWEEP_FILE, LoadedSweep

TRIAL_FILE = "trial.json"
SUMMARY_CSV, SUMMARY_MD, BEST_CONFIG = "summary.csv", "summary.md", "best_config.yaml"


def trial_name(trial_id: str) -> str:
    """Tune's ``<experiment>_<index>`` trial id -> ``trial_<index>`` (stable across restores)."""
    return "trial_" + trial_id.rsplit("_", 1)[-1]


def eval_rows(run_dir: Path) -> list[dict[str, float]]:
    """EvalCallback's log as rows {timesteps, eval_mean_reward, eval_success_rate} (NaN where
    the log has no successes); none for a run without a log, or with a damaged one (said on
    stderr)."""
    if not (Path(run_dir) / EVALUATIONS_FILE).is_file():
        return []
    try:
        curve = load_learning_curve(run_dir)
    except UserError as exc:
        print(f"warning: {exc}; the run's evaluations are left out", file=sys.stderr)
        return []
    return [
        {
            "timesteps": row["timesteps"],
            "eval_mean_reward": row["mean_return"],
            "eval_success_rate": (
                float("nan") if row["success_rate"] is None else row["success_rate"]
            ),
        }
        for row in curve.rows()
    ]


def is_sweep_dir(path: str | Path) -> bool:
    return (Path(path) / SWEEP_FILE).is_file()


def trial_dirs(sweep_dir: str | Path) -> list[Path]:
    """The trials' run directories, in trial order."""
    return sorted(p for p in Path(sweep_dir).glob("trial_*") if (p / CONFIG_FILE).is_file())


def _best_row(rows: list[dict], metric: str, mode: str) -> dict[str, float] | None:
    """Best evaluation by `metric` (highest with mode "max", lowest with "min"; ties broken by the
    higher mean return, whichever the mode), NaN values ranked last."""
    sign = 1.0 if mode == "max" else -1.0

    def key(row: dict) -> tuple[float, float]:
        value, reward = row[metric], row["eval_mean_reward"]
        return (
            sign * value if np.isfinite(value) else -np.inf,
            reward if np.isfinite(reward) else -np.inf,
        )

    rows = [r for r in rows if np.isfinite(r[metric]) or np.isfinite(r["eval_mean_reward"])]
    return max(rows, key=key) if rows else None


TUNE_STATUS = {
    "TERMINATED": "stopped early",  # without final/: stopped by the scheduler
    "ERROR": "error",
    "RUNNING": "interrupted",
    "PENDING": "interrupted",
    "PAUSED": "interrupted",
}


def trial_row(run_dir: Path, metric: str, mode: str, tune_status: str | None = None) -> dict:
    """One summary row of a trial, from its run directory (and Tune's status of the trial)."""
    info_path = run_dir / TRIAL_FILE
    info = json.loads(info_path.read_text()) if info_path.is_file() else {}
    config = load_yaml(run_dir / CONFIG_FILE)
    budget = int(info.get("budget") or config.get("train", {}).get("total_timesteps", 0))
    latest = latest_model_dir(run_dir)
    steps = int(read_meta(latest).get("num_timesteps", 0)) if latest else 0
    final = steps >= budget  # final/, or a checkpoint at the budget when ASHA stopped it there
    rows = eval_rows(run_dir)
    best = _best_row(rows, metric, mode)
    attempts = info.get("attempts") or [{}]
    last = attempts[-1]
    return {
        "trial": run_dir.name,
        "status": "finished" if final else TUNE_STATUS.get(tune_status or "", "incomplete"),
        "overrides": " ".join(info.get("overrides", [])),
        "budget": budget,
        "steps": steps,
        f"best_{metric}": best[metric] if best else float("nan"),
        "best_at_step": best["timesteps"] if best else None,
        "best_eval_mean_reward": best["eval_mean_reward"] if best else float("nan"),
        "evaluations": len(rows),
        "wall_seconds": float(info.get("wall_seconds", float("nan"))),
        "node_id": last.get("node_id", ""),
        "node_ip": last.get("node_ip", ""),
        "hostname": last.get("hostname", ""),
        "attempts": len(info.get("attempts", [])),
        "run_dir": str(run_dir),
    }


def write_summary(
    sweep_dir: str | Path, sweep: LoadedSweep, statuses: dict[str, str] | None = None
) -> list[dict[str, Any]]:
    """Write summary.csv, summary.md and best_config.yaml from the trials' run directories;
    `statuses`: Ray Tune's status per trial name (tells early-stopped from interrupted)."""
    sweep_dir = Path(sweep_dir)
    cfg = sweep.config
    statuses = statuses or {}
    rows = [trial_row(d, cfg.metric, cfg.mode, statuses.get(d.name)) for d in trial_dirs(sweep_dir)]
    best = _best_row(
        [
            {
                "r": r,
                cfg.metric: r[f"best_{cfg.metric}"],
                "eval_mean_reward": r["best_eval_mean_reward"],
            }
            for r in rows
        ],
        cfg.metric,
        cfg.mode,
    )
    for r in rows:
        r["best"] = best is not None and r is best["r"]
    if rows:
        with open(sweep_dir / SUMMARY_CSV, "w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
    (sweep_dir / SUMMARY_MD).write_text(summary_markdown(rows, sweep))
    if best is not None:
        trial_dir = Path(best["r"]["run_dir"])
        header = (
            f"# Best trial of {sweep_dir.name}: {trial_dir.name} "
            f"({cfg.metric} {best[cfg.metric]:.4g}, {cfg.mode}); resolved training config\n"
        )
        (sweep_dir / BEST_CONFIG).write_text(header + (trial_dir / CONFIG_FILE).read_text())
    return rows


def _fmt(x: Any) -> str:
    if isinstance(x, float):
        return "n/a" if not np.isfinite(x) else f"{x:.4g}"
    return "" if x is None else str(x)


def summary_markdown(rows: list[dict[str, Any]], sweep: LoadedSweep) -> str:
    cfg = sweep.config
    space = ", ".join(f"`{k}` {d.kind} {d.values}" for k, d in cfg.space.items())
    lines = [
        f"# Sweep summary ({len(rows)} trials)",
        "",
        f"Search space: {space}; {cfg.num_samples} sample(s); metric `{cfg.metric}` ({cfg.mode}) "
        f"from each run's evaluation callback; scheduler: "
        f"{'ASHA' if cfg.scheduler else 'none'}; searcher: {cfg.searcher}. Best eval: the best "
        "evaluation of the run (ties broken by the mean return). Wall time: the trial's training "
        "time summed over its attempts [s]. Status: finished, stopped early (by the scheduler), "
        "interrupted (continue with `train.py --resume <sweep dir>`) or error.",
        "",
        f"| trial | status | overrides | budget [steps] | steps | best {cfg.metric} "
        "| at step | best eval return | wall time [s] | node id | host |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        mark = " (best)" if r["best"] else ""
        cells = [
            f"`{r['trial']}`{mark}",
            r["status"],
            f"`{r['overrides']}`",
            r["budget"],
            r["steps"],
            _fmt(r[f"best_{cfg.metric}"]),
            r["best_at_step"],
            _fmt(r["best_eval_mean_reward"]),
            _fmt(r["wall_seconds"]),
            str(r["node_id"])[:12],
            r["hostname"],
        ]
        lines.append("| " + " | ".join(_fmt(c) for c in cells) + " |")
    return "\n".join(lines) + "\n"
