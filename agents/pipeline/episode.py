"""Per-episode statistics from the env's ``info`` dicts, shared by training logs and evaluation.

Standard keys read from ``info`` (docs/architecture.md, Conventions): ``fasm_margin_deg`` (every
step),
``reward_<term>`` (every step), ``is_success`` and ``distance`` (last step), ``is_tipped_over``
(any step), and, when an env reports it, ``actuator_power_w`` (sum over actuators of
|force x velocity| in W, integrated to energy in J).

Env-specific metrics — the evaluation hook
------------------------------------------
An env adds its own episode metrics in one or both of two ways; neither needs any import from
``agents``:

1. A class attribute ``evaluation_metrics`` mapping an ``info`` key to how it is reduced over
   the episode, either a string (the reduction) or a mapping with keys ``reduce``, ``better``
   (``"higher"``/``"lower"``, used for the PPO-vs-analytical verdicts) and ``description``::

       class StewartTiltEnv(HeavyDutyEnv):
           evaluation_metrics = {
               "recovery_time_s": {"reduce": "episode", "better": "lower",
                                   "description": "time from tipping alarm to landing"},
               "adjustment_leg": "episode",
               "platform_angle_deg": {"reduce": "max"},
           }

   Reductions over the per-step values: ``last``, ``first``, ``min``, ``max``, ``mean``,
   ``sum``, ``rms``, ``any``, ``all``; ``episode`` means "read it from
   ``info["episode_metrics"]``" (declaring only its direction/description).

2. ``info["episode_metrics"]``: a dict the env fills itself, ``{name: value}``. The evaluator
   keeps the **last one seen in the episode**, so an env that cannot tell when a TimeLimit
   truncation ends the episode should include the (running) dict on every step, or at least
   update it whenever it changes. Values: numbers or bools (aggregated with mean ± std, median,
   min/max over episodes), strings or None (counted: e.g. which adjustment leg), or lists of
   numbers (per-cycle values such as height/pitch/roll RMS: pooled over all episodes and shown
   as box plots, medians and spreads as in Coelho et al. 2024).

Every key of ``info["episode_metrics"]`` is collected, declared or not.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from hexapod_envs import info_keys as keys

XI_F_DEG = 20.0
"""Tipping threshold ξ_f of Zhang et al. 2024 [deg]: time below it is reported."""

STEP_REDUCTIONS = ("last", "first", "min", "max", "mean", "sum", "rms", "any", "all")
REDUCTIONS = (*STEP_REDUCTIONS, "episode")
DIRECTIONS = ("higher", "lower")
POWER_KEY = keys.ACTUATOR_POWER_W
EPISODE_METRICS_KEY = "episode_metrics"


@dataclass(frozen=True)
class MetricSpec:
    """One env-specific metric: the info key, its reduction, which direction is better."""

    name: str
    reduce: str = "last"
    better: str | None = None
    description: str = ""

    def __post_init__(self):
        if self.reduce not in REDUCTIONS:
            raise ValueError(
                f"evaluation_metrics[{self.name!r}]: reduce={self.reduce!r} is not valid; "
                f"valid: {list(REDUCTIONS)}"
            )
        if self.better not in (None, *DIRECTIONS):
            raise ValueError(
                f"evaluation_metrics[{self.name!r}]: better={self.better!r} is not valid; "
                f"valid: {list(DIRECTIONS)} or null"
            )


def metric_specs(env: Any) -> list[MetricSpec]:
    """The env's declared metrics (``type(env.unwrapped).evaluation_metrics``), validated."""
    declared = getattr(type(getattr(env, "unwrapped", env)), "evaluation_metrics", None) or {}
    if isinstance(declared, list | tuple):
        declared = dict.fromkeys(declared, "last")
    specs = []
    for name, value in declared.items():
        if isinstance(value, str):
            specs.append(MetricSpec(name, reduce=value))
        elif isinstance(value, Mapping):
            unknown = set(value) - {"reduce", "better", "description"}
            if unknown:
                raise ValueError(
                    f"evaluation_metrics[{name!r}] has unknown keys {sorted(unknown)}; "
                    "valid: ['better', 'description', 'reduce']"
                )
            specs.append(MetricSpec(name, **value))
        else:
            raise ValueError(
                f"evaluation_metrics[{name!r}] must be a reduction name or a mapping, got {value!r}"
            )
    return specs


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _as_float(value: Any) -> float:
    return float(value.item() if hasattr(value, "item") else value)


class _Reducer:
    __slots__ = ("kind", "value", "count")

    def __init__(self, kind: str):
        self.kind, self.value, self.count = kind, None, 0

    def add(self, raw: Any) -> None:
        kind = self.kind
        if kind in ("last", "first"):
            if kind == "last" or self.count == 0:
                self.value = raw.item() if hasattr(raw, "item") else raw
            self.count += 1
            return
        if kind in ("any", "all"):
            b = bool(raw)
            if self.count == 0:
                self.value = b
            elif kind == "any":
                self.value = self.value or b
            else:
                self.value = self.value and b
            self.count += 1
            return
        x = _as_float(raw)
        if self.count == 0:
            self.value = x * x if kind == "rms" else x
        elif kind == "min":
            self.value = min(self.value, x)
        elif kind == "max":
            self.value = max(self.value, x)
        elif kind == "rms":
            self.value += x * x
        else:  # sum, mean
            self.value += x
        self.count += 1

    def result(self) -> Any:
        if self.count == 0:
            return None
        if self.kind == "mean":
            return self.value / self.count
        if self.kind == "rms":
            return math.sqrt(self.value / self.count)
        return self.value


@dataclass
class EpisodeRecord:
    """Statistics of one finished episode (SI units; angles in degrees)."""

    length: int
    duration_s: float | None
    episode_return: float
    reward_terms: dict[str, float]
    success: bool | None
    tipped_over: bool
    terminated: bool
    truncated: bool
    fasm_min_deg: float | None
    fasm_mean_deg: float | None
    time_below_xi_s: float | None
    fraction_below_xi: float | None
    distance_m: float | None
    energy_j: float | None
    specifics: dict[str, Any] = field(default_factory=dict)
    fasm_trace_deg: list[float] | None = None
    task: dict[str, Any] = field(default_factory=dict)  # the env's info["task"] (sampled task)
    sim_unstable: bool = False  # ended by an unstable simulation (info["sim_unstable"])

    def scalar_metrics(self) -> dict[str, Any]:
        """Flat name -> value of every per-episode metric (for JSON and aggregation)."""
        out = {
            "success": self.success,
            "tipped_over": self.tipped_over,
            "fasm_min_deg": self.fasm_min_deg,
            "fasm_mean_deg": self.fasm_mean_deg,
            "time_below_xi_s": self.time_below_xi_s,
            "fraction_below_xi": self.fraction_below_xi,
            "distance_m": self.distance_m,
            "episode_length": self.length,
            "duration_s": self.duration_s,
            "episode_return": self.episode_return,
            "energy_j": self.energy_j,
            "speed_m_s": _per_second(self.distance_m, self.duration_s),
            "mean_power_w": _per_second(self.energy_j, self.duration_s),
            "sim_unstable": self.sim_unstable,
        }
        out.update({f"return_{k}": v for k, v in self.reward_terms.items()})
        return out


def _per_second(total: float | None, duration_s: float | None) -> float | None:
    """A time-integrated total divided by the episode's duration (None when either is unknown)."""
    if total is None or not duration_s:
        return None
    return total / duration_s


class EpisodeAccumulator:
    """Feed it each step's (reward, info); `finish()` returns an `EpisodeRecord`.

    `dt` is the env step in seconds (None: durations are not reported). `keep_trace` stores the
    FASM value of every step (for figures).
    """

    def __init__(
        self,
        dt: float | None,
        specs: list[MetricSpec] | tuple[MetricSpec, ...] = (),
        keep_trace: bool = False,
        xi_f_deg: float | None = XI_F_DEG,
    ):
        self.dt, self.specs, self.keep_trace, self.xi = dt, list(specs), keep_trace, xi_f_deg
        self._step_specs = [s for s in self.specs if s.reduce != "episode"]
        self.reset()

    def reset(self) -> None:
        self.length = 0
        self.episode_return = 0.0
        self.terms: dict[str, float] = {}
        self.fasm_min = math.inf
        self.fasm_sum = 0.0
        self.fasm_count = 0
        self.below = 0
        self.energy = 0.0
        self.has_power = False
        self.tipped = False
        self.unstable = False
        self.last_info: Mapping[str, Any] = {}
        self.episode_metrics: dict[str, Any] = {}
        self.reducers = {s.name: _Reducer(s.reduce) for s in self._step_specs}
        self.trace: list[float] = []

    def add(self, reward: float, info: Mapping[str, Any]) -> None:
        self.length += 1
        self.episode_return += float(reward)
        if info.get(keys.SIM_UNSTABLE):
            # The step that went unstable repeats the last good step's readings (FASM, power,
            # the env's metrics): counted once, with that step, not twice.
            self.unstable = True
            self.last_info = info
            return
        for key, value in info.items():
            if key.startswith(keys.REWARD_PREFIX):
                name = key[len(keys.REWARD_PREFIX) :]
                self.terms[name] = self.terms.get(name, 0.0) + float(value)
        margin = info.get(keys.FASM_MARGIN_DEG)
        if margin is not None:
            m = float(margin)
            self.fasm_min = min(self.fasm_min, m)
            self.fasm_sum += m
            self.fasm_count += 1
            self.below += self.xi is not None and m < self.xi
            if self.keep_trace:
                self.trace.append(m)
        power = info.get(POWER_KEY)
        if power is not None and self.dt is not None:
            self.energy += abs(float(power)) * self.dt
            self.has_power = True
        if info.get(keys.IS_TIPPED_OVER):
            self.tipped = True
        episode_metrics = info.get(EPISODE_METRICS_KEY)
        if episode_metrics:
            self.episode_metrics = dict(episode_metrics)
        for name, reducer in self.reducers.items():
            value = info.get(name)
            if value is not None:
                reducer.add(value)
        self.last_info = info

    def finish(self, terminated: bool, truncated: bool) -> EpisodeRecord:
        info = self.last_info
        n = self.fasm_count
        specifics: dict[str, Any] = {
            name: _plain(r.result()) for name, r in self.reducers.items() if r.count
        }
        specifics.update({k: _plain(v) for k, v in self.episode_metrics.items()})
        success = info.get(keys.IS_SUCCESS)
        distance = info.get(keys.DISTANCE)
        record = EpisodeRecord(
            length=self.length,
            duration_s=self.length * self.dt if self.dt is not None else None,
            episode_return=self.episode_return,
            reward_terms=dict(self.terms),
            success=None if success is None else bool(success),
            tipped_over=self.tipped,
            terminated=bool(terminated),
            truncated=bool(truncated),
            fasm_min_deg=self.fasm_min if n else None,
            fasm_mean_deg=self.fasm_sum / n if n else None,
            time_below_xi_s=(
                self.below * self.dt if n and self.dt is not None and self.xi is not None else None
            ),
            fraction_below_xi=self.below / n if n and self.xi is not None else None,
            distance_m=None if distance is None else float(distance),
            energy_j=self.energy if self.has_power else None,
            specifics=specifics,
            task=_plain(dict(info.get(keys.TASK) or {})),
            fasm_trace_deg=list(self.trace) if self.keep_trace else None,
            sim_unstable=self.unstable,
        )
        self.reset()
        return record


def _plain(value: Any) -> Any:
    """numpy scalars/arrays -> Python numbers/lists; tuples -> lists (JSON-friendly)."""
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, tuple | list):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value
