"""Env ids, env creation with clear errors, and SB3 vec-env building (Monitor, VecNormalize).

An `EnvSpec` with a ``hybrid`` section builds the env wrapped in `agents.hybrid.HybridWrapper`
(the learned action on top of the env's analytical controller), so training, its evaluation
callback and every subprocess worker see the same hybrid env.
"""

from __future__ import annotations

import difflib
import importlib
import signal
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym
import numpy as np

from ..hybrid import wrap
from ..run_files.errors import UserError


def import_gym_packages(packages: Sequence[str]) -> None:
    """Import the modules that register env ids (e.g. ``hexapod_envs``), by name."""
    for name in packages:
        try:
            importlib.import_module(name)
        except ImportError as exc:
            raise UserError(f"cannot import gym package {name!r}: {exc}") from None


def registered_ids(prefix: str = "Hexapod") -> list[str]:
    return sorted(k for k in gym.registry if k.startswith(prefix))


def check_env_id(env_id: str, packages: Sequence[str] = ()) -> None:
    """UserError for an unregistered id, listing the registered Hexapod ids (and a close match)."""
    import_gym_packages(packages)
    if env_id in gym.registry:
        return
    hexapod = registered_ids()
    close = difflib.get_close_matches(env_id, list(gym.registry), n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    raise UserError(
        f"unknown env id {env_id!r}{hint}; registered Hexapod env ids: "
        f"{', '.join(hexapod) if hexapod else '(none)'}"
    )


def env_time_step(env: gym.Env) -> float | None:
    """Seconds per env step: ``control_dt`` of the hexapod envs, ``dt`` of Gymnasium MuJoCo."""
    for name in ("control_dt", "dt"):
        try:
            value = env.get_wrapper_attr(name)
        except AttributeError:
            continue
        if isinstance(value, int | float):
            return float(value)
    return None


@dataclass
class EnvSpec:
    """An env id with its keyword arguments: everything needed to build identical copies."""

    id: str
    kwargs: dict[str, Any] = field(default_factory=dict)
    max_episode_steps: int | None = None
    gym_packages: list[str] = field(default_factory=list)
    hybrid: Any = None
    """`agents.hybrid.HybridSettings` (or the training config's ``hybrid`` section): wrap the env
    so that actions are combined with its analytical controller; None: the env as it is."""
    reward_exclude: list[str] = field(default_factory=list)
    """Reward terms (``info["reward_<term>"]``) taken out of the reward the learner sees (see
    `ExcludeRewardTerms`); empty: the env's reward."""
    decision: str = "step"
    """"step": the learner acts at every env step; "gait_cycle": once per gait cycle, through
    `hexapod_envs.wrappers.GainsPerCycle` (the irregular terrain's "gains" mode; the ditch
    crossing's stride action with the residuals off, once per platform step); "episode":
    once per episode, through `hexapod_envs.wrappers.GainsPerEpisode`."""
    cycle_baseline: str = "none"
    """With decision "gait_cycle": "zero_action" rewards each cycle relative to the zero action
    replayed from the same state (`GainsPerCycle`'s ``baseline_action``); "none": plain."""
    privileged_critic: bool = False
    """Append the task and the episode's elapsed share to the observation for an asymmetric
    critic (`agents.privileged_critic.PrivilegedObservation`, inside every wrapper but
    `MinimumDifficulty`, `StabilityRulePenalty` and `StrideClearances`)."""
    knobs: Any = None
    """`agents.knobs.KnobSettings` (or the training config's ``knobs`` section): one learner
    step per tipping event, which sets the recovery's knobs (`agents.knobs.KnobsPerEvent`), or
    per episode, which sets the ditch planner's (`agents.plan_knobs.PlanKnobsPerEpisode`)."""
    episode_reward: str = "success"
    """With decision "episode": the reward of the learner's one step, one of
    `hexapod_envs.wrappers.EPISODE_REWARDS`."""
    min_task_difficulty: float | None = None
    """Only sampled tasks of at least this difficulty (`hexapod_envs.curriculum.MinimumDifficulty`,
    the innermost wrapper); None: every task of the distribution."""
    stability_penalty: float = 0.0
    """Weight of `hexapod_envs.wrappers.StabilityRulePenalty` (the next wrapper: every other
    one sees its penalised rewards); 0: none."""
    progress_penalty: float = 0.0
    """`StabilityRulePenalty`'s ``progress_weight`` (walking heavy-duty envs); 0: none."""
    stride_choices: list[float] | None = None
    """The ditch crossing's stride action as a choice among these stride values
    (`hexapod_envs.wrappers.StrideChoices`, inside the decision wrappers); None: the env's."""
    stride_clearances: bool = False
    """Append each stride choice's landing clearance to the observation
    (`hexapod_envs.wrappers.StrideClearances`, inside `PrivilegedObservation`: the actor sees
    it); needs `stride_choices`."""

    def make(self, **extra: Any) -> gym.Env:
        """gym.make (then the hybrid wrapper, if any) with the env's own errors (bad kwargs)
        turned into a UserError."""
        check_env_id(self.id, self.gym_packages)
        self._check_decision()
        kwargs = {**self.kwargs, **extra}
        if self.max_episode_steps is not None:
            kwargs["max_episode_steps"] = self.max_episode_steps
        try:
            env = gym.make(self.id, **kwargs)
        except (TypeError, ValueError) as exc:
            message = str(exc).split(" was raised from the environment creator")[0]
            raise UserError(f"cannot create {self.id} with {self.kwargs}: {message}") from None
        if self.min_task_difficulty is not None:
            from hexapod_envs.curriculum import MinimumDifficulty

            minimum = self.min_task_difficulty
            where = f"env.min_task_difficulty on {self.id}"
            env = _wrapped(env, lambda e: MinimumDifficulty(e, minimum), where)
        if self.stability_penalty:
            from hexapod_envs.wrappers import StabilityRulePenalty

            weight, progress = self.stability_penalty, self.progress_penalty
            where = f"env.stability_penalty / env.progress_penalty on {self.id}"
            env = _wrapped(env, lambda e: StabilityRulePenalty(e, weight, progress), where)
        if self.stride_clearances:
            from hexapod_envs.wrappers import StrideClearances

            choices, where = self.stride_choices, f"env.stride_clearances on {self.id}"
            env = _wrapped(env, lambda e: StrideClearances(e, choices), where)
        if self.privileged_critic:
            from ..privileged_critic import PrivilegedObservation

            env = PrivilegedObservation(env, env.spec.max_episode_steps)
        if self.knobs is not None:
            from ..knob_wiring import knobs_env
            from ..knobs import settings_from_config

            where = f"cannot build the knobs env on {self.id}"
            env = _wrapped(env, lambda e: knobs_env(e, settings_from_config(self.knobs)), where)
        if self.hybrid is not None:
            where = f"cannot build the hybrid policy env on {self.id}"
            env = _wrapped(env, lambda e: wrap(e, self.hybrid), where)
        if self.reward_exclude:
            env = ExcludeRewardTerms(env, self.reward_exclude)
        if self.stride_choices is not None:
            from hexapod_envs.wrappers import StrideChoices

            choices, where = self.stride_choices, f"env.stride_choices on {self.id}"
            env = _wrapped(env, lambda e: StrideChoices(e, choices), where)
        if self.decision == "gait_cycle":
            from hexapod_envs.wrappers import GainsPerCycle

            baseline = None
            if self.cycle_baseline == "zero_action":
                baseline = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)
            where = f"env.decision='gait_cycle' on {self.id}"
            env = _wrapped(env, lambda e: GainsPerCycle(e, baseline_action=baseline), where)
        if self.decision == "episode":
            from hexapod_envs.wrappers import GainsPerEpisode

            where = f"env.decision='episode' on {self.id}"
            env = _wrapped(env, lambda e: GainsPerEpisode(e, reward=self.episode_reward), where)
        return env

    def _check_decision(self) -> None:
        """`decision` and `cycle_baseline` name valid choices that fit together (before any env
        is built)."""
        if self.stride_clearances and self.stride_choices is None:
            raise UserError(
                "env.stride_clearances appends one value per stride choice; it needs "
                "env.stride_choices"
            )
        if self.decision not in ("step", "gait_cycle", "episode"):
            raise UserError(
                f"env.decision must be 'step', 'gait_cycle' or 'episode', got {self.decision!r}"
            )
        if self.cycle_baseline not in ("none", "zero_action"):
            raise UserError(
                f"env.cycle_baseline must be 'none' or 'zero_action', got {self.cycle_baseline!r}"
            )
        if self.cycle_baseline != "none" and self.decision != "gait_cycle":
            raise UserError(
                "env.cycle_baseline needs env.decision: gait_cycle (the baseline replays whole "
                f"gait cycles), got decision {self.decision!r}"
            )


def _wrapped(env: gym.Env, wrapper: Any, where: str) -> gym.Env:
    """``wrapper(env)``; a ValueError of it closes `env` and becomes a UserError "where: ..."."""
    try:
        return wrapper(env)
    except ValueError as exc:
        env.close()
        raise UserError(f"{where}: {exc}") from None


class ExcludeRewardTerms(gym.Wrapper):
    """The env's reward minus the named terms of its ``info["reward_<term>"]`` breakdown.

    For terms that drown what a run should learn, e.g. the irregular terrain's ``alive`` term in
    the "gains" mode: it pays the bound of every cost (rate_weight x 4 rad²/s² for the rate term
    alone) on every upright step, ~2000 times the rate term's differences between gain settings.
    A term missing from an info dict is an error (a misspelt name must not train silently)."""

    def __init__(self, env: gym.Env, terms: Sequence[str]):
        super().__init__(env)
        self.keys = [f"reward_{t}" for t in terms]

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        missing = [k for k in self.keys if k not in info]
        if missing and not info.get("sim_unstable", False):
            raise UserError(f"reward_exclude: no {', '.join(missing)} in the env's info")
        reward = float(reward) - sum(float(info.get(k, 0.0)) for k in self.keys)
        return obs, reward, terminated, truncated, info


class EnvFactory:
    """Picklable env constructor for SB3 vec envs (runs in subprocess workers too).

    With `worker` set (SubprocVecEnv), the worker process ignores SIGINT: a Ctrl-C is for the
    parent, which saves a checkpoint and then closes the workers itself. A worker that died of
    the same Ctrl-C mid-step would leave the parent waiting for its reply."""

    def __init__(self, spec: EnvSpec, worker: bool = False):
        self.spec, self.worker = spec, worker

    def __call__(self) -> gym.Env:
        from stable_baselines3.common.monitor import Monitor

        if self.worker:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        return Monitor(self.spec.make())


def make_vec_env(
    spec: EnvSpec,
    n_envs: int,
    seed: int,
    subprocess: bool,
    start_method: str | None = None,
):
    """A DummyVecEnv/SubprocVecEnv of `n_envs` monitored copies of `spec`, seeded seed..seed+n-1."""
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    spec.make().close()  # fail here, in the main process, with a clear error
    factories = [EnvFactory(spec, worker=subprocess) for _ in range(n_envs)]
    if subprocess:
        venv = SubprocVecEnv(factories, start_method=start_method)
    else:
        venv = DummyVecEnv(factories)
    venv.seed(seed)
    return venv
