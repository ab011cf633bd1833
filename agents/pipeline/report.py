"""Write an evaluation's ``metrics.json``, ``report.md`` (+ ``figures/*.png``, videos) and a
self-contained ``report.html`` (figures embedded as base64 PNG; videos linked beside it).

Each env section opens with a **Verdict:** computed from the metrics, then the table and the
like-with-like comparison bullets (`summary.compare`) against the analytical controller and the
reference motion. Policy names are shown with ``{env_id}`` expanded.
"""

from __future__ import annotations

import base64
import html
import json
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from . import benchmark_score, figures
from .episode import POWER_KEY
from .eval_config import DEFAULT_REFERENCES, PPO_PREFIX
from .evaluation import EnvResult, SuiteResult
from .summary import (
    STANDARD_METRICS,
    Verdict,
    aggregate,
    compare,
    is_tie,
    paired_difference_interval,
)


# --- tables --------------------------------------------------------------------------------
@dataclass
class Table:
    headers: list[str]
    rows: list[list[str]] = field(default_factory=list)

    def markdown(self) -> str:
        def esc(s: str) -> str:
            return s.replace("|", "\\|")

        lines = ["| " + " | ".join(esc(h) for h in self.headers) + " |"]
        lines.append("|" + "|".join("---" for _ in self.headers) + "|")
        lines += ["| " + " | ".join(esc(c) for c in row) + " |" for row in self.rows]
        return "\n".join(lines)

    def html(self) -> str:
        head = "".join(f"<th>{html.escape(h)}</th>" for h in self.headers)
        body = "".join(
            "<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>"
            for row in self.rows
        )
        return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _num(x: float | None) -> str:
    """Three significant figures, without exponents for everyday magnitudes."""
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    ax = abs(x)
    if ax == 0:
        return "0"
    if ax >= 1e6 or ax < 1e-3:
        return f"{x:.3g}"
    if ax >= 100:
        return f"{x:.0f}"
    return f"{x:.3g}"


def mean_std(s: dict | None) -> str:
    if not s:
        return "n/a"
    return f"{_num(s['mean'])} ± {_num(s['std'])}"


def median_range(s: dict | None) -> str:
    if not s:
        return "n/a"
    return f"{_num(s['median'])} [{_num(s['min'])}, {_num(s['max'])}]"


def rate(s: dict | None) -> str:
    if not s:
        return "n/a"
    return f"{100 * s['mean']:.0f} % ({round(s['mean'] * s['n'])}/{s['n']})"


MAIN_COLUMNS = (
    "fasm_min_deg",
    "fasm_mean_deg",
    "time_below_xi_s",
    "distance_m",
    "episode_length",
    "energy_j",
    "episode_return",
)


def _label(key: str) -> str:
    label, unit, _ = STANDARD_METRICS[key]
    return f"{label} [{unit}]" if unit else label


def main_table(aggs: dict[str, dict]) -> Table:
    t = Table(["policy", "success", "tip-overs", *(_label(k) for k in MAIN_COLUMNS)])
    for name, a in aggs.items():
        t.rows.append(
            [name, rate(a["success"]), rate(a["tipped_over"])]
            + [mean_std(a[k]) for k in MAIN_COLUMNS]
        )
    return t


def spread_table(aggs: dict[str, dict]) -> Table:
    t = Table(["policy", *(_label(k) for k in MAIN_COLUMNS)])
    for name, a in aggs.items():
        t.rows.append([name] + [median_range(a[k]) for k in MAIN_COLUMNS])
    return t


def reward_table(aggs: dict[str, dict]) -> Table | None:
    terms = sorted({k for a in aggs.values() for k in a if k.startswith("return_")})
    if not terms:
        return None
    t = Table(["policy", *(f"Σ reward_{k[7:]}" for k in terms)])
    for name, a in aggs.items():
        t.rows.append([name] + [mean_std(a.get(k)) for k in terms])
    return t


def specifics_table(result: EnvResult, aggs: dict[str, dict]) -> Table | None:
    names = sorted({k for a in aggs.values() for k in a["specifics"]})
    if not names:
        return None
    specs = {s.name: s for s in result.specs}
    t = Table(["metric", "better", *aggs])
    for name in names:
        spec = specs.get(name)
        label = f"{name} ({spec.description})" if spec and spec.description else name
        row = [label, spec.better if spec and spec.better else "-"]
        for a in aggs.values():
            s = a["specifics"].get(name)
            if s is None:
                row.append("n/a")
            elif s["kind"] == "category":
                row.append(", ".join(f"{k} ×{v}" for k, v in s["counts"].items()))
            elif s["kind"] == "list":
                row.append(
                    f"median {_num(s.get('median'))} [{_num(s.get('min'))}, "
                    f"{_num(s.get('max'))}] over {s.get('n', 0)} values"
                )
            else:
                row.append(f"{mean_std(s)}; median {median_range(s)}")
        t.rows.append(row)
    return t


def task_table(result: EnvResult) -> Table | None:
    """Success and tip-over counts per policy, grouped by each sampled task parameter that
    varies across the episodes: categories by value, numbers split at their median."""
    runs = [r for r in result.runs.values() if r.episodes]
    if not runs:
        return None
    tasks = [e.task for e in runs[0].episodes]
    keys = [k for k in tasks[0] if len({repr(t.get(k)) for t in tasks}) > 1] if tasks else []
    if not keys:
        return None
    t = Table(["task parameter", "group", "episodes", *(result.label(r.name) for r in runs)])
    for key in keys:
        values = [t_.get(key) for t_ in tasks]
        if all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
            median = float(np.median(values))
            groups = {
                f"≤ {_num(median)}": [v <= median for v in values],
                f"> {_num(median)}": [v > median for v in values],
            }
        else:
            groups = {str(g): [v == g for v in values] for g in dict.fromkeys(values)}
        for label, members in groups.items():
            if not any(members):
                continue
            row = [key, label, str(sum(members))]
            for run in runs:
                chosen = [e for e, m in zip(run.episodes, members, strict=False) if m]
                wins = sum(bool(e.success) for e in chosen)
                tips = sum(e.tipped_over for e in chosen)
                row.append(f"{wins} ok, {tips} tipped")
            t.rows.append(row)
    return t


# --- verdicts -------------------------------------------------------------------------------
REFERENCE_WORDS = {"analytical": "the analytical controller", "zero": "the reference motion"}


def _count(a: dict, key: str) -> tuple[int, int] | None:
    s = a.get(key)
    if not s:
        return None
    return round(s["mean"] * s["n"]), s["n"]


def _fraction(c: tuple[int, int] | None) -> str:
    return "n/a" if c is None else f"{c[0]}/{c[1]}"


def verdict_paragraph(result: EnvResult, aggs: dict[str, dict]) -> str:
    """One paragraph from the metrics: who succeeds most, and at what stability cost.

    Ranking: success rate, then fewer tip-overs, then the higher median per-episode minimum
    FASM (the stability cost)."""
    if not aggs:
        return f"**Verdict:** no policy ran on {result.env_id}."

    def rank(name: str) -> tuple[float, float, float]:
        a = aggs[name]
        success = a["success"]["mean"] if a.get("success") else -1.0
        tips = a["tipped_over"]["mean"] if a.get("tipped_over") else 1.0
        return (-success, tips, -_median_min_fasm(a))

    ranked = sorted(aggs, key=rank)
    leaders = [n for n in ranked if rank(n)[:2] == rank(ranked[0])[:2]]
    best = aggs[leaders[0]]
    outcome = (
        f"{_fraction(_count(best, 'success'))} successes, "
        f"{_fraction(_count(best, 'tipped_over'))} tip-overs"
    )
    names = ", ".join(f"`{n}`" for n in leaders)
    if not best.get("success") or best["success"]["mean"] == 0:
        head = f"no policy succeeds; the fewest tip-overs: {names} ({outcome})."
    elif len(leaders) == len(aggs) and len(aggs) > 1:
        head = f"every policy succeeds equally often ({outcome} each)."
    else:
        verb = "succeed" if len(leaders) > 1 else "succeeds"
        head = f"{names} {verb} most often ({outcome})."
    parts = [f"**Verdict:** {head}"]
    with_fasm = [n for n in leaders if math.isfinite(_median_min_fasm(aggs[n]))]
    medians = [_median_min_fasm(aggs[n]) for n in with_fasm]
    if len(with_fasm) > 1 and not is_tie(medians[0], medians[-1]):
        most, least = with_fasm[0], with_fasm[-1]
        parts.append(
            f"Among them the stability cost differs: median minimum FASM "
            f"{_num(medians[0])}° for `{most}` down to {_num(medians[-1])}° for `{least}`."
        )
    elif len(with_fasm) > 1:
        parts.append(f"Their median minimum FASM is the same, {_num(medians[0])}°.")
    elif with_fasm:
        parts.append(f"Median minimum FASM {_num(_median_min_fasm(best))}°.")
    others = [
        f"`{n}` {_fraction(_count(aggs[n], 'success'))} successes, "
        f"{_fraction(_count(aggs[n], 'tipped_over'))} tip-overs"
        for n in ranked
        if n not in leaders
    ]
    if others:
        parts.append("Then: " + "; ".join(others) + ".")
        lead = _success_lead(result, leaders[0], ranked[len(leaders)])
        if lead:
            parts.append(lead)
    return " ".join(parts)


def _episodes_by_key(result: EnvResult) -> dict[str, list]:
    """Each policy's episodes under its name as given and as labelled (``{env_id}`` expanded),
    the two ways `aggs` may be keyed."""
    return {k: run.episodes for n, run in result.runs.items() for k in (n, result.label(n))}


def _success_lead(result: EnvResult, leader: str, runner_up: str) -> str:
    """Whether the leader's higher success rate over the runner-up is resolved: the paired
    interval of the difference over the same tasks ("" without a lead or without pairs)."""
    episodes = _episodes_by_key(result)
    if leader not in episodes or runner_up not in episodes:
        return ""
    a = [e.success for e in episodes[leader]]
    b = [e.success for e in episodes[runner_up]]
    if sum(x for x in a if x is not None) <= sum(x for x in b if x is not None):
        return ""
    interval = paired_difference_interval(a, b, pooled=False)
    if interval is None:
        return ""
    word = "not resolved" if interval[0] <= 0.0 <= interval[1] else "resolved"
    low, high = (_num(x) for x in interval)
    return (
        f"The lead in successes over `{runner_up}` is {word} (paired difference [{low}, {high}])."
    )


def _rule_cells(rules: dict) -> list[str]:
    """The tip-over, success-tilt and success-tipping cells of an env's rules ("-": none)."""
    if not rules:
        return ["-", "-", "-"]
    tip = f"tilt > {rules['tip_over_angle_deg']:g}°"
    if rules["tip_over_margin_time"] is not None:
        tip += f", or FASM <= 0 for {rules['tip_over_margin_time']:g} s"
    tilt, share = rules["success_max_tilt_deg"], rules["success_max_tipping_share"]
    return [
        tip,
        "-" if tilt is None else f"<= {tilt:g}°",
        "-" if share is None else f"<= {share * 100:g} % of the episode",
    ]


def _median_min_fasm(a: dict) -> float:
    s = a.get("fasm_min_deg")
    return s["median"] if s else -math.inf


def verdict_lines(
    result: EnvResult, aggs: dict[str, dict], references: Sequence[str] = DEFAULT_REFERENCES
) -> tuple[list[str], list[Verdict]]:
    """Bullets comparing every policy with each of the `references` that ran (by default the
    analytical controller and the reference motion), in order; a pair is compared once.

    Rates are per episode and time-integrated metrics per second of episode (see `summary`);
    a policy that tips over more often than its reference is said to, first."""
    lines: list[str] = []
    all_verdicts: list[Verdict] = []
    episodes = _episodes_by_key(result)
    keys = [k for k in (_agg_key(r, result, aggs) for r in references) if k is not None]
    for i, reference in enumerate(keys):
        for name in aggs:
            if name in keys[: i + 1]:
                continue  # itself, or a pair already compared the other way round
            verdicts = compare(name, reference, aggs, result.specs, episodes, result.unranked)
            all_verdicts += verdicts
            lines.append(_bullet(name, reference, aggs, verdicts))
    if not lines:
        names = ", ".join(f"`{result.label(r)}`" for r in references)
        lines.append(
            f"- No comparison on {result.env_id}: none of the references ({names}) ran beside "
            "another policy."
        )
    return lines, all_verdicts


def _agg_key(reference: str, result: EnvResult, aggs: dict[str, dict]) -> str | None:
    """The key of `reference` in `aggs` (given or labelled name); None when it did not run."""
    for key in (reference, result.label(reference)):
        if key in aggs:
            return key
    return None


def _unresolved(v: Verdict | None) -> str:
    """ " (not resolved: difference [lo, hi])" for a difference whose interval includes 0,
    " (no paired interval)" for one that has none (fewer than two episodes pair up)."""
    if v is None or v.outcome == "tie" or v.resolved:
        return ""
    if v.interval is None:
        return " (no paired interval)"
    return f" (not resolved: difference [{_num(v.interval[0])}, {_num(v.interval[1])}])"


def _bullet(name: str, reference: str, aggs: dict[str, dict], verdicts: list[Verdict]) -> str:
    def fmt(vs: list[Verdict]) -> str:
        return "; ".join(
            f"{v.label} {_num(v.challenger_value)} vs {_num(v.baseline_value)}{_unresolved(v)}"
            for v in vs
        )

    def rate(metric: str) -> Verdict | None:
        return next((v for v in verdicts if v.metric == metric), None)

    rates = [v for v in verdicts if v.metric in ("success", "tipped_over")]
    rest = [v for v in verdicts if v not in rates]
    better = [v for v in rest if v.outcome == "better"]
    worse = [v for v in rest if v.outcome == "worse"]
    a, b = aggs[name], aggs[reference]
    words = (
        f"{REFERENCE_WORDS[reference]} (`{reference}`)"
        if reference in REFERENCE_WORDS
        else f"`{reference}`"
    )
    text = (
        f"- `{name}` vs {words}: success "
        f"{_fraction(_count(a, 'success'))} vs {_fraction(_count(b, 'success'))}"
        f"{_unresolved(rate('success'))}, tip-overs "
        f"{_fraction(_count(a, 'tipped_over'))} vs {_fraction(_count(b, 'tipped_over'))}"
        f"{_unresolved(rate('tipped_over'))}."
    )
    if a["tip_overs"] > b["tip_overs"]:
        text += " It tips over more often, so its episodes are shorter; the time-integrated"
        text += " figures below are per second of episode."
    if better:
        text += f" Better on {fmt(better)}."
    if worse:
        text += f" Worse on {fmt(worse)}."
    if not better and not worse:
        text += " Equal on every other compared metric."
    return text


HOW_TO_READ = [
    "- **FASM** (force-angle stability measure, Papadopoulos & Rey): over the edges of the "
    "support polygon, the smallest angle between the net force on the centre of mass and the "
    "perpendicular from the centre of mass to the edge [deg]. "
    "Large is stable; it falls as the robot leans towards a tipping edge.",
    "- **0** means fewer than three feet are loaded (no support polygon, e.g. during a tripod "
    "switch or in the air) or the force points at a tipping edge; **negative** values mean the "
    "net force points outside the polygon: the robot is rotating about an edge. A short negative "
    "spike while a foot lands is not a tip-over; a tip-over is the body tilting past the env's "
    "tip-over angle or, where the env sets a time, the FASM at or below 0 for that long (the "
    "table below), counted in the tip-over column.",
    "- **ξ** is the robot's FASM threshold (below it the robot is judged to be tipping); it "
    "differs per robot and is listed per env below. Where the paper judges a robot by another "
    "criterion (the 3-UPU robot: the static margin > 0), its FASM is shown for comparison and "
    "ξ = 0° only marks a net force outside the support polygon.",
    "- **Success** is the env's `is_success` at the episode's end, without a tip-over: the cliff "
    "walk: at least `min_progress` of the distance the reference gait covers in that time; the "
    "Stewart tilt: standing to the time limit; the irregular terrain: no torso contact and at "
    "least half the distance the gait's nominal speed covers; the ditch crossing: every foot "
    "past the far edge and loaded. The `-v1` envs also require the episode's largest tilt "
    "(`max_tilt_deg`) and, where the env bounds it, its share of time tipping (`tipping_share`) "
    "within the bounds in the table below, and on the Stewart tilt the lifted tripod kept up "
    "until the robot first tips (docs/benchmark.md).",
    "- **Benchmark scores** put each policy's success rate on a scale from 0 (random actions) to "
    "100 (the analytical controller) per env, on the same tasks, and aggregate them across envs "
    "with the interquartile mean and its 95 % stratified-bootstrap interval (rliable).",
    "- **Comparisons** use rates per episode and, for time-integrated quantities (time below ξ, "
    "distance, energy), values per second of episode (share of time below ξ, speed, mean "
    "power), so a policy whose episodes end early cannot look better on a total. Every policy is "
    "compared with each of the suite's references (its `references`; by default the analytical "
    "controller `analytical` and the env's reference motion `zero`: the zero action, the "
    "paper's gait without feedback).",
    "- **Not resolved** marks a difference whose 95 % paired-bootstrap interval includes 0: "
    "every policy runs the same seeds, hence the same tasks, and the bootstrap resamples the "
    "tasks with both policies' episodes together, so the interval shows how much of the "
    "difference the draw of the tasks alone could make. **No paired interval** marks one "
    "measured on fewer than two pairs of episodes: its uncertainty is unknown.",
    "- **Ties**: a difference within 1 % of the larger value counts as equal and gets no "
    "verdict, even where its interval excludes 0 (the per-policy tables show the values). Where "
    "the robot stands rather than walks (the Stewart tilt), distance per second gets no verdict: "
    "its distance is drift or the direction of a fall, not progress.",
]


def benchmark_section(result: SuiteResult) -> tuple[Table | None, str]:
    """The normalised scores (0 = random actions, 100 = the analytical controller) per env and
    policy, with the IQM across envs and its 95 % interval (`benchmark_score`); and a sentence
    on what is left out. (None, reason) when no env ran both references."""
    successes = {
        r.env_id: {
            r.label(name): [bool(e.success) for e in run.episodes] for name, run in r.runs.items()
        }
        for r in result.envs
        if r.runs
    }
    matrices, envs = benchmark_score.score_matrices(successes)
    if not envs:
        return None, (
            "No normalised scores: they need `analytical` and `random` on an env, with the "
            "analytical controller succeeding more often than random actions."
        )
    left_out = [env for env in successes if env not in envs]
    try:
        intervals = benchmark_score.iqm_intervals(matrices)
    except ImportError as error:
        intervals, note = {}, f" {error}."
    else:
        note = ""
    table = Table(["policy", *envs, "IQM [95 % CI]"])
    partial = False
    for policy, by_env in benchmark_score.env_scores(successes).items():
        cells = [f"{by_env[env]:.0f}" if env in by_env else "-" for env in envs]
        if policy in intervals:
            iqm, low, high = intervals[policy]
            cells.append(f"{iqm:.0f} [{low:.0f}, {high:.0f}]")
        else:
            partial = partial or policy not in matrices
            cells.append("n/a")
        table.rows.append([f"`{policy}`", *cells])
    text = (
        "Normalised success score per env: 0 = random actions, 100 = the analytical "
        "controller, on the same tasks; the last column is the interquartile mean across envs "
        "with its 95 % stratified-bootstrap interval (episodes resampled within each env). "
        "The scale is fixed by these episodes, so even the references' intervals are wide: "
        "a resample of the analytical controller's episodes succeeds more or less often than "
        "the episodes that set 100."
    )
    if partial:
        text += (
            " A policy without a score on every env (-), or with unequal episode counts, gets "
            "no IQM."
        )
    unbeaten = [e for e in left_out if {"analytical", "random"} <= set(successes[e])]
    unreferenced = [e for e in left_out if e not in unbeaten]
    for envs_out, why in (
        (unbeaten, "the analytical controller does not beat random actions there"),
        (unreferenced, "`analytical` or `random` did not run there"),
    ):
        if envs_out:
            text += f" Left out ({why}): {', '.join(f'`{e}`' for e in envs_out)}."
    return table, text + note


def policy_kind(name: str) -> str:
    if name == "analytical":
        return "analytical controllers"
    if name == "zero":
        return "reference motion"
    if name == "random":
        return "random actions"
    path = name[len(PPO_PREFIX) :]
    if path.startswith("models/{env_id}"):
        rest = path[len("models/{env_id}") :].strip("/")
        return f"shipped PPO ({rest})" if rest else "shipped PPO"
    return f"PPO {path}"


def report_title(suite: Any) -> str:
    kinds = list(dict.fromkeys(policy_kind(n) for n in suite.policies))
    return f"{suite.title}: " + " vs ".join(kinds)


def _action_settings(kwargs: dict[str, Any]) -> str:
    """ " (with action_mode=joint, ...)" for a policy run in other action settings than the
    suite's env (each policy runs in the action mode it was built for)."""
    if not kwargs:
        return ""
    return " (with " + ", ".join(f"{k}={v}" for k, v in kwargs.items()) + ")"


# --- assembling -----------------------------------------------------------------------------
def _episode_json(seed: int, record) -> dict[str, Any]:
    out = {"seed": seed, **record.scalar_metrics()}
    out["terminated"], out["truncated"] = record.terminated, record.truncated
    out["specifics"] = record.specifics
    out["task"] = record.task
    return out


def build_metrics(result: SuiteResult) -> dict[str, Any]:
    suite = result.suite
    envs = {}
    for r in result.envs:
        aggs = {n: aggregate(run.episodes) for n, run in r.runs.items()}
        _, verdicts = verdict_lines(r, aggs, suite.reference_names)
        envs[r.env_id] = {
            "kwargs": r.kwargs,
            "xi_deg": r.xi_deg,
            "rules": r.rules,
            "stability_criterion": r.criterion,
            "max_episode_steps": r.max_episode_steps,
            "dt_s": r.dt,
            "metric_specs": [s.__dict__ for s in r.specs],
            "unranked_metrics": list(r.unranked),
            "policies": {
                n: {
                    "label": r.label(n),
                    "source": run.source,
                    "env_kwargs": dict(run.env_kwargs),
                    "notes": run.notes,
                    "aggregate": aggs[n],
                    "episodes": [
                        _episode_json(seed, e)
                        for seed, e in zip(suite.seeds, run.episodes, strict=False)
                    ],
                }
                for n, run in r.runs.items()
            },
            "comparisons": [v.to_json() for v in verdicts],
        }
    return {
        "title": report_title(suite),
        "created": time.strftime("%Y-%m-%dT%H:%M:%S"),
        "seconds": result.seconds,
        "seeds": suite.seeds,
        "xi_f_deg": suite.xi_f_deg,
        "policies": suite.policies,
        # the policies the comparisons are against (those of the suite's references that ran)
        "references": [r for r in suite.reference_names if r in suite.policies],
        "warnings": result.warnings,
        "notes": result.notes,
        "envs": envs,
    }


def _json_default(obj: Any) -> Any:
    if hasattr(obj, "tolist"):
        return obj.tolist()
    return str(obj)


def _clean(obj: Any) -> Any:
    """NaN/inf -> None so that metrics.json is strict JSON."""
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v) for v in obj]
    return obj


CSS = """
body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:0.8em 0;font-size:0.85em}
th,td{border:1px solid #ccc;padding:3px 7px;text-align:left}
th{background:#f0f0f0} .warn{background:#fff4e5;border-left:4px solid #f0a020;padding:0.5em 1em}
img{max-width:100%} code{background:#f4f4f4;padding:0 3px}
"""


class _Document:
    """The report as it is written: every element goes to the Markdown and to the HTML page at
    once, and figures are saved under ``figures/`` beside them."""

    def __init__(self, out: Path, title: str):
        self.out, self.fig_dir, self.title = out, out / "figures", title
        self.fig_dir.mkdir(parents=True, exist_ok=True)
        self.md: list[str] = [f"# {title}", ""]
        self.hx: list[str] = [f"<h1>{html.escape(title)}</h1>"]

    def para(self, text: str) -> None:
        self.md.extend([text, ""])
        self.hx.append(f"<p>{_inline_html(text)}</p>")

    def bullets(self, lines: list[str]) -> None:
        self.md.extend(lines + [""])
        self.hx.append(
            "<ul>" + "".join(f"<li>{_inline_html(x.lstrip('- '))}</li>" for x in lines) + "</ul>"
        )

    def heading(self, text: str, level: int) -> None:
        self.md.extend(["#" * level + " " + text, ""])
        self.hx.append(f"<h{level}>{html.escape(text)}</h{level}>")

    def table(self, t: Table | None) -> None:
        if t is not None:
            self.md.extend([t.markdown(), ""])
            self.hx.append(t.html())

    def warnings(self, lines: list[str]) -> None:
        """The warnings as a highlighted list (a ``warn`` box on the page)."""
        self.md.extend([f"- **warning:** {w}" for w in lines] + [""])
        self.hx.append(
            '<div class="warn"><ul>'
            + "".join(f"<li><b>warning:</b> {html.escape(w)}</li>" for w in lines)
            + "</ul></div>"
        )

    def figure(self, name: str, png: bytes | None, caption: str) -> None:
        """Save `png` as ``figures/<name>``, linked from the Markdown and embedded in the page
        (base64); nothing when the figure has no data (None)."""
        if png is None:
            return
        (self.fig_dir / name).write_bytes(png)
        self.md.extend([f"![{caption}](figures/{name})", ""])
        b64 = base64.b64encode(png).decode()
        self.hx.append(
            f'<figure><img alt="{html.escape(caption)}" src="data:image/png;base64,{b64}">'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>"
        )

    def video(self, path: Path, caption: str) -> None:
        """A video under the report folder, linked (not embedded) by its relative path."""
        rel = path.relative_to(self.out).as_posix()
        self.md.extend([f"[{caption}]({rel})", ""])
        self.hx.append(
            f'<figure><video controls muted loop width="480" src="{html.escape(rel)}"></video>'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>"
        )

    def save(self) -> list[Path]:
        """Write ``report.md`` and the self-contained ``report.html``; their paths."""
        (self.out / "report.md").write_text("\n".join(self.md))
        page = (
            f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(self.title)}"
            f"</title><style>{CSS}</style></head><body>{''.join(self.hx)}</body></html>\n"
        )
        (self.out / "report.html").write_text(page)
        return [self.out / "report.md", self.out / "report.html"]


def write_report(result: SuiteResult, out_dir: str | Path) -> list[Path]:
    """Write metrics.json, report.md, figures/*.png and report.html into `out_dir`: the suite's
    overview, the verdicts and benchmark scores across envs, then one section per env."""
    out = Path(out_dir)
    doc = _Document(out, report_title(result.suite))
    metrics = build_metrics(result)
    (out / "metrics.json").write_text(
        json.dumps(_clean(metrics), indent=1, default=_json_default) + "\n"
    )
    _write_overview(doc, result)
    _write_verdicts_and_scores(doc, result)
    for r in result.envs:
        _write_env_section(doc, r, result.suite)
    md_path, html_path = doc.save()
    return [out / "metrics.json", md_path, html_path]


def _write_overview(doc: _Document, result: SuiteResult) -> None:
    """What ran (policies, envs, seeds, run time), the reading guide, each env's stability
    criterion and ξ, then the run's warnings and notes."""
    suite = result.suite
    shown = []
    for p in suite.policies:  # a per-env template is listed expanded for every env
        names = [e.label(p) for e in result.envs] if "{env_id}" in p else [p]
        shown.append(", ".join(f"`{n}`" for n in dict.fromkeys(names)) + f" ({policy_kind(p)})")
    doc.para(
        f"Policies: {'; '.join(shown)}. Envs: "
        f"{', '.join(f'`{e.id}`' for e in suite.envs)}. {suite.episodes} episode(s) per policy "
        f"and env on seeds {suite.seeds} (identical seeds, terrain and start for every policy). "
        f"Cells: mean ± std over episodes; the spread table gives median [min, max]. "
        f"Run time {result.seconds:.1f} s."
    )
    doc.heading("How to read this report", 2)
    doc.bullets(HOW_TO_READ)
    thresholds = Table(
        [
            "env",
            "stability criterion",
            "ξ [deg]",
            "tip-over",
            "success: largest tilt",
            "success: time tipping",
        ]
    )
    for r in result.envs:
        xi = "none (FASM for comparison)" if r.xi_deg is None else f"{r.xi_deg:g}"
        thresholds.rows.append([r.env_id, r.criterion, xi, *_rule_cells(r.rules)])
    doc.table(thresholds)
    if result.warnings:
        doc.heading("Warnings", 2)
        doc.warnings(result.warnings)
    if result.notes:  # e.g. a per-env model, an agent trained with other reward scales
        doc.heading("Notes", 2)
        doc.bullets([f"- **note:** {n}" for n in result.notes])


def _write_verdicts_and_scores(doc: _Document, result: SuiteResult) -> None:
    """The verdict of every env, the success-rate figure, the benchmark scores and the success
    against task difficulty: the comparison across envs before the per-env sections."""
    doc.heading("Verdicts", 2)
    for r in result.envs:
        aggs = {r.label(n): aggregate(run.episodes) for n, run in r.runs.items()}
        doc.para(f"{r.env_id}: " + verdict_paragraph(r, aggs))
    doc.figure(
        "success_rates.png",
        figures.success_bars(result),
        "Success and tip-over rate per env and policy (share of episodes)",
    )
    doc.heading("Benchmark scores", 2)
    scores, text = benchmark_section(result)
    doc.para(text)
    doc.table(scores)
    doc.figure(
        "success_by_difficulty.png",
        figures.success_by_difficulty(result),
        "Success rate against the task's difficulty (info['task']['difficulty']), per env",
    )


def _write_env_section(doc: _Document, r: EnvResult, suite: Any) -> None:
    """One env's section: its verdict and setup, then (if any policy ran) its tables and
    figures."""
    doc.heading(r.env_id, 2)
    aggs = {r.label(n): aggregate(run.episodes) for n, run in r.runs.items()}
    doc.para(verdict_paragraph(r, aggs))
    doc.para(_env_setup_text(r))
    if not r.runs:
        return
    _write_env_tables(doc, r, aggs, suite)
    _write_env_figures(doc, r, suite)


def _env_setup_text(r: EnvResult) -> str:
    """The env's kwargs, time limit, stability criterion and each policy's source."""
    sources = "; ".join(
        f"`{r.label(n)}`: {run.source}{_action_settings(run.env_kwargs)}"
        for n, run in r.runs.items()
    )
    xi = "no ξ" if r.xi_deg is None else f"ξ = {r.xi_deg:g}°"
    tasks = [e.task for run in r.runs.values() for e in run.episodes]
    same_task = len(tasks) > len(r.runs) and bool(tasks[0]) and all(t == tasks[0] for t in tasks)
    return (
        f"Env kwargs: `{r.kwargs or {}}`; time limit {r.max_episode_steps} steps"
        + (f" × {r.dt:g} s" if r.dt else "")
        + f"; stability criterion: {r.criterion} ({xi})"
        + (f". Sources: {sources}." if sources else ". No policy ran on this env.")
        + (
            " Every episode ran the same task (the env's `task_distribution`: the paper's "
            "scenario), so the seeds differ only in the reset noise and the paired intervals "
            "show that noise, not a spread of tasks; `kwargs: {task_distribution: test}` "
            "samples held-out tasks."
            if same_task
            else ""
        )
    )


def _write_env_tables(doc: _Document, r: EnvResult, aggs: dict[str, dict], suite: Any) -> None:
    """The env's main table, unstable episodes, like-with-like comparisons, spread, reward
    terms, the breakdown by sampled task parameter and the env-specific metrics."""
    doc.table(main_table(aggs))
    unstable = [
        f"`{name}` {rate(a['sim_unstable'])}"
        for name, a in aggs.items()
        if a.get("sim_unstable") and a["sim_unstable"]["mean"] > 0
    ]
    if unstable:
        doc.para(
            "Episodes that ended in an unstable simulation (`info['sim_unstable']`: the "
            "episode truncates; it counts as no success, and its last step's repeated "
            "readings are left out): " + ", ".join(unstable) + "."
        )
    doc.heading("Comparisons (like with like)", 3)
    doc.bullets(verdict_lines(r, aggs, suite.reference_names)[0])
    if all(a["energy_j"] is None for a in aggs.values()):
        doc.para(f"Energy: n/a, this env reports no `{POWER_KEY}` in info.")
    doc.heading("Spread (median [min, max])", 3)
    doc.table(spread_table(aggs))
    doc.heading("Reward terms (episode sums)", 3)
    doc.table(reward_table(aggs))
    breakdown = task_table(r)
    if breakdown is not None:
        doc.heading("By sampled task parameter (episodes that succeeded / tipped over)", 3)
        doc.table(breakdown)
    spec_table = specifics_table(r, aggs)
    if spec_table is not None:
        doc.heading("Env-specific metrics", 3)
        doc.table(spec_table)


def _write_env_figures(doc: _Document, r: EnvResult, suite: Any) -> None:
    """The env's figures (FASM over time on the first seed, per-episode metrics, learning
    curves, env-specific metrics), then each policy's frame strip and video, if recorded."""
    slug = r.env_id.replace("/", "_")
    seed = suite.seeds[0]
    doc.figure(
        f"{slug}_fasm.png",
        figures.fasm_over_time(r, r.xi_deg, seed),
        f"{r.env_id}: FASM over time on seed {seed}",
    )
    doc.figure(f"{slug}_boxes.png", figures.metric_boxes(r), f"{r.env_id}: per-episode metrics")
    doc.figure(
        f"{slug}_learning.png",
        figures.learning_curves(r),
        f"{r.env_id}: learning curves of the PPO runs (evaluation success rate and return)",
    )
    doc.figure(
        f"{slug}_specific.png", figures.specific_boxes(r), f"{r.env_id}: env-specific metrics"
    )
    for name, run in r.runs.items():
        label = r.label(name)
        safe = "".join(c if c.isalnum() else "_" for c in name)
        if run.frames:
            doc.figure(
                f"{slug}_{safe}_frames.png",
                figures.frame_strip(run.frames),
                f"{r.env_id}, {label}: frames over the episode on seed {seed}",
            )
        if run.video is not None:
            doc.video(run.video, f"{r.env_id}, {label}: video of seed {seed}")


def _inline_html(text: str) -> str:
    """Escape, then render **bold** and `code` spans (the only Markdown the report uses)."""
    import re

    s = html.escape(text)
    s = re.sub(r"\*\*(.+?)\*\*", r"<b>\1</b>", s)
    return re.sub(r"`(.+?)`", r"<code>\1</code>", s)
