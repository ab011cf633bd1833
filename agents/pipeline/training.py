"""PPO training runs: start a new run from a config, or resume the latest checkpoint of a run.

See `artifacts` for the run directory layout and `callbacks` for what goes to TensorBoard.
"""

from __future__ import annotations

import contextlib
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .artifacts import (
    BEST,
    COMMAND_FILE,
    CONFIG_FILE,
    FINAL,
    VECNORM_FILE,
    command_line,
    latest_model_dir,
    prepare_new_dir,
    read_meta,
    run_name,
)
from .configtools import dump_yaml, load_yaml, parse_override
from .envs import EnvSpec, env_time_step, make_vec_env
from .episode import metric_specs
from .errors import UserError
from .train_config import TrainConfig, load_train_config

EVAL_SEED_OFFSET = 10_000
"""Evaluation envs are seeded apart from the training envs."""

RESUME_FIXED_SECTIONS = ("env", "policy", "normalize", "hybrid")
"""Config sections a resumed run cannot change (the model and its statistics depend on them)."""


@dataclass
class TrainResult:
    run_dir: Path
    num_timesteps: int
    steps_this_call: int
    seconds: float
    interrupted: bool
    saved_to: Path

    @property
    def steps_per_second(self) -> float:
        return self.steps_this_call / self.seconds if self.seconds > 0 else float("nan")


def env_spec(config: TrainConfig) -> EnvSpec:
    env = config.env
    return EnvSpec(
        env.id, dict(env.kwargs), env.max_episode_steps, list(env.gym_packages), config.hybrid
    )


def _probe(spec: EnvSpec) -> tuple[float | None, list]:
    """Make one env in this process: clear errors early; read its time step and metric specs."""
    env = spec.make()
    try:
        return env_time_step(env), metric_specs(env)
    finally:
        env.close()


def _vec_envs(config: TrainConfig, seed: int, vecnormalize_path: Path | None = None):
    """Training vec env (VecNormalize on top when configured) and a 1-env evaluation vec env."""
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    from .envs import EnvFactory

    spec = env_spec(config)
    venv = make_vec_env(
        spec,
        config.vec_env.n_envs,
        seed,
        subprocess=config.vec_env.use_subprocess,
        start_method=config.vec_env.start_method,
    )
    eval_env = DummyVecEnv([EnvFactory(spec)]) if config.eval.freq > 0 else None
    if eval_env is not None:
        eval_env.seed(seed + EVAL_SEED_OFFSET)
    norm = config.normalize
    if norm.observation or norm.reward:
        if vecnormalize_path is not None:
            venv = VecNormalize.load(str(vecnormalize_path), venv)
            venv.training = True
        else:
            venv = VecNormalize(
                venv,
                norm_obs=norm.observation,
                norm_reward=norm.reward,
                clip_obs=norm.clip_observation,
                clip_reward=norm.clip_reward,
                gamma=config.ppo.gamma,
            )
        if eval_env is not None:
            eval_env = VecNormalize(
                eval_env,
                training=False,
                norm_obs=norm.observation,
                norm_reward=False,
                clip_obs=norm.clip_observation,
            )
    return venv, eval_env


def start_training(
    config: TrainConfig,
    output_dir: str | Path = "runs",
    name: str | None = None,
    force: bool = False,
    command: str | None = None,
) -> TrainResult:
    """Create ``output_dir/name`` (default ``{env}__ppo__{seed}__{time}``) and train PPO in it."""
    from stable_baselines3 import PPO

    spec = env_spec(config)
    dt, specs = _probe(spec)
    name = name or run_name(config.env.id, config.train.seed)
    run_dir = prepare_new_dir(Path(output_dir) / name, force, "run directory")
    command = command or command_line()
    (run_dir / CONFIG_FILE).write_text(dump_yaml(config))
    (run_dir / COMMAND_FILE).write_text(command + "\n")
    venv, eval_env = _vec_envs(config, config.train.seed)
    model = PPO(
        "MlpPolicy",
        venv,
        policy_kwargs=config.policy.policy_kwargs(),
        seed=config.train.seed,
        device=config.train.device,
        verbose=config.logging.verbose,
        **config.ppo.sb3_kwargs(),
    )
    if config.hybrid is not None and config.hybrid.zero_init_action_net:
        from ..hybrid import zero_init_action_net

        zero_init_action_net(model)  # start exactly at the analytical controller
    return _learn(model, config, run_dir, command, eval_env, dt, specs, resumed=False)


def resume_training(
    run_dir: str | Path, overrides: list[str] | tuple[str, ...] = (), command: str | None = None
) -> TrainResult:
    """Continue a run from its latest checkpoint (model, VecNormalize, timestep count) in place.

    Overrides may change the budget, PPO hyperparameters, evaluation/checkpoint frequencies and
    the number of envs, but not the env, the policy network or the normalisation.
    """
    from stable_baselines3 import PPO

    run_dir = Path(run_dir)
    if not (run_dir / CONFIG_FILE).is_file():
        raise UserError(f"{run_dir} is not a training run directory (no {CONFIG_FILE})")
    for text in overrides:
        section = parse_override(text)[0][0]
        if section in RESUME_FIXED_SECTIONS:
            raise UserError(
                f"cannot change {section!r} when resuming ({text!r}); the sections "
                f"{list(RESUME_FIXED_SECTIONS)} are fixed by the saved model"
            )
    config = load_train_config(data=load_yaml(run_dir / CONFIG_FILE), overrides=overrides)
    latest = latest_model_dir(run_dir)
    if latest is None:
        raise UserError(f"{run_dir} holds no checkpoint to resume from")
    done = int(read_meta(latest).get("num_timesteps", 0))
    if done >= config.train.total_timesteps:
        raise UserError(
            f"{run_dir} is already trained to {done} steps >= train.total_timesteps="
            f"{config.train.total_timesteps}; raise it, e.g. "
            f"--set train.total_timesteps={2 * config.train.total_timesteps}"
        )
    spec = env_spec(config)
    dt, specs = _probe(spec)
    command = command or command_line()
    (run_dir / CONFIG_FILE).write_text(dump_yaml(config))
    with open(run_dir / COMMAND_FILE, "a") as fh:
        fh.write(command + "\n")
    vecnorm = latest / VECNORM_FILE
    seed = config.train.seed + done
    venv, eval_env = _vec_envs(config, seed, vecnorm if vecnorm.is_file() else None)
    model = PPO.load(
        latest / "model.zip",
        env=venv,
        device=config.train.device,
        verbose=config.logging.verbose,
        **config.ppo.sb3_kwargs(),
    )
    model.set_random_seed(seed)
    print(f"resuming {run_dir} from {latest.name} at {model.num_timesteps} steps")
    return _learn(model, config, run_dir, command, eval_env, dt, specs, resumed=True)


def _learn(
    model: Any,
    config: TrainConfig,
    run_dir: Path,
    command: str,
    eval_env: Any,
    dt: float | None,
    specs: list,
    resumed: bool,
) -> TrainResult:
    import torch
    from stable_baselines3.common.callbacks import CallbackList
    from stable_baselines3.common.logger import Logger, make_output_format

    torch.set_num_threads(config.train.num_threads)

    from .callbacks import (
        CheckpointEvery,
        EpisodeStatsCallback,
        ModelSaver,
        SaveBest,
        StatsEvalCallback,
    )

    saver = ModelSaver(run_dir, config, command)
    callbacks = [EpisodeStatsCallback(dt, specs)]
    if config.checkpoint.freq > 0:
        callbacks.append(CheckpointEvery(config.checkpoint.freq, saver))
    if eval_env is not None:
        eval_cb = StatsEvalCallback(
            eval_env,
            n_eval_episodes=config.eval.n_episodes,
            eval_freq=max(config.eval.freq // config.vec_env.n_envs, 1),
            log_path=str(run_dir),
            deterministic=config.eval.deterministic,
            callback_on_new_best=SaveBest(saver),
            warn=False,
            verbose=config.logging.verbose,
            dt=dt,
            specs=specs,
        )
        if resumed:
            _restore_eval_history(eval_cb, run_dir)
        callbacks.append(eval_cb)
    tb_dir = run_dir / "tb"
    formats = []
    if config.logging.tensorboard:
        formats.append(make_output_format("tensorboard", str(tb_dir)))
    if config.logging.verbose >= 1:
        formats.append(make_output_format("stdout", str(tb_dir)))
    model.set_logger(
        Logger(folder=str(tb_dir) if config.logging.tensorboard else None, output_formats=formats)
    )

    start_steps = model.num_timesteps
    remaining = config.train.total_timesteps - start_steps
    start = time.perf_counter()
    interrupted = False
    try:
        model.learn(
            remaining,
            callback=CallbackList(callbacks),
            reset_num_timesteps=not resumed,
            progress_bar=config.logging.progress_bar,
        )
    except KeyboardInterrupt:
        interrupted = True
    seconds = time.perf_counter() - start
    if interrupted:
        saved = saver.save(model, "interrupt")
    else:
        saved = saver.save(model, "final", run_dir / FINAL)
    for env in (model.get_env(), eval_env):
        _close_quietly(env)
    return TrainResult(
        run_dir=run_dir,
        num_timesteps=int(model.num_timesteps),
        steps_this_call=int(model.num_timesteps - start_steps),
        seconds=seconds,
        interrupted=interrupted,
        saved_to=saved,
    )


def _restore_eval_history(eval_cb: Any, run_dir: Path) -> None:
    """Keep the best reward and the evaluation log of the earlier part of a resumed run."""
    best = read_meta(run_dir / BEST)
    if "eval_mean_reward" in best:
        eval_cb.best_mean_reward = float(best["eval_mean_reward"])
    log = run_dir / "evaluations.npz"
    if log.is_file():
        with np.load(log) as data:
            eval_cb.evaluations_timesteps = list(data["timesteps"])
            eval_cb.evaluations_results = [list(r) for r in data["results"]]
            eval_cb.evaluations_length = [list(r) for r in data["ep_lengths"]]
            if "successes" in data:
                eval_cb.evaluations_successes = [list(r) for r in data["successes"]]


def _close_quietly(env: Any) -> None:
    """Close a vec env; after Ctrl-C its subprocess workers may already be gone."""
    if env is None:
        return
    with contextlib.suppress(BrokenPipeError, EOFError, ConnectionResetError, OSError):
        env.close()
