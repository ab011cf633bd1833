"""Speed of seed 000's tipping-recovery controller (agents/tipping/controller.py).

1. The force-distribution QP for four stance feet (the problem of bench_force_distribution.py:
   a tripod plus the landed adjustment leg, body pitched 10°, stability cone on): median and 90th
   percentile of the solver call and of build + solve, per back end (target: daqp ≤ 30 µs).
2. The whole controller step (TippingRecoveryPolicy.__call__: sensor model, FASM, judgment,
   foothold, time budget and trajectory, touch-down, QP and force offsets, action mapping)
   timed at every control period of recovery episodes on HexapodStewartTilt-v0, grouped by
   phase, with the env step beside it (target: median ≤ 0.5 ms).

Usage: python benchmarks/bench_recovery_controller.py [--repeats N] [--cases all|climb]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import gymnasium as gym
import numpy as np
import qpsolvers

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_force_distribution import timings  # noqa: E402

import hexapod_envs  # noqa: E402, F401
from agents.tipping.controller import TippingRecoveryPolicy  # noqa: E402
from agents.tipping.force_distribution import (  # noqa: E402
    GRAVITY,
    SOLVERS,
    ForceDistributionConfig,
    ForceDistributor,
    desired_wrench,
)
from hexapod_envs.robots.heavy_duty import HeavyDutyParams, standing_feet  # noqa: E402

CASES = [(s, st) for s in ("climb", "descend", "side") for st in ("LF-LR-RM", "LM-RF-RR")]


def qp_figures(repeats: int) -> None:
    params = HeavyDutyParams()
    feet_by_leg = standing_feet(params)
    feet = np.array([feet_by_leg[leg] for leg in ("LF", "LR", "RM", "RR")])
    cog = np.zeros(3)
    pitch = np.radians(10.0)
    gravity = GRAVITY * np.array([np.sin(pitch), 0.0, -np.cos(pitch)])
    wrench = desired_wrench(params.total_mass, np.diag([3.0e3, 8.5e3, 1.0e4]), gravity)
    print(f"force-distribution QP, 4 stance feet, stability cone on, {repeats} repeats [µs]")
    print(f"  {'solver':9s} {'stage':16s} {'median':>8s} {'p90':>8s}")
    for solver in SOLVERS:
        distributor = ForceDistributor(4, ForceDistributionConfig(solver=solver))
        qp = distributor.build(feet, cog, wrench)
        assert distributor.solve_qp(qp).ok
        stages = {
            "solver call": lambda qp=qp, s=solver: qpsolvers.solve_qp(
                qp.U, qp.f, qp.G, qp.h, solver=s
            ),
            "build + solve": lambda d=distributor: d.solve(feet, cog, wrench),
        }
        for stage, fn in stages.items():
            t = timings(fn, repeats)
            print(f"  {solver:9s} {stage:16s} {np.median(t):8.1f} {np.percentile(t, 90):8.1f}")


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
    qp_figures(args.repeats)
    controller_figures(CASES if args.cases == "all" else CASES[:1])


if __name__ == "__main__":
    main()
