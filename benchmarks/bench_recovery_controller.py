"""Speed of Zhang et al. 2024's tipping-recovery controller (agents/tipping/controller.py).

1. The force-distribution QP for four stance feet (the problem of bench_force_distribution.py:
   a tripod plus the landed adjustment leg, body pitched 10°, stability cone on): median and 90th
   percentile of the solver call and of build + solve, per back end (target: daqp ≤ 30 µs).
2. The whole controller step (TippingRecoveryPolicy.__call__: sensor model, FASM, judgment,
   foothold, time budget and trajectory, touch-down, QP and force offsets, action mapping)
   timed at every control period of recovery episodes on HexapodStewartTilt-v0, grouped by
   phase, with the env step beside it (target of issue 14: median ≤ 150 µs over all steps,
   printed beside the figure; the earlier target was 0.5 ms).

Usage: python benchmarks/bench_recovery_controller.py [--repeats N] [--cases all|climb]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_force_distribution import print_qp_timings  # noqa: E402

import hexapod_envs  # noqa: E402, F401
from agents.tipping.controller import TippingRecoveryPolicy  # noqa: E402

STEP_TARGET_US = 150.0
CASES = [(s, st) for s in ("climb", "descend", "side") for st in ("LF-LR-RM", "LM-RF-RR")]


def controller_figures(cases: list[tuple[str, str]]) -> None:
    per_phase: dict[str, list[float]] = {}
    events: dict[str, list[float]] = {"judgment + foothold + trajectory": [], "QP step": []}
    env_times: list[float] = []
    for scenario, stance in cases:
        env = gym.make("HexapodStewartTilt-v0", scenario=scenario, stance=stance)
        policy = TippingRecoveryPolicy(env)
        obs, _ = env.reset(seed=0)
        policy.reset()
        was_active = False
        while True:
            t0 = time.perf_counter()
            action = policy(obs)
            t1 = time.perf_counter()
            obs, _, terminated, truncated, _ = env.step(action)
            env_times.append(time.perf_counter() - t1)
            d = policy.diagnostics
            step_us = (t1 - t0) * 1e6
            phase = policy.controller.phase
            per_phase.setdefault(phase, []).append(step_us)
            if policy.controller.active and not was_active:
                events["judgment + foothold + trajectory"].append(step_us)
            if phase == "supported" and d["qp_status"] is not None:
                events["QP step"].append(step_us)
            was_active = policy.controller.active
            if terminated or truncated:
                break
        env.close()
    every = np.concatenate([np.asarray(v) for v in per_phase.values()])
    print(f"\ncontroller step over {len(cases)} recovery episode(s), {len(every)} steps [µs]")
    print(f"  {'steps':34s} {'n':>6s} {'median':>8s} {'p90':>8s} {'max':>8s}")

    def row(name: str, values) -> None:
        v = np.asarray(values)
        if len(v):
            print(
                f"  {name:34s} {len(v):6d} {np.median(v):8.1f} {np.percentile(v, 90):8.1f} "
                f"{v.max():8.1f}"
            )

    row("all", every)
    median = float(np.median(every))
    print(
        f"  target (issue 14): median <= {STEP_TARGET_US:.0f} µs: "
        f"{'met' if median <= STEP_TARGET_US else 'missed'} ({median:.1f})"
    )
    for phase, values in per_phase.items():
        row(f"phase {phase}", values)
    for name, values in events.items():
        row(name, values)
    row("env.step (physics, for scale)", np.asarray(env_times) * 1e6)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3000)
    parser.add_argument("--cases", choices=("all", "climb"), default="all")
    args = parser.parse_args()
    print_qp_timings(args.repeats, stages=("solver call", "build + solve"))
    controller_figures(CASES if args.cases == "all" else CASES[:1])


if __name__ == "__main__":
    main()
