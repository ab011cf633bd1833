"""Report figures (matplotlib, Agg back end) returned as PNG bytes."""

from __future__ import annotations

import io
import warnings
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .evaluation import EnvResult, SuiteResult  # noqa: E402

BOX_METRICS = (
    ("fasm_min_deg", "min FASM [deg]"),
    ("fasm_mean_deg", "mean FASM [deg]"),
    ("fraction_below_xi", "share of time below ξ"),
    ("distance_m", "distance [m]"),
)


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def fasm_over_time(result: EnvResult, xi_deg: float | None, seed: int) -> bytes | None:
    """FASM over time of every policy on the first seed (same terrain and start), with the
    robot's threshold ξ drawn when it has one."""
    traces = {
        result.label(n): r.episodes[0].fasm_trace_deg for n, r in result.runs.items() if r.episodes
    }
    traces = {n: t for n, t in traces.items() if t}
    if not traces:
        return None
    fig, ax = plt.subplots(figsize=(8, 3.2))
    dt = result.dt or 1.0
    for name, trace in traces.items():
        t = (np.arange(len(trace)) + 1) * dt
        ax.plot(t, trace, lw=1.0, label=name)
    if xi_deg is not None:
        ax.axhline(xi_deg, color="k", ls="--", lw=1.0, label=f"ξ = {xi_deg:g}°")
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.set_xlabel("time [s]" if result.dt else "step")
    ax.set_ylabel("FASM [deg]")
    ax.set_title(f"{result.env_id}: FASM over time, seed {seed}")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
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
            result.label(n): [v for e in r.episodes if (v := e.scalar_metrics()[key]) is not None]
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
            data[result.label(policy)] = values
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
    """Success and tip-over rates per policy, one panel per env (horizontal bars, every rate
    written beside its bar so that 0 % is visible)."""
    envs = [r for r in result.envs if r.runs]
    if not envs:
        return None
    rows = max(len(r.runs) for r in envs)
    fig, axes = plt.subplots(
        1, len(envs), figsize=(3.6 * len(envs), 0.55 * rows + 1.4), squeeze=False, sharex=True
    )
    for ax, r in zip(axes[0], envs, strict=True):
        names = list(r.runs)
        y = np.arange(len(names))
        for offset, key, color, label in (
            (-0.2, "success", "tab:green", "success"),
            (0.2, "tipped_over", "tab:red", "tip-over"),
        ):
            rates = []
            for name in names:
                flags = [getattr(e, key) for e in r.runs[name].episodes]
                flags = [f for f in flags if f is not None]
                rates.append(float(np.mean(flags)) if flags else np.nan)
            ax.barh(y + offset, rates, 0.38, color=color, label=label)
            for yi, v in zip(y + offset, rates, strict=True):
                text = "n/a" if np.isnan(v) else f"{100 * v:.0f} %"
                ax.text(0.01 if np.isnan(v) else v + 0.02, yi, text, va="center", fontsize=7)
        ax.set_yticks(y, [_short(r.label(n), 34) for n in names], fontsize=7)
        ax.invert_yaxis()
        ax.set_xlim(0, 1.25)
        ax.set_xticks([0, 0.5, 1.0], ["0", "50 %", "100 %"], fontsize=7)
        ax.set_title(r.env_id, fontsize=8)
        ax.grid(alpha=0.3, axis="x")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    return _png(fig)


def success_by_difficulty(result: SuiteResult, bins: int = 4) -> bytes | None:
    """Success rate per policy against the task difficulty (``task["difficulty"]``, in [0, 1])
    in `bins` equal bins, one panel per env that reports a difficulty; a marker per bin that
    holds episodes."""
    envs = [
        r
        for r in result.envs
        if r.runs and any("difficulty" in e.task for run in r.runs.values() for e in run.episodes)
    ]
    if not envs:
        return None
    edges = np.linspace(0.0, 1.0, bins + 1)
    centres = (edges[:-1] + edges[1:]) / 2
    fig, axes = plt.subplots(1, len(envs), figsize=(3.6 * len(envs), 3.2), squeeze=False)
    for ax, r in zip(axes[0], envs, strict=True):
        for name, run in r.runs.items():
            d = np.array([e.task.get("difficulty", np.nan) for e in run.episodes], dtype=float)
            ok = np.array([bool(e.success) for e in run.episodes], dtype=float)
            index = np.clip(np.digitize(d, edges) - 1, 0, bins - 1)
            rates = [ok[index == b].mean() if np.any(index == b) else np.nan for b in range(bins)]
            ax.plot(centres, rates, marker="o", label=_short(r.label(name), 28))
        ax.set_xlim(0, 1)
        ax.set_ylim(-0.05, 1.05)
        ax.set_xlabel("task difficulty", fontsize=8)
        ax.set_ylabel("success rate", fontsize=8)
        ax.set_title(r.env_id, fontsize=8)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6)
    fig.tight_layout()
    return _png(fig)


def learning_curves(result: EnvResult) -> bytes | None:
    """Evaluation success rate and mean return against learner steps (env steps; gait cycles, in
    a row of their own, for a run that acts once per cycle) for every PPO policy whose
    run directory holds an ``evaluations.npz`` (shipped model directories do not)."""
    from ..run_files.errors import UserError
    from .learning_curve import evaluation_log, load_learning_curve

    curves = {}
    for name, run in result.runs.items():
        directory = getattr(run, "model_dir", None)
        log = None if directory is None else evaluation_log(directory)
        if log is not None:
            try:
                curves[result.label(name)] = load_learning_curve(log.parent)
            except UserError as exc:
                warnings.warn(f"{exc}; no learning curve for {name}", stacklevel=2)
    if not curves:
        return None
    units = sorted({curve.unit for curve in curves.values()})
    # One row per unit: gait-cycle runs count other steps (and their learner's reward leaves
    # terms out), so they get their own axes.
    fig, axes = plt.subplots(len(units), 2, figsize=(9, 3.0 * len(units)), squeeze=False)
    for (ax_s, ax_r), unit in zip(axes, units, strict=True):
        for label, curve in curves.items():
            if curve.unit != unit:
                continue
            rate = curve.success_rate
            if rate is not None:
                ax_s.plot(curve.timesteps, rate, marker="o", ms=3, label=_short(label, 40))
            ax_r.plot(curve.timesteps, curve.mean_return, marker="o", ms=3, label=_short(label, 40))
        ax_s.set(xlabel=unit, ylabel="success rate", ylim=(-0.05, 1.05))
        ax_r.set(xlabel=unit, ylabel="mean evaluation return")
        for ax in (ax_s, ax_r):
            ax.grid(alpha=0.3)
        ax_r.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
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
