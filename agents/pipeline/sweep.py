"""Hyperparameter sweeps and multi-seed studies on Ray Tune (``python train.py --sweep``).

Each trial is an ordinary training run (`training.start_training`) in its own run directory inside
the sweep directory; Ray Tune only schedules the trials, samples the search space, and stops
unpromising trials early (ASHA) from the metrics each run reports after every evaluation. A sweep
directory::

    sweep.yaml, base_config.yaml, command.txt   the resolved sweep, its base config, commands
    trial_00000/ ...            run directories (config.yaml, tb/, checkpoints/, best/, final/,
                                evaluations.npz) plus trial.json (overrides, node, wall time)
    summary.csv, summary.md     one row per trial: overrides, budget, best eval metric, wall
                                time, node
    best_config.yaml            the resolved training config of the best trial
    ray/                        Ray Tune's experiment state (used by ``--resume``)

Without ``--address`` the command starts a local Ray instance with ``max(cores,
max_concurrent x cpus_per_trial)`` CPUs; with ``--address auto|host:port`` the trials run on an
existing cluster (every node must see the sweep directory at the same path, e.g. over NFS).
Every trial runs with ``train.num_threads=1`` and reserves ``cpus_per_trial`` CPUs. Ctrl-C stops
all trials within seconds (their periodic checkpoints stay); ``python train.py --resume <sweep
dir>`` restores the Tune experiment and continues unfinished trials from their latest
checkpoints.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import socket
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..run_files.artifacts import (
    CONFIG_FILE,
    command_line,
    latest_model_dir,
    prepare_new_dir,
    read_meta,
)
from ..run_files.configtools import dump_yaml, to_mapping
from ..run_files.errors import UserError
from .sweep_config import SWEEP_FILE, LoadedSweep, load_sweep
from .sweep_summary import (
    SUMMARY_MD,
    TRIAL_FILE,
    eval_rows,
    is_sweep_dir,
    trial_name,
    write_summary,
)

BASE_FILE = "base_config.yaml"
RAY_DIR = "ray"
TRIAL_FORCED = ("train.num_threads=1", "logging.progress_bar=false")
"""Overrides of every trial: one torch thread per trial (trials share the cores), no bars."""


@dataclass
class SweepResult:
    sweep_dir: Path
    num_trials: int
    finished: int
    errors: list[str]
    interrupted: bool
    seconds: float
    best_trial: str | None


# --- the trial (runs in a Ray worker) ------------------------------------------------------
def _node_info() -> dict[str, Any]:
    import ray

    context = ray.get_runtime_context()
    return {
        "node_id": context.get_node_id(),
        "node_ip": ray.util.get_node_ip_address(),
        "hostname": socket.gethostname(),
        "pid": os.getpid(),
    }


def _make_reporter(node: dict[str, Any], on_eval: Any) -> Any:
    """SB3 callback run after each evaluation: calls `on_eval()`, then reports the evaluation's
    means to Ray Tune."""
    from ray import tune
    from stable_baselines3.common.callbacks import BaseCallback

    class TuneReport(BaseCallback):
        reported = 0

        def _on_step(self) -> bool:
            on_eval()
            evaluation = self.parent
            buffer = evaluation._is_success_buffer
            tune.report(
                {
                    "timesteps": int(self.num_timesteps),
                    "eval_mean_reward": float(evaluation.last_mean_reward),
                    "eval_success_rate": float(np.mean(buffer)) if buffer else float("nan"),
                    **node,
                }
            )
            TuneReport.reported += 1
            return True

    return TuneReport()


def run_trial(
    params: dict[str, Any],
    sweep: LoadedSweep,
    sweep_dir: str,
    command: str,
    trust_pickle: bool = False,
) -> None:
    """Ray Tune function trainable: train one run (or continue it after an interruption;
    `trust_pickle` as ``train.py --resume --trust-pickle`` for a run with pickled files)."""
    import torch
    from ray import tune

    from ..run_files.train_config import load_train_config
    from .training import resume_training, start_training

    torch.set_num_threads(1)
    trial_id = tune.get_context().get_trial_id()
    name = trial_name(trial_id)
    run_dir = Path(sweep_dir) / name
    overrides = sweep.trial_overrides(params)
    config = load_train_config(data=sweep.base_data, overrides=[*overrides, *TRIAL_FORCED])
    node = _node_info()
    info_path = run_dir / TRIAL_FILE
    info = json.loads(info_path.read_text()) if info_path.is_file() else {}
    info.update(trial=name, trial_id=trial_id, overrides=overrides)
    info["budget"] = config.train.total_timesteps
    attempts = info.setdefault("attempts", [])
    attempts.append({**node, "started": time.strftime("%Y-%m-%dT%H:%M:%S"), "seconds": None})
    start = time.perf_counter()

    def save_info(interrupted: bool | None = None) -> None:
        """trial.json in the run directory: at the start, after every evaluation, at the end."""
        attempts[-1]["seconds"] = time.perf_counter() - start
        if interrupted is not None:
            attempts[-1]["interrupted"] = interrupted
        info["wall_seconds"] = sum(a["seconds"] or 0.0 for a in attempts)
        if run_dir.is_dir():
            info_path.write_text(json.dumps(info, indent=1) + "\n")

    reporter = _make_reporter({"node_id": node["node_id"], "hostname": node["hostname"]}, save_info)
    latest = latest_model_dir(run_dir) if (run_dir / CONFIG_FILE).is_file() else None
    done = int(read_meta(latest).get("num_timesteps", 0)) if latest else 0
    result = None
    if latest is None:
        # A new trial, or one interrupted before its first checkpoint: (re)start from scratch.
        if run_dir.exists():
            shutil.rmtree(run_dir)
        result = start_training(config, sweep_dir, name, command=command, after_eval=reporter)
    elif done < config.train.total_timesteps:
        save_info()
        result = resume_training(
            run_dir, command=command, after_eval=reporter, trust_pickle=trust_pickle
        )
    save_info(interrupted=bool(result and result.interrupted))
    if reporter.reported == 0:  # nothing evaluated in this attempt: report the run's last eval
        rows = eval_rows(run_dir)
        last = rows[-1] if rows else {"timesteps": done, "eval_mean_reward": float("nan")}
        tune.report({"eval_success_rate": float("nan"), **last, **node})


# --- the driver ----------------------------------------------------------------------------
def _init_ray(address: str | None, max_concurrent: int | None, cpus_per_trial: float) -> None:
    """Join `address` or start a local instance sized to the machine (and `max_concurrent`)."""
    import ray

    if ray.is_initialized():
        return
    if address is not None:
        _check_reachable(address)
        try:
            ray.init(address=address, log_to_driver=True)
        except (ConnectionError, RuntimeError, ValueError) as exc:
            raise UserError(f"cannot join the Ray cluster at {address!r}: {exc}") from None
        return
    cores = os.cpu_count() or 1
    wanted = (max_concurrent or cores) * cpus_per_trial
    # address="local": a new instance even when `ray start` runs a cluster on this machine.
    ray.init(address="local", num_cpus=max(cores, int(np.ceil(wanted))), include_dashboard=False)


def _check_reachable(address: str, timeout_s: float = 5.0) -> None:
    """Fail fast on a ``host:port`` nobody listens on (Ray itself retries for minutes)."""
    if address in ("auto", "local") or "://" in address:
        return
    host, sep, port = address.rpartition(":")
    if not sep or not port.isdigit():
        raise UserError(f"--address must be auto or host:port, got {address!r}")
    try:
        socket.create_connection((host, int(port)), timeout=timeout_s).close()
    except OSError as exc:
        raise UserError(
            f"no Ray cluster answers at {address} ({exc}); start one with `ray start --head`"
        ) from None


def _tuner_parts(
    sweep: LoadedSweep, sweep_dir: Path, command: str, trust_pickle: bool = False
) -> tuple[Any, dict]:
    from ray import tune

    trainable = tune.with_parameters(
        run_trial,
        sweep=sweep,
        sweep_dir=str(sweep_dir.resolve()),
        command=command,
        trust_pickle=trust_pickle,
    )
    trainable = tune.with_resources(trainable, {"cpu": sweep.config.cpus_per_trial})
    space = {key: domain.to_tune() for key, domain in sweep.config.space.items()}
    return trainable, space


def _tune_config(sweep: LoadedSweep, max_concurrent: int | None) -> Any:
    from ray import tune

    cfg = sweep.config
    scheduler = search_alg = None
    if cfg.scheduler is not None:
        from ray.tune.schedulers import ASHAScheduler

        scheduler = ASHAScheduler(
            time_attr="timesteps",
            # Past the budget: a trial that reaches it finishes (saves final/) before ASHA acts.
            max_t=cfg.scheduler.max_t or sweep.base_config.train.total_timesteps + 1,
            grace_period=cfg.scheduler.grace_period,
            reduction_factor=cfg.scheduler.reduction_factor,
        )
    if cfg.searcher == "optuna":
        from ray.tune.search.optuna import OptunaSearch

        search_alg = OptunaSearch(seed=sweep.base_config.train.seed)
    return tune.TuneConfig(
        metric=cfg.metric,
        mode=cfg.mode,
        num_samples=cfg.num_samples,
        scheduler=scheduler,
        search_alg=search_alg,
        max_concurrent_trials=max_concurrent,
        trial_dirname_creator=lambda trial: trial_name(trial.trial_id),
    )


def _default_concurrency(address: str | None, max_concurrent: int | None) -> int | None:
    if max_concurrent is not None:
        if max_concurrent < 1:
            raise UserError(f"--max-concurrent must be >= 1, got {max_concurrent}")
        return max_concurrent
    return None if address is not None else (os.cpu_count() or 1)


def run_sweep(
    sweep: LoadedSweep,
    output_dir: str | Path = "runs",
    name: str | None = None,
    force: bool = False,
    command: str | None = None,
    address: str | None = None,
    max_concurrent: int | None = None,
    trust_pickle: bool = False,
) -> SweepResult:
    """Create the sweep directory, run every trial on Ray Tune, write the summaries."""
    from ray import tune

    from .training import check_env

    max_concurrent = _default_concurrency(address, max_concurrent)
    check_env(sweep.base_config)  # before the sweep directory exists, as is:
    if address is not None:
        _check_reachable(address)
    stem = sweep.path.stem if sweep.path else "sweep"
    name = name or sweep.config.name or f"{stem}__{time.strftime('%Y%m%d-%H%M%S')}"
    sweep_dir = prepare_new_dir(
        Path(output_dir) / name, force, "sweep directory", (SWEEP_FILE,)
    ).resolve()
    command = command or command_line()
    resolved = to_mapping(sweep.config)
    resolved["base"] = BASE_FILE  # self-contained: the sweep directory holds its base config
    (sweep_dir / SWEEP_FILE).write_text(dump_yaml(resolved))
    (sweep_dir / BASE_FILE).write_text(dump_yaml(sweep.base_data))
    (sweep_dir / "command.txt").write_text(command + "\n")
    _init_ray(address, max_concurrent, sweep.config.cpus_per_trial)
    trainable, space = _tuner_parts(sweep, sweep_dir, command, trust_pickle)
    tuner = tune.Tuner(
        trainable,
        param_space=space,
        tune_config=_tune_config(sweep, max_concurrent),
        run_config=_run_config(sweep, sweep_dir),
    )
    return _fit(tuner, sweep, sweep_dir)


def resume_sweep(
    sweep_dir: str | Path,
    command: str | None = None,
    address: str | None = None,
    max_concurrent: int | None = None,
    trust_pickle: bool = False,
) -> SweepResult:
    """Continue an interrupted sweep: unfinished and errored trials resume from checkpoints,
    with the concurrency the sweep started with unless `max_concurrent` is given."""
    from ray import tune

    sweep_dir = Path(sweep_dir).resolve()
    if not is_sweep_dir(sweep_dir):
        raise UserError(f"{sweep_dir} is not a sweep directory (no {SWEEP_FILE})")
    if not tune.Tuner.can_restore(str(sweep_dir / RAY_DIR)):
        raise UserError(f"{sweep_dir / RAY_DIR} holds no Ray Tune experiment state to resume")
    sweep = load_sweep(sweep_dir / SWEEP_FILE)
    command = command or command_line()
    with open(sweep_dir / "command.txt", "a") as fh:
        fh.write(command + "\n")
    _init_ray(address, _default_concurrency(address, max_concurrent), sweep.config.cpus_per_trial)
    trainable, _ = _tuner_parts(sweep, sweep_dir, command, trust_pickle)
    tuner = tune.Tuner.restore(
        str(sweep_dir / RAY_DIR), trainable, resume_unfinished=True, restart_errored=True
    )
    if max_concurrent is not None:  # else the restored state's (the sweep's start)
        with contextlib.suppress(AttributeError):
            tuner._local_tuner._tune_config.max_concurrent_trials = max_concurrent
    return _fit(tuner, sweep, sweep_dir)


def _run_config(sweep: LoadedSweep, sweep_dir: Path) -> Any:
    from ray import tune

    return tune.RunConfig(
        name=RAY_DIR,
        storage_path=str(sweep_dir),
        failure_config=tune.FailureConfig(max_failures=sweep.config.max_failures),
        checkpoint_config=tune.CheckpointConfig(num_to_keep=None),
        verbose=1,
    )


def _fit(tuner: Any, sweep: LoadedSweep, sweep_dir: Path) -> SweepResult:
    start = time.perf_counter()
    grid = tuner.fit()
    seconds = time.perf_counter() - start
    errors = [f"{r.path}: {type(r.error).__name__}: {r.error}" for r in grid if r.error]
    # Tune returns normally after Ctrl-C, leaving the trials it stopped RUNNING or PENDING.
    statuses = {trial_name(t.trial_id): t.status for t in _tune_trials(grid)}
    rows = write_summary(sweep_dir, sweep, statuses)
    finished = sum(row["status"] == "finished" for row in rows)
    interrupted = any(s in ("RUNNING", "PENDING", "PAUSED") for s in statuses.values())
    num_trials = max(len(statuses), sweep.config.num_trials)
    best = next((r["trial"] for r in rows if r.get("best")), None)
    return SweepResult(sweep_dir, num_trials, finished, errors, interrupted, seconds, best)


def _tune_trials(grid: Any) -> list[Any]:
    """Every trial of the experiment with its status (the ResultGrid lists results only)."""
    from ray.tune import ExperimentAnalysis

    return ExperimentAnalysis(grid.experiment_path).trials


# --- train.py --sweep ----------------------------------------------------------------------
def require_ray() -> None:
    try:
        import ray  # noqa: F401
        from ray import tune  # noqa: F401
    except ImportError:
        raise UserError(
            'sweeps need Ray Tune: pip install -e ".[sweep]" (ray[tune], optuna, rliable)'
        ) from None


def sweep_main(args: Any, command: str) -> int:
    """``train.py --sweep FILE`` / ``train.py --resume SWEEP_DIR`` (arguments already parsed)."""
    import sys

    require_ray()
    if args.resume is not None:
        if args.overrides or args.run_name or args.force:
            raise UserError("--set, --run-name and --force do not apply to resuming a sweep")
        result = resume_sweep(
            args.resume, command, args.address, args.max_concurrent, args.trust_pickle
        )
    else:
        sweep = load_sweep(args.sweep, args.overrides)
        result = run_sweep(
            sweep,
            args.output_dir,
            args.run_name,
            force=args.force,
            command=command,
            address=args.address,
            max_concurrent=args.max_concurrent,
            trust_pickle=args.trust_pickle,
        )
    for line in result.errors:
        print(f"trial error: {line}", file=sys.stderr)
    print(
        f"sweep: {result.finished}/{result.num_trials} trials finished in {result.seconds:.1f} s"
        f"; best trial: {result.best_trial}\nsweep directory: {result.sweep_dir}\n"
        f"summary: {result.sweep_dir / SUMMARY_MD}"
    )
    if result.interrupted:
        print(
            f"interrupted; continue with: python train.py --resume {result.sweep_dir}",
            file=sys.stderr,
        )
        return 130
    return 1 if result.errors else 0
