"""Export a trained PPO actor for a robot: an ONNX file and a model card beside it.

``hexapod-export <run or model dir> [--output FILE]`` writes

- ``FILE`` (default ``<env id>__<model dir name>.onnx`` in the working directory): one graph
  from a raw env observation to the deterministic action of the learned actor,
  ``observation (float64, [batch, n_obs]) -> action (float32, [batch, n_act])``. The graph holds,
  in this order: the VecNormalize observation statistics of the model directory,
  ``clip((obs - mean) / sqrt(var + eps), -clip_obs, clip_obs)`` computed in float64 as
  `agents.run_files.model_files.NormalizationStats.normalize_obs` does, then the SB3
  ``MlpPolicy`` actor (features extractor -> ``mlp_extractor.policy_net`` -> ``action_net``:
  the mean of the Gaussian, i.e. the deterministic action) and the clip to the action space that
  SB3's ``predict`` applies. Its output equals `agents.ppo.PPOPolicy`'s action on the same
  observation (a test checks it with onnxruntime).
- ``<stem>_card.json`` and ``<stem>_card.md``: the model card (env id and version, the
  observation layout by name and index range, the action mode and space, the training budget,
  what the graph holds, and the evaluation results found in the model directory: EvalCallback's
  ``evaluations.npz``; with ``--report`` the success rate and normalised benchmark score of this
  model in a ``hexapod-evaluate`` report).

A hybrid model (its config has a ``hybrid`` section: the learned action combined with the env's
analytical controller), a knobs model (a ``knobs`` section: the learned action sets the tipping
recovery's settings at its judgment, or the ditch planner's from the course) and the irregular
terrain's gains models (the learned action is the posture gains, applied once per gait cycle)
are exported as their learned actor only; the card says what the robot must add around it. The
export needs the ``[export]`` extra (``onnx``; ``onnxruntime`` to check the file).
"""

from __future__ import annotations

import argparse
import json
import os
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from .knobs import KNOB_RANGES, PLANNER_KNOB_RANGES, settings_from_config
from .pipeline.callbacks import evaluation_score
from .pipeline.cli import _add_trust_pickle_option, _run
from .pipeline.learning_curve import evaluation_log, read_evaluation_log
from .plan_knobs import COURSE_FEATURES, course_space
from .policy import LearnedWithController
from .run_files.artifacts import ModelFiles, find_model, learner_step_unit, read_meta
from .run_files.errors import UserError
from .run_files.model_files import NormalizationStats, atomic_path, atomic_write_text

OPSET = 17
INPUT, OUTPUT = "observation", "action"


@dataclass
class Exported:
    """What `export_model` wrote."""

    onnx: Path
    card_json: Path
    card_md: Path
    card: dict[str, Any]


def card_paths(onnx_path: Path) -> tuple[Path, Path]:
    """The model card files beside an ONNX file: ``<stem>_card.json`` and ``<stem>_card.md``."""
    onnx_path = Path(onnx_path)
    return (
        onnx_path.with_name(f"{onnx_path.stem}_card.json"),
        onnx_path.with_name(f"{onnx_path.stem}_card.md"),
    )


def default_output(files: ModelFiles, env_id: str) -> Path:
    return Path(f"{env_id}__{files.directory.name}.onnx")


# --- the graph -----------------------------------------------------------------------------
def actor_module(model: Any, stats: NormalizationStats | None) -> Any:
    """A torch module: raw observation (float64) -> the deterministic action of `model`'s actor
    (float32), with `stats`' normalisation in front and the action-space clip behind. The actor
    of an asymmetric actor-critic (`agents.privileged_critic`) takes the sensor observation: the
    privileged values its actor ignores are set to 0 inside the graph."""
    import torch

    from .privileged_critic import PRIVILEGED_DIM
    from .privileged_critic_policy import SensorOnly

    policy = model.policy
    if not isinstance(model.action_space, gym.spaces.Box):
        raise UserError(
            f"cannot export a model of a {type(model.action_space).__name__} action space (e.g. "
            "env.stride_choices): only a Gaussian (Box) action is supported"
        )
    if getattr(policy, "squash_output", False) or not hasattr(policy, "action_net"):
        raise UserError(
            f"cannot export {type(policy).__name__}: only SB3's MlpPolicy with a Gaussian "
            "action (no squashing) is supported"
        )
    space = model.action_space

    class Actor(torch.nn.Module):
        def __init__(self):
            super().__init__()
            self.features = policy.pi_features_extractor
            self.policy_net = policy.mlp_extractor.policy_net
            self.action_net = policy.action_net
            self.normalize = stats is not None and stats.norm_obs
            if self.normalize:
                mean, std = stats.obs_mean, np.sqrt(stats.obs_var + stats.epsilon)
                self.register_buffer("mean", torch.as_tensor(mean, dtype=torch.float64))
                self.register_buffer("std", torch.as_tensor(std, dtype=torch.float64))
                self.clip = float(stats.clip_obs)
            self.register_buffer("low", torch.as_tensor(space.low, dtype=torch.float32))
            self.register_buffer("high", torch.as_tensor(space.high, dtype=torch.float32))
            self.padding = PRIVILEGED_DIM if isinstance(self.features, SensorOnly) else 0

        def forward(self, observation):
            x = observation
            if self.padding:
                zeros = torch.zeros_like(x[:, :1]).expand(-1, self.padding)
                x = torch.cat([x, zeros], dim=1)
            if self.normalize:
                x = torch.clamp((x - self.mean) / self.std, -self.clip, self.clip)
            x = x.to(torch.float32)
            action = self.action_net(self.policy_net(self.features(x)))
            return torch.minimum(torch.maximum(action, self.low), self.high)

    return Actor().eval().cpu()


def write_onnx(module: Any, n_obs: int, path: Path) -> None:
    """`module` as an ONNX file (torch's TorchScript-based exporter, a dynamic batch axis)."""
    import torch

    try:
        import onnx  # noqa: F401  (torch.onnx.export needs it)
    except ImportError:
        raise UserError("exporting needs onnx: pip install 'hexapod_envs[export]'") from None
    example = torch.zeros((1, n_obs), dtype=torch.float64)
    with atomic_path(path) as tmp, warnings.catch_warnings(), torch.no_grad():
        # The TorchScript exporter is deprecated in favour of the torch.export one, which needs
        # onnxscript; it still exports this plain MLP exactly.
        warnings.simplefilter("ignore", DeprecationWarning)
        torch.onnx.export(
            module,
            (example,),
            str(tmp),
            dynamo=False,
            input_names=[INPUT],
            output_names=[OUTPUT],
            dynamic_axes={INPUT: {0: "batch"}, OUTPUT: {0: "batch"}},
            opset_version=OPSET,
        )


# --- the model card ------------------------------------------------------------------------
def _learned_part(config: dict[str, Any]) -> str:
    env = config.get("env") or {}
    kwargs = env.get("kwargs") or {}
    notes = []
    if config.get("hybrid") is not None:
        hybrid = config["hybrid"]
        notes.append(
            "hybrid model: the file holds the learned actor only, whose action lies in [-1, 1]; "
            f"the env action is combined with the env's analytical controller (mode "
            f"{hybrid.get('mode')!r}, scale {hybrid.get('scale')}, safety_filter "
            f"{hybrid.get('safety_filter')}; agents.hybrid), which the robot must run beside it"
        )
    knobs = config.get("knobs")
    if _planner_knobs(config):
        names = settings_from_config(knobs).names
        spans = ", ".join(
            f"{n} {PLANNER_KNOB_RANGES[n][0]}..{PLANNER_KNOB_RANGES[n][1]} m" for n in names
        )
        seen = (
            "three zeros (knobs.course: false, one setting for every ditch)"
            if _course_blind(config)
            else "the course (the ditch's distance ahead, width and depth [m])"
        )
        notes.append(
            f"planner knobs model: the input is {seen}, the action {len(names)} values in "
            "[-1, 1] that set the ditch planner's settings (0: the env's own, +-1: the ends of "
            f"the ranges {spans}; "
            "agents.plan_knobs), chosen once per episode; the planner (agents.upu_gait) plans "
            "and walks with them, with its own settings where they give no plan"
        )
    elif knobs is not None:
        names = settings_from_config(knobs).names
        spans = ", ".join(f"{n} {KNOB_RANGES[n][0]}..{KNOB_RANGES[n][1]}" for n in names)
        notes.append(
            f"knobs model: the action is {len(names)} values in [-1, 1] that set the tipping "
            f"recovery's knobs (0: the controller's own settings, +-1: the ends of the ranges "
            f"{spans}; agents.knobs), chosen once per episode at the controller's tipping "
            "judgment; the recovery controller (agents.tipping) runs beside it"
        )
    if kwargs.get("action_mode") == "gains":
        notes.append(
            "gains model: the action is the posture gains (k_z, k_a, k_b) in [0, 1] of the env's "
            "analytical gait, which turns them into joint targets"
            + (
                f", and a fourth value in [-1, 1] x {kwargs['gains_height_offset_m']} m that "
                "moves the height control's torso-height reference"
                if kwargs.get("gains_height_offset_m")
                else ""
            )
            + {
                "gait_cycle": ", chosen once per gait cycle",
                "episode": ", chosen once per episode at its first observation and held",
            }.get(env.get("decision"), "")
        )
    return "; ".join(notes) if notes else "the complete policy (the env action itself)"


def _publish(path: Path) -> None:
    """Give a file written through a temporary file the usual permissions (umask), not 0600."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(path, 0o666 & ~umask)


def _bounds(values: list[float]) -> str:
    return f"{values[0]:g} (every component)" if len(set(values)) == 1 else str(values)


def _space(space: Any) -> dict[str, Any]:
    return {
        "shape": list(space.shape),
        "dtype": str(space.dtype),
        "low": np.asarray(space.low, dtype=float).tolist(),
        "high": np.asarray(space.high, dtype=float).tolist(),
    }


def training_evaluations(model_dir: Path, select: str = "reward") -> dict[str, Any] | None:
    """The model directory's EvalCallback log (``evaluations.npz``): the number of evaluations,
    the last one and the best one (mean return, success rate), best by the training run's
    ``eval.select`` rule, the one that chose its ``best/`` checkpoint: the mean return
    ("reward"), or the success rate and then the mean return ("success"). A model inside a run
    directory (``best/``, ``final/``, ``checkpoints/step_N/``) reads its run's log
    (`evaluation_log`). The successes are read as logged, as the callback scored them (SB3 logs
    them only for evaluations whose episodes report ``is_success``)."""
    path = evaluation_log(model_dir)
    if path is None:
        return None
    arrays = read_evaluation_log(path, required=("timesteps", "results"))
    steps, results = arrays["timesteps"], np.asarray(arrays["results"], dtype=float)
    successes = arrays.get("successes")
    if len(steps) == 0:
        return None

    def row(i: int) -> dict[str, Any]:
        out = {
            "timesteps": int(steps[i]),
            "episodes": int(results.shape[1]),
            "mean_return": float(np.mean(results[i])),
        }
        if successes is not None and i < len(successes) and np.size(successes[i]):
            out["success_rate"] = float(np.mean(successes[i]))
        return out

    if select == "success":
        logged = successes if successes is not None else []
        best = max(range(len(steps)), key=lambda i: evaluation_score(logged, results, i))
    else:
        best = int(np.argmax(results.mean(axis=1)))
    return {"evaluations": int(len(steps)), "last": row(len(steps) - 1), "best": row(best)}


def report_scores(metrics_path: Path, model_dir: Path) -> list[dict[str, Any]]:
    """This model's results in a ``hexapod-evaluate`` report (a report directory or its
    ``metrics.json``): per env, the success rate and the normalised benchmark score (0 = random
    actions, 100 = the analytical controller; `benchmark_score`) of every ``ppo:`` policy that
    names this model directory."""
    from .pipeline.benchmark_score import ANALYTICAL, RANDOM, env_scale, normalised

    metrics_path = Path(metrics_path)
    if metrics_path.is_dir():
        metrics_path = metrics_path / "metrics.json"
    try:
        metrics = json.loads(metrics_path.read_text())
    except (OSError, ValueError) as exc:
        raise UserError(f"cannot read the report {metrics_path}: {exc}") from None
    target = Path(model_dir).resolve()
    scores = []
    for env_id, env in (metrics.get("envs") or {}).items():
        policies = env.get("policies") or {}
        rates = {
            name: p["aggregate"]["success"]["mean"]
            for name, p in policies.items()
            if "success" in (p.get("aggregate") or {})
        }
        for name, rate in rates.items():
            if not name.startswith("ppo:"):
                continue
            try:
                directory = find_model(name[4:].replace("{env_id}", env_id)).directory
            except UserError:
                continue
            if directory.resolve() != target:
                continue
            scale = env_scale({k: rates[k] for k in (RANDOM, ANALYTICAL) if k in rates})
            scores.append(
                {
                    "report": str(metrics_path),
                    "env_id": env_id,
                    "env_kwargs": env.get("kwargs") or {},
                    "policy": name,
                    "episodes": policies[name]["aggregate"].get("episodes"),
                    "success_rate": rate,
                    "benchmark_score": None if scale is None else normalised(rate, scale),
                }
            )
    return scores


def _planner_knobs(config: dict[str, Any]) -> bool:
    """Whether the run's ``knobs`` section names the ditch planner's settings."""
    knobs = settings_from_config(config.get("knobs"))
    return knobs is not None and knobs.controller == "planner"


def _course_blind(config: dict[str, Any]) -> bool:
    """Whether the run's planner knobs see zeros instead of the course (``knobs.course``)."""
    return not settings_from_config(config.get("knobs")).course


def actor_input_space(config: dict[str, Any], env: Any) -> Any:
    """What the exported actor reads: the env's observation, or for a planner-knobs model the
    course (`COURSE_FEATURES`)."""
    return course_space() if _planner_knobs(config) else env.observation_space


def model_card(
    files: ModelFiles,
    env: Any,
    stats: NormalizationStats | None,
    onnx_name: str,
    output_space: Any,
    report: Path | None = None,
) -> dict[str, Any]:
    """The model card of the export of `files` (see module doc) as a JSON-able dict;
    `output_space`: the exported actor's action space (a hybrid's learned one is [-1, 1])."""
    import hexapod_envs

    config = files.training_config() or {}
    meta = read_meta(files.directory)
    spec = env.spec
    unwrapped = env.unwrapped
    structure = getattr(unwrapped, "observation_structure", None) or {}
    observation_space = actor_input_space(config, env)
    if _planner_knobs(config):
        blind = _course_blind(config)
        structure = {
            f"{name} (zero: knobs.course false)" if blind else name: slice(i, i + 1)
            for i, name in enumerate(COURSE_FEATURES)
        }
    folded = []
    if stats is not None and stats.norm_obs:
        folded.append(
            f"observation normalisation: clip((obs - mean) / sqrt(var + {stats.epsilon:g}), "
            f"-{stats.clip_obs:g}, {stats.clip_obs:g}) with the frozen VecNormalize statistics "
            f"of {files.directory.name}/ ({stats.obs_count:.0f} observations), in float64"
        )
    folded.append("the actor network's mean action (deterministic; no sampling, no critic)")
    folded.append("the clip of the action to the action space (as SB3's predict)")
    train = config.get("train") or {}
    control_dt = getattr(unwrapped, "control_dt", None)
    return {
        "file": onnx_name,
        "format": {"onnx_opset": OPSET, "input": INPUT, "output": OUTPUT},
        "env": {
            "id": spec.id,
            "name": spec.name,
            "version": spec.version,
            "kwargs": (config.get("env") or {}).get("kwargs") or {},
            "package": "hexapod_envs",
            "package_version": hexapod_envs.__version__,
            "control_dt_s": None if control_dt is None else float(control_dt),
        },
        "observation": {
            "shape": list(observation_space.shape),
            "dtype": str(observation_space.dtype),
            "layout": [
                {"name": name, "start": sl.start, "stop": sl.stop}
                for name, sl in sorted(structure.items(), key=lambda item: item[1].start)
            ],
        },
        "action": {
            "mode": getattr(unwrapped, "action_mode", None),
            "env_space": _space(env.action_space),
            "output_space": _space(output_space),
            "exported": _learned_part(config),
        },
        "folded_in": folded,
        "training": {
            "num_timesteps": meta.get("num_timesteps"),
            "unit": learner_step_unit(config),
            "total_timesteps_configured": train.get("total_timesteps"),
            "checkpoint": meta.get("kind"),
            "saved_at": meta.get("saved_at"),
            "seed": train.get("seed"),
            "eval_mean_reward": meta.get("eval_mean_reward"),
        },
        "source": {"model": str(files.model), "config": str(files.config)},
        "training_evaluations": training_evaluations(
            files.directory, (config.get("eval") or {}).get("select", "reward")
        ),
        "benchmark": report_scores(report, files.directory) if report is not None else None,
    }


def card_markdown(card: dict[str, Any]) -> str:
    """The model card as Markdown."""
    env, obs, action, train = card["env"], card["observation"], card["action"], card["training"]
    lines = [
        f"# Model card: {card['file']}",
        "",
        f"- **Env**: `{env['id']}` (version {env['version']}, hexapod_envs "
        f"{env['package_version']}), kwargs `{json.dumps(env['kwargs'])}`; "
        f"control step {env['control_dt_s']} s",
        f"- **Graph**: `{card['format']['input']}` ({obs['dtype']}, [batch, {obs['shape'][0]}]) -> "
        f"`{card['format']['output']}` ({action['output_space']['dtype']}, "
        f"[batch, {action['output_space']['shape'][0]}]), ONNX opset "
        f"{card['format']['onnx_opset']}",
        f"- **Action mode**: `{action['mode']}`; exported: {action['exported']}",
        f"- **Output range**: low {_bounds(action['output_space']['low'])}, high "
        f"{_bounds(action['output_space']['high'])} (the env's action space: low "
        f"{_bounds(action['env_space']['low'])}, high {_bounds(action['env_space']['high'])})",
        f"- **Training budget**: {train['num_timesteps']} {train.get('unit', 'env steps')} "
        f"({train['checkpoint']} "
        f"checkpoint; {train['total_timesteps_configured']} configured, seed {train['seed']}), "
        f"saved {train['saved_at']}",
        f"- **Source**: `{card['source']['model']}`",
        "",
        "## Folded into the graph",
        "",
        *[f"- {item}" for item in card["folded_in"]],
        "",
        "## Observation layout",
        "",
        "| name | indices |",
        "| --- | --- |",
        *[f"| {p['name']} | [{p['start']}, {p['stop']}) |" for p in obs["layout"]],
        "",
    ]
    evaluations = card.get("training_evaluations")
    if evaluations:
        lines += ["## Evaluations during training (evaluations.npz)", ""]
        for key in ("best", "last"):
            row = evaluations[key]
            success = row.get("success_rate")
            lines.append(
                f"- {key}: at {row['timesteps']} steps, mean return {row['mean_return']:.1f} "
                f"over {row['episodes']} episodes"
                + ("" if success is None else f", success rate {success:.2f}")
            )
        lines.append("")
    if card.get("benchmark") is not None:
        lines += ["## Benchmark", ""]
        if not card["benchmark"]:
            lines.append("This model does not appear in the given report.")
        for row in card["benchmark"]:
            score = row["benchmark_score"]
            lines.append(
                f"- `{row['env_id']}` {json.dumps(row['env_kwargs'])}: success rate "
                f"{row['success_rate']:.2f} over {row['episodes']} episodes, benchmark score "
                + (
                    "n/a (the analytical controller does not beat random actions there)"
                    if score is None
                    else f"{score:.0f}"
                )
                + f" (0 = random actions, 100 = analytical controller; {row['report']})"
            )
        lines.append("")
    return "\n".join(lines)


# --- the export ----------------------------------------------------------------------------
def load_actor(path: str | Path, trust_pickle: bool = False) -> tuple[Any, Any, ModelFiles]:
    """(`agents.ppo.PPOPolicy` of the learned actor, the env it was trained on, its files): the
    env is built from the model's config (its id and kwargs, no wrappers)."""
    from .pipeline.envs import EnvSpec
    from .ppo import PPOPolicy

    files = find_model(path)
    config = files.training_config()
    if config is None or not (config.get("env") or {}).get("id"):
        raise UserError(
            f"cannot export the model at {files.model}: no config.yaml next to it to tell "
            "which env it was trained for"
        )
    section = config["env"]
    if section.get("stride_choices") is not None:
        raise UserError(
            f"cannot export the model at {files.model}: it chooses among stride values "
            "(env.stride_choices, a Discrete action); the ONNX export takes Gaussian (Box) "
            "actions only"
        )
    spec = EnvSpec(
        id=section["id"],
        kwargs=dict(section.get("kwargs") or {}),
        gym_packages=list(section.get("gym_packages") or ["hexapod_envs"]),
    )
    env = spec.make()
    try:
        policy = PPOPolicy.load(files.model, env, trust_pickle=trust_pickle)
    except BaseException:
        env.close()
        raise
    if isinstance(policy, LearnedWithController):  # a hybrid or knobs model: its learned actor
        policy = policy.learned
    return policy, env, files


def export_model(
    path: str | Path,
    output: str | Path | None = None,
    force: bool = False,
    report: str | Path | None = None,
    trust_pickle: bool = False,
) -> Exported:
    """Write the ONNX file and the model card of the model at `path` (a model file, model
    directory or run directory); see the module doc."""
    policy, env, files = load_actor(path, trust_pickle)
    try:
        out = Path(output) if output is not None else default_output(files, env.spec.id)
        if out.suffix != ".onnx":
            raise UserError(f"the output {out} must end in .onnx")
        card_json, card_md = card_paths(out)
        existing = [p for p in (out, card_json, card_md) if p.exists()]
        if existing and not force:
            raise UserError(
                f"{', '.join(map(str, existing))} already exist(s); pass --force to overwrite"
            )
        # The card first: a report that cannot be read stops the export before any file is
        # written.
        card = model_card(files, env, policy.stats, out.name, policy.model.action_space, report)
        out.parent.mkdir(parents=True, exist_ok=True)
        module = actor_module(policy.model, policy.stats)
        write_onnx(module, actor_input_space(files.training_config() or {}, env).shape[0], out)
    finally:
        env.close()
    atomic_write_text(card_json, json.dumps(card, indent=2) + "\n")
    atomic_write_text(card_md, card_markdown(card))
    for written in (out, card_json, card_md):
        _publish(written)
    return Exported(out, card_json, card_md, card)


# --- hexapod-export ------------------------------------------------------------------------
def export_parser(prog: str = "hexapod-export") -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=prog,
        description="Write an ONNX file of a trained PPO model's actor (raw observation -> "
        "deterministic action, observation normalisation folded in) and a model card beside it "
        "(<stem>_card.json, <stem>_card.md). A relative models/... path that is not in the "
        "working directory is a shipped model. Needs: pip install 'hexapod_envs[export]'.",
        epilog="examples:\n"
        f"  {prog} models/HexapodIrregularTerrain-v0/ppo\n"
        f"  {prog} runs/HexapodCliffWalk-v0__ppo__0__20250101-120000 --output cliff.onnx "
        "--report reports/mine",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("model", type=Path, help="model file, model directory or run directory")
    p.add_argument(
        "--output",
        type=Path,
        metavar="FILE",
        help="ONNX file to write (default: <env id>__<model dir name>.onnx here)",
    )
    p.add_argument(
        "--report",
        type=Path,
        metavar="REPORT",
        help="a hexapod-evaluate report (directory or metrics.json) whose results for this "
        "model go into the card (success rate, benchmark score)",
    )
    p.add_argument("--force", action="store_true", help="overwrite existing output files")
    _add_trust_pickle_option(p)
    return p


def export_main(argv: Sequence[str] | None = None, prog: str = "hexapod-export") -> int:
    args = export_parser(prog).parse_args(argv)

    def body() -> int:
        result = export_model(args.model, args.output, args.force, args.report, args.trust_pickle)
        print(f"wrote {result.onnx}, {result.card_json}, {result.card_md}")
        return 0

    return _run(prog, body)


def hexapod_export() -> int:
    """The ``hexapod-export`` console script."""
    return export_main()
