"""Aggregates over episodes (mean ± std, median, min/max) and policy-vs-policy verdicts with
paired-bootstrap intervals of their differences.

Verdicts compare like with like: rates per episode (success, tip-over), per-episode extremes
(min FASM), and time-integrated quantities only per second of episode (share of time below ξ,
speed, mean power), so a policy whose episodes end early cannot look better on a total that is
small only because its episode was short. The totals stay in the tables, with no verdict; the
exceptions are the return, the objective the agents are trained on, and the totals an env
declares with a direction (e.g. the irregular terrain's torso-collision count)."""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .episode import EpisodeRecord, MetricSpec

STANDARD_METRICS: dict[str, tuple[str, str, str | None]] = {
    # key: (label, unit, better)
    "success": ("success rate", "", "higher"),
    "tipped_over": ("tip-over rate", "", "lower"),
    "fasm_min_deg": ("min FASM", "deg", "higher"),
    "fasm_mean_deg": ("mean FASM", "deg", "higher"),
    "time_below_xi_s": ("time below ξ", "s", None),  # a total: compared per second below
    "fraction_below_xi": ("share of time below ξ", "", "lower"),
    "distance_m": ("distance", "m", None),
    "speed_m_s": ("distance per second", "m/s", "higher"),
    "energy_j": ("energy", "J", None),
    "mean_power_w": ("mean power", "W", "lower"),
    "episode_length": ("episode length", "steps", None),
    "episode_return": ("return", "", "higher"),
}


TIE_TOLERANCE = 0.01
"""Relative difference below which two policies count as equal on a metric (1 %)."""


def is_tie(a: float, b: float) -> bool:
    """Two values within `TIE_TOLERANCE` of the larger magnitude: equal for a verdict."""
    return abs(a - b) <= TIE_TOLERANCE * max(abs(a), abs(b))


CONFIDENCE = 0.95
"""Level of the verdicts' paired-bootstrap intervals (`paired_difference_interval`)."""


def summarize(values: Iterable[Any]) -> dict[str, float] | None:
    """{n, mean, std, median, min, max} of the numeric values (None/NaN skipped; bools as 0/1)."""
    xs = [float(v) for v in values if v is not None and not _is_nan(v)]
    if not xs:
        return None
    a = np.asarray(xs)
    return {
        "n": len(xs),
        "mean": float(a.mean()),
        "std": float(a.std()),
        "median": float(np.median(a)),
        "min": float(a.min()),
        "max": float(a.max()),
    }


def _is_nan(v: Any) -> bool:
    return isinstance(v, float) and math.isnan(v)


def _kind(values: list[Any]) -> str:
    present = [v for v in values if v is not None]
    if not present:
        return "empty"
    if all(isinstance(v, list) for v in present):
        return "list"
    if all(isinstance(v, bool | int | float) for v in present):
        return "number"
    return "category"


def aggregate(records: list[EpisodeRecord]) -> dict[str, Any]:
    """Per-policy aggregate: standard metrics, reward term sums, env-specific metrics."""
    out: dict[str, Any] = {"episodes": len(records)}
    scalars = [r.scalar_metrics() for r in records]
    for key in scalars[0] if scalars else []:
        out[key] = summarize(s.get(key) for s in scalars)
    out["tip_overs"] = sum(r.tipped_over for r in records)
    specifics: dict[str, Any] = {}
    names = sorted({k for r in records for k in r.specifics})
    for name in names:
        values = [r.specifics.get(name) for r in records]
        kind = _kind(values)
        if kind == "number":
            specifics[name] = {"kind": kind, **(summarize(values) or {})}
        elif kind == "list":
            pooled = [x for v in values if v for x in v if isinstance(x, int | float)]
            specifics[name] = {"kind": kind, "pooled": True, **(summarize(pooled) or {})}
        elif kind == "category":
            counts = Counter("None" if v is None else str(v) for v in values)
            specifics[name] = {"kind": kind, "counts": dict(counts.most_common())}
    out["specifics"] = specifics
    return out


@dataclass
class Verdict:
    metric: str
    label: str
    better: str
    challenger: str
    baseline: str
    challenger_value: float
    baseline_value: float
    outcome: str  # "better", "worse" or "tie"
    interval: tuple[float, float] | None = None
    """`CONFIDENCE` interval of challenger - baseline over the paired episodes (None: unpaired
    or fewer than 2 pairs)."""

    @property
    def resolved(self) -> bool:
        """The difference's interval excludes 0 (unknown, i.e. False, without an interval)."""
        return self.interval is not None and not self.interval[0] <= 0.0 <= self.interval[1]

    def to_json(self) -> dict[str, Any]:
        return {**self.__dict__, "resolved": self.resolved}


def paired_difference_interval(
    challenger: list[Any], baseline: list[Any], pooled: bool, n_resamples: int = 2000
) -> tuple[float, float] | None:
    """Percentile-bootstrap interval (`CONFIDENCE`) of challenger - baseline over paired
    episodes: the i-th episodes of both ran the same seed, hence the same task, and are resampled
    together. The statistic is the verdicts' own: the difference of the means of per-episode
    values, or with `pooled` of the medians of the episodes' pooled per-cycle lists. None with
    fewer than 2 pairs (scalars: pairs where both values are known).

    Why: the tasks of an evaluation differ (terrain, tilt rate, ...), and with 20 of them a
    difference of a few per cent is often the draw of the tasks, not the policy."""
    if pooled:
        a = [np.asarray([x for x in v or [] if x is not None], float) for v in challenger]
        b = [np.asarray([x for x in v or [] if x is not None], float) for v in baseline]

        def diff(idx: np.ndarray) -> float:
            pa, pb = np.concatenate([a[i] for i in idx]), np.concatenate([b[i] for i in idx])
            return float(np.median(pa) - np.median(pb)) if pa.size and pb.size else math.nan

        n = min(len(a), len(b))
    else:
        pairs = [
            (float(x), float(y))
            for x, y in zip(challenger, baseline, strict=False)
            if x is not None and y is not None and not _is_nan(x) and not _is_nan(y)
        ]
        d = np.array([x - y for x, y in pairs])

        def diff(idx: np.ndarray) -> float:
            return float(d[idx].mean())

        n = len(pairs)
    if n < 2:
        return None
    low, high = bootstrap_interval(diff, n, n_resamples)
    return None if math.isnan(low) or math.isnan(high) else (low, high)


def bootstrap_interval(
    statistic: Callable[[np.ndarray], float], n: int, n_resamples: int = 2000
) -> tuple[float, float]:
    """`CONFIDENCE` percentile-bootstrap interval of ``statistic(indices)`` over `n` units
    (episodes, beds) resampled with replacement; seeded, so a report is reproducible."""
    from scipy.stats import bootstrap

    ci = bootstrap(
        (np.arange(n),),
        statistic,
        vectorized=False,
        n_resamples=n_resamples,
        confidence_level=CONFIDENCE,
        method="percentile",
        rng=np.random.default_rng(0),
    ).confidence_interval
    return float(ci.low), float(ci.high)


def _central(summary: dict[str, Any] | None, use_median: bool) -> float | None:
    if not summary or "mean" not in summary:
        return None
    return summary["median"] if use_median else summary["mean"]


def compare(
    challenger: str,
    baseline: str,
    aggregates: dict[str, dict[str, Any]],
    specs: list[MetricSpec],
    episodes: dict[str, list[EpisodeRecord]] | None = None,
    unranked: Iterable[str] = (),
) -> list[Verdict]:
    """Metric-by-metric verdicts of `challenger` against `baseline` (means; medians for pooled
    per-cycle lists). Differences up to `TIE_TOLERANCE` of the larger magnitude are ties. With
    `episodes` (per policy, in seed order, the same seeds for both) every verdict carries the
    paired-bootstrap interval of the difference (`paired_difference_interval`). `unranked`:
    standard metrics that have no better direction on this env (speed where the robot stands)."""
    a, b = aggregates[challenger], aggregates[baseline]
    per_episode = None  # name -> every episode's metrics (standard ones over specifics)
    if episodes is not None and len(episodes[challenger]) == len(episodes[baseline]):
        per_episode = {
            name: [{**r.specifics, **r.scalar_metrics()} for r in episodes[name]]
            for name in (challenger, baseline)
        }
    rows: list[tuple[str, str, str, dict | None, dict | None, bool]] = []
    for key, (label, _, better) in STANDARD_METRICS.items():
        if better is not None and key not in unranked:
            rows.append((key, label, better, a.get(key), b.get(key), False))
    for spec in specs:
        if spec.better is None:
            continue
        sa, sb = a["specifics"].get(spec.name), b["specifics"].get(spec.name)
        pooled = bool(sa and sa.get("pooled")) or bool(sb and sb.get("pooled"))
        rows.append((spec.name, spec.name, spec.better, sa, sb, pooled))
    verdicts = []
    for key, label, better, sa, sb, pooled in rows:
        va, vb = _central(sa, pooled), _central(sb, pooled)
        if va is None or vb is None:
            continue
        diff = va - vb
        if is_tie(va, vb):
            outcome = "tie"
        elif (diff > 0) == (better == "higher"):
            outcome = "better"
        else:
            outcome = "worse"
        interval = None
        if per_episode is not None:
            interval = paired_difference_interval(
                [m.get(key) for m in per_episode[challenger]],
                [m.get(key) for m in per_episode[baseline]],
                pooled,
            )
        verdicts.append(
            Verdict(key, label, better, challenger, baseline, va, vb, outcome, interval)
        )
    return verdicts
