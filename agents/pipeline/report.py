"""Write an evaluation's ``metrics.json``, ``report.md`` (+ ``figures/*.png``) and a
self-contained ``report.html`` (figures embedded as base64 PNG).

The PPO-vs-analytical statements are computed from the aggregates (`summary.compare`).
"""

from __future__ import annotations

import base64
import html
import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from . import figures
from .episode import POWER_KEY
from .eval_config import PPO_PREFIX
from .evaluation import EnvResult, SuiteResult
from .summary import STANDARD_METRICS, Verdict, aggregate, compare


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


# --- verdicts -------------------------------------------------------------------------------
def verdict_lines(result: EnvResult, aggs: dict[str, dict]) -> tuple[list[str], list[Verdict]]:
    """Plain sentences: where each PPO policy beats / loses to the analytical controller."""
    ppo = [n for n in aggs if n.startswith(PPO_PREFIX)]
    if "analytical" not in aggs or not ppo:
        missing = "an analytical controller" if "analytical" not in aggs else "a PPO policy"
        line = f"No PPO-vs-analytical comparison on {result.env_id}: no results for {missing}."
        return [line], []
    lines, all_verdicts = [], []
    for name in ppo:
        verdicts = compare(name, "analytical", aggs, result.specs)
        all_verdicts += verdicts

        def fmt(vs: list[Verdict]) -> str:
            return (
                "; ".join(
                    f"{v.label} ({_num(v.challenger_value)} vs {_num(v.baseline_value)}"
                    f"{', within spread' if v.within_spread else ''})"
                    for v in vs
                )
                or "nothing"
            )

        better = [v for v in verdicts if v.outcome == "better"]
        worse = [v for v in verdicts if v.outcome == "worse"]
        tie = [v for v in verdicts if v.outcome == "tie"]
        lines.append(f"**{name}** vs **analytical** on {result.env_id} (PPO value vs analytical):")
        lines.append(f"- PPO beats the analytical controller on: {fmt(better)}.")
        lines.append(f"- PPO loses to the analytical controller on: {fmt(worse)}.")
        if tie:
            lines.append(f"- Equal on: {fmt(tie)}.")
    return lines, all_verdicts


# --- assembling -----------------------------------------------------------------------------
def _episode_json(seed: int, record) -> dict[str, Any]:
    out = {"seed": seed, **record.scalar_metrics()}
    out["terminated"], out["truncated"] = record.terminated, record.truncated
    out["specifics"] = record.specifics
    return out


def build_metrics(result: SuiteResult) -> dict[str, Any]:
    suite = result.suite
    envs = {}
    for r in result.envs:
        aggs = {n: aggregate(run.episodes) for n, run in r.runs.items()}
        _, verdicts = verdict_lines(r, aggs)
        envs[r.env_id] = {
            "kwargs": r.kwargs,
            "max_episode_steps": r.max_episode_steps,
            "dt_s": r.dt,
            "metric_specs": [s.__dict__ for s in r.specs],
            "policies": {
                n: {
                    "source": run.source,
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
        "title": suite.title,
        "created": time.strftime("%Y-%m-%dT%H:%M:%S"),
        "seconds": result.seconds,
        "seeds": suite.seeds,
        "xi_f_deg": suite.xi_f_deg,
        "policies": suite.policies,
        "warnings": result.warnings,
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


def write_report(result: SuiteResult, out_dir: str | Path) -> list[Path]:
    """Write metrics.json, report.md, figures/*.png and report.html into `out_dir`."""
    out = Path(out_dir)
    fig_dir = out / "figures"
    fig_dir.mkdir(parents=True, exist_ok=True)
    suite = result.suite
    metrics = build_metrics(result)
    (out / "metrics.json").write_text(
        json.dumps(_clean(metrics), indent=1, default=_json_default) + "\n"
    )

    md: list[str] = [f"# {suite.title}", ""]
    hx: list[str] = [f"<h1>{html.escape(suite.title)}</h1>"]

    def para(text: str) -> None:
        md.extend([text, ""])
        hx.append(f"<p>{_inline_html(text)}</p>")

    def heading(text: str, level: int) -> None:
        md.extend(["#" * level + " " + text, ""])
        hx.append(f"<h{level}>{html.escape(text)}</h{level}>")

    def table(t: Table | None) -> None:
        if t is not None:
            md.extend([t.markdown(), ""])
            hx.append(t.html())

    def figure(name: str, png: bytes | None, caption: str) -> None:
        if png is None:
            return
        (fig_dir / name).write_bytes(png)
        md.extend([f"![{caption}](figures/{name})", ""])
        b64 = base64.b64encode(png).decode()
        hx.append(
            f'<figure><img alt="{html.escape(caption)}" src="data:image/png;base64,{b64}">'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>"
        )

    para(
        f"Policies: {', '.join(f'`{p}`' for p in suite.policies)}. Envs: "
        f"{', '.join(f'`{e.id}`' for e in suite.envs)}. {suite.episodes} episode(s) per policy "
        f"and env on seeds {suite.seeds} (identical seeds, terrain and start for every policy). "
        f"ξ_f = {suite.xi_f_deg:g}°. Cells: mean ± std over episodes; the spread table gives "
        f"median [min, max]. Run time {result.seconds:.1f} s."
    )
    if result.warnings:
        heading("Warnings", 2)
        md.extend([f"- **warning:** {w}" for w in result.warnings] + [""])
        hx.append(
            '<div class="warn"><ul>'
            + "".join(f"<li><b>warning:</b> {html.escape(w)}</li>" for w in result.warnings)
            + "</ul></div>"
        )

    heading("PPO vs analytical", 2)
    for r in result.envs:
        aggs = {n: aggregate(run.episodes) for n, run in r.runs.items()}
        lines, _ = verdict_lines(r, aggs)
        md.extend(lines + [""])
        hx.append(
            "<ul>" + "".join(f"<li>{_inline_html(x.lstrip('- '))}</li>" for x in lines) + "</ul>"
        )
    figure("success_rates.png", figures.success_bars(result), "Success rate per env and policy")

    for r in result.envs:
        slug = r.env_id.replace("/", "_")
        heading(r.env_id, 2)
        limit = r.max_episode_steps
        sources = "; ".join(f"`{n}`: {run.source}" for n, run in r.runs.items())
        para(
            f"Env kwargs: `{r.kwargs or {}}`; time limit {limit} steps"
            + (f" × {r.dt:g} s" if r.dt else "")
            + (f". Sources: {sources}." if sources else ". No policy ran on this env.")
        )
        if not r.runs:
            continue
        aggs = {n: aggregate(run.episodes) for n, run in r.runs.items()}
        table(main_table(aggs))
        if all(a["energy_j"] is None for a in aggs.values()):
            para(f"Energy: n/a, this env reports no `{POWER_KEY}` in info.")
        heading("Spread (median [min, max])", 3)
        table(spread_table(aggs))
        heading("Reward terms (episode sums)", 3)
        table(reward_table(aggs))
        spec_table = specifics_table(r, aggs)
        if spec_table is not None:
            heading("Env-specific metrics", 3)
            table(spec_table)
        figure(
            f"{slug}_fasm.png",
            figures.fasm_over_time(r, suite.xi_f_deg, suite.seeds[0]),
            f"{r.env_id}: FASM over time on seed {suite.seeds[0]}",
        )
        figure(f"{slug}_boxes.png", figures.metric_boxes(r), f"{r.env_id}: per-episode metrics")
        figure(
            f"{slug}_specific.png", figures.specific_boxes(r), f"{r.env_id}: env-specific metrics"
        )
        for name, run in r.runs.items():
            if run.frames:
                safe = "".join(c if c.isalnum() else "_" for c in name)
                figure(
                    f"{slug}_{safe}_frames.png",
                    figures.frame_strip(run.frames),
                    f"{r.env_id}, {name}: frames over the episode on seed {suite.seeds[0]}",
                )

    (out / "report.md").write_text("\n".join(md))
    page = (
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(suite.title)}"
        f"</title><style>{CSS}</style></head><body>{''.join(hx)}</body></html>\n"
    )
    (out / "report.html").write_text(page)
    return [out / "metrics.json", out / "report.md", out / "report.html"]


def _inline_html(text: str) -> str:
    """Escape, then render **bold** and `code` spans (the only Markdown the report uses)."""
    import re

    s = html.escape(text)
    s = re.sub(r"\*\*(.+?)\*\*", r"<b>\1</b>", s)
    return re.sub(r"`(.+?)`", r"<code>\1</code>", s)
