"""Command-line front ends: ``hexapod-train`` / ``train.py`` and ``hexapod-evaluate`` /
``evaluate.py`` (argument parsing and error reporting). The console scripts (installed with the
package, see pyproject.toml) and the two scripts at the repository root run the same functions.

User errors (`UserError`: bad config keys, unknown env ids, missing models, existing output
directories) are printed on stderr as one ``<prog>: error: ...`` line and exit with code 2;
Ctrl-C during training saves a checkpoint and exits with 130.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import shutil
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from ..run_files.errors import UserError
from ..run_files.shipped import resolve_shipped, shipped_path

DEFAULT_SUITE = shipped_path("configs", "evaluate_default.yaml")
"""The suite of ``hexapod-evaluate`` without --config (the shipped copy, see
`agents.run_files.shipped`)."""

SCRIPTS = {"train.py": "python train.py", "evaluate.py": "python evaluate.py"}
"""How the usage examples call a prog: the root scripts with python, console scripts as is."""


def _invocation(prog: str) -> str:
    return SCRIPTS.get(prog, prog)


def _add_set_option(p: argparse.ArgumentParser, what: str) -> None:
    """``--set KEY=VALUE`` (repeatable), collected in ``args.overrides``."""
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help=f"override a {what} key (dotted path, value read as YAML); repeatable",
    )


def _add_trust_pickle_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--trust-pickle",
        action="store_true",
        help="load pickled model files (vecnormalize.pkl, unknown pickled entries in model.zip) "
        "of older runs; a pickle can run code when loaded: only for files you trust",
    )


def _run(prog: str, body: Callable[[], int]) -> int:
    try:
        return body()
    except UserError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 2


# --- train.py / hexapod-train --------------------------------------------------------------
def train_parser(prog: str = "train.py") -> argparse.ArgumentParser:
    run = _invocation(prog)
    p = argparse.ArgumentParser(
        prog=prog,
        description="Train PPO (stable-baselines3) on an env from a YAML config. A relative "
        "configs/... path that is not in the working directory is read from the shipped configs.",
        epilog="examples:\n"
        f"  {run} --config configs/cliff_walk_ppo.yaml\n"
        f"  {run} --config configs/cliff_walk_ppo.yaml --set ppo.learning_rate=1e-4 "
        "--set vec_env.n_envs=2\n"
        f"  {run} --resume runs/HexapodCliffWalk-v0__ppo__0__20250101-120000 "
        "--set train.total_timesteps=2000000\n"
        f"  {run} --sweep configs/sweep_irregular_terrain_seeds.yaml "
        "[--address auto] [--max-concurrent 2]",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--config", type=Path, help="training config (YAML)")
    source.add_argument(
        "--resume",
        type=Path,
        metavar="RUN_DIR",
        help="continue a run (or a sweep directory) from its last checkpoint",
    )
    source.add_argument(
        "--sweep", type=Path, metavar="SWEEP", help="run a sweep/study on Ray Tune (YAML)"
    )
    _add_set_option(p, "config (with --sweep: sweep file)")
    sweep = p.add_argument_group("sweeps (--sweep, --resume <sweep dir>; pip install .[sweep])")
    sweep.add_argument(
        "--address", metavar="auto|HOST:PORT", help="join this Ray cluster (default: local Ray)"
    )
    sweep.add_argument(
        "--max-concurrent", type=int, metavar="N", help="trials at once (default: CPU cores)"
    )
    p.add_argument("--output-dir", type=Path, default=Path("runs"), help="parent of run dirs")
    p.add_argument("--run-name", help="run directory name (default {env}__ppo__{seed}__{time})")
    p.add_argument("--force", action="store_true", help="overwrite an existing run directory")
    _add_trust_pickle_option(p)
    return p


def train_main(argv: Sequence[str] | None = None, prog: str = "train.py") -> int:
    args = train_parser(prog).parse_args(argv)
    command = _command(prog, argv)

    def body() -> int:
        from ..run_files.train_config import load_train_config
        from .training import resume_training, start_training

        if args.sweep is not None:
            args.sweep = resolve_shipped(args.sweep)
        if args.sweep is not None or (args.resume is not None and _is_sweep_dir(args.resume)):
            from .sweep import sweep_main

            return sweep_main(args, command)
        if args.address is not None or args.max_concurrent is not None:
            raise UserError("--address and --max-concurrent apply to sweeps only")
        if args.resume is not None:
            if args.run_name or args.force:
                raise UserError("--run-name and --force do not apply to --resume")
            result = resume_training(
                args.resume, args.overrides, command=command, trust_pickle=args.trust_pickle
            )
        else:
            config = load_train_config(resolve_shipped(args.config), args.overrides)
            result = start_training(
                config, args.output_dir, args.run_name, force=args.force, command=command
            )
        rate = result.steps_per_second
        if result.interrupted:
            print(
                f"interrupted at {result.num_timesteps} steps; checkpoint saved to "
                f"{result.saved_to}\nresume with: {_invocation(prog)} --resume {result.run_dir}",
                file=sys.stderr,
            )
            return 130
        print(
            f"trained {result.steps_this_call} steps in {result.seconds:.1f} s "
            f"({rate:.0f} steps/s), {result.num_timesteps} in total\n"
            f"run directory: {result.run_dir}\nfinal model: {result.saved_to}"
        )
        return 0

    return _run(prog, body)


def hexapod_train() -> int:
    """The ``hexapod-train`` console script."""
    return train_main(prog="hexapod-train")


def _is_sweep_dir(path: Path) -> bool:
    from .sweep_config import SWEEP_FILE

    return (Path(path) / SWEEP_FILE).is_file()


def _command(script: str, argv: Sequence[str] | None) -> str:
    from ..run_files.artifacts import command_line

    return command_line(sys.argv if argv is None else [script, *argv])


# --- evaluate.py / hexapod-evaluate --------------------------------------------------------
def evaluate_parser(prog: str = "evaluate.py") -> argparse.ArgumentParser:
    run = _invocation(prog)
    p = argparse.ArgumentParser(
        prog=prog,
        description="Run policies (analytical, ppo:<path>, zero, random) on envs over fixed seeds "
        "and write metrics.json, report.md and report.html. Without arguments runs "
        "configs/evaluate_default.yaml into reports/default (replacing a previous default "
        "report; any other existing report directory needs --force). Relative configs/... and "
        "models/... paths that are not in the working directory are read from the shipped "
        "configs and models.",
        epilog="examples:\n"
        f"  {run}\n"
        f"  {run} --envs HexapodCliffWalk-v0 --policies analytical zero "
        "ppo:runs/HexapodCliffWalk-v0__ppo__0__20250101-120000 --episodes 3 "
        "--output-dir reports/mine\n"
        f"  {run} --config configs/evaluate_default.yaml --set episodes=10 "
        "--output-dir reports/ten --force",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--config", type=Path, help="evaluation suite (YAML)")
    p.add_argument("--envs", nargs="+", metavar="ENV_ID", help="env ids (replaces the suite's)")
    p.add_argument(
        "--policies",
        nargs="+",
        metavar="POLICY",
        help="analytical | ppo:<model file, model dir, run dir or sweep dir> | zero | random "
        "(a sweep dir is a multi-seed study: every trial, aggregated with CIs)",
    )
    p.add_argument("--episodes", type=int, help="episodes per policy and env")
    p.add_argument("--seed", type=int, help="seed of the first episode (episode k: seed + k)")
    p.add_argument("--max-episode-steps", type=int, help="override every env's time limit")
    p.add_argument("--output-dir", type=Path, help="report directory")
    p.add_argument("--frames", action="store_true", help="add a frame strip per policy (EGL)")
    p.add_argument(
        "--video",
        action="store_true",
        help="write an MP4 per policy and env (first seed, tracking camera) into videos/",
    )
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    _add_trust_pickle_option(p)
    _add_set_option(p, "suite")
    p.add_argument("--force", action="store_true", help="overwrite an existing report directory")
    return p


def evaluate_main(argv: Sequence[str] | None = None, prog: str = "evaluate.py") -> int:
    args = evaluate_parser(prog).parse_args(argv)
    if args.config is not None:
        args.config = resolve_shipped(args.config)

    def body() -> int:
        from .eval_config import DEFAULT_TITLE, load_suite
        from .evaluation import run_suite
        from .report import write_report

        # Models named on the command line must exist (the suite may say skip for shipped ones).
        overrides = ["missing_models=error"] if args.policies else []
        overrides += args.overrides
        if args.envs:
            entries, unlisted = _suite_envs(args.config, args.envs)
            overrides.append(f"envs={json.dumps(entries)}")
            titled = any(o.startswith("title=") for o in args.overrides)
            if args.config is None and unlisted and not titled:
                # an env the default suite does not list: its title ("benchmark v1") may not hold
                overrides.append(f"title={json.dumps(DEFAULT_TITLE)}")
        for key, value in (
            ("policies", args.policies),
            ("episodes", args.episodes),
            ("seed", args.seed),
            ("max_episode_steps", args.max_episode_steps),
            ("output_dir", None if args.output_dir is None else str(args.output_dir)),
        ):
            if value is not None:
                overrides.append(f"{key}={json.dumps(value)}")  # JSON is YAML
        if args.frames:
            overrides.append("frames=true")
        if args.trust_pickle:
            overrides.append("trust_pickle=true")
        if args.video:
            overrides.append("frames=true")  # the strip comes from the same rendered episode
        suite = load_suite(args.config or DEFAULT_SUITE, overrides)
        from .study import expand_studies, write_study_section

        suite, studies, study_warnings = expand_studies(suite)  # ppo:<sweep dir> -> trials
        shown = Path(suite.output_dir)
        out = shown.resolve()  # a symbolic link: the directory it points to
        _check_report_dir(shown, args.force or _is_default_report(suite))  # before the run
        with _partial_dir(out) as partial:  # an earlier report stays until the new one is done
            video_dir = partial / "videos" if args.video else None
            result = run_suite(suite, progress=not args.no_progress, video_dir=video_dir)
            result.warnings[:0] = study_warnings
            paths = write_report(result, partial)
            paths += write_study_section(result, studies, partial)  # none without sweep dirs
            shutil.rmtree(out, ignore_errors=True)  # an earlier report, checked above
            partial.rename(out)
        for line in result.warnings:
            print(f"warning: {line}", file=sys.stderr)
        for line in result.notes:
            print(f"note: {line}", file=sys.stderr)
        print("wrote " + ", ".join(str(shown / p.relative_to(partial)) for p in paths))
        return 0

    return _run(prog, body)


def hexapod_evaluate() -> int:
    """The ``hexapod-evaluate`` console script."""
    default_headless_gl()
    return evaluate_main(prog="hexapod-evaluate")


def default_headless_gl() -> None:
    """Render without a display (``--frames``, ``--video``): ``MUJOCO_GL=egl`` unless the
    variable is set already or the machine has no libEGL. Call it before MuJoCo is imported.
    Without libEGL MuJoCo cannot even be imported with ``MUJOCO_GL=egl`` (its renderer loads
    at import), so the evaluation runs there without rendering, and a frame strip or video
    says what to set (`hexapod_envs` render errors)."""
    import ctypes.util
    import os

    if "MUJOCO_GL" not in os.environ and ctypes.util.find_library("EGL"):
        os.environ["MUJOCO_GL"] = "egl"


def _suite_envs(config: Path | None, ids: list[str]) -> tuple[list[dict], list[str]]:
    """`--envs` entries with the suite's kwargs and time limit for ids the suite names (so the
    shipped agents are evaluated in the env they were trained in); other ids bare, and those
    ids (they run with the env's registered defaults: a -v0 id the paper's scenario)."""
    from ..run_files.configtools import load_yaml

    listed = load_yaml(config or DEFAULT_SUITE).get("envs") or []
    known = {}
    for item in listed:
        entry = {"id": item} if isinstance(item, str) else dict(item)
        known[entry.get("id")] = entry
    unlisted = [env_id for env_id in ids if env_id not in known]
    return [known.get(env_id, {"id": env_id}) for env_id in ids], unlisted


def _is_default_report(suite) -> bool:
    """The suite writes to the default suite's report directory (``reports/default``, a scratch
    output that git ignores) and what is there is a previous report (its metrics.json): running
    the default evaluation again replaces it without --force."""
    from ..run_files.configtools import load_yaml

    default = load_yaml(DEFAULT_SUITE).get("output_dir")
    out = Path(suite.output_dir)
    return default is not None and out == Path(default) and (out / "metrics.json").is_file()


def _check_report_dir(path: Path, force: bool) -> None:
    """UserError unless `path` may take a new report: not the working directory or one above
    it (the report replaces the whole directory), and empty or missing, or with `force` an
    earlier report (`prepare_new_dir`'s rule; nothing is changed here)."""
    from ..run_files.artifacts import prepare_new_dir

    cwd, out = Path.cwd().resolve(), path.resolve()
    if out == cwd or out in cwd.parents:
        raise UserError(
            f"the report directory {path} is the working directory or above it, which a new "
            "report would replace; choose a new directory (e.g. --output-dir reports/mine)"
        )
    prepare_new_dir(path, force, "report directory", ("metrics.json",), check_only=True)


@contextlib.contextmanager
def _partial_dir(out: Path):
    """A new directory beside `out` that the report is written to, removed if the run fails or
    is interrupted (a finished report is renamed to `out` inside the block)."""
    partial = out.parent / f".{out.name}.partial"
    shutil.rmtree(partial, ignore_errors=True)  # left by a killed run
    partial.mkdir(parents=True)
    try:
        yield partial
    finally:
        shutil.rmtree(partial, ignore_errors=True)
