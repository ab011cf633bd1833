"""Teach a gains policy with the one-cycle look-ahead (`experiments.gains_lookahead.distill`).

Collect once (the expensive step), then fit:

    collect   the look-ahead walks training beds of the config's env (its task distribution,
              seeds --first-seed ...); writes the demonstrations (.npz)
    fit       fits the actor of the config's PPO model to them; writes a model directory that
              evaluate.py's ppo:<dir> runs
    curve     the held-out cost of fits to growing subsets of the training beds
    choose    is the look-ahead's per-cycle choice predictable from the observation? A
              diagnostic student (`fit_choice`) starts from the best fixed setting and departs
              from it where it predicts a cheaper candidate; its choices' cost on the last beds,
              trained on growing subsets of the others, optionally without some observation
              pieces (--drop)

Findings (measured on the blocks, dated): README.md beside this script.

Run (CONFIG: configs/irregular_terrain_gains_blocks_scan.yaml):
    python experiments/gains_lookahead/distill_gains.py collect \
        --config CONFIG --episodes 56 --workers 2 \
        --out runs/distill/demos.npz
    python experiments/gains_lookahead/distill_gains.py fit \
        --config CONFIG --demos runs/distill/demos.npz \
        --out runs/distill/model
"""

from __future__ import annotations

import argparse
import multiprocessing
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
import numpy as np  # noqa: E402

from agents.pipeline.training import env_spec  # noqa: E402
from agents.run_files.artifacts import command_line, save_model_dir  # noqa: E402
from agents.run_files.train_config import load_train_config  # noqa: E402
from experiments.gains_lookahead.distill import (  # noqa: E402
    Demonstrations,
    demonstrate,
    distill,
    fit_choice,
    ground_deviation_features,
    held_out_rows,
)
from experiments.gains_lookahead.lookahead import CycleCost  # noqa: E402


def collect(args: argparse.Namespace) -> None:
    spec = env_spec(load_train_config(args.config, args.set))
    seeds = range(args.first_seed, args.first_seed + args.episodes)
    start = time.perf_counter()
    parts = []
    n = len(seeds)
    with ProcessPoolExecutor(args.workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        jobs = pool.map(demonstrate, [spec] * n, seeds, [args.levels] * n, [_cost(args)] * n)
        for part in jobs:
            parts.append(part)
            steps = sum(p.env_steps for p in parts)
            print(
                f"bed {part.beds[0]}: {len(part.beds)} cycles; total {steps} env steps, "
                f"{time.perf_counter() - start:.0f} s",
                flush=True,
            )
    demos = Demonstrations.concatenate(parts)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    demos.save(args.out)
    print(f"wrote {args.out}: {len(demos.beds)} cycles, {demos.env_steps} env steps")


def fit(args: argparse.Namespace) -> None:
    config = load_train_config(args.config, args.set)
    demos = Demonstrations.load(args.demos)
    validation = held_out_rows(demos, args.validation_fraction)
    model, vec_normalize, result, settings = distill(
        config, demos, validation, **_fit_settings(args)
    )
    for epoch, train_cost, val_cost in result.history[:: max(1, args.epochs // 20)]:
        print(
            f"epoch {epoch:4d}: mean cycle cost: training {train_cost:.5f}, held out {val_cost:.5f}"
        )
    summary = {
        "best_epoch": result.best_epoch,
        "held_out_cost": round(result.best_cost, 6),
        "reference_cost": round(result.reference_cost, 6),
        "best_constant_cost": round(result.best_constant_cost, 6),
        "teacher_cost": round(result.teacher_cost, 6),
    }
    print(f"held-out beds {np.unique(demos.beds[validation]).tolist()}: {summary}")
    save_model_dir(
        args.out,
        model,
        vec_normalize,
        config,
        command_line(),
        kind="distilled",
        extra_meta={
            "demonstrations": str(args.demos),
            "demonstration_cycles": len(demos.beds),
            "env_steps": demos.env_steps,
            **summary,
        },
        env_settings=settings,
    )
    print(f"wrote {args.out}")


def curve(args: argparse.Namespace) -> None:
    """Held-out cost against the number of training beds: does more data help?"""
    demos = Demonstrations.load(args.demos)
    validation = held_out_rows(demos, args.validation_fraction)
    pool = np.unique(demos.beds[~validation])
    for fraction in args.fractions:
        costs = []
        for seed in range(args.seeds):
            config = load_train_config(args.config, [*args.set, f"train.seed={seed}"])
            chosen = np.random.default_rng(seed).choice(
                pool, max(1, round(fraction * len(pool))), replace=False
            )
            rows = validation | np.isin(demos.beds, chosen)
            subset = demos.subset(rows)
            _, _, result, _ = distill(config, subset, validation[rows], **_fit_settings(args))
            costs.append(result.best_cost)
        print(
            f"{len(chosen)} training beds: held-out cost {np.mean(costs):.5f} "
            f"± {np.std(costs):.5f} over {args.seeds} seeds (reference "
            f"{result.reference_cost:.5f}, best constant {result.best_constant_cost:.5f}, "
            f"teacher {result.teacher_cost:.5f})",
            flush=True,
        )


def choose(args: argparse.Namespace) -> None:
    """Is the teacher's per-cycle choice predictable from the observation (`fit_choice`)? Test
    rows: the last --test-beds beds; students trained on growing random subsets of the others
    (a fifth of each subset's beds for early stopping), without the --drop pieces."""
    demos = Demonstrations.load(args.demos)
    with env_spec(load_train_config(args.config, args.set)).make() as env:
        structure = env.unwrapped.observation_structure
        controller = env.unwrapped.controller
        (width,) = env.observation_space.shape
    if demos.observations.shape[1] != width:
        raise ValueError(
            f"{args.demos} has {demos.observations.shape[1]}-wide observations, the config's env "
            f"{width}: pass the --set options it was collected with"
        )
    unknown = sorted(set(args.drop) - set(structure))
    if unknown:
        raise ValueError(f"--drop {unknown}: not observation pieces; valid: {sorted(structure)}")
    keep = np.ones(width, dtype=bool)
    for name in args.drop:
        keep[structure[name]] = False
    observations = demos.observations[:, keep]
    if args.with_deviation:
        deviation = ground_deviation_features(demos.observations, structure, controller)
        observations = np.hstack([observations, deviation])
    beds = np.unique(demos.beds)
    if not 0 < args.test_beds <= len(beds) - 2:
        raise ValueError(
            f"--test-beds {args.test_beds}: {args.demos} has {len(beds)} beds, and at least two "
            "must remain for training and validation"
        )
    if min(args.beds) < 2:
        raise ValueError(f"--beds {args.beds}: each needs at least 2 (training and validation)")
    test = np.isin(demos.beds, beds[-args.test_beds :])
    pool = beds[: -args.test_beds]
    for n in args.beds:
        results = []
        for seed in range(args.seeds):
            chosen = np.random.default_rng(seed).choice(pool, min(n, len(pool)), replace=False)
            validation = np.isin(demos.beds, chosen[: max(1, len(chosen) // 5)])
            train = np.isin(demos.beds, chosen) & ~validation
            results.append(
                fit_choice(
                    observations,
                    demos,
                    train,
                    validation,
                    test,
                    _cost(args),
                    epochs=args.epochs,
                    seed=seed,
                )
            )
        costs = [r.cost for r in results]
        first = results[0]
        print(
            f"{len(chosen)} beds (a fifth for early stopping): test cost {np.mean(costs):.5f} ± "
            f"{np.std(costs):.5f} over {args.seeds} seeds (margins "
            f"{', '.join(f'{r.margin:g}' for r in results)}; off its default on "
            f"{np.mean([r.departed for r in results]):.0%} of the cycles); best fixed setting "
            f"{np.mean([r.best_constant_cost for r in results]):.5f}, reference "
            f"{first.reference_cost:.5f}, oracle {first.oracle_cost:.5f}; {test.sum()} test cycles",
            flush=True,
        )


def _cost(args: argparse.Namespace) -> CycleCost:
    return CycleCost(args.contact_cost, args.clearance_cost, args.clearance_margin)


def _fit_settings(args: argparse.Namespace) -> dict:
    return {
        "cost": _cost(args),
        "epochs": args.epochs,
        "learning_rate": args.learning_rate,
    }


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    c = commands.add_parser("collect", help="the look-ahead's demonstrations on training beds")
    f = commands.add_parser("fit", help="fit the config's actor to demonstrations")
    r = commands.add_parser("curve", help="held-out cost against the number of training beds")
    h = commands.add_parser("choose", help="is the teacher's choice predictable? (fit_choice)")
    for p in (c, f, r, h):
        p.add_argument("--config", type=Path, required=True, help="training config (gains mode)")
        p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
        # the cycle cost (lookahead.CycleCost) the teacher or the student minimises
        p.add_argument("--contact-cost", type=float, default=1.0, help="rad/s per contact step")
        p.add_argument("--clearance-cost", type=float, default=0.0, help="rad/s per m short")
        p.add_argument("--clearance-margin", type=float, default=0.0, help="footprint clearance, m")
    c.add_argument("--episodes", type=int, default=56)
    c.add_argument("--first-seed", type=int, default=0)
    c.add_argument("--levels", type=float, nargs="+", default=[0.2, 0.5, 0.8])
    c.add_argument("--workers", type=int, default=1, help="processes (one core each)")
    c.add_argument("--out", type=Path, required=True)
    for p in (f, r):
        p.add_argument("--demos", type=Path, required=True)
        p.add_argument("--epochs", type=int, default=300)
        p.add_argument("--learning-rate", type=float, default=1e-3)
        p.add_argument(
            "--validation-fraction", type=float, default=0.2, help="held-out beds (early stopping)"
        )
    f.add_argument("--out", type=Path, required=True, help="model directory to write")
    r.add_argument("--fractions", type=float, nargs="+", default=[0.25, 0.5, 1.0])
    r.add_argument("--seeds", type=int, default=3)
    h.add_argument("--demos", type=Path, required=True)
    h.add_argument("--test-beds", type=int, default=22, help="the last beds, held out for testing")
    h.add_argument("--beds", type=int, nargs="+", default=[22, 45, 90], help="training beds")
    h.add_argument("--seeds", type=int, default=3)
    h.add_argument("--epochs", type=int, default=150)
    h.add_argument("--drop", nargs="+", default=[], metavar="PIECE", help="observation pieces")
    h.add_argument(
        "--with-deviation",
        action="store_true",
        help="add the posture controller's ground-plane estimate (ground_deviation_features)",
    )
    args = parser.parse_args(argv)
    {"collect": collect, "fit": fit, "curve": curve, "choose": choose}[args.command](args)


if __name__ == "__main__":
    main()
