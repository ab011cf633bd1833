"""Coelho et al. 2024 Figs. 16-19 for HexapodIrregularTerrain-v0: posture control vs "simple
control".

For the ramp ((k_z, k_α, k_β) = (0.8, 0.6, 0.0)) and the block bed ((0.6, 0.4, 0.4)) it runs
one default episode (60 s) per seed with each controller on the same seeds and draws box plots of
the per-gait-cycle RMS torso height, pitch-rate and roll-rate RMS and the ZMP stability margin
(per time step, as in the paper's Figs. 18-19), like the paper's Figs. 10-19. Writes
`reports/figures/athena_ramp_posture.png`, `athena_blocks_posture.png` and the numbers to
`athena_posture_study.json`, and prints the medians next to the paper's changes.

Run: python experiments/athena_posture/athena_posture_study.py [--seeds 3] [--steps 1200]
     [--out reports/figures]
     [--block-size B]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from experiments.athena_posture.study import PAPER_CHANGES, compare, percent_change, pooled  # noqa: E402

PANELS = (
    ("height", "torso height RMS per cycle [m]"),
    ("pitch_rate", "pitch rate RMS per cycle [rad/s]"),
    ("roll_rate", "roll rate RMS per cycle [rad/s]"),
    ("zmp_margin_step", "ZMP stability margin per step [m]"),
)


def plot(terrain: str, result: dict, path: Path) -> None:
    fig, axes = plt.subplots(1, len(PANELS), figsize=(14, 3.8))
    gains = ", ".join(f"{g:.1f}" for g in result["gains"])
    labels = ["simple\n(0, 0, 0)", f"posture\n({gains})"]
    for ax, (metric, title) in zip(axes, PANELS, strict=True):
        data = [pooled(result[name], metric) for name in ("simple", "posture")]
        ax.boxplot(data, showfliers=True)
        ax.set_xticks([1, 2], labels)
        ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3)
    s = result["summary"]
    fig.suptitle(
        f"ATHENA on the {terrain} (Coelho et al. 2024 protocol, {s['posture']['cycles']} posture / "
        f"{s['simple']['cycles']} simple gait cycles); torso-contact steps: simple "
        f"{s['simple']['torso_collision_steps']}, posture {s['posture']['torso_collision_steps']}",
        fontsize=10,
    )
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def report(terrain: str, result: dict) -> dict:
    s = result["summary"]
    changes: dict[str, float | None] = {}
    print(f"\n{terrain}: gains {result['gains']}")
    print(f"  {'metric':24s} {'simple':>10s} {'posture':>10s} {'change':>9s} {'paper':>9s}")
    for metric in ("height", "pitch_rate", "roll_rate", "zmp_margin", "zmp_margin_step"):
        a, b = s["simple"][f"{metric}_median"], s["posture"][f"{metric}_median"]
        paper = PAPER_CHANGES.get(terrain, {}).get(metric)
        paper_txt = f"{paper:+8.2f}%" if paper is not None else f"{'-':>9s}"
        change = changes[metric] = percent_change(a, b)
        change_txt = f"{change:+8.1f}%" if change is not None else f"{'n/a':>9s}"
        print(f"  {metric + ' median':24s} {a:10.4f} {b:10.4f} {change_txt} {paper_txt}")
    for key in ("episodes_with_collision", "torso_collision_steps", "mean_distance"):
        print(f"  {key:24s} {s['simple'][key]:10.3g} {s['posture'][key]:10.3g}")
    return {"gains": result["gains"], "summary": s, "change_pct": changes}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=3, help="episodes per controller")
    parser.add_argument("--steps", type=int, default=1200, help="20 Hz steps per episode")
    parser.add_argument("--out", type=Path, default=Path("reports/figures"))
    parser.add_argument(
        "--block-size", type=float, default=None, help="block edge [m] (default: the env's)"
    )
    args = parser.parse_args(argv)
    seeds = range(args.seeds)
    numbers = {}
    for terrain in ("ramp", "blocks"):
        kwargs = {}
        if terrain == "blocks" and args.block_size is not None:
            kwargs["block_size"] = (args.block_size, args.block_size)
        result = compare(terrain, seeds, steps=args.steps, **kwargs)
        plot(terrain, result, args.out / f"athena_{terrain}_posture.png")
        numbers[terrain] = report(terrain, result)
    numbers["seeds"], numbers["steps"] = list(seeds), args.steps
    (args.out / "athena_posture_study.json").write_text(json.dumps(numbers, indent=2))
    print(f"\nwrote {args.out}/athena_{{ramp,blocks}}_posture.png and athena_posture_study.json")


if __name__ == "__main__":
    main()
