"""HexapodDitchCrossing-v0 speed: raw mj_step rate vs the env's rate with substeps counted.

Target (issue 5): env/raw ratio >= 0.9, both measured over the same motion (the reference gait
walking toward and into the ditch; see `benchmarks.common.replay_step_rate`). Also prints the
cost of the env's per-step stability work and of planning at reset. Run:
    python benchmarks/bench_ditch_crossing.py
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run as a script from anywhere

import hexapod_envs  # noqa: F401
from benchmarks.common import ENV_RAW_TARGET, env_vs_raw, per_call_us, replay_step_rate, verdict
from hexapod_envs.envs.ditch_crossing import DitchCrossingEnv
from hexapod_envs.robots.upu.gait_plan import Ditch, plan_ditch_crossing
from hexapod_envs.robots.upu.params import UpuParams

ENV_ID = "HexapodDitchCrossing-v0"


def main() -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()  # --help
    print(
        f"{'env':32s} {'raw mj_step/s':>14s} {'env physics steps/s':>20s} {'env/raw':>8s} "
        f"{'env/sensing last':>17s}"
    )
    for label, kwargs in (
        ("HexapodDitchCrossing-v0", {}),
        ("  terrain='flat'", {"terrain": "flat"}),
    ):
        rates = env_vs_raw(ENV_ID, steps=1000, repeats=5, **kwargs)
        print(
            f"{label:32s} {rates.raw:14.0f} {rates.env:20.0f} {rates.env / rates.raw:8.3f} "
            f"{rates.env / rates.raw_sensing_last:17.3f}"
        )
        substeps = round(0.1 / 0.002)
        physics_us = substeps / rates.raw * 1e6
        sensed_us = substeps / rates.raw_sensing_last * 1e6
        overhead_us = substeps / rates.env * 1e6 - sensed_us
        print(
            f"{'':32s} per control step: physics {physics_us:6.0f} us "
            f"({substeps} x mj_step; {sensed_us:4.0f} us sensing last), "
            f"env overhead {overhead_us:5.0f} us"
        )

    # Load-robust cross-check on a shared machine: each replay measures the env and the raw
    # physics back to back over the same motion; the median of those paired ratios.
    paired = gym.make(ENV_ID)
    replays = [replay_step_rate(paired, 400, seed=s) for s in range(7)]
    ratios = sorted(r.env / r.raw for r in replays)
    overhead_only = sorted(r.env / r.raw_sensing_last for r in replays)
    paired.close()
    print(
        f"paired env/raw ratios over 7 replays: median {ratios[3]:.3f} "
        f"(range {ratios[0]:.3f}-{ratios[-1]:.3f}); env/sensing last: median "
        f"{overhead_only[3]:.3f} (range {overhead_only[0]:.3f}-{overhead_only[-1]:.3f})"
    )
    print(
        f"issue 14's target: env/raw >= {ENV_RAW_TARGET} (paired median): "
        f"{verdict(ratios[3], ENV_RAW_TARGET)}"
    )

    env = DitchCrossingEnv()
    env.reset(seed=0)
    for _ in range(300):
        env.step(np.zeros(9))
    rows = (
        ("stability update (forces, FASM, static margin)", env._measure, ()),
        ("observation vector", env._observation, ()),
        ("info dict", env._info, ({}, False)),
    )
    for label, fn, args in rows:
        print(f"{label:48s} {per_call_us(fn, *args):6.1f} us per control step")

    params = UpuParams()
    start = time.perf_counter()
    plan_ditch_crossing(params, Ditch(0.6, 0.33, 0.12))
    cold = time.perf_counter() - start
    start = time.perf_counter()
    plan_ditch_crossing(params, Ditch(0.6, 0.31, 0.13))
    warm = time.perf_counter() - start
    print(f"ditch plan at reset: {cold * 1e3:.0f} ms cold, {warm * 1e3:.0f} ms warm")


if __name__ == "__main__":
    main()
