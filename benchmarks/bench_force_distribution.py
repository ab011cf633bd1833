"""Speed of the Zhang et al. 2024 force-distribution QP (agents/tipping/force_distribution.py).

Problem: the 5 t heavy-duty robot on four stance feet (LF, LR, RM, RR: a tripod plus the landed
adjustment leg), body pitched 10° nose-up, stability cone on: 12 variables, 4 normal-force,
16 friction and 16 stability-cone constraints.

Prints median and 90th-percentile times [µs] per back end for
  - the solver call alone (qpsolvers.solve_qp on the pre-built U, f, G, h),
  - ForceDistributor.solve_qp (solver call + slack/wrench bookkeeping; for daqp it calls
    daqp.solve directly, see force_distribution._solve_dense),
  - build (geometry, cone and constraint assembly from feet, CoG and wrench), with issue 14's
    target (<= 30 µs) beside it and, as "build, before", the assembly as it was before that
    issue (the verbatim copy in tests/helpers/reference_force_distribution.py, when the tests are
    there), timed in the same run,
  - the full build + solve of one control step.

Usage: python benchmarks/bench_force_distribution.py [--repeats N]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
import qpsolvers

from agents.tipping.force_distribution import (
    GRAVITY,
    SOLVERS,
    ForceDistributionConfig,
    ForceDistributor,
    desired_wrench,
)
from hexapod_envs.checks import count_argument
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


def paired_timings(fn_a, fn_b, repeats: int) -> tuple[np.ndarray, np.ndarray]:
    """Per-call times [µs] of ``fn_a`` and ``fn_b``, called alternately ``repeats`` times each."""
    for _ in range(min(50, repeats)):
        fn_a()
        fn_b()
    out = np.empty((2, repeats))
    for i in range(repeats):
        for j, fn in enumerate((fn_a, fn_b)):
            t0 = time.perf_counter()
            fn()
            out[j, i] = time.perf_counter() - t0
    return out[0] * 1e6, out[1] * 1e6


STAGES = ("solver call", "solve_qp (+bookkeeping)", "build", "build, before", "build + solve")
BUILD_TARGET_US = 30.0  # issue 14


def reference_build():
    """The pre-issue-14 ForceDistributor.build (tests/helpers/reference_force_distribution.py), or
    None when the tests are not next to the benchmarks."""
    tests = Path(__file__).resolve().parents[1] / "tests"
    sys.path.insert(0, str(tests))
    try:
        from helpers.reference_force_distribution import reference_build as build
    except ImportError:
        return None
    finally:
        sys.path.remove(str(tests))
    return build


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
    old_build = reference_build()
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
            "build, before": lambda d=distributor: old_build(d, feet, cog, wrench),
            "build + solve": lambda d=distributor: d.solve(feet, cog, wrench),
        }
        paired = {}
        if "build" in stages and "build, before" in stages and old_build is not None:
            # Alternate the two calls so that both see the same machine load.
            paired["build"], paired["build, before"] = paired_timings(
                calls["build"], calls["build, before"], repeats
            )
        for stage in stages:
            if stage == "build, before" and old_build is None:
                continue
            t = paired[stage] if stage in paired else timings(calls[stage], repeats)
            median = np.median(t)
            note = ""
            if stage == "build":
                met = "met" if median <= BUILD_TARGET_US else "missed"
                note = f"   target <= {BUILD_TARGET_US:.0f}: {met}"
            print(f"{solver:10s} {stage:24s} {median:8.1f} {np.percentile(t, 90):8.1f}{note}")
        print(f"{solver:10s} {'max |Δforce| vs daqp':24s} {gap:8.2e} N")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=count_argument(), default=3000)
    args = parser.parse_args()
    print_qp_timings(args.repeats)


if __name__ == "__main__":
    main()
