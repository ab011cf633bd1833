"""PPO training runs: start a new run from a config, or resume the latest checkpoint of a run.

See `agents.run_files.artifacts` for the run directory layout and `callbacks` for what goes to
TensorBoard.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import os
import shutil
import signal
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from ..run_files.artifacts import (
    BEST,
    COMMAND_FILE,
    CONFIG_FILE,
    FINAL,
    MODEL_FILE,
    WARM_START,
    command_line,
    is_complete,
    prepare_new_dir,
    read_meta,
    run_name,
    saved_model_dirs,
)
from ..run_files.configtools import dump_yaml, load_yaml, parse_override
from ..run_files.env_settings import (
    RENDERING,
    describe,
    differences,
    read_settings,
    resolved_settings,
    write_settings,
)
from ..run_files.errors import UserError
from ..run_files.model_files import (
    NormalizationStats,
    atomic_write_text,
    load_ppo,
    load_stats,
    policy_class,
    ppo_custom_objects,
)
from ..run_files.train_config import TrainConfig, load_train_config
from .envs import EnvSpec, env_time_step, make_vec_env
from .episode import XI_F_DEG, EpisodeAccumulator, metric_specs
from .learning_curve import EVALUATIONS_FILE, read_evaluation_log

EVAL_SEED_OFFSET = 10_000
"""Evaluation envs are seeded apart from the training envs."""

RESUME_FIXED_SECTIONS = ("env", "policy", "normalize", "hybrid", "knobs", "warm_start")
"""Config sections a resumed run cannot change (the model and its statistics depend on them)."""

RESUME_FREE_KEYS = (("env", "vectorization"),)
"""Keys of those sections that a resumed run may change: how the envs run, not what they are."""

WORKER_CLOSE_TIMEOUT_S = 10.0
"""How long closing the vec env waits for subprocess workers before terminating them."""


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
        env.id,
        dict(env.kwargs),
        env.max_episode_steps,
        list(env.gym_packages),
        config.hybrid,
        list(env.reward_exclude),
        env.decision,
        env.cycle_baseline,
        config.policy.critic_privileged,
        config.knobs,
        env.episode_reward,
        env.min_task_difficulty,
        env.stability_penalty,
        env.progress_penalty,
        None if env.stride_choices is None else list(env.stride_choices),
        env.stride_clearances,
    )


def _probe(
    spec: EnvSpec, score_read_actions_only: bool = False
) -> tuple[Callable[[], EpisodeAccumulator], dict[str, Any] | None]:
    """Make one env in this process: clear errors early; read its time step (None when a
    learner step is a gait cycle), metric specs and the robot's tipping threshold ξ (the time
    below it is logged). Returns a factory of episode
    accumulators for the training and evaluation callbacks, and the env's resolved settings
    (recorded with the run, see `agents.run_files.env_settings`); with ``reward_exclude``, one
    step checks that the terms exist; with `score_read_actions_only`, that the env has action
    values it reads only on some steps or never."""
    env = spec.make()
    try:
        base = env.unwrapped
        if score_read_actions_only and not (base.action_read_flags or base.inert_actions):
            raise UserError(
                f"policy.score_read_actions_only: {spec.id} with env.kwargs {spec.kwargs} "
                "reads every action value on every step (no action_read_flags or "
                "inert_actions), so there is nothing to leave out; the option applies to "
                "HexapodDitchCrossing-v1 with stride_action: true, or set it to false"
            )
        if score_read_actions_only and len(base.inert_actions) == base.action_space.shape[0]:
            raise UserError(
                f"policy.score_read_actions_only: {spec.id} with env.kwargs {spec.kwargs} "
                f"reads none of its action values (all inert: {list(base.inert_actions)}), so "
                "there is nothing to learn; give the residuals a range or add stride_action: true"
            )
        if spec.reward_exclude:  # a term missing from the info is named at the first step
            env.reset(seed=0)
            env.step(np.zeros(env.action_space.shape, env.action_space.dtype))
        dt, specs = env_time_step(env), metric_specs(env)
        if spec.decision != "step" or spec.knobs is not None:
            dt = None  # a learner step is a gait cycle or an episode: no durations or energy
        xi = getattr(env.unwrapped, "tipping_threshold_deg", XI_F_DEG)
        settings = resolved_settings(env)
    finally:
        env.close()
    return partial(EpisodeAccumulator, dt, specs, xi_f_deg=xi), settings


def check_env(config: TrainConfig) -> None:
    """Build the config's env once in this process, so that its errors (an unknown keyword, a
    misspelt reward term) come before any folder exists, e.g. before a sweep starts Ray."""
    _probe(env_spec(config), config.policy.score_read_actions_only)


def _vec_envs(config: TrainConfig, seed: int, stats: NormalizationStats | None = None):
    """Training vec env (VecNormalize on top when configured) and a 1-env evaluation vec env."""
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    from .envs import EnvFactory

    spec = env_spec(config)
    if config.env.vectorization == "batched":
        from .batched_vec_env import make_batched_vec_env

        venv = make_batched_vec_env(
            spec, config.vec_env.n_envs, seed, config.vec_env.physics_threads
        )
    else:
        venv = make_vec_env(
            spec,
            config.vec_env.n_envs,
            seed,
            subprocess=config.vec_env.use_subprocess,
            start_method=config.vec_env.start_method,
        )
    # Evaluations of a per-cycle learner act at every env step (the same actions as per gait
    # cycle, see GainsPerCycle), so that their episode metrics see every step's info; a
    # per-episode learner's act once per episode, as it was trained.
    eval_spec = spec
    if spec.decision == "gait_cycle":
        eval_spec = dataclasses.replace(spec, decision="step", cycle_baseline="none")
    eval_env = DummyVecEnv([EnvFactory(eval_spec)]) if config.eval.freq > 0 else None
    if eval_env is not None:
        eval_env.seed(seed + EVAL_SEED_OFFSET)
    norm = config.normalize
    if norm.observation or norm.reward:
        venv = VecNormalize(
            venv,
            norm_obs=norm.observation,
            norm_reward=norm.reward,
            clip_obs=norm.clip_observation,
            clip_reward=norm.clip_reward,
            gamma=config.ppo.gamma,
        )
        if stats is not None:
            stats.apply_to(venv)
        if eval_env is not None:
            eval_env = VecNormalize(
                eval_env,
                training=False,
                norm_obs=norm.observation,
                norm_reward=False,
                clip_obs=norm.clip_observation,
            )
    return venv, eval_env


def new_model(config: TrainConfig, venv: Any) -> Any:
    """An untrained SB3 PPO model of `config` on `venv`; with a zero-initialised action net when
    the config asks (it then starts exactly at the analytical controller or reference motion)."""
    from stable_baselines3 import PPO

    model = PPO(
        policy_class(config.policy.critic_privileged, config.policy.score_read_actions_only),
        venv,
        policy_kwargs=config.policy.policy_kwargs(),
        seed=config.train.seed,
        device=config.train.device,
        verbose=config.logging.verbose,
        **_ppo_kwargs(config),
    )
    if config.starts_at_zero_action:
        from ..hybrid import zero_init_action_net

        zero_init_action_net(model)
    _set_action_read_flags(config, model, venv)
    return model


def _set_action_read_flags(config: TrainConfig, model: Any, venv: Any) -> None:
    """With ``policy.score_read_actions_only``: tell the policy which action values the env
    reads only on some steps and which never (`_probe` has checked that it has some)."""
    if config.policy.score_read_actions_only:
        flags, inert = (venv.get_attr(name, indices=[0])[0] for name in _READS)
        model.policy.set_action_read_flags(flags, inert)


_READS = ("action_read_flags", "inert_actions")
"""The env's attributes that say which action values it reads only on some steps, or never."""


def _masks_overridden(config: TrainConfig) -> bool:
    return config.hybrid is not None and config.hybrid.mask_overridden


def _ppo_kwargs(config: TrainConfig) -> dict[str, Any]:
    """SB3 PPO's keyword arguments: the ``ppo`` section's, with the override-masking rollout
    buffer when ``hybrid.mask_overridden`` (`override_mask`)."""
    kwargs = config.ppo.sb3_kwargs()
    if _masks_overridden(config):
        from .override_mask import masked_ppo_kwargs

        kwargs.update(masked_ppo_kwargs(config.ppo.normalize_advantage))
    return kwargs


def untrained_model(config: TrainConfig) -> tuple[Any, dict[str, Any] | None]:
    """`new_model` on the config's training vec env (VecNormalize on top when configured), for
    models fitted outside PPO's own loop (e.g. by distillation), and the env's resolved
    settings (to record with the model, see `agents.run_files.env_settings`)."""
    _, settings = _probe(env_spec(config), config.policy.score_read_actions_only)
    venv, eval_env = _vec_envs(config, config.train.seed)
    if eval_env is not None:
        eval_env.close()
    return new_model(config, venv), settings


def start_training(
    config: TrainConfig,
    output_dir: str | Path = "runs",
    name: str | None = None,
    force: bool = False,
    command: str | None = None,
    after_eval: Any = None,
) -> TrainResult:
    """Create ``output_dir/name`` (default ``{env}__ppo__{seed}__{time}``) and train PPO in it.

    A run that fails before its first training step removes the directory it created, so the
    same command can simply be run again. `after_eval`: an optional SB3 callback run after each
    evaluation (its ``parent`` is the EvalCallback); sweeps use it to report the evaluation
    metrics to Ray Tune.
    """
    spec = env_spec(config)
    new_accumulator, settings = _probe(spec, config.policy.score_read_actions_only)
    name = name or run_name(config.env.id, config.train.seed)
    run_dir = prepare_new_dir(Path(output_dir) / name, force, "run directory", (CONFIG_FILE,))
    venv = eval_env = None
    try:
        command = command or command_line()
        atomic_write_text(run_dir / CONFIG_FILE, dump_yaml(config))
        write_settings(run_dir, settings)
        atomic_write_text(run_dir / COMMAND_FILE, command + "\n")
        venv, eval_env = _vec_envs(config, config.train.seed)
        model = new_model(config, venv)
        if config.warm_start is not None:
            _warm_start(model, config, venv, spec, run_dir, command, settings)
    except BaseException:  # e.g. Ctrl-C during a warm start: close the envs, remove the run
        for env in (venv, eval_env):
            if env is not None:
                close_vec_env(env)
        shutil.rmtree(run_dir, ignore_errors=True)
        raise
    return _learn(
        model, config, run_dir, command, eval_env, new_accumulator, False, after_eval, settings
    )


def _warm_start(
    model: Any,
    config: TrainConfig,
    venv: Any,
    spec: EnvSpec,
    run_dir: Path,
    command: str,
    settings: dict[str, Any] | None,
) -> None:
    """Clone the config's teacher into the actor (`agents.warm_start`) and save the result as
    the run's ``warm_start/`` model: its step-0 policy."""
    import torch

    from ..warm_start import warm_start
    from .callbacks import ModelSaver

    torch.set_num_threads(config.train.num_threads)  # as the PPO updates will
    ws = config.warm_start
    print(f"warm start: cloning {ws.teacher!r} from {ws.episodes} episodes", flush=True)
    summary = warm_start(
        model,
        venv,
        spec.make,
        ws,
        config.train.seed,
        lambda line: print(f"warm start: {line}", flush=True),
    )
    ModelSaver(run_dir, config, command, settings).save(
        model, "warm_start", run_dir / WARM_START, warm_start=summary
    )


def resume_training(
    run_dir: str | Path,
    overrides: list[str] | tuple[str, ...] = (),
    command: str | None = None,
    trust_pickle: bool = False,
    after_eval: Any = None,
) -> TrainResult:
    """Continue a run from its newest loadable checkpoint (model, statistics, timestep count);
    a warm-started run that saved none starts PPO again from its clone (``warm_start/``).

    Overrides may change the budget, PPO hyperparameters, evaluation/checkpoint frequencies,
    the number of envs and how they run (``env.vectorization``), but not the env, the policy
    network or the normalisation, nor the evaluation episodes of a run with an evaluation log
    (``eval.n_episodes``, ``eval.same_tasks``: its learning curve). A damaged
    newest checkpoint is reported and the next newest is used; no file of the run is written
    before a checkpoint has loaded.
    """
    run_dir = Path(run_dir)
    if not (run_dir / CONFIG_FILE).is_file():
        raise UserError(f"{run_dir} is not a training run directory (no {CONFIG_FILE})")
    for text in overrides:
        key = tuple(parse_override(text)[0])
        section = key[0]
        if section in RESUME_FIXED_SECTIONS and key[:2] not in RESUME_FREE_KEYS:
            raise UserError(
                f"cannot change {section!r} when resuming ({text!r}); the sections "
                f"{list(RESUME_FIXED_SECTIONS)} are fixed by the saved model"
            )
    data = load_yaml(run_dir / CONFIG_FILE)
    saved = load_train_config(data=copy.deepcopy(data))  # the overrides edit the mapping given
    config = load_train_config(data=data, overrides=overrides)
    _check_eval_tasks_kept(run_dir, saved, config)
    candidates = saved_model_dirs(run_dir)
    if not candidates and is_complete(run_dir / WARM_START):
        # Killed after its warm start, before PPO saved a checkpoint: PPO starts from the clone
        # again, on freshly seeded envs. (Damaged checkpoints stay an error: falling back to
        # the clone would drop the training done.)
        candidates = [run_dir / WARM_START]
    if not candidates:
        raise UserError(f"{run_dir} holds no checkpoint to resume from")
    spec = env_spec(config)
    new_accumulator, settings = _probe(spec, config.policy.score_read_actions_only)
    _warn_if_settings_changed(run_dir, settings)
    model = eval_env = None
    problems = []
    for checkpoint in candidates:
        done = int(read_meta(checkpoint).get("num_timesteps", 0))
        if done >= config.train.total_timesteps:
            raise UserError(
                f"{run_dir} is already trained to {done} steps >= train.total_timesteps="
                f"{config.train.total_timesteps}; raise it, e.g. "
                f"--set train.total_timesteps={2 * config.train.total_timesteps}"
            )
        try:
            model, eval_env = _load_checkpoint(checkpoint, config, done, trust_pickle)
            break
        except UserError as exc:
            problems.append(f"{checkpoint.name}: {exc}")
            print(f"warning: cannot resume from {checkpoint}: {exc}", file=sys.stderr)
    if model is None:
        raise UserError(f"no loadable checkpoint in {run_dir}:\n  " + "\n  ".join(problems))
    if problems:
        print(f"falling back to {checkpoint.name} ({done} steps)", file=sys.stderr)
    command = command or command_line()
    atomic_write_text(run_dir / CONFIG_FILE, dump_yaml(config))
    with open(run_dir / COMMAND_FILE, "a") as fh:
        fh.write(command + "\n")
    print(f"resuming {run_dir} from {checkpoint.name} at {model.num_timesteps} steps")
    return _learn(
        model, config, run_dir, command, eval_env, new_accumulator, True, after_eval, settings
    )


def _check_eval_tasks_kept(run_dir: Path, before: Any, after: Any) -> None:
    """UserError if the overrides change the evaluation episodes of a run with an evaluation
    log: its rows hold ``eval.n_episodes`` episodes each (rows of two widths cannot share the
    log), on the same tasks at every evaluation with ``eval.same_tasks`` (the learning curve
    compares them)."""
    if not (run_dir / EVALUATIONS_FILE).is_file():
        return
    for key in ("n_episodes", "same_tasks"):
        old, new = getattr(before.eval, key), getattr(after.eval, key)
        if old != new:
            raise UserError(
                f"cannot change eval.{key} when resuming ({old} -> {new}): the run's "
                f"{EVALUATIONS_FILE} holds its learning curve on the earlier evaluation "
                "episodes; start a new run to evaluate otherwise"
            )


def _warn_if_settings_changed(run_dir: Path, settings: dict[str, Any] | None) -> None:
    """Say so when the env's settings now differ from those the run started with (a default
    changed in the code since): the resumed part trains on the env as it is now, and the model
    directories it saves record that env's settings."""
    recorded = read_settings(run_dir)
    if recorded is None or settings is None:
        return
    found = differences(recorded, settings, ignore=RENDERING)
    if found:
        print(
            f"warning: the env's settings differ from those {run_dir} started with "
            f"(setting: then -> now): {describe(found, reward_note='the reward it learns from')}",
            file=sys.stderr,
        )


def _load_checkpoint(
    checkpoint: Path, config: TrainConfig, done: int, trust_pickle: bool
) -> tuple[Any, Any]:
    """The PPO model of a checkpoint on fresh vec envs; UserError (envs closed) if damaged."""
    norm = config.normalize
    stats = load_stats(checkpoint, trust_pickle, required=norm.observation or norm.reward)
    seed = config.train.seed + done
    venv, eval_env = _vec_envs(config, seed, stats)
    ppo = config.ppo
    objects = ppo_custom_objects(
        config.policy.policy_kwargs(),
        venv.observation_space,
        venv.action_space,
        learning_rate=ppo.learning_rate,
        clip_range=ppo.clip_range,
        clip_range_vf=ppo.clip_range_vf,
        privileged_critic=config.policy.critic_privileged,
        score_read_actions_only=config.policy.score_read_actions_only,
    )
    try:
        model = load_ppo(
            checkpoint / MODEL_FILE,
            objects,
            trust_pickle,
            env=venv,
            device=config.train.device,
            verbose=config.logging.verbose,
            **_ppo_kwargs(config),
        )
        _set_action_read_flags(config, model, venv)
    except BaseException:
        for env in (venv, eval_env):
            close_vec_env(env)
        raise
    model.set_random_seed(seed)
    return model, eval_env


def _learn(
    model: Any,
    config: TrainConfig,
    run_dir: Path,
    command: str,
    eval_env: Any,
    new_accumulator: Callable[[], EpisodeAccumulator],
    resumed: bool,
    after_eval: Any = None,
    env_settings: dict[str, Any] | None = None,
) -> TrainResult:
    """Train `model` in `run_dir` up to ``train.total_timesteps`` and save the result.

    Shared by a new run and a resumed one (`resumed`: keep the timestep count and the earlier
    evaluations). Ctrl-C or SIGTERM saves an ``interrupt`` checkpoint and returns with
    `interrupted` set; any other error saves a ``crash`` checkpoint and is re-raised; a run that
    completes saves the final model. The vec envs are closed in every case.
    """
    import torch

    torch.set_num_threads(config.train.num_threads)

    from .callbacks import ModelSaver

    saver = ModelSaver(run_dir, config, command, env_settings)
    callbacks = _callbacks(config, saver, new_accumulator)
    if eval_env is not None:
        eval_cb = _eval_callback(config, run_dir, saver, eval_env, new_accumulator, after_eval)
        if resumed:
            _restore_eval_history(eval_cb, run_dir, model.num_timesteps)
        callbacks.append(eval_cb)
    _set_logger(model, config, run_dir)
    start_steps = model.num_timesteps
    remaining = config.train.total_timesteps - start_steps
    start = time.perf_counter()
    interrupted = _run_learn(model, config, remaining, callbacks, resumed, saver, eval_env)
    seconds = time.perf_counter() - start
    with _exit_on_second_interrupt():
        if interrupted:
            saved = saver.save(model, "interrupt")
        else:
            saved = saver.save(model, "final", run_dir / FINAL)
        _close_envs(model, eval_env)
    return TrainResult(
        run_dir=run_dir,
        num_timesteps=int(model.num_timesteps),
        steps_this_call=int(model.num_timesteps - start_steps),
        seconds=seconds,
        interrupted=interrupted,
        saved_to=saved,
    )


def _callbacks(
    config: TrainConfig, saver: Any, new_accumulator: Callable[[], EpisodeAccumulator]
) -> list[Any]:
    """The training callbacks other than evaluation: each finished episode's statistics to the
    log, each step's safety override into the rollout buffer when ``hybrid.mask_overridden``,
    the critic's head start after a warm start (``warm_start.critic_steps``) and a checkpoint
    every ``checkpoint.freq`` steps (0: none)."""
    from .callbacks import CheckpointEvery, CriticFirst, EpisodeStatsCallback

    callbacks = [EpisodeStatsCallback(new_accumulator)]
    if config.warm_start is not None and config.warm_start.critic_steps > 0:
        callbacks.append(CriticFirst(config.warm_start.critic_steps))
    if _masks_overridden(config):
        from .override_mask import RecordOverrides

        callbacks.append(RecordOverrides())
    if config.checkpoint.freq > 0:
        callbacks.append(CheckpointEvery(config.checkpoint.freq, saver))
    return callbacks


def _eval_callback(
    config: TrainConfig,
    run_dir: Path,
    saver: Any,
    eval_env: Any,
    new_accumulator: Callable[[], EpisodeAccumulator],
    after_eval: Any,
) -> Any:
    """The evaluation callback: ``eval.n_episodes`` episodes on `eval_env` every ``eval.freq``
    steps summed over the envs, logged to ``evaluations.npz`` in `run_dir`; it saves ``best/``
    by mean return, or by success rate then mean return when ``eval.select`` is "success", and
    runs `after_eval` after each evaluation. With ``eval.same_tasks`` every evaluation draws the
    same tasks (seeded apart from training by EVAL_SEED_OFFSET)."""
    from .callbacks import SaveBest, StatsEvalCallback

    by_success = config.eval.select == "success"
    return StatsEvalCallback(
        eval_env,
        n_eval_episodes=config.eval.n_episodes,
        eval_freq=max(config.eval.freq // config.vec_env.n_envs, 1),
        log_path=str(run_dir),
        deterministic=config.eval.deterministic,
        callback_on_new_best=None if by_success else SaveBest(saver),
        callback_after_eval=after_eval,
        warn=False,
        verbose=config.logging.verbose,
        new_accumulator=new_accumulator,
        task_seed=config.train.seed + EVAL_SEED_OFFSET if config.eval.same_tasks else None,
        select_saver=saver if by_success else None,
    )


def _set_logger(model: Any, config: TrainConfig, run_dir: Path) -> None:
    """Send SB3's log to TensorBoard (``run_dir/tb``) when ``logging.tensorboard`` and to
    stdout when ``logging.verbose`` >= 1."""
    from stable_baselines3.common.logger import Logger, make_output_format

    tb_dir = run_dir / "tb"
    formats = []
    if config.logging.tensorboard:
        formats.append(make_output_format("tensorboard", str(tb_dir)))
    if config.logging.verbose >= 1:
        formats.append(make_output_format("stdout", str(tb_dir)))
    model.set_logger(
        Logger(folder=str(tb_dir) if config.logging.tensorboard else None, output_formats=formats)
    )


def _run_learn(
    model: Any,
    config: TrainConfig,
    remaining: int,
    callbacks: list[Any],
    resumed: bool,
    saver: Any,
    eval_env: Any,
) -> bool:
    """Run PPO's learn() for `remaining` steps; True if Ctrl-C or SIGTERM stopped it.

    Any other error saves a crash checkpoint, closes the envs and is re-raised; a second Ctrl-C
    meanwhile exits at once."""
    from stable_baselines3.common.callbacks import CallbackList

    try:
        with _interruptible():
            model.learn(
                remaining,
                callback=CallbackList(callbacks),
                reset_num_timesteps=not resumed,
                progress_bar=config.logging.progress_bar,
            )
    except KeyboardInterrupt:
        return True
    except BaseException as exc:
        with _exit_on_second_interrupt():
            _save_after_crash(saver, model, exc)
            _close_envs(model, eval_env)
        raise
    return False


def _close_envs(model: Any, eval_env: Any) -> None:
    """Close the training vec env and the evaluation one (None: nothing to close)."""
    for env in (model.get_env(), eval_env):
        close_vec_env(env)


def _save_after_crash(saver: Any, model: Any, exc: BaseException) -> None:
    """Keep the training done so far when learn() raised; the original error is re-raised."""
    try:
        path = saver.save(model, "crash")
    except Exception as save_exc:  # the model itself may be what broke
        print(
            f"error: training failed ({exc!r}) and no checkpoint could be saved ({save_exc!r})",
            file=sys.stderr,
        )
        return
    print(
        f"error: training failed at {model.num_timesteps} steps; checkpoint saved to {path}\n"
        f"resume with: python train.py --resume {saver.run_dir}",
        file=sys.stderr,
    )


@contextlib.contextmanager
def _interruptible():
    """During learning, SIGINT and SIGTERM raise KeyboardInterrupt (checkpoint, exit 130).

    Also when the process started with SIGINT ignored (a background job of a non-interactive
    shell, some schedulers): a training run must stop when asked, and SIGTERM is how job
    schedulers ask."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    previous = {sig: signal.signal(sig, interrupt) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


@contextlib.contextmanager
def _exit_on_second_interrupt():
    """While saving and closing after a Ctrl-C, a second Ctrl-C exits at once (code 130).

    Files are written atomically, so the newest complete checkpoint stays valid."""
    if threading.current_thread() is not threading.main_thread():
        yield  # signal handlers can only be set from the main thread (e.g. not in Ray trials)
        return

    def exit_now(signum, frame):
        print("\nsecond interrupt: exiting without waiting for the workers", file=sys.stderr)
        os._exit(130)

    previous = signal.signal(signal.SIGINT, exit_now)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def close_vec_env(venv: Any, timeout: float = WORKER_CLOSE_TIMEOUT_S) -> None:
    """Close a vec env without ever hanging on its subprocess workers.

    SB3's ``SubprocVecEnv.close()`` waits for the reply to a step that a Ctrl-C may have cut
    in half, which can block forever. Here the workers are told to close (a worker busy with
    a step finishes it first), given `timeout` seconds, and then terminated."""
    from stable_baselines3.common.vec_env import SubprocVecEnv, VecEnvWrapper

    inner = venv
    while isinstance(inner, VecEnvWrapper):
        inner = inner.venv
    if inner is None:
        return
    if not isinstance(inner, SubprocVecEnv):
        with contextlib.suppress(Exception):
            inner.close()
        return
    if inner.closed:
        return
    for remote in inner.remotes:
        with contextlib.suppress(OSError, ValueError):
            remote.send(("close", None))
    deadline = time.monotonic() + timeout
    for process in inner.processes:
        process.join(max(deadline - time.monotonic(), 0.0))
    for process in inner.processes:
        if process.is_alive():
            process.terminate()
            process.join(1.0)
        if process.is_alive():
            process.kill()
            process.join(1.0)
    for remote in inner.remotes:
        with contextlib.suppress(OSError):
            remote.close()
    inner.closed = True


def _restore_eval_history(eval_cb: Any, run_dir: Path, done: int) -> None:
    """Keep the best reward and the evaluation log of the earlier part of a resumed run: the
    log's entries up to the resumed checkpoint's `done` steps (resuming from an older checkpoint
    than the newest, the later evaluations are made again), the best score over all of them
    (``best/`` keeps the model that scored it)."""
    best = read_meta(run_dir / BEST)
    if "eval_mean_reward" in best:
        eval_cb.best_mean_reward = float(best["eval_mean_reward"])
    log = run_dir / EVALUATIONS_FILE
    if not log.is_file():
        return
    try:
        data = read_evaluation_log(log)
    except UserError as exc:
        print(f"warning: {exc}; it starts anew", file=sys.stderr)
        return
    eval_cb.evaluations_timesteps = list(data["timesteps"])
    eval_cb.evaluations_results = [list(r) for r in data["results"]]
    eval_cb.evaluations_length = [list(r) for r in data["ep_lengths"]]
    if "successes" in data:
        eval_cb.evaluations_successes = [list(r) for r in data["successes"]]
    if eval_cb.select_saver is not None and eval_cb.evaluations_results:
        eval_cb.best_score = max(eval_cb.score(i) for i in range(len(eval_cb.evaluations_results)))
    kept = sum(1 for t in eval_cb.evaluations_timesteps if t <= done)
    for name in ("timesteps", "results", "length", "successes"):
        entries = getattr(eval_cb, f"evaluations_{name}")
        del entries[kept:]
