"""Run a suite: every policy on every env for the same seeds; collect per-episode records.

Everything the suite names is checked before the first episode runs (unknown env ids, bad env
kwargs, missing or mismatched models), so a typo fails in seconds with one clear message.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from ..env_kwargs import POLICY_SETTINGS, constructor_defaults, registered_defaults
from ..policy import Policy, RandomPolicy, ZeroPolicy
from ..ppo import PPOPolicy
from ..run_files.artifacts import checkpoint_note, other_env_error
from ..run_files.env_settings import (
    describe,
    differences,
    read_settings,
    resolved_settings,
    reward_only,
)
from ..run_files.errors import UserError
from ..run_files.shipped import resolve_shipped
from .envs import EnvSpec, check_env_id, env_time_step, import_gym_packages
from .episode import EpisodeAccumulator, EpisodeRecord, MetricSpec, metric_specs
from .eval_config import PPO_PREFIX, EvaluationSuite, SuiteEnv


class EpisodeSeededRandomPolicy(RandomPolicy):
    """Uniform random actions, reseeded from each episode's seed (reproducible per episode)."""

    def seed_episode(self, seed: int) -> None:
        self.seed = seed


@dataclass
class PolicyRun:
    """One policy on one env: its episodes (same seeds as every other policy)."""

    name: str
    source: str
    episodes: list[EpisodeRecord] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    frames: list[np.ndarray] | None = None
    video: Path | None = None  # MP4 of the first seed (with --video)
    model_dir: Path | None = None  # a ppo: policy's model directory (for learning curves)
    env_kwargs: dict[str, Any] = field(default_factory=dict)  # on top of the suite's (action mode)


@dataclass
class EnvResult:
    env_id: str
    kwargs: dict[str, Any]
    max_episode_steps: int | None
    dt: float | None
    specs: list[MetricSpec]
    runs: dict[str, PolicyRun] = field(default_factory=dict)
    xi_deg: float | None = None  # the robot's FASM threshold ξ; None: FASM is not its criterion
    criterion: str = ""  # the robot's stability criterion, in words
    unranked: tuple[str, ...] = ()  # standard metrics without a verdict here (see `prepare`)
    aliases: dict[str, str] = field(default_factory=dict)  # policy name -> short name
    rules: dict[str, float | None] = field(default_factory=dict)
    """The env's episode-end and success bounds (`episode_rules`); empty for other envs."""

    def label(self, name: str) -> str:
        """What a reader of this env sees: the policy's short alias (`policy_aliases`), else
        its name with ``{env_id}`` expanded."""
        return (self.aliases.get(name) or name).replace("{env_id}", self.env_id)


_RUN_PARTS = {"best", "final", "model.zip", "checkpoints"}
"""Path components that name a model inside a run rather than the run."""


def policy_aliases(names: list[str]) -> dict[str, str]:
    """Short names for the ``ppo:<path>`` policies of a suite: the path's last component that
    names the model (``ppo:models/{env_id}/hybrid`` -> ``hybrid``; ``runs/<run>/best`` ->
    ``<run>``; ``ppo:mine/{env_id}`` -> ``mine``; `EnvResult.label` expands a ``{env_id}``
    left in it). A policy whose alias would be ambiguous (another policy's alias or name) keeps
    its full name; the report's sources list every path."""
    short = {}
    for name in names:
        if name.startswith(PPO_PREFIX):
            parts = [
                p
                for p in Path(name[len(PPO_PREFIX) :]).parts
                if p not in _RUN_PARTS and p != "{env_id}"
            ]
            if parts:
                short[name] = parts[-1]
    taken = [*short.values(), *(n for n in names if n not in short)]
    return {name: alias for name, alias in short.items() if taken.count(alias) == 1}


RULE_SETTINGS = (
    "tip_over_angle_deg",
    "tip_over_margin_time",
    "success_max_tilt_deg",
    "success_max_tipping_share",
)
"""A hexapod env's settings that end an episode (tip-over: a tilt [deg], or the FASM at or
below 0 for a time [s]) and bound a success (its largest tilt [deg], its share of time
tipping [-]); None: not bounded."""


def episode_rules(env: gym.Env) -> dict[str, float | None]:
    """`RULE_SETTINGS` of the env's settings (none for an env without them)."""
    settings = getattr(env.unwrapped, "settings", None)
    if settings is None or not all(hasattr(settings, name) for name in RULE_SETTINGS):
        return {}
    return {name: getattr(settings, name) for name in RULE_SETTINGS}


def stability_threshold(env: gym.Env, default_deg: float) -> tuple[float | None, str]:
    """(ξ [deg] or None, criterion in words) as the env declares them (``tipping_threshold_deg``,
    ``stability_criterion``); envs that declare nothing get the suite's `default_deg`."""
    unwrapped = env.unwrapped
    criterion = getattr(unwrapped, "stability_criterion", None)
    if hasattr(unwrapped, "tipping_threshold_deg"):
        xi = unwrapped.tipping_threshold_deg
        xi = None if xi is None else float(xi)
    else:
        xi = float(default_deg)
    if criterion is None:
        criterion = f"FASM >= {xi:g} deg" if xi is not None else "(not declared by the env)"
    return xi, str(criterion)


@dataclass
class SuiteResult:
    suite: EvaluationSuite
    envs: list[EnvResult]
    warnings: list[str]
    seconds: float
    # lines that are no mismatch: a per-env model found for some envs only, an agent trained
    # with other reward scales only
    notes: list[str] = field(default_factory=list)


def run_episode(
    env: gym.Env,
    policy: Policy,
    seed: int,
    accumulator: EpisodeAccumulator,
    on_step: Any = None,
) -> EpisodeRecord:
    """One episode from ``reset(seed=seed)`` until terminated or truncated."""
    seed_episode = getattr(policy, "seed_episode", None)
    if seed_episode is not None:
        seed_episode(seed)
    policy.reset()
    accumulator.reset()
    obs, _ = env.reset(seed=seed)
    if on_step is not None:
        on_step(0)
    step = 0
    while True:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        step += 1
        accumulator.add(reward, info)
        if on_step is not None:
            on_step(step)
        if terminated or truncated:
            return accumulator.finish(terminated, truncated)


def _env_spec(suite: EvaluationSuite, env: SuiteEnv, **extra: Any) -> EnvSpec:
    kwargs = {**env.kwargs, **extra}
    limit, packages = suite.env_time_limit(env), suite.gym_packages
    return EnvSpec(env.id, kwargs, limit, packages, min_task_difficulty=env.min_task_difficulty)


def policy_env_kwargs(name: str, env_id: str, suite_kwargs: dict | None = None) -> dict[str, Any]:
    """The env kwargs `name` needs on top of the suite's (`suite_kwargs`): the analytical
    controller's action mode (`agents.registry.ANALYTICAL_ENV_KWARGS`); a PPO run's trained
    `POLICY_SETTINGS` (a setting the suite sets but the run left at its default goes back to the
    default); none for the zero and random actions (the env's default mode: zero is the
    reference motion)."""
    if name == "analytical":
        from ..registry import ANALYTICAL_ENV_KWARGS

        return dict(ANALYTICAL_ENV_KWARGS.get(env_id, {}))
    if not name.startswith(PPO_PREFIX):
        return {}
    from ..run_files.artifacts import find_model

    files = find_model(_ppo_path(name, env_id))
    config = files.training_config() or {}
    trained_for = (config.get("env") or {}).get("id")
    if trained_for is not None and trained_for != env_id:  # before its kwargs reach the env
        raise other_env_error(files, trained_for, env_id)
    trained = (config.get("env") or {}).get("kwargs") or {}
    extra = {k: trained[k] for k in POLICY_SETTINGS if k in trained}
    reset = [k for k in POLICY_SETTINGS if k in (suite_kwargs or {}) and k not in trained]
    if reset:
        defaults = registered_defaults(env_id)
        extra.update({k: defaults[k] for k in reset if k in defaults})
    return extra


def _ppo_path(name: str, env_id: str) -> Path:
    """The model path of ``ppo:<path>`` for `env_id` (``models/...``: the shipped model unless
    the working directory has one, see `agents.run_files.shipped`)."""
    return resolve_shipped(name[len(PPO_PREFIX) :].replace("{env_id}", env_id))


def build_policy(
    name: str, env: gym.Env, env_id: str, suite: EvaluationSuite
) -> tuple[Policy, str]:
    """(policy, where it comes from) for a policy name of the suite."""
    if name == "zero":
        return ZeroPolicy(env.action_space), "zero action"
    if name == "random":
        return EpisodeSeededRandomPolicy(env.action_space), "uniform random actions"
    if name == "analytical":
        from ..registry import ANALYTICAL_POLICIES, analytical_factory

        try:
            factory = analytical_factory(env_id)
        except ValueError as exc:
            raise UserError(str(exc)) from None
        entry = ANALYTICAL_POLICIES[env_id]
        source = entry if isinstance(entry, str) else getattr(entry, "__qualname__", repr(entry))
        return factory(env), str(source)
    path = _ppo_path(name, env_id)
    policy = PPOPolicy.load(
        path, env, deterministic=suite.deterministic, trust_pickle=suite.trust_pickle
    )
    return policy, f"{policy.files.model}{checkpoint_note(policy.files.directory)}"


def _check_env_ids(suite: EvaluationSuite) -> None:
    import_gym_packages(suite.gym_packages)
    unknown = [e.id for e in suite.envs if e.id not in gym.registry]
    if len(unknown) == 1:
        check_env_id(unknown[0])
    if unknown:
        from .envs import registered_ids

        raise UserError(
            f"unknown env ids {unknown}; registered Hexapod env ids: "
            f"{', '.join(registered_ids()) or '(none)'}"
        )


def _missing_reason(name: str, env_id: str) -> str | None:
    """Why a shipped policy does not exist yet (no model file, no registry entry), or None."""
    if name.startswith(PPO_PREFIX):
        path = _ppo_path(name, env_id)
        if not path.exists():
            return f"no model at {path} (train one and copy its model directory there)"
    if name == "analytical":
        from ..registry import ANALYTICAL_POLICIES

        if env_id not in ANALYTICAL_POLICIES:
            return "no analytical controller registered in agents/registry.py"
    return None


def _kwargs_note(
    env: gym.Env,
    suite_env: SuiteEnv,
    name: str,
    trained: dict[str, Any] | None,
    policy_kwargs: dict[str, Any],
) -> str | None:
    """A warning when a model was trained with env kwargs (defaults filled in) other than the
    suite's with `policy_kwargs` (its action and observation settings) on top."""
    if trained is None:
        return None
    defaults = constructor_defaults(env)
    evaluated = {**suite_env.kwargs, **policy_kwargs}
    differing = {}
    # a held-out task distribution is the point of the evaluation, not a mismatch
    for key in sorted((set(trained) | set(evaluated)) - {"task_distribution"}):
        a = trained.get(key, defaults.get(key))
        b = evaluated.get(key, defaults.get(key))
        if a != b:
            differing[key] = (a, b)
    if not differing:
        return None
    return (
        f"{suite_env.id}: {name} was trained with other env kwargs than evaluated here "
        "(key: trained -> evaluated): "
        + ", ".join(f"{k}: {a!r} -> {b!r}" for k, (a, b) in differing.items())
    )


def _settings_note(
    env: gym.Env,
    suite_env: SuiteEnv,
    name: str,
    model_dir: Path | None,
    policy: Policy,
    policy_kwargs: dict[str, Any],
) -> tuple[str | None, bool]:
    """(note, harmless) when a model was trained on an env set up otherwise than `env`, the
    one it is evaluated on: every recorded setting of its training env
    (`agents.run_files.env_settings`) against `env`'s, so that a default changed since the training
    shows; for a model without that record (older runs, envs without typed settings) its
    config's kwargs against the suite's.

    Harmless: only reward scales differ (told apart for models with the settings record only;
    the kwargs comparison of older models is always a warning). The agent acts the same under
    any reward, and the evaluation scores every policy with the evaluated env's reward, so that
    is a note of the report, not a warning."""
    trained, current = read_settings(model_dir), resolved_settings(env)
    if trained is None or current is None:
        trained_kwargs = getattr(policy, "train_env_kwargs", None)
        return _kwargs_note(env, suite_env, name, trained_kwargs, policy_kwargs), False
    found = differences(trained, current)
    if not found:
        return None, False
    note = (
        f"{suite_env.id}: {name} was trained on an env set up otherwise than evaluated here "
        f"(setting: trained -> evaluated): {describe(found)}"
    )
    return note, reward_only(found)


def prepare(
    suite: EvaluationSuite,
) -> tuple[list[tuple[EnvResult, dict]], list[str], list[str]]:
    """Make every env and policy (all checks happen here). Returns, per suite env, its result
    and ``{policy name: (policy, env)}`` (policies that read actions alike share one env), then
    warning lines and note lines."""
    _check_env_ids(suite)
    warnings: list[str] = []
    notes: list[str] = []
    skipped: dict[str, list[tuple[str, str]]] = {}  # policy -> [(env id, why)]
    prepared = []
    for suite_env in suite.envs:
        env = _env_spec(suite, suite_env).make()
        envs: dict[tuple, gym.Env] = {(): env}
        result = EnvResult(
            env_id=suite_env.id,
            kwargs=dict(suite_env.kwargs),
            max_episode_steps=env.spec.max_episode_steps if env.spec else None,
            dt=env_time_step(env),
            specs=metric_specs(env),
            aliases=policy_aliases(suite.policies),
        )
        result.xi_deg, result.criterion = stability_threshold(env, suite.xi_f_deg)
        result.rules = episode_rules(env)
        if not getattr(env.unwrapped, "walks", True):  # a standing task (the Stewart tilt):
            result.unranked = ("speed_m_s",)  # distance is drift or a fall, not progress
        policies = {}
        for name in suite.policies:
            missing = _missing_reason(name, suite_env.id)
            if missing and suite.missing_models == "skip":
                skipped.setdefault(name, []).append((suite_env.id, missing))
                continue
            extra = policy_env_kwargs(name, suite_env.id, suite_env.kwargs)
            key = tuple(sorted(extra.items()))
            if key not in envs:
                envs[key] = _env_spec(suite, suite_env, **extra).make()
            policy, source = build_policy(name, envs[key], suite_env.id, suite)
            run = PolicyRun(name=name, source=source, env_kwargs=extra)
            files = getattr(getattr(policy, "learned", policy), "files", None)
            run.model_dir = getattr(files, "directory", None)
            note, harmless = _settings_note(
                envs[key],
                suite_env,
                name.replace("{env_id}", suite_env.id),
                run.model_dir,
                policy,
                extra,
            )
            if note:
                run.notes.append(note)
                (notes if harmless else warnings).append(note)
            result.runs[name] = run
            policies[name] = (policy, envs[key])
        used = {id(e) for _, e in policies.values()}
        for unused in (e for e in envs.values() if id(e) not in used):
            unused.close()
        prepared.append((result, policies))
    skip_warnings, skip_notes = _skip_lines(skipped, [r for r, _ in prepared])
    return prepared, warnings + skip_warnings, skip_notes + notes


def _skip_lines(
    skipped: dict[str, list[tuple[str, str]]], results: list[EnvResult]
) -> tuple[list[str], list[str]]:
    """(warnings, notes) for the skipped policies: a warning per env, except for a per-env
    model path that exists for some envs only (e.g. ``ppo:models/{env_id}/gains``, a model for
    one env), which is one note."""
    warnings, notes = [], []
    for name, misses in skipped.items():
        ran = [r.env_id for r in results if name in r.runs]
        if "{env_id}" in name and ran:
            notes.append(
                f"{name} runs on {', '.join(ran)} only: no model at "
                f"{name[len(PPO_PREFIX) :]} for {', '.join(env for env, _ in misses)}"
            )
        else:
            warnings.extend(f"{env}: skipped {name} - {why}" for env, why in misses)
    return warnings, notes


def run_suite(
    suite: EvaluationSuite, progress: bool = True, video_dir: Path | None = None
) -> SuiteResult:
    """Run every policy on every env; `video_dir`: write an MP4 per policy and env there."""
    from tqdm.auto import tqdm

    start = time.perf_counter()
    prepared, warnings, notes = prepare(suite)
    for result, policies in prepared:
        for name, (policy, env) in policies.items():
            run = result.runs[name]
            # one bar (with its ETA) per env x policy; it stays on screen when done
            with tqdm(
                total=suite.episodes,
                desc=f"{result.env_id} {result.label(name)}",
                unit="episode",
                disable=not progress,
                dynamic_ncols=True,
            ) as bar:
                for k, seed in enumerate(suite.seeds):
                    acc = EpisodeAccumulator(
                        result.dt, result.specs, keep_trace=k == 0, xi_f_deg=result.xi_deg
                    )
                    run.episodes.append(run_episode(env, policy, seed, acc))
                    bar.update(1)
        for env in {id(e): e for _, e in policies.values()}.values():
            env.close()
        if suite.frames or video_dir is not None:
            warnings.extend(_render(suite, result, policies, video_dir))
    return SuiteResult(
        suite, [r for r, _ in prepared], warnings, time.perf_counter() - start, notes
    )


CAMERA = "track"
"""Every robot model has a camera of this name that tracks the body and keeps it in frame."""


def _render(suite: EvaluationSuite, result: EnvResult, policies: dict, video_dir: Path | None):
    """Re-run the first seed of each policy with rendering: keep `frame_count` frames for the
    strip and, with `video_dir`, write about `video_fps` frames per simulated second to an MP4
    that plays in real time."""
    width, height = suite.frame_size
    suite_env = next(e for e in suite.envs if e.id == result.env_id)
    render_kwargs = {"render_mode": "rgb_array", "width": width, "height": height}
    envs: dict[tuple, gym.Env] = {}

    def render_env(extra: dict[str, Any]) -> gym.Env:
        key = tuple(sorted(extra.items()))
        if key not in envs:
            try:
                spec = _env_spec(suite, suite_env, **extra, **render_kwargs, camera_name=CAMERA)
                envs[key] = spec.make()
            except UserError:  # envs of other packages: no size or camera keywords
                envs[key] = _env_spec(suite, suite_env, **extra, render_mode="rgb_array").make()
        return envs[key]

    warnings = []
    slug = result.env_id.replace("/", "_")
    steps_per_s = 1.0 / result.dt if result.dt else 50.0
    stride = max(1, round(steps_per_s / suite.video_fps))
    try:
        for name in policies:
            run = result.runs[name]
            env = render_env(run.env_kwargs)
            # a new policy on the render env: controllers read their env's state
            policy, _ = build_policy(name, env, result.env_id, suite)
            length = run.episodes[0].length
            wanted = set(np.linspace(0, length, suite.frame_count).round().astype(int).tolist())
            frames: list[np.ndarray] = []
            movie: list[np.ndarray] = []

            def grab(step: int, env=env, wanted=wanted, frames=frames, movie=movie) -> None:
                keep_frame = suite.frames and step in wanted
                keep_movie = video_dir is not None and step % stride == 0
                if keep_frame or keep_movie:
                    image = np.asarray(env.render())
                    if keep_frame:
                        frames.append(image)
                    if keep_movie:
                        movie.append(image)

            acc = EpisodeAccumulator(result.dt, result.specs)
            try:
                run_episode(env, policy, suite.seeds[0], acc, on_step=grab)
            except Exception as exc:  # rendering back ends fail in many ways (no EGL, ...)
                warnings.append(f"{result.env_id} {name}: no frames ({type(exc).__name__}: {exc})")
                return warnings
            if suite.frames:
                run.frames = frames
            if video_dir is not None and movie:
                safe = "".join(c if c.isalnum() else "_" for c in name)
                run.video = video_dir / f"{slug}_{safe}.mp4"
                _write_mp4(run.video, movie, steps_per_s / stride)
    finally:
        for env in envs.values():
            env.close()
    return warnings


def _write_mp4(path: Path, frames: list[np.ndarray], fps: float) -> None:
    """H.264 MP4 through imageio's ffmpeg plugin (the ffmpeg binary ships in imageio-ffmpeg)."""
    import imageio.v2 as imageio

    path.parent.mkdir(parents=True, exist_ok=True)
    with imageio.get_writer(path, fps=fps, codec="libx264", quality=7, macro_block_size=8) as w:
        for frame in frames:
            w.append_data(frame)
