"""The heavy-duty robot's physics step and servo armature: which pair keeps every fidelity row?

The heavy-duty envs used to step MuJoCo at 1 ms with a servo armature of (20, 20, 50) (x [kg],
leg length [kg], swing [kg·m²]; `HeavyDutyParams.joint_armature`): about 65 simulated seconds
per wall second on the cliff walk, where the performance target is 100. `physics_settings.py`
had shown that every coarser step with that armature loses fidelity rows: on the paper cliff the
reference gait no longer tips over, and at 2 ms the recovery controller tips on two of the six
Stewart cases. The legs' fastest motions are the servo damping acting on the light legs (for the
leg-length slide 1.5e5 N·s/m on about 50 kg, a time constant of 0.3 ms), which a coarser step
integrates coarsely; a heavier armature slows them. This probe runs the heavy-duty fidelity rows
of `physics_settings.heavy_duty_fidelity` (flat-ground FASM standing and walking, the paper
cliff's reference tip-over and peak tilt, the analytical controller on the six Stewart cases)
for pairs of physics step and armature, judges each row against the former model (the first
case) by the sweep's own tolerances, and times the cliff walk with random actions
(`physics_settings.sim_rate`).

Findings (dated): README.md beside this script.

Run: python experiments/physics_settings/heavy_duty_armature_probe.py [--workers 2]
     [MS,SLIDE,HINGE ...]
"""

from __future__ import annotations

import argparse
import itertools
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from experiments.physics_settings import physics_settings as ps  # noqa: E402
from hexapod_envs.envs.heavy_duty import HeavyDutySettings  # noqa: E402

FORMER_ARMATURE = (20.0, 20.0, 50.0)
"""The servo armature (x, leg length, swing) of the former 1 ms model."""

CASES = (
    (1.0, 1.0, 1.0),
    (2.0, 1.0, 1.0),
    (2.0, 2.0, 2.0),
    (2.0, 3.0, 3.0),
    (2.0, 4.0, 4.0),
    (2.0, 5.0, 5.0),
    (2.0, 6.0, 6.0),
    (2.0, 8.0, 8.0),
    (2.0, 4.0, 1.0),
    (2.0, 1.0, 4.0),
)
"""(physics step [ms], slide armature factor, hinge armature factor), factors of
`FORMER_ARMATURE`; the first, the former model, is the reference every row is judged against."""


def case_setting(case: tuple[float, float, float]) -> ps.PhysicsSetting:
    """The sweep's setting of a case: its step as a factor of the envs' default step, and its
    armature."""
    dt_ms, slide, hinge = case
    x, z, swing = FORMER_ARMATURE
    default_ms = HeavyDutySettings().physics_dt * 1e3
    return ps.PhysicsSetting(
        factor=dt_ms / default_ms, armature=(x * slide, z * slide, swing * hinge)
    )


def measure(case: tuple[float, float, float], seconds: float, reference=None) -> dict:
    """The fidelity rows and the cliff's speed of one case. `reference`: the former model's row
    values, against which each row is judged (by the sweep's rule)."""
    setting = case_setting(case)
    rows = ps.heavy_duty_fidelity(setting, quick=False)
    reference = reference or [row.value for row in rows]
    rate = ps.sim_rate("HexapodCliffWalk-v0", setting, "random", seconds)
    return {
        "case": case,
        "rows": [
            (row.name, row.value, ref, ps.holds(row, ref))
            for row, ref in zip(rows, reference, strict=True)
        ],
        "sim_per_wall": rate["sim_per_wall"],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument(
        "--seconds", type=float, default=20.0, help="simulated seconds of the speed figure"
    )
    parser.add_argument(
        "cases",
        nargs="*",
        metavar="MS,SLIDE,HINGE",
        help="cases to run instead of CASES' (the default case is always run first)",
    )
    args = parser.parse_args()
    cases = [CASES[0], *(tuple(float(v) for v in c.split(",")) for c in args.cases)]
    if len(cases) == 1:
        cases = list(CASES)
    with ProcessPoolExecutor(args.workers) as pool:
        default = pool.submit(measure, cases[0], args.seconds).result()
        values = [value for _, value, _, _ in default["rows"]]
        rest = pool.map(
            measure, cases[1:], itertools.repeat(args.seconds), itertools.repeat(values)
        )
        results = [default, *rest]
    for result in results:
        dt_ms, slide, hinge = result["case"]
        failed = [
            f"{name}: {ps.format_value(value)} (default {ps.format_value(ref)})"
            for name, value, ref, holds in result["rows"]
            if not holds
        ]
        print(
            f"{dt_ms:g} ms, armature slides x{slide:g}, hinge x{hinge:g}: "
            f"cliff {result['sim_per_wall']:.1f} sim s per wall s; "
            f"{len(result['rows']) - len(failed)} of {len(result['rows'])} rows hold"
        )
        for line in failed:
            print(f"    fails  {line}")


if __name__ == "__main__":
    main()
