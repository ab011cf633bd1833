"""Speed of the Zhang et al. 2024 force-distribution QP (agents/tipping/force_distribution.py).

Problem: the 5 t heavy-duty robot on four stance feet (LF, LR, RM, RR: a tripod plus the landed
adjustment leg), body pitched 10° nose-up, stability cone on: 12 variables, 4 normal-force,
16 friction and 16 stability-cone constraints.

Prints median and 90th-percentile times [µs] per back end for
  - the solver call alone (qpsolvers.solve_qp on the pre-built U, f, G, h),
  - ForceDistributor.solve_qp (solver call + slack/wrench bookkeeping),
  - build (geometry, cone and constraint assembly from feet, CoG and wrench),
  - the full build + solve of one control step.

Usage: python benchmarks/bench_force_distribution.py [--repeats N]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
import qpsolvers

from agents.tipping.force_distribution import (
    GRAVITY,
    SOLVERS,
    ForceDistributionConfig,
    ForceDistributor,
    desired_wrench,
)
from hexapod_envs.robots.heavy_duty import HeavyDutyParams, standing_feet


def timings(fn, repeats: int) -> np.ndarray:
    """Per-call wall times [µs] of ``repeats`` calls after a short warm-up."""
    for _ in range(min(50, repeats)):
        fn()
    out = np.empty(repeats)
    for i in range(repeats):
        t0 = time.perf_counter()
        fn()
        out[i] = time.perf_counter() - t0
    return out * 1e6


STAGES = ("solver call", "solve_qp (+bookkeeping)", "build", "build + solve")


def print_qp_timings(repeats: int, stages: tuple[str, ...] = STAGES) -> None:
    """Median and 90th-percentile times [µs] of the 4-stance-foot QP per back end and stage."""
    params = HeavyDutyParams()
    feet_by_leg = standing_feet(params)
    feet = np.array([feet_by_leg[leg] for leg in ("LF", "LR", "RM", "RR")])
    cog = np.zeros(3)
    pitch = math.radians(10.0)
    gravity = GRAVITY * np.array([math.sin(pitch), 0.0, -math.cos(pitch)])
    wrench = desired_wrench(params.total_mass, np.diag([3.0e3, 8.5e3, 1.0e4]), gravity)

    print(f"force distribution QP, 4 stance feet, {repeats} repeats, times in µs")
    print(f"{'solver':10s} {'stage':24s} {'median':>8s} {'p90':>8s}")
    reference = None
    for solver in SOLVERS:
        distributor = ForceDistributor(4, ForceDistributionConfig(solver=solver))
        qp = distributor.build(feet, cog, wrench)
        result = distributor.solve_qp(qp)
        assert result.status == "optimal", result.message
        if reference is None:
            reference = result.forces
        gap = float(np.abs(result.forces - reference).max())
        calls = {
            "solver call": lambda qp=qp, s=solver: qpsolvers.solve_qp(
                qp.U, qp.f, qp.G, qp.h, solver=s
            ),
            "solve_qp (+bookkeeping)": lambda d=distributor, qp=qp: d.solve_qp(qp),
            "build": lambda d=distributor: d.build(feet, cog, wrench),
            "build + solve": lambda d=distributor: d.solve(feet, cog, wrench),
        }
        for stage in stages:
            t = timings(calls[stage], repeats)
            print(f"{solver:10s} {stage:24s} {np.median(t):8.1f} {np.percentile(t, 90):8.1f}")
        print(f"{solver:10s} {'max |Δforce| vs daqp':24s} {gap:8.2e} N")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3000)
    args = parser.parse_args()
    print_qp_timings(args.repeats)


if __name__ == "__main__":
    main()
