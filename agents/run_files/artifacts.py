"""Where models live on disk: run directories and self-describing model directories.

A **model directory** holds everything needed to use or resume one saved model::

    model.zip          SB3 PPO model (weights, optimiser, num_timesteps)
    vecnormalize.npz   VecNormalize statistics as plain arrays (absent when normalisation is
                       off; older runs have a pickled vecnormalize.pkl, see `model_files`)
    config.yaml        the resolved training config (env id and kwargs included)
    env_settings.yaml  every setting of the training env, defaults filled in (`env_settings`)
    command.txt        the command line that produced it
    meta.json          num_timesteps, observation/action shapes, kind, eval reward (if best)

A **run directory** (``runs/{env}__ppo__{seed}__{time}``)::

    config.yaml, command.txt    resolved config; every command run on it, one per line
    env_settings.yaml           the training env's settings, defaults filled in
    tb/                         TensorBoard event files (a resumed run appends here)
    checkpoints/step_<N>/       periodic and Ctrl-C checkpoints (model directories)
    best/                       best model by EvalCallback's mean reward (model directory)
    final/                      model at the end of training (model directory)
    evaluations.npz             EvalCallback's log

Shipped models (``models/<env_id>/``) are model directories. Every file is written atomically
and ``meta.json`` last, so a model directory with a ``meta.json`` was completely written.
"""

from __future__ import annotations

import json
import re
import shlex
import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .configtools import dump_yaml, load_yaml
from .env_settings import SETTINGS_FILE, write_settings
from .errors import UserError
from .model_files import (
    LEGACY_STATS_FILE,
    STATS_FILE,
    NormalizationStats,
    atomic_path,
    atomic_write_text,
)
from .shipped import resolve_shipped

MODEL_FILE = "model.zip"
CONFIG_FILE = "config.yaml"
COMMAND_FILE = "command.txt"
META_FILE = "meta.json"
CHECKPOINTS = "checkpoints"
BEST, FINAL = "best", "final"
WARM_START = "warm_start"
"""A warm-started run's model after the warm start, before PPO: its step-0 policy."""


def command_line(argv: list[str] | None = None) -> str:
    """The command as typed (``python train.py --config ...``), shell-quoted."""
    argv = sys.argv if argv is None else argv
    return shlex.join(["python", *argv])


def run_name(env_id: str, seed: int, now: float | None = None) -> str:
    stamp = time.strftime("%Y%m%d-%H%M%S", time.localtime(now))
    return f"{env_id}__ppo__{seed}__{stamp}"


def prepare_new_dir(
    path: Path, force: bool, what: str, markers: tuple[str, ...] = (), check_only: bool = False
) -> Path:
    """Create `path`; an existing non-empty directory is an error unless `force` (then emptied).
    `check_only`: raise where that would be refused, and change nothing.

    `markers`: file names of which this tool's own output holds at least one (a run's
    ``config.yaml``, a report's ``metrics.json``). With markers given, `force` empties only a
    directory that holds one of them, and never the working directory, the home directory or
    a directory above either: a mistyped ``--output-dir`` must not delete someone's files.
    """
    path = Path(path)
    if path.exists() and (not path.is_dir() or any(path.iterdir())):
        if not force:
            raise UserError(f"{what} {path} already exists; pass --force to overwrite it")
        if markers:
            _check_replaceable(path, what, markers)
        if check_only:
            return path
        if path.is_dir():
            shutil.rmtree(path)
        else:
            path.unlink()
    if not check_only:
        path.mkdir(parents=True, exist_ok=True)
    return path


def _check_replaceable(path: Path, what: str, markers: tuple[str, ...]) -> None:
    """UserError unless `path` looks like an earlier `what` (holds a marker file) and is
    neither the working nor the home directory nor above one of them."""
    resolved = path.resolve()
    for protected in (Path.cwd().resolve(), Path.home().resolve()):
        if resolved == protected or resolved in protected.parents:
            raise UserError(
                f"--force would delete {path}, which is or contains {protected}; "
                f"choose a new directory for the {what}"
            )
    if not path.is_dir():
        raise UserError(f"{path} exists and is not a directory; choose another {what}")
    if not any((path / name).exists() for name in markers):
        raise UserError(
            f"{path} exists and is not an earlier {what} (it has none of {list(markers)}); "
            "--force only replaces the tool's own output: choose another directory or empty "
            "it yourself"
        )


def save_model_dir(
    path: Path,
    model: Any,
    vec_normalize: Any | None,
    config: Any,
    command: str,
    kind: str,
    extra_meta: dict[str, Any] | None = None,
    env_settings: dict[str, Any] | None = None,
) -> Path:
    """Write a model directory (see module docstring): each file atomically, meta.json last.
    `env_settings`: the training env's resolved settings (`env_settings.resolved_settings`)."""
    path = Path(path)
    path.mkdir(parents=True, exist_ok=True)
    (path / META_FILE).unlink(missing_ok=True)  # rewriting: incomplete until the new meta.json
    with atomic_path(path / MODEL_FILE) as tmp:
        model.save(tmp)  # the temporary name ends in .tmp, so SB3 adds no .zip
    if vec_normalize is not None:
        NormalizationStats.from_vec_normalize(vec_normalize).save(path / STATS_FILE)
    elif (path / STATS_FILE).exists():
        (path / STATS_FILE).unlink()
    if (path / LEGACY_STATS_FILE).exists():  # superseded by the .npz just written
        (path / LEGACY_STATS_FILE).unlink()
    atomic_write_text(path / CONFIG_FILE, dump_yaml(config))
    if env_settings is None:
        (path / SETTINGS_FILE).unlink(missing_ok=True)  # an earlier model's, not this one's
    else:
        write_settings(path, env_settings)
    atomic_write_text(path / COMMAND_FILE, command + "\n")
    meta = {
        "kind": kind,
        "num_timesteps": int(model.num_timesteps),
        "observation_shape": list(model.observation_space.shape),
        "action_shape": list(model.action_space.shape),
        "saved_at": time.strftime("%Y-%m-%dT%H:%M:%S"),
        **(extra_meta or {}),
    }
    atomic_write_text(path / META_FILE, json.dumps(meta, indent=2) + "\n")
    return path


def read_meta(model_dir: Path) -> dict[str, Any]:
    path = Path(model_dir) / META_FILE
    return json.loads(path.read_text()) if path.is_file() else {}


def checkpoint_note(model_dir: Path) -> str:
    """The text ' (<kind> checkpoint at <n> <unit>)' from a model directory's meta.json (the
    unit from the config.yaml beside it, `learner_step_unit`), saying so when it is the initial
    policy (a best/ that no later evaluation beat); '' without a meta.json."""
    meta = read_meta(model_dir)
    steps = meta.get("num_timesteps")
    if steps is None:
        return ""
    kind = meta.get("kind", "saved")
    initial = ": the initial policy, no training step kept" if steps == 0 else ""
    config = Path(model_dir) / "config.yaml"
    unit = learner_step_unit(load_yaml(config) if config.is_file() else None)
    return f" ({kind} checkpoint at {steps} {unit}{initial})"


def learner_step_unit(config: dict | None) -> str:
    """What a run's learner steps count, from its resolved config: "env steps", "gait cycles"
    (``env.decision: gait_cycle``; "platform steps" on the ditch crossing's stride action),
    "episodes" (``env.decision: episode``) or "tipping events" (a recovery ``knobs`` run, one
    step per episode at the controller's tipping judgment; a planner ``knobs`` run counts
    episodes)."""
    config = config or {}
    if config.get("knobs") is not None:
        from ..knobs import settings_from_config

        planner = settings_from_config(config["knobs"]).controller == "planner"
        return "episodes" if planner else "tipping events"
    env = config.get("env") or {}
    decision = env.get("decision")
    if decision == "gait_cycle" and (env.get("kwargs") or {}).get("stride_action"):
        return "platform steps"
    return {"gait_cycle": "gait cycles", "episode": "episodes"}.get(decision, "env steps")


def checkpoint_dir(run_dir: Path, num_timesteps: int) -> Path:
    return Path(run_dir) / CHECKPOINTS / f"step_{num_timesteps:012d}"


def _timesteps(model_dir: Path) -> int:
    meta = read_meta(model_dir)
    if "num_timesteps" in meta:
        return int(meta["num_timesteps"])
    match = re.search(r"(\d+)$", model_dir.name)
    return int(match.group(1)) if match else -1


def saved_model_dirs(run_dir: Path) -> list[Path]:
    """The completely written (`is_complete`) checkpoints/* and final/ of a run, newest (most
    timesteps) first."""
    run_dir = Path(run_dir)
    candidates = sorted((run_dir / CHECKPOINTS).glob("step_*")) + [run_dir / FINAL]
    candidates = [c for c in candidates if is_complete(c)]
    return sorted(candidates, key=lambda c: (_timesteps(c), c.name == FINAL), reverse=True)


def is_complete(model_dir: Path) -> bool:
    """Whether a model directory of a run was completely written: its ``meta.json`` is written
    last (a save interrupted by a kill or a second Ctrl-C leaves none)."""
    return (Path(model_dir) / MODEL_FILE).is_file() and (Path(model_dir) / META_FILE).is_file()


def latest_model_dir(run_dir: Path) -> Path | None:
    """The saved model with the most timesteps among checkpoints/* and final/ (None if none)."""
    dirs = saved_model_dirs(run_dir)
    return dirs[0] if dirs else None


def is_run_dir(path: Path) -> bool:
    path = Path(path)
    return any((path / sub).is_dir() for sub in (BEST, FINAL, CHECKPOINTS))


@dataclass(frozen=True)
class ModelFiles:
    """The files of one saved model, found from a user-given path."""

    directory: Path
    model: Path
    vec_normalize: Path | None  # vecnormalize.npz, or a legacy vecnormalize.pkl
    config: Path | None

    def training_config(self) -> dict[str, Any] | None:
        return load_yaml(self.config) if self.config is not None else None


def other_env_error(files: ModelFiles, trained_for: str | None, env_id: str | None) -> UserError:
    """The error for a model evaluated on an env other than the one it was trained on."""
    return UserError(
        f"the model at {files.model} was trained on another env ({trained_for}), not {env_id}"
    )


def find_model(path: str | Path) -> ModelFiles:
    """Resolve a model file, a model directory or a run directory (best/ > final/ > latest
    checkpoint) to its files; UserError naming the path otherwise. A relative ``models/...``
    path missing from the working directory is a shipped model (`shipped.resolve_shipped`)."""
    path = resolve_shipped(path)
    if not path.exists():
        raise UserError(f"no PPO model at {path}: the path does not exist")
    if path.is_file():
        if path.suffix != ".zip":
            raise UserError(f"{path} is not an SB3 model file (expected a .zip)")
        directory, model = path.parent, path
    elif (path / MODEL_FILE).is_file():
        directory, model = path, path / MODEL_FILE
    elif is_run_dir(path):
        for sub in (path / BEST, path / FINAL):
            if is_complete(sub):
                directory = sub
                break
        else:
            directory = latest_model_dir(path)
            if directory is None:
                raise UserError(f"run directory {path} holds no saved model yet")
        model = directory / MODEL_FILE
    else:
        raise UserError(
            f"no PPO model at {path}: expected a .zip file, a directory with {MODEL_FILE}, "
            f"or a run directory with {BEST}/, {FINAL}/ or {CHECKPOINTS}/"
        )
    vecnorm = directory / STATS_FILE
    if not vecnorm.is_file():
        vecnorm = directory / LEGACY_STATS_FILE
    config = directory / CONFIG_FILE
    return ModelFiles(
        directory=directory,
        model=model,
        vec_normalize=vecnorm if vecnorm.is_file() else None,
        config=config if config.is_file() else None,
    )
