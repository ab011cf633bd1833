"""Report figures (matplotlib, Agg back end) returned as PNG bytes."""

from __future__ import annotations

import io
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .evaluation import EnvResult, SuiteResult  # noqa: E402

BOX_METRICS = (
    ("fasm_min_deg", "min FASM [deg]"),
    ("fasm_mean_deg", "mean FASM [deg]"),
    ("time_below_xi_s", "time below ξ_f [s]"),
    ("distance_m", "distance [m]"),
)


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def fasm_over_time(result: EnvResult, xi_f_deg: float, seed: int) -> bytes | None:
    """FASM over time of every policy on the first seed (same terrain and start)."""
    traces = {n: r.episodes[0].fasm_trace_deg for n, r in result.runs.items() if r.episodes}
    traces = {n: t for n, t in traces.items() if t}
    if not traces:
        return None
    fig, ax = plt.subplots(figsize=(8, 3.2))
    dt = result.dt or 1.0
    for name, trace in traces.items():
        t = (np.arange(len(trace)) + 1) * dt
        ax.plot(t, trace, lw=1.0, label=name)
    ax.axhline(xi_f_deg, color="k", ls="--", lw=0.8, label=f"ξ_f = {xi_f_deg:g}°")
    ax.set_xlabel("time [s]" if result.dt else "step")
    ax.set_ylabel("FASM [deg]")
    ax.set_title(f"{result.env_id}: FASM over time, seed {seed}")
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3)
    return _png(fig)


def _boxes(ax, data: dict[str, list[float]], title: str) -> None:
    names = [n for n, v in data.items() if v]
    if not names:
        ax.set_visible(False)
        return
    ax.boxplot([data[n] for n in names], showmeans=True)
    ax.set_xticks(range(1, len(names) + 1), [_short(n) for n in names], rotation=20, fontsize=7)
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3, axis="y")


def _short(name: str, limit: int = 22) -> str:
    return name if len(name) <= limit else name[: limit // 2 - 1] + "…" + name[-(limit // 2) :]


def metric_boxes(result: EnvResult) -> bytes | None:
    """Per-episode box plots of the FASM statistics and distance, one box per policy."""
    panels = []
    for key, title in BOX_METRICS:
        data = {
            n: [v for e in r.episodes if (v := e.scalar_metrics()[key]) is not None]
            for n, r in result.runs.items()
        }
        if any(data.values()):
            panels.append((data, title))
    return _panels(panels, f"{result.env_id}: per-episode metrics")


def specific_boxes(result: EnvResult) -> bytes | None:
    """Box plots of the env's numeric and per-cycle metrics (pooled over episodes)."""
    names = sorted({k for r in result.runs.values() for e in r.episodes for k in e.specifics})
    panels = []
    for name in names:
        data: dict[str, list[float]] = {}
        for policy, run in result.runs.items():
            values = []
            for e in run.episodes:
                v = e.specifics.get(name)
                if isinstance(v, list):
                    values.extend(x for x in v if isinstance(x, int | float))
                elif isinstance(v, int | float) and not isinstance(v, bool):
                    values.append(float(v))
            data[policy] = values
        if any(data.values()):
            panels.append((data, name))
    return _panels(panels, f"{result.env_id}: env-specific metrics")


def _panels(panels: Sequence[tuple[dict, str]], title: str) -> bytes | None:
    if not panels:
        return None
    cols = min(len(panels), 4)
    rows = -(-len(panels) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 3.0 * rows), squeeze=False)
    for ax, (data, name) in zip(axes.flat, panels, strict=False):
        _boxes(ax, data, name)
    for ax in list(axes.flat)[len(panels) :]:
        ax.set_visible(False)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return _png(fig)


def success_bars(result: SuiteResult) -> bytes | None:
    """Success rate of every policy on every env (grouped bars)."""
    envs = [r for r in result.envs if r.runs]
    policies = list(dict.fromkeys(n for r in envs for n in r.runs))
    if not envs or not policies:
        return None
    fig, ax = plt.subplots(figsize=(max(5.0, 1.8 * len(envs)), 3.2))
    width = 0.8 / len(policies)
    x = np.arange(len(envs))
    for i, name in enumerate(policies):
        rates = []
        for r in envs:
            run = r.runs.get(name)
            flags = [e.success for e in run.episodes if e.success is not None] if run else []
            rates.append(np.mean(flags) if flags else np.nan)
        ax.bar(x + (i - (len(policies) - 1) / 2) * width, rates, width, label=_short(name, 30))
    ax.set_xticks(x, [r.env_id for r in envs], fontsize=8)
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("success rate")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, axis="y")
    return _png(fig)


def frame_strip(frames: list[np.ndarray], gap: int = 4) -> bytes | None:
    """Frames side by side with white gaps, as one PNG."""
    if not frames:
        return None
    h = max(f.shape[0] for f in frames)
    pieces = []
    for k, frame in enumerate(frames):
        pad = np.full((h, frame.shape[1], 3), 255, dtype=np.uint8)
        pad[: frame.shape[0]] = frame[..., :3]
        pieces.append(pad)
        if k < len(frames) - 1:
            pieces.append(np.full((h, gap, 3), 255, dtype=np.uint8))
    buf = io.BytesIO()
    plt.imsave(buf, np.concatenate(pieces, axis=1), format="png")
    return buf.getvalue()
