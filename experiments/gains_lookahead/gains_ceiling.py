"""What per-gait-cycle posture gains can gain over the paper's fixed gains on held-out beds.

Runs, on HexapodIrregularTerrain-v0's ``test`` task distribution (the beds the learned gains
are judged on, seeds 0..episodes-1 like `configs/evaluate_gains_blocks.yaml`), the paper's gains
for the terrain, every fixed setting of a grid and the one-cycle look-ahead over the same grid
(`lookahead`, this study), and writes a table of the pooled per-cycle pitch/roll-rate RMS
medians, torso-contact steps and successes, marking the rows that beat the paper's gains on both
rates with no more contact steps.

Writes `reports/gains_ceiling_<terrain>.md` and `.json`. The committed blocks report is the
default run (20 episodes, levels 0.2 0.5 0.8: about 30 min on one core, most of it the
look-ahead, which plays every candidate for every cycle; `--workers 2` halves that).

`--state-noise σ ...` adds, per σ, a look-ahead that chooses from copies whose velocities carry
an error of σ (`--samples` copies per candidate, mean cost), while the episode runs on exactly:
how much of the look-ahead's advantage is foresight rather than hindsight of chaotic contacts
(see lookahead.py); `--position-noise σ_p ...` likewise with the robot, stance feet
included, shifted horizontally by σ_p per axis (how much a cycle hangs on where the feet stand on
the blocks). Such runs write `gains_foresight_<terrain>.md`/`.json`; `--no-grid` leaves out the
fixed settings of the grid. The committed `reports/gains_foresight_blocks.md` is the run its
header names (10 beds, 3 velocity and 3 position errors, 4 copies each: about 65 min on 2 cores;
each noisy row costs 4 look-aheads).

Run: python experiments/gains_lookahead/gains_ceiling.py [--terrain blocks] [--episodes 20]
     [--levels 0.2 0.5 0.8]
     [--no-lookahead] [--no-grid] [--state-noise S ...] [--position-noise P ...] [--samples K]
     [--workers 1] [--out-dir reports]
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
import hexapod_envs  # noqa: E402, F401
from agents.athena_policy import PAPER_GAINS  # noqa: E402
from experiments.gains_lookahead.lookahead import (  # noqa: E402
    Fixed,
    Lookahead,
    beats,
    gain_grid,
    gains_env,
    run_episode,
    summarize,
)

EXACT = "look-ahead over the grid and the paper's"


make_env = gains_env  # the env of every row (a seam for the tests)


def _row(terrain: str, episodes: int, choose) -> dict:
    env = make_env(terrain)
    start = time.perf_counter()
    row = summarize([run_episode(env, seed, choose) for seed in range(episodes)])
    row["wall_s"] = round(time.perf_counter() - start, 1)
    env.close()
    return row


def measure(
    terrain: str,
    episodes: int,
    levels: list[float],
    with_lookahead: bool,
    workers: int = 1,
    with_grid: bool = True,
    state_noise: tuple[float, ...] = (),
    samples: int = 1,
    position_noise: tuple[float, ...] = (),
) -> dict:
    """{label: summary} for the paper's gains, each grid setting, the look-ahead and the
    look-aheads from noisy copies, the rows spread over `workers` processes."""
    paper = PAPER_GAINS[terrain]
    grid = gain_grid(levels)
    choosers = {f"paper {paper}": Fixed(paper)}  # in the table's order
    if with_grid:
        choosers.update({f"fixed {g}": Fixed(g) for g in grid if g != paper})
    if with_lookahead:
        choosers[EXACT] = Lookahead((*grid, paper))
    for sigma in state_noise:
        label = f"look-ahead from copies with velocity error σ = {sigma:g} (mean of {samples})"
        choosers[label] = Lookahead((*grid, paper), state_noise=sigma, samples=samples)
    for sigma in position_noise:
        label = f"look-ahead from copies with position error σ = {sigma:g} m (mean of {samples})"
        choosers[label] = Lookahead((*grid, paper), position_noise=sigma, samples=samples)
    if workers == 1:
        rows = {label: _row(terrain, episodes, c) for label, c in choosers.items()}
    else:
        # The longest rows first (a look-ahead from noisy copies, then the exact one), so that
        # the shorter rows fill the other workers.
        first = sorted(choosers, key=lambda label: -_row_cost(choosers[label]))
        with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
            futures = {
                label: pool.submit(_row, terrain, episodes, choosers[label]) for label in first
            }
            rows = {label: futures[label].result() for label in choosers}
    for label, row in rows.items():
        print(label, row, flush=True)
    return rows


def report(rows: dict, terrain: str, args: argparse.Namespace) -> str:
    reference = next(iter(rows.values()))
    exact = rows.get(EXACT)
    kept = exact is not None and _noisy(args)
    title = (
        "how much of the one-cycle look-ahead's advantage is foresight"
        if kept
        else "fixed settings and a one-cycle look-ahead"
    )
    lines = [
        f"# Per-cycle posture gains on the {terrain}: {title}",
        "",
        "Generated by `python experiments/gains_lookahead/gains_ceiling.py "
        f"--terrain {terrain} --episodes "
        f"{args.episodes} --levels {' '.join(str(v) for v in args.levels)}"
        f"{' --no-lookahead' if not args.lookahead else ''}{_noise_flags(args)}`. "
        "HexapodIrregularTerrain-v0, "
        f"`task_distribution=test`, seeds 0-{args.episodes - 1} (the beds of "
        "`configs/evaluate_gains_blocks.yaml`), gains mode with `gait_ground_search=always`. "
        "Rates: medians over all gait cycles of all episodes of the per-cycle RMS; contact: "
        "torso-contact steps summed over the episodes. **beats paper**: both rates lower and no "
        "more contact steps. The look-ahead (experiments/gains_lookahead) copies the env at each "
        "cycle start, plays every grid setting and the paper's for one cycle and applies the "
        "one of lowest pitch-rate RMS + roll-rate RMS [rad/s] + 1 per torso-contact step; it "
        "sees the terrain the cycle meets and the cycle's outcome, so it shows what a greedy "
        "per-cycle choice of gains can reach, not what a policy without that knowledge can."
        + _noise_sentence(args)
        + (
            " **kept**: the share of the exact look-ahead's lead over the paper's gains in the "
            "pitch / roll-rate median that the row keeps."
            if kept
            else ""
        ),
        "",
        "| gains (k_z, k_α, k_β) | pitch rate [rad/s] | roll rate [rad/s] | contact steps "
        f"| successes | cycles | beats paper |{' kept |' if kept else ''}",
        f"|---|---|---|---|---|---|---|{'---|' if kept else ''}",
    ]
    for label, r in rows.items():
        mark = "" if r is reference else ("yes" if beats(r, reference) else "no")
        line = (
            f"| {label} | {r['pitch_rate_median']:.5f} | {r['roll_rate_median']:.5f} | "
            f"{r['contact_steps']} | {r['successes']}/{r['episodes']} | {r['cycles']} | {mark} |"
        )
        if kept:
            shares = [
                _share(reference[key] - r[key], reference[key] - exact[key])
                for key in ("pitch_rate_median", "roll_rate_median")
            ]
            line += "  |" if r is reference else f" {shares[0]} / {shares[1]} |"
        lines.append(line)
    return "\n".join(lines) + "\n"


def _row_cost(choose) -> int:
    """Cycles played per episode cycle, roughly: the sort key of the rows' scheduling."""
    if not isinstance(choose, Lookahead):
        return 1
    return len(choose.candidates) * (choose.samples if choose.noisy else 1)


def _noisy(args: argparse.Namespace) -> bool:
    """Whether the run has look-aheads from noisy copies (a foresight run)."""
    return bool(args.state_noise or args.position_noise)


def _share(part: float, whole: float) -> str:
    return f"{part / whole:.0%}" if whole != 0.0 else "-"


def _noise_sentence(args: argparse.Namespace) -> str:
    if not _noisy(args):
        return ""
    return (
        " The rows 'from copies with ... error σ' choose the same way from "
        f"{args.samples} copies per candidate whose joint and body velocities (qvel, velocity "
        "error) or horizontal position (the root's x and y, position error) carry an error "
        "drawn from N(0, σ²), the same errors for every candidate, by the mean cost; the "
        "episode itself goes on from the exact state. What such a row keeps of the exact "
        "look-ahead's advantage is foresight that a state known to σ supports. A position "
        "error moves the stance feet with the robot, so a copy can start with a foot pressed "
        "into a block's face or off its edge: those rows say how much a cycle hangs on where "
        "the feet stand relative to the blocks, not on a terrain-map error alone."
    )


def _noise_flags(args: argparse.Namespace) -> str:
    flags = "" if args.grid else " --no-grid"
    for name, values in (("state", args.state_noise), ("position", args.position_noise)):
        if values:
            flags += f" --{name}-noise " + " ".join(f"{v:g}" for v in values)
    if _noisy(args):
        flags += f" --samples {args.samples}"
    return flags


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--terrain", choices=sorted(PAPER_GAINS), default="blocks")
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--levels", type=float, nargs="+", default=[0.2, 0.5, 0.8])
    parser.add_argument("--no-lookahead", dest="lookahead", action="store_false")
    parser.add_argument("--no-grid", dest="grid", action="store_false")
    parser.add_argument("--state-noise", type=float, nargs="+", default=[], metavar="SIGMA")
    parser.add_argument("--position-noise", type=float, nargs="+", default=[], metavar="SIGMA")
    parser.add_argument("--samples", type=int, default=1, help="noisy copies per candidate")
    parser.add_argument("--workers", type=int, default=1, help="processes (one core each)")
    parser.add_argument("--out-dir", type=Path, default=Path("reports"))
    args = parser.parse_args(argv)
    rows = measure(
        args.terrain,
        args.episodes,
        args.levels,
        args.lookahead,
        workers=args.workers,
        with_grid=args.grid,
        state_noise=tuple(args.state_noise),
        samples=args.samples,
        position_noise=tuple(args.position_noise),
    )
    args.out_dir.mkdir(parents=True, exist_ok=True)
    kind = "foresight" if _noisy(args) else "ceiling"
    stem = args.out_dir / f"gains_{kind}_{args.terrain}"
    stem.with_suffix(".md").write_text(report(rows, args.terrain, args))
    stem.with_suffix(".json").write_text(json.dumps(rows, indent=1) + "\n")
    print(f"wrote {stem}.md and .json")


if __name__ == "__main__":
    main()
