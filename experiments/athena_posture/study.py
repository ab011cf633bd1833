"""Coelho et al. 2024's evaluation protocol on ``HexapodIrregularTerrain-v0``: run the posture
controller
with given gains and collect the paper's per-gait-cycle metrics.

The paper (Section 5.2) computes, per gait cycle, the RMS of the torso height (infrared sensor)
and of the pitch and roll angular velocities (IMU), and compares their medians and spreads over
cycles; the ZMP stability margin (eqs. 32-33) is compared over time steps. `run_episode` drives
the env through the common policy interface (`AthenaPosturePolicy` in the env's "gains" action
mode, where the env runs the controller) and keeps the env's ``cycle_stats``; on the ramp only
cycles with all feet on the slope count (`on_slope`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import gymnasium as gym
import numpy as np

import hexapod_envs  # noqa: F401  (registers the env ids)
from agents.athena_policy import PAPER_GAINS, AthenaPosturePolicy

ENV_ID = "HexapodIrregularTerrain-v0"
SIMPLE = (0.0, 0.0, 0.0)
"""The paper's "simple control"."""
PAPER_CHANGES = {
    "ramp": {"height": +60.77, "pitch_rate": -11.92, "roll_rate": -35.98},
    "blocks": {"pitch_rate": +54.33, "roll_rate": +82.16},
}
"""The paper's change of the medians, posture vs simple control, in % (Figs. 16-17)."""
DEFAULT_STEPS = 1200
"""Study length: one whole default episode (``max_episode_steps`` of the env id), 60 s at 20 Hz
(30 gait cycles). The default ramp is long enough that the robot stays on the slope all along."""
FOOT_REACH_X = 0.25
"""How far ahead of the torso centre the front feet reach, m (a cycle counts as "on the slope"
while its end position plus this is below the top of the slope)."""
METRICS = ("height", "pitch_rate", "roll_rate", "zmp_margin")


@dataclass
class EpisodeRecord:
    """One run: per-cycle statistics (from the env's ``info["cycle_stats"]``) and per-step
    ZMP margins, plus the episode outcome."""

    terrain: str
    gains: tuple[float, float, float]
    seed: int
    cycles: list[dict] = field(default_factory=list)
    zmp_margins: list[float] = field(default_factory=list)
    torso_collisions: int = 0
    distance: float = 0.0
    tipped_over: bool = False
    steps: int = 0

    def per_cycle(self, metric: str) -> np.ndarray:
        """Per-cycle values of `metric` (one of `METRICS`; zmp_margin: the cycle's mean)."""
        key = {
            "height": "height_rms",
            "pitch_rate": "pitch_rate_rms",
            "roll_rate": "roll_rate_rms",
            "zmp_margin": "zmp_margin_mean",
        }[metric]
        return np.array([c[key] for c in self.cycles])


def run_episode(
    terrain: str,
    gains: tuple[float, float, float],
    seed: int,
    steps: int | None = None,
    cycles: int | None = None,
    **env_kwargs,
) -> EpisodeRecord:
    """Walk `terrain` with the posture controller at `gains` from ``reset(seed=seed)``.

    Runs `steps` 20 Hz steps (default `DEFAULT_STEPS`), or fewer if `cycles` gait cycles are
    complete first; stops early on tip-over. On the ramp, cycles that end with the front feet
    past the top of the slope are dropped.
    """
    steps = DEFAULT_STEPS if steps is None else steps
    env = gym.make(
        ENV_ID, terrain=terrain, action_mode="gains", max_episode_steps=steps, **env_kwargs
    )
    base = env.unwrapped
    policy = AthenaPosturePolicy(env, *gains)
    record = EpisodeRecord(terrain=terrain, gains=tuple(gains), seed=seed)
    obs, info = env.reset(seed=seed)
    policy.reset()
    top = None
    if terrain == "ramp":
        top = base.ramp["start_x"] + base.ramp["length"] - FOOT_REACH_X
    for k in range(steps):
        obs, _, terminated, truncated, info = env.step(policy(obs))
        record.zmp_margins.append(info["zmp_margin"])
        stats = info.get("cycle_stats")
        if stats is not None and (top is None or stats["x_end"] < top):
            record.cycles.append(stats)
        record.steps = k + 1
        if terminated or truncated or (cycles is not None and len(record.cycles) >= cycles):
            break
    record.torso_collisions = info["torso_collisions"]
    record.distance = info["distance"]
    record.tipped_over = info["is_tipped_over"]
    env.close()
    return record


def pooled(records: list[EpisodeRecord], metric: str) -> np.ndarray:
    """All per-cycle values of `metric` over `records` (per-step values for "zmp_margin_step")."""
    if metric == "zmp_margin_step":
        return np.concatenate([np.asarray(r.zmp_margins) for r in records])
    return np.concatenate([r.per_cycle(metric) for r in records])


def summarize(records: list[EpisodeRecord]) -> dict[str, float]:
    """Medians over cycles (and time steps for the ZMP margin) plus collision/distance totals."""
    out = {f"{m}_median": float(np.median(pooled(records, m))) for m in METRICS}
    out["zmp_margin_step_median"] = float(np.median(pooled(records, "zmp_margin_step")))
    out["cycles"] = int(sum(len(r.cycles) for r in records))
    out["torso_collision_steps"] = int(sum(r.torso_collisions for r in records))
    out["episodes_with_collision"] = int(sum(r.torso_collisions > 0 for r in records))
    out["mean_distance"] = float(np.mean([r.distance for r in records]))
    out["tipped_over"] = int(sum(r.tipped_over for r in records))
    return out


def percent_change(before: float, after: float) -> float | None:
    """100 (after / before - 1), or None when `before` is 0 (e.g. a median ZMP margin of 0 m
    when the torso rests on the blocks and no foot carries load)."""
    return None if before == 0 else 100.0 * (after / before - 1.0)


def change_interval(result: dict, metric: str) -> tuple[float, float, float]:
    """The posture-vs-simple change of `metric`'s pooled median (%) in a `compare` result, with
    its 95 % percentile-bootstrap interval over the beds (seeds; both controllers resampled
    together, since they walked the same beds): (estimate, low, high).

    Why: on the block bed the pooled medians of a few beds swing widely from bed to bed (the
    simple controller's torso rests on some blocks, which stills its rates), so a change
    measured on 4 beds says little without its spread."""
    from agents.pipeline.summary import bootstrap_interval

    simple = [r.per_cycle(metric) for r in result["simple"]]
    posture = [r.per_cycle(metric) for r in result["posture"]]

    def change(beds: np.ndarray) -> float:
        before = np.median(np.concatenate([simple[i] for i in beds]))
        after = np.median(np.concatenate([posture[i] for i in beds]))
        return 100.0 * (after / before - 1.0)

    return (float(change(np.arange(len(simple)))), *bootstrap_interval(change, len(simple)))


def compare(terrain: str, seeds, gains=None, steps: int | None = None, **env_kwargs) -> dict:
    """Simple vs posture control (`gains`, default the paper's) on the same seeds.

    Returns {"simple": records, "posture": records, "summary": {...}, "change_pct": {...}}.
    """
    gains = PAPER_GAINS[terrain] if gains is None else tuple(gains)
    runs = {
        name: [run_episode(terrain, g, s, steps=steps, **env_kwargs) for s in seeds]
        for name, g in (("simple", SIMPLE), ("posture", gains))
    }
    summary = {name: summarize(records) for name, records in runs.items()}
    change = {
        m: percent_change(summary["simple"][f"{m}_median"], summary["posture"][f"{m}_median"])
        for m in METRICS
    }
    return {**runs, "gains": gains, "summary": summary, "change_pct": change}
