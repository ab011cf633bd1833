"""Multi-seed studies: a sweep directory evaluated as one policy aggregated over its trials.

``python evaluate.py --policies ppo:<sweep dir>`` evaluates every trial's model (best/ > final/ >
latest checkpoint, as for a run directory) on the suite's episode seeds, then reports the policy
over its training seeds. Each training seed is one independent sample of the training procedure,
so it is the unit of the statistics: per env, every seed scores its success rate and its mean
return over the (identical) evaluation episodes, and the confidence intervals come from rliable's
stratified bootstrap over these per-seed scores (a score matrix of seeds x 1 task; the
episodes of one model are not independent samples, so they are averaged, not resampled).

Reported per study and env: per-seed success rates and mean returns, the mean success rate with
its 95 % stratified-bootstrap CI, and the interquartile mean (IQM) of the per-seed mean returns
with its CI (the IQM drops the lowest and highest quarter of the seeds; with fewer than 4 seeds
it drops none and equals the mean). Written as a "Multi-seed studies" section appended to
report.md/report.html and as ``study.json``.
"""

from __future__ import annotations

import dataclasses
import html
import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..run_files.errors import UserError
from .eval_config import PPO_PREFIX, EvaluationSuite

CONFIDENCE = 0.95
BOOTSTRAP_REPS = 20_000
BOOTSTRAP_SEED = 0
STUDY_FILE = "study.json"


@dataclass
class Study:
    """A sweep directory named as a policy, expanded to one ``ppo:<trial dir>`` per trial."""

    name: str  # as given, e.g. "ppo:runs/sweep_irregular_terrain_seeds"
    sweep_dir: Path
    members: dict[str, str] = field(default_factory=dict)  # member policy -> its overrides


def _sweep_dir_of(policy: str) -> Path | None:
    from .sweep_config import SWEEP_FILE

    if not policy.startswith(PPO_PREFIX) or "{env_id}" in policy:
        return None
    path = Path(policy[len(PPO_PREFIX) :])
    return path if (path / SWEEP_FILE).is_file() else None


def expand_studies(suite: EvaluationSuite) -> tuple[EvaluationSuite, list[Study], list[str]]:
    """Replace each ``ppo:<sweep dir>`` policy by its trials' run directories.

    Returns the expanded suite, the studies and warning lines (trials without a saved model).
    """
    from ..run_files.artifacts import checkpoint_note, find_model
    from .sweep_summary import TRIAL_FILE, trial_dirs

    policies: list[str] = []
    studies: list[Study] = []
    warnings: list[str] = []
    for name in suite.policies:
        sweep_dir = _sweep_dir_of(name)
        if sweep_dir is None:
            policies.append(name)
            continue
        if name in (suite.references or ()):
            raise UserError(
                f"references: {name} is a sweep directory (a study of several runs); name one "
                "of its trials' run directories as the reference instead"
            )
        study = Study(name, sweep_dir)
        varied: set[str] = set()
        for trial in trial_dirs(sweep_dir):
            try:  # the model evaluated: best/ > final/ > the latest checkpoint
                evaluated = find_model(trial).directory
            except UserError:
                warnings.append(f"{name}: {trial.name} holds no saved model yet; left out")
                continue
            info_path = trial / TRIAL_FILE
            info = json.loads(info_path.read_text()) if info_path.is_file() else {}
            varied.update(o.split("=", 1)[0] for o in info.get("overrides", []))
            label = " ".join(info.get("overrides", [])) or trial.name
            study.members[f"{PPO_PREFIX}{trial}"] = f"{label}{checkpoint_note(evaluated)}"
        if not study.members:
            raise UserError(f"{name}: the sweep directory {sweep_dir} holds no trained trial")
        if varied - {"train.seed"}:
            warnings.append(
                f"{name}: its trials vary {sorted(varied - {'train.seed'})}, not the training "
                "seed alone; the study pools them as if they were seeds of one policy"
            )
        policies.extend(m for m in study.members if m not in policies)
        studies.append(study)
    return dataclasses.replace(suite, policies=policies), studies, warnings


def _interval(matrix: np.ndarray, aggregate: Any, point: str) -> dict[str, float | None]:
    """{point: estimate, ci_low, ci_high} of `aggregate` by rliable's stratified bootstrap over
    the rows (training seeds); no interval (None) from a single seed."""
    from rliable import library as rly

    if len(matrix) < 2:
        return {point: float(aggregate(matrix)), "ci_low": None, "ci_high": None}

    # rliable's StratifiedBootstrap draws its resampling indices from NumPy's global generator
    # (its random_state argument only reaches arch's unused generator); seed that for reproducible
    # CIs, then restore it.
    saved = np.random.get_state()  # noqa: NPY002
    np.random.seed(BOOTSTRAP_SEED)  # noqa: NPY002
    try:
        points, intervals = rly.get_interval_estimates(
            {"policy": matrix},
            lambda scores: np.array([aggregate(scores)]),
            reps=BOOTSTRAP_REPS,
            confidence_interval_size=CONFIDENCE,
        )
    finally:
        np.random.set_state(saved)  # noqa: NPY002
    low, high = intervals["policy"][:, 0]
    return {point: float(points["policy"][0]), "ci_low": float(low), "ci_high": float(high)}


def study_statistics(result: Any, studies: list[Study]) -> dict[str, dict[str, Any]]:
    """env id -> study name -> statistics over the training seeds (see module docstring)."""
    from rliable import metrics

    out: dict[str, dict[str, Any]] = {}
    for env in result.envs:
        for study in studies:
            runs = [(m, env.runs[m]) for m in study.members if m in env.runs]
            if not runs:
                continue
            returns = np.array([[e.episode_return for e in r.episodes] for _, r in runs], float)
            successes = [[e.success for e in r.episodes] for _, r in runs]
            has_success = all(s is not None for row in successes for s in row)
            success = np.array(successes, float) if has_success else None
            seeds = [
                {
                    "policy": m,
                    "overrides": study.members[m],
                    "success_rate": None if success is None else float(success[i].mean()),
                    "mean_return": float(returns[i].mean()),
                }
                for i, (m, _) in enumerate(runs)
            ]
            stats: dict[str, Any] = {
                "sweep_dir": str(study.sweep_dir),
                "n_seeds": len(runs),
                "n_episodes": int(returns.shape[1]),
                "confidence": CONFIDENCE,
                "bootstrap": f"rliable stratified bootstrap, {BOOTSTRAP_REPS} reps, percentile",
                "seeds": seeds,
                "mean_return": float(returns.mean()),
            }
            # One column: the env is the only task; rows are the training seeds.
            if success is not None:
                per_seed = success.mean(axis=1, keepdims=True)
                stats["success_rate"] = _interval(per_seed, metrics.aggregate_mean, "mean")
            per_seed_return = returns.mean(axis=1, keepdims=True)
            stats["iqm_return"] = _interval(per_seed_return, metrics.aggregate_iqm, "iqm")
            out.setdefault(env.env_id, {})[study.name] = stats
    return out


def _pct(x: float) -> str:
    return f"{100 * x:.0f} %"


def _ci(stats: dict[str, Any], show: Any) -> str:
    if stats["ci_low"] is None:
        return "no CI from one training seed"
    return f"95 % CI {show(stats['ci_low'])} to {show(stats['ci_high'])}"


INTRO = (
    "Each study is one policy trained with several training seeds (a sweep directory); every "
    "seed's model ran the same evaluation episodes. CI: 95 % stratified-bootstrap confidence "
    "interval over the training seeds (rliable), each seed scored by its success rate and mean "
    "return over the episodes. IQM: interquartile mean of the seeds' mean returns."
)
HEADERS = ["trial", "overrides", "success rate", "mean return"]


def study_blocks(stats: dict[str, dict[str, Any]]) -> list[tuple[str, str, list[list[str]]]]:
    """(heading, sentence, per-seed table rows) per env and study."""
    blocks = []
    for env_id, studies in stats.items():
        for name, s in studies.items():
            rate, iqm = s.get("success_rate"), s["iqm_return"]
            rate_text = (
                f"success rate **{_pct(rate['mean'])}** ({_ci(rate, _pct)})"
                if rate
                else "success rate n/a (the env reports no is_success)"
            )
            sentence = (
                f"{s['n_seeds']} training seeds x {s['n_episodes']} episodes: {rate_text}; "
                f"IQM return **{iqm['iqm']:.4g}** ({_ci(iqm, lambda x: f'{x:.4g}')}); "
                f"mean return {s['mean_return']:.4g}."
            )
            rows = [
                [
                    Path(x["policy"][len(PPO_PREFIX) :]).name,
                    x["overrides"],
                    "n/a" if x["success_rate"] is None else _pct(x["success_rate"]),
                    f"{x['mean_return']:.4g}",
                ]
                for x in s["seeds"]
            ]
            blocks.append((f"{env_id}: {name}", sentence, rows))
    return blocks


def _markdown_table(rows: list[list[str]]) -> list[str]:
    lines = ["| " + " | ".join(HEADERS) + " |", "|" + "---|" * len(HEADERS)]
    return lines + ["| " + " | ".join(c.replace("|", "\\|") for c in row) + " |" for row in rows]


def _html_table(rows: list[list[str]]) -> str:
    head = "".join(f"<th>{html.escape(h)}</th>" for h in HEADERS)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>" for row in rows
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def write_study_section(result: Any, studies: list[Study], out_dir: str | Path) -> list[Path]:
    """Append the study section to report.md and report.html; write study.json."""
    if not studies:
        return []
    out = Path(out_dir)
    stats = study_statistics(result, studies)
    (out / STUDY_FILE).write_text(json.dumps(stats, indent=1) + "\n")
    blocks = study_blocks(stats)
    md = ["## Multi-seed studies", "", INTRO, ""]
    hx = [f"<h2>Multi-seed studies</h2><p>{html.escape(INTRO)}</p>"]
    for heading, sentence, rows in blocks:
        md += [f"### {heading}", "", sentence, "", *_markdown_table(rows), ""]
        bold = re.sub(r"\*\*(.+?)\*\*", r"<b>\1</b>", html.escape(sentence))
        hx.append(f"<h3>{html.escape(heading)}</h3><p>{bold}</p>{_html_table(rows)}")
    report_md = out / "report.md"
    if report_md.is_file():
        report_md.write_text(report_md.read_text().rstrip("\n") + "\n\n" + "\n".join(md))
    page = out / "report.html"
    if page.is_file():
        page.write_text(page.read_text().replace("</body>", "".join(hx) + "</body>", 1))
    return [out / STUDY_FILE]
