"""The ditch planner with constant settings on HexapodDitchCrossing-v1: successes per setting.

The analytical controller (Li et al. 2018's planner, `agents.upu_gait`) plans every crossing
with the same `GaitSettings`. The scan runs it with other constant settings, through the planner
knobs' own path (`agents.plan_knobs.PlanKnobCore`: settings without a plan fall back to the
env's), on the tasks of a distribution, and prints per setting the successes, tip-overs and
fallbacks, and the tasks it wins and loses against the env's own settings. It tells whether a
setting that helps on one distribution helps on the other (docs/results.md, the planner knobs).

    python experiments/ditch_planner/settings_scan.py --distribution train --seeds 1000 1100 \
        --settings "" "min_margin=0.02" "edge_clearance=0.015" [--json out.json]

A setting is a comma-separated list of ``knob=value`` [m] (knobs: `PLANNER_KNOB_RANGES`); the
empty setting is the env's own.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # run as a script from anywhere

import hexapod_envs  # noqa: E402, F401  (registers the ids)
from agents.knobs import PLANNER_KNOB_RANGES, KnobSettings  # noqa: E402
from agents.plan_knobs import PlanKnobsPerEpisode, resolved_settings  # noqa: E402

ENV_ID = "HexapodDitchCrossing-v1"


def parse_setting(text: str) -> dict[str, float]:
    """``"min_margin=0.02,edge_clearance=0.015"`` -> {knob: value [m]}; "" -> {}."""
    values = {}
    for item in filter(None, (part.strip() for part in text.split(","))):
        name, _, value = item.partition("=")
        if name not in PLANNER_KNOB_RANGES:
            raise SystemExit(f"unknown knob {name!r}; knobs: {sorted(PLANNER_KNOB_RANGES)}")
        low, high = PLANNER_KNOB_RANGES[name]
        if not low <= float(value) <= high:
            raise SystemExit(f"{name}={value} is outside the knob's range [{low}, {high}] m")
        values[name] = float(value)
    return values


def action_for(values: dict[str, float], default, names: tuple[str, ...]) -> np.ndarray:
    """The knob action that means `values` (the inverse of `agents.knobs.knob_values`)."""
    action = []
    for name in names:
        base = getattr(default, name)
        low, high = PLANNER_KNOB_RANGES[name]
        value = values.get(name, base)
        end = max(high, base) if value >= base else min(low, base)
        action.append(0.0 if end == base else (value - base) / abs(end - base))
    return np.array(action, dtype=np.float32)


def scan(
    distribution: str, seeds: range, settings: list[str]
) -> tuple[dict[str, dict[int, str]], dict[str, dict[int, float]]]:
    """({setting: {seed: outcome}}, {setting: {seed: the episode's largest tilt [deg]}}):
    outcome "S" success, "T" tip-over, "F" other failure; a trailing "*" marks a fallback to the
    env's settings."""
    knobs = KnobSettings(names=tuple(PLANNER_KNOB_RANGES))
    raw = gym.make(ENV_ID, task_distribution=distribution, action_mode="joint")
    env = PlanKnobsPerEpisode(raw, knobs)
    default = resolved_settings(env.core.default, env.core.base.task.robot)
    results, tilts = {}, {}
    for text in settings:
        action = action_for(parse_setting(text), default, knobs.names)
        outcomes, tilt = {}, {}
        for seed in seeds:
            env.reset(seed=seed)
            _, success, *_, info = env.step(action)
            outcome = "S" if success else ("T" if info["is_tipped_over"] else "F")
            outcomes[seed] = outcome + ("*" if info["planner_fallback"] else "")
            tilt[seed] = float(info["max_tilt_deg"])
        results[text], tilts[text] = outcomes, tilt
        print(summary(text, outcomes, results.get(""), tilt, tilts.get("")), flush=True)
    env.close()
    return results, tilts


def summary(
    text: str,
    outcomes: dict[int, str],
    reference: dict[int, str] | None,
    tilt: dict[int, float] | None = None,
    reference_tilt: dict[int, float] | None = None,
) -> str:
    """One line per setting: successes, tip-overs, fallbacks; against the reference (the env's
    settings) the tasks won and lost and, with the tilts, on how many tasks both succeed and
    this setting's largest tilt is lower, and the median change of it there [deg]."""
    ok = {s for s, o in outcomes.items() if o.startswith("S")}
    line = (
        f"{text or '(env settings)'}: {len(ok)}/{len(outcomes)} successes, "
        f"{sum(o.startswith('T') for o in outcomes.values())} tip-overs, "
        f"{sum(o.endswith('*') for o in outcomes.values())} fallbacks"
    )
    if reference is not None and text:
        base = {s for s, o in reference.items() if o.startswith("S")}
        line += f"; wins {sorted(ok - base)}, losses {sorted(base - ok)}"
        both = sorted(ok & base)
        if tilt is not None and reference_tilt is not None and both:
            change = np.array([tilt[s] - reference_tilt[s] for s in both])
            line += (
                f"; largest tilt lower on {int((change < 0).sum())} of the {len(both)} tasks both "
                f"cross, median change {np.median(change):+.3f} deg"
            )
    return line


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--distribution", choices=("train", "test"), default="train")
    parser.add_argument("--seeds", type=int, nargs=2, default=(1000, 1100), metavar=("FROM", "TO"))
    parser.add_argument("--settings", nargs="+", default=["", "min_margin=0.02"])
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    settings = [""] + [s for s in args.settings if s]  # the env's own first: the reference
    results, _ = scan(args.distribution, range(*args.seeds), settings)
    if args.json is not None:
        args.json.write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
