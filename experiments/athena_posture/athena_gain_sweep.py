"""Coelho et al. 2024 §5.2.1-5.2.2 gain sweep on HexapodIrregularTerrain-v0, with a table of
medians.

The paper's protocol: one gain at a time over {0, 0.2, ..., 1.0} with the other two at 0, on the
ramp and on the block bed; per setting the medians over gait cycles of the RMS torso height and
pitch/roll rates, and (here) the ZMP margin over time steps, torso-contact steps and distance.
The paper's tuned combinations are added as the last rows. With ``--servo-kp`` a second table
compares simple vs the tuned ramp gains for several servo stiffnesses and both phase-start
rules (the sensitivity of the ramp result to the one servo number the paper does not give).

Writes `reports/athena_gain_sweep.md`. The default run is short (6 gait cycles per setting, one
seed: ~20 s); the committed report used ``--cycles 30 --seeds 2 --servo-kp 5 6.5 8 10 12 20``.

Run: python experiments/athena_posture/athena_gain_sweep.py [--cycles 6] [--seeds 1]
     [--servo-kp 5 8 20] [--out F]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from experiments.athena_posture.study import PAPER_GAINS, SIMPLE, run_episode, summarize  # noqa: E402
from hexapod_envs.envs.irregular_terrain import IrregularTerrainSettings  # noqa: E402

DEFAULTS = IrregularTerrainSettings()

VALUES = (0.0, 0.2, 0.4, 0.6, 0.8, 1.0)
GAIN_NAMES = ("k_z", "k_α", "k_β")
KP_NOTE = (
    "Simple control vs the paper's ramp gains (0.8, 0.6, 0.0) for several position-servo "
    "stiffnesses (all with the 1.89 N·m torque limit) and both ways of starting a phase "
    "(`measured`: the paper's eq. 12 on the encoders for x, y and z; `measured_height`: the "
    "default, z only). Directions as the paper: height up (h), pitch rate not up (p), roll rate "
    "down (r)."
)
COLUMNS = (
    ("height_median", "height [m]", "{:.4f}"),
    ("pitch_rate_median", "pitch rate [rad/s]", "{:.4f}"),
    ("roll_rate_median", "roll rate [rad/s]", "{:.4f}"),
    ("zmp_margin_step_median", "ZMP margin [m]", "{:.4f}"),
    ("torso_collision_steps", "torso-contact steps", "{:d}"),
    ("mean_distance", "distance [m]", "{:.2f}"),
    ("cycles", "cycles", "{:d}"),
)


def settings() -> list[tuple[str, tuple[float, float, float]]]:
    """(label, gains): the simple control once, then each gain alone over VALUES[1:]."""
    rows = [("simple", SIMPLE)]
    for k, name in enumerate(GAIN_NAMES):
        for v in VALUES[1:]:
            gains = [0.0, 0.0, 0.0]
            gains[k] = v
            rows.append((f"{name} = {v:.1f}", tuple(gains)))
    return rows


def table(rows: list[tuple[str, dict]]) -> list[str]:
    lines = ["| setting | " + " | ".join(c[1] for c in COLUMNS) + " |"]
    lines.append("|---" * (len(COLUMNS) + 1) + "|")
    for label, s in rows:
        cells = [fmt.format(s[key]) for key, _, fmt in COLUMNS]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def sweep(terrain: str, seeds, cycles: int) -> list[tuple[str, dict]]:
    rows = []
    gains_rows = settings() + [(f"paper's tuned {PAPER_GAINS[terrain]}", PAPER_GAINS[terrain])]
    for label, gains in gains_rows:
        records = [run_episode(terrain, gains, s, cycles=cycles) for s in seeds]
        rows.append((label, summarize(records)))
        print(f"  {terrain:6s} {label:32s} height {rows[-1][1]['height_median']:.4f}", flush=True)
    return rows


def kp_sensitivity(kps, seeds, cycles: int) -> list[str]:
    lines = [
        "| servo_kp [N·m/rad] | phase start | height simple → posture | change | pitch rate "
        "change | roll rate change | directions as the paper |",
        "|---|---|---|---|---|---|---|",
    ]
    for kp in kps:
        for start in ("measured_height", "measured"):
            kw = {"servo_kp": kp, "gait_start_from": start}
            s = {
                name: summarize([run_episode("ramp", g, x, cycles=cycles, **kw) for x in seeds])
                for name, g in (("simple", SIMPLE), ("posture", PAPER_GAINS["ramp"]))
            }
            change = {
                m: 100 * (s["posture"][f"{m}_median"] / s["simple"][f"{m}_median"] - 1)
                for m in ("height", "pitch_rate", "roll_rate")
            }
            ok = (change["height"] > 0, change["pitch_rate"] <= 0, change["roll_rate"] < 0)
            marks = " ".join(f"{n}{'✓' if o else '✗'}" for n, o in zip("hpr", ok, strict=True))
            lines.append(
                f"| {kp:g} | {start} | {s['simple']['height_median']:.4f} → "
                f"{s['posture']['height_median']:.4f} | {change['height']:+.1f} % | "
                f"{change['pitch_rate']:+.1f} % | {change['roll_rate']:+.1f} % | {marks} |"
            )
            print(f"  kp {kp:g} {start}: {lines[-1]}", flush=True)
    return lines


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cycles", type=int, default=6, help="gait cycles per setting and seed")
    parser.add_argument("--seeds", type=int, default=1, help="seeds per setting")
    parser.add_argument("--servo-kp", type=float, nargs="*", default=[], help="kp sensitivity")
    parser.add_argument("--out", type=Path, default=Path("reports/athena_gain_sweep.md"))
    args = parser.parse_args(argv)
    seeds = range(args.seeds)
    start = time.perf_counter()
    lines = [
        "# ATHENA posture-control gain sweep (Coelho et al. 2024 §5.2, HexapodIrregularTerrain-v0)",
        "",
        "Generated by `python experiments/athena_posture/athena_gain_sweep.py "
        f"--cycles {args.cycles} --seeds "
        f"{args.seeds}"
        + (" --servo-kp " + " ".join(f"{k:g}" for k in args.servo_kp))
        * bool(args.servo_kp)
        + "`. One gain at a time over {0, 0.2, …, 1}, the other two at 0 (the paper's "
        f"protocol); {args.cycles} gait cycles (2 t_g = 2 s each) per setting and seed, seeds "
        f"{list(seeds)}, default env (servo_kp {DEFAULTS.servo_kp:g} N·m/rad, "
        f"{DEFAULTS.block_size[0]:g} m blocks, phase start `{DEFAULTS.gait_start_from}`). "
        "Medians over gait cycles of the per-cycle RMS torso height (infrared reading) and "
        "pitch/roll rates (IMU); the ZMP margin (eqs. 32-33) median over time steps; "
        "torso-contact steps summed over seeds; distance = mean CoG travel along x. On the ramp "
        "only cycles with all feet on the slope count. Landing legs that found no ground are "
        "extended until they touch only when the plane is used (k_α or k_β > 0, "
        '`gait_ground_search="auto"`): on the blocks the k_α and k_β rows ride on the tallest '
        "blocks, the simple and k_z rows touch them with the torso (the simple row rests on "
        "them: ZMP margin 0, no foot loaded).",
        "",
    ]
    for terrain in ("ramp", "blocks"):
        lines += [f"## {terrain}", ""] + table(sweep(terrain, seeds, args.cycles)) + [""]
    if args.servo_kp:
        lines += (
            [
                "## Ramp: sensitivity to the servo stiffness and the phase-start rule",
                "",
                KP_NOTE,
                "",
            ]
            + kp_sensitivity(args.servo_kp, seeds, args.cycles)
            + [""]
        )
    lines.append(f"Run time: {time.perf_counter() - start:.0f} s.")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text("\n".join(lines) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
