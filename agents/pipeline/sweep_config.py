"""The sweep file (``configs/sweep_*.yaml``) as typed dataclasses.

A sweep names a base training config, fixed overrides of it, and a search space over any dotted
training-config key::

    base: irregular_terrain_ppo.yaml      # relative to the sweep file
    fixed: {train.total_timesteps: 30000, vec_env.n_envs: 1}
    space:
      train.seed: {grid: [0, 1, 2]}
      ppo.learning_rate: {loguniform: [1.0e-5, 1.0e-3]}
    num_samples: 1                        # samples of the random dimensions (x the grid)
    metric: eval_success_rate             # or eval_mean_reward
    mode: max
    scheduler: {type: asha, grace_period: 10000}   # optional early stopping
    searcher: random                      # or optuna (no grid dimensions then)

Domains: ``grid`` (every value, crossed with the other grids), ``choice`` (one value at random per
sample), ``uniform`` / ``loguniform`` ``[low, high]`` (floats) and ``randint`` ``[low, high)``.
Like every config, unknown keys are errors listing the valid ones, ``--set key=value`` overrides
apply to the sweep file (``--set num_samples=4``, ``--set fixed.train.total_timesteps=5000``,
``--set space.train.seed.grid=[0,1]``), and every space key is checked against the training
config before any trial starts.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from ..run_files.configtools import apply_overrides, from_mapping, load_yaml, unknown_key_message
from ..run_files.errors import ConfigError
from ..run_files.train_config import TrainConfig, load_train_config

SWEEP_FILE = "sweep.yaml"
"""The resolved sweep file inside a sweep directory (marks the directory as a sweep)."""

METRICS = ("eval_success_rate", "eval_mean_reward")
"""What a trial reports after each evaluation of its EvalCallback (the mean over its episodes)."""

DOMAIN_KINDS = ("grid", "choice", "uniform", "loguniform", "randint")


@dataclass
class Domain:
    """One search dimension: exactly one of the fields is set."""

    grid: list[Any] | None = None
    choice: list[Any] | None = None
    uniform: list[float] | None = None
    loguniform: list[float] | None = None
    randint: list[int] | None = None

    def __post_init__(self):
        given = [k for k in DOMAIN_KINDS if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of {list(DOMAIN_KINDS)}, got {given or 'none'}")
        kind = given[0]
        values = getattr(self, kind)
        if kind in ("grid", "choice"):
            if not values:
                raise ValueError(f"{kind} needs a non-empty list of values")
        else:
            if len(values) != 2 or not values[0] < values[1]:
                raise ValueError(f"{kind} needs [low, high] with low < high, got {values}")
            if kind == "loguniform" and values[0] <= 0:
                raise ValueError(f"loguniform needs low > 0, got {values}")

    @property
    def kind(self) -> str:
        return next(k for k in DOMAIN_KINDS if getattr(self, k) is not None)

    @property
    def values(self) -> list[Any]:
        return getattr(self, self.kind)

    def to_yaml(self) -> dict[str, Any]:
        return {self.kind: self.values}

    def examples(self) -> list[Any]:
        """Values used to check the key against the training config (ends of ranges)."""
        values = self.values
        if self.kind == "randint":
            return [values[0], values[1] - 1]
        return list(values)

    def to_tune(self) -> Any:
        from ray import tune

        v = self.values
        return {
            "grid": lambda: tune.grid_search(list(v)),
            "choice": lambda: tune.choice(list(v)),
            "uniform": lambda: tune.uniform(v[0], v[1]),
            "loguniform": lambda: tune.loguniform(v[0], v[1]),
            "randint": lambda: tune.randint(v[0], v[1]),
        }[self.kind]()


@dataclass
class SchedulerConfig:
    """ASHA early stopping on the metric; time is in env steps (the ``timesteps`` result)."""

    type: Literal["asha"] = "asha"
    grace_period: int = 10_000  # env steps before a trial may be stopped
    reduction_factor: float = 2.0
    max_t: int | None = None  # None: the base config's train.total_timesteps

    def __post_init__(self):
        if self.grace_period < 1 or self.reduction_factor <= 1:
            raise ValueError("scheduler needs grace_period >= 1 and reduction_factor > 1")


def _plain(value: Any) -> Any:
    """numpy scalars (from Tune's samplers) -> Python numbers."""
    return value.item() if hasattr(value, "item") else value


def flatten(data: Any, prefix: str = "", stop: tuple[str, ...] = ()) -> dict[str, Any]:
    """``{"a": {"b": 1}}`` -> ``{"a.b": 1}``; stops at empty mappings, non-mappings and at
    mappings whose keys are all in `stop` (domain specs)."""
    if not isinstance(data, dict) or not data or (stop and set(data) <= set(stop)):
        return {prefix: data} if prefix else ({} if isinstance(data, dict) else {"": data})
    out: dict[str, Any] = {}
    for key, value in data.items():
        out.update(flatten(value, f"{prefix}.{key}" if prefix else str(key), stop))
    return out


def _parse_space(value: Any, where: str) -> dict[str, Domain]:
    if not isinstance(value, dict):
        raise ConfigError(f"{where}: expected a mapping of dotted config keys to domains")
    flat = flatten(value, stop=DOMAIN_KINDS)
    space = {}
    for key, spec in flat.items():
        if not isinstance(spec, dict):
            raise ConfigError(
                f"{where}.{key}: expected a domain such as {{grid: [...]}}; "
                f"valid domains: {', '.join(DOMAIN_KINDS)}"
            )
        for kind in spec:
            if kind not in DOMAIN_KINDS:
                raise ConfigError(unknown_key_message(str(kind), f"{where}.{key}", DOMAIN_KINDS))
        space[key] = from_mapping(Domain, spec, f"{where}.{key}")
    return space


def _parse_fixed(value: Any, where: str) -> dict[str, Any]:
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise ConfigError(f"{where}: expected a mapping of dotted config keys to values")
    return flatten(value)


@dataclass
class SweepConfig:
    base: str  # training config (YAML), relative to the sweep file
    space: dict[str, Domain] = field(metadata={"parse": _parse_space})
    fixed: dict[str, Any] = field(default_factory=dict, metadata={"parse": _parse_fixed})
    # fixed: dotted key -> value, set on every trial
    name: str | None = None  # sweep directory name, as given (default: the file's stem + time)
    num_samples: int = 1
    metric: Literal["eval_success_rate", "eval_mean_reward"] = "eval_success_rate"
    mode: Literal["max", "min"] = "max"
    scheduler: SchedulerConfig | None = None
    searcher: Literal["random", "optuna"] = "random"
    cpus_per_trial: float = 1.0
    max_failures: int = 0  # retries of a failed trial

    def __post_init__(self):
        if self.num_samples < 1:
            raise ValueError(f"num_samples must be >= 1, got {self.num_samples}")
        if not self.space:
            raise ValueError("space must name at least one config key")
        if self.searcher == "optuna":
            grids = [k for k, d in self.space.items() if d.kind == "grid"]
            if grids:
                raise ValueError(
                    f"the optuna searcher does not take grid dimensions ({grids}); "
                    "use choice instead"
                )

    @property
    def num_trials(self) -> int:
        grid = math.prod(len(d.grid) for d in self.space.values() if d.grid is not None)
        return grid * self.num_samples


@dataclass
class LoadedSweep:
    """A checked sweep: its config, the base training data (fixed overrides applied), source."""

    config: SweepConfig
    base_data: dict[str, Any]
    base_config: TrainConfig
    path: Path | None

    def trial_overrides(self, params: dict[str, Any]) -> list[str]:
        """``key=value`` override strings of one trial's sampled parameters (JSON is YAML)."""
        return [f"{k}={json.dumps(_plain(v))}" for k, v in sorted(params.items())]

    def trial_config(self, params: dict[str, Any]) -> TrainConfig:
        return load_train_config(data=self.base_data, overrides=self.trial_overrides(params))


def load_sweep(
    path: str | Path | None = None,
    overrides: list[str] | tuple[str, ...] = (),
    data: dict[str, Any] | None = None,
    base_dir: str | Path | None = None,
) -> LoadedSweep:
    """Read and check a sweep file: its keys, the base config, and every search-space key.

    Each space key is tried with its example values (grid/choice values, range ends) on the base
    config, so a typo (``ppo.lerning_rate``) or an impossible value fails before Ray starts.
    """
    if (path is None) == (data is None):
        raise ConfigError("give either a sweep file path or sweep data")
    raw = load_yaml(path) if path is not None else data
    config = from_mapping(SweepConfig, apply_overrides(raw, list(overrides)))
    root = Path(base_dir) if base_dir is not None else Path(path).parent if path else Path.cwd()
    base_path = Path(config.base)
    if not base_path.is_absolute():
        base_path = root / base_path
    base_raw = load_yaml(base_path)
    fixed = [f"{k}={json.dumps(v)}" for k, v in config.fixed.items()]
    try:
        base_data = apply_overrides(base_raw, fixed)
        base_config = load_train_config(data=base_data)
    except ConfigError as exc:
        raise ConfigError(f"fixed (on {base_path}): {exc}") from None
    for key, domain in config.space.items():
        for example in domain.examples():
            try:
                load_train_config(data=base_data, overrides=[f"{key}={json.dumps(example)}"])
            except ConfigError as exc:
                raise ConfigError(f"space.{key} = {example!r}: {exc}") from None
    _check_evaluation(config, base_config)
    return LoadedSweep(config, base_data, base_config, Path(path) if path else None)


def _check_evaluation(config: SweepConfig, base: TrainConfig) -> None:
    """Trials report the metric from their evaluation callback: it must run at least once."""
    if "eval.freq" in config.space or "train.total_timesteps" in config.space:
        return
    if base.eval.freq <= 0 or base.eval.freq > base.train.total_timesteps:
        raise ConfigError(
            f"the sweep optimises {config.metric}, reported by each run's evaluation: set "
            f"eval.freq between 1 and train.total_timesteps={base.train.total_timesteps} "
            f"(got {base.eval.freq}), e.g. fixed: {{eval.freq: {base.train.total_timesteps}}}"
        )
