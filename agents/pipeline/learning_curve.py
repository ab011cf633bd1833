"""Learning curves of a training run: evaluation return and success rate against env steps.

Every run with ``eval.freq > 0`` writes SB3's EvalCallback log ``<run dir>/evaluations.npz``
(kept across resumes, see `training`): at each evaluation the env-step count, every episode's
return and length, and, since the hexapod envs report ``info["is_success"]``, every episode's
success. `load_learning_curve` reads it into arrays a report can plot or tabulate.
"""

from __future__ import annotations

import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from ..run_files.artifacts import is_run_dir, learner_step_unit
from ..run_files.errors import UserError

EVALUATIONS_FILE = "evaluations.npz"


@dataclass(frozen=True)
class LearningCurve:
    """One run's evaluations: row i is the evaluation after ``timesteps[i]`` learner steps."""

    timesteps: np.ndarray  # (n,) learner steps (`unit`) summed over the parallel envs
    returns: np.ndarray  # (n, episodes) undiscounted, unnormalised episode returns
    lengths: np.ndarray  # (n, episodes) episode lengths [steps]
    successes: np.ndarray | None  # (n, episodes) 0/1; None if the env reports no is_success
    unit: str = "env steps"
    """What ``timesteps`` counts: the learner's steps, "env steps", "gait cycles" for a run
    whose learner acts once per gait cycle (``env.decision: gait_cycle`` in its config;
    "platform steps" on the ditch crossing's stride action),
    "episodes" for one that acts once per episode (``env.decision: episode``) or
    "tipping events" for a recovery knobs run (one learner step per episode, at the event,
    `agents.knobs`); a planner knobs run counts "episodes" (`agents.plan_knobs`)."""

    @property
    def mean_return(self) -> np.ndarray:
        return self.returns.mean(axis=1)

    @property
    def success_rate(self) -> np.ndarray | None:
        return None if self.successes is None else self.successes.mean(axis=1)

    def rows(self) -> list[dict[str, float]]:
        """One plain dict per evaluation (steps, mean return, success rate) for tables/JSON."""
        rates = self.success_rate
        return [
            {
                "timesteps": int(t),
                "mean_return": float(r),
                "success_rate": None if rates is None else float(rates[i]),
            }
            for i, (t, r) in enumerate(zip(self.timesteps, self.mean_return, strict=True))
        ]


def evaluation_log(model_dir: str | Path) -> Path | None:
    """The evaluation log of the model at `model_dir`: its own ``evaluations.npz`` (a shipped
    model directory keeps a copy), else its run's, for a model inside a run directory
    (``best/``, ``final/``, ``checkpoints/step_N/``); None if there is none."""
    model_dir = Path(model_dir)
    if (model_dir / EVALUATIONS_FILE).is_file():
        return model_dir / EVALUATIONS_FILE
    for run in (model_dir.parent, model_dir.parent.parent):
        if is_run_dir(run) and (run / EVALUATIONS_FILE).is_file():
            return run / EVALUATIONS_FILE
    return None


def read_evaluation_log(
    path: str | Path, required: tuple[str, ...] = ("timesteps", "results", "ep_lengths")
) -> dict[str, np.ndarray]:
    """The arrays of an evaluation log as SB3 wrote them (``successes`` absent where it logged
    none); UserError if the file is damaged (unreadable, truncated, ragged, or without one of
    the `required` arrays), as a kill during SB3's in-place write could leave it."""
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {name: data[name] for name in data.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise UserError(f"the evaluation log {path} is damaged ({exc})") from None
    missing = [name for name in required if name not in arrays]
    if missing:
        raise UserError(f"the evaluation log {path} is damaged (no {', '.join(missing)})")
    return arrays


def load_learning_curve(run_dir: str | Path) -> LearningCurve:
    """The evaluation log of `run_dir`; UserError if it has none (eval.freq 0, or too early) or
    if it is damaged (unreadable, an array missing, rows of different lengths). SB3 logs
    successes only for evaluations whose episodes report ``is_success``; a successes array that
    does not have a row per evaluation is left out (``successes`` None)."""
    path = Path(run_dir) / EVALUATIONS_FILE
    if not path.is_file():
        raise UserError(
            f"{run_dir} has no {EVALUATIONS_FILE}: the run has not been evaluated yet "
            "(eval.freq 0, or fewer than eval.freq steps trained)"
        )
    config = Path(run_dir) / "config.yaml"
    unit = learner_step_unit(yaml.safe_load(config.read_text()) if config.is_file() else None)
    arrays = read_evaluation_log(path)
    timesteps = np.asarray(arrays["timesteps"], dtype=np.int64).reshape(-1)
    returns = np.asarray(arrays["results"], dtype=float)
    lengths = np.asarray(arrays["ep_lengths"], dtype=np.int64)
    successes = arrays.get("successes")
    successes = None if successes is None else np.asarray(successes, dtype=float)
    n = len(timesteps)
    if returns.ndim != 2 or len(returns) != n or lengths.shape != returns.shape:
        raise UserError(
            f"the evaluation log {path} is damaged: {n} evaluations, but returns of shape "
            f"{returns.shape} and lengths of shape {lengths.shape}"
        )
    if successes is not None and successes.shape != returns.shape:
        successes = None
    return LearningCurve(timesteps, returns, lengths, successes, unit=unit)
