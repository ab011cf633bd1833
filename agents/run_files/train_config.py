"""The training config (``configs/<env>_ppo.yaml``) as typed dataclasses.

Every level rejects unknown keys (listing the valid ones); see `configtools`. Frequencies are in
environment steps summed over all parallel envs (the unit of ``total_timesteps``).

Numeric ranges, checked when the config is loaded (a value outside names its key; NaN and
infinities are outside every range):

| key | valid |
|---|---|
| ``ppo.learning_rate``, ``ppo.clip_range``, ``ppo.clip_range_vf`` | > 0 at start, >= 0 at end |
| ``ppo.n_steps``, ``ppo.n_epochs`` | >= 1 |
| ``ppo.batch_size`` | 1 .. ``ppo.n_steps`` x ``vec_env.n_envs`` |
| ``ppo.gamma`` | (0, 1] |
| ``ppo.gae_lambda`` | [0, 1] |
| ``ppo.ent_coef``, ``ppo.vf_coef`` | >= 0 |
| ``ppo.max_grad_norm``, ``ppo.target_kl`` (unless null) | > 0 |
| ``ppo.sde_sample_freq`` | >= -1 (-1: only at the start of a rollout) |
| ``normalize.clip_observation``, ``normalize.clip_reward`` | > 0 |
| ``policy.pi``, ``policy.vf`` | layer sizes >= 1 |
| ``policy.log_std_init`` | finite |
| ``train.total_timesteps``, ``train.num_threads``, ``vec_env.n_envs``, ``eval.n_episodes`` | >= 1 |
| ``train.seed``, ``eval.freq``, ``checkpoint.freq`` | >= 0 (a frequency of 0 disables it) |
| ``logging.verbose`` | 0, 1 or 2 |
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from hexapod_envs.wrappers import EpisodeReward

from ..hybrid import HybridSettings
from ..knobs import KnobSettings
from ..warm_start import WarmStartSettings
from .configtools import apply_overrides, from_mapping, load_yaml
from .errors import ConfigError
from .schedules import Schedule, parse_optional_schedule, parse_schedule

DEFAULT_GYM_PACKAGES = ["hexapod_envs"]


def _require(key: str, value: Any, valid: str, ok: bool) -> None:
    """ValueError naming `key` and its valid range unless `ok`."""
    if not ok:
        raise ValueError(f"{key} must be {valid}, got {value!r}")


def _finite(value: Any) -> bool:
    return isinstance(value, int | float) and math.isfinite(value)


def _require_schedule(key: str, schedule: Schedule) -> None:
    """A learning-rate-like schedule: positive at the start, never negative."""
    values = (schedule.initial, schedule.final)
    ok = all(_finite(v) for v in values) and schedule.initial > 0 and schedule.final >= 0
    shown = schedule.initial if schedule.is_constant else values
    _require(key, shown, "> 0 (a linear schedule may end at 0)", ok)


@dataclass
class EnvConfig:
    """Which env to train on and how to build it."""

    id: str
    kwargs: dict[str, Any] = field(default_factory=dict)
    max_episode_steps: int | None = None  # None: the registered time limit
    gym_packages: list[str] = field(default_factory=lambda: list(DEFAULT_GYM_PACKAGES))
    # modules imported (by name) before gym.make so that their env ids are registered
    reward_exclude: list[str] = field(default_factory=list)
    """Reward terms (``info["reward_<term>"]``) taken out of the reward the learner sees
    (`agents.pipeline.envs.ExcludeRewardTerms`); the evaluation reports the env's own return."""
    decision: Literal["step", "gait_cycle", "episode"] = "step"
    """When the learner acts: every env step, once per gait cycle (`gait_cycle`: the
    irregular terrain's "gains" mode, or, on the ditch crossing's stride action with the
    residuals off, once per platform step, through `hexapod_envs.wrappers.GainsPerCycle`; training
    steps then count gait cycles (platform steps), and the training episodes' TensorBoard
    statistics see each cycle's last step only; evaluations still run every env step, see the
    wrapper), or once per episode (`episode`: the gains mode with one setting held over the
    whole episode, `hexapod_envs.wrappers.GainsPerEpisode`; training steps and evaluations
    count episodes, rewarded as ``episode_reward`` says)."""
    episode_reward: EpisodeReward = "success"
    """With ``decision: episode``: the learner's reward per episode, "success" (1 when it meets
    the env's success rule, else 0), "stable_success" (a success graded by its largest tilt,
    `hexapod_envs.wrappers.episode_reward`; -v1 ids) or "return" (the env's rewards summed).
    ("margin_success" is for the ditch planner's knobs, ``knobs.reward``.)"""
    stability_penalty: float = 0.0
    """A per-step penalty of this weight while the robot tips and while its tilt is past the
    success rule's bound (`hexapod_envs.wrappers.StabilityRulePenalty`, terms ``rule_tipping``
    and ``rule_tilt``; -v1 ids): the return then pays for what the v1 success rule demands;
    0: off. Training-time evaluations include it (their returns in ``evaluations.npz`` and the
    return tie-break of ``eval.select``); ``evaluate.py`` reports the env's own return."""
    progress_penalty: float = 0.0
    """With ``stability_penalty``: a per-step penalty of this weight while a walking heavy-duty
    env's CoG is short of the success rule's share of the reference gait's distance so far
    (``info["behind_pace"]``, term ``rule_progress``; the cliff walk): a policy that can stop
    the gait (``clock_action``) otherwise earns the most return by stopping early; 0: off."""
    min_task_difficulty: float | None = None
    """Train (and evaluate during training) on the sampled tasks of difficulty at least this
    (`hexapod_envs.curriculum.MinimumDifficulty`, drawn through the env's ``np_random``); None:
    the whole ``task_distribution``."""
    cycle_baseline: Literal["none", "zero_action"] = "none"
    """With ``decision: gait_cycle``: "zero_action" makes each cycle's reward the difference to
    the same cycle replayed from the same state with the zero action (a hybrid run's paper
    gains), see `hexapod_envs.wrappers.GainsPerCycle`; every cycle is then simulated twice."""
    stride_choices: list[float] | None = None
    """The ditch crossing's stride action (``stride_action: true``, residuals off) as a choice
    among these stride values (`hexapod_envs.wrappers.StrideChoices`: 0 the full stride, -0.5
    half of it), learnt by a categorical policy once per platform step (``decision:
    gait_cycle``); the first must be the full stride (0.0): an untrained model takes it
    deterministically, its step 0. None: the env's own action."""
    stride_clearances: bool = False
    """With ``stride_choices``: append to the observation, for each stride value, where it would
    land the moving platform's worst-placed foot relative to the ditch's edges
    (`hexapod_envs.wrappers.StrideClearances`); the actor sees it."""
    vectorization: Literal["vec_env", "batched"] = "vec_env"
    """How the ``vec_env.n_envs`` training envs run: "vec_env", the SB3 vec env that
    ``vec_env.type`` picks (SubprocVecEnv or DummyVecEnv); "batched", one process whose envs'
    physics runs on ``vec_env.physics_threads`` threads beside the rest of each env's step
    (`agents.pipeline.batched_vec_env`, on `hexapod_envs.vector.BatchedPhysics`): the same
    transitions as DummyVecEnv, for hexapod env ids whose learner acts at every step without a
    hybrid policy (those wrappers change the action between the learner and the env)."""


@dataclass
class VecEnvConfig:
    n_envs: int = 1
    type: Literal["auto", "subprocess", "dummy"] = "auto"  # auto: subprocess when n_envs > 1
    start_method: Literal["forkserver", "spawn", "fork"] | None = None  # None: SB3's default
    physics_threads: int | None = None
    """With ``env.vectorization: batched``: the threads that step the envs' physics, the main
    thread among them where the envs' periods run compiled (`hexapod_envs.vector.BatchedPhysics`;
    None: the CPUs, at most ``n_envs``; 0: the main thread steps each env within its step)."""

    def __post_init__(self):
        _require("vec_env.n_envs", self.n_envs, ">= 1", self.n_envs >= 1)
        threads = self.physics_threads
        whole = isinstance(threads, int) and not isinstance(threads, bool)
        ok = threads is None or (whole and threads >= 0)
        _require("vec_env.physics_threads", threads, "an integer >= 0 or null", ok)

    @property
    def use_subprocess(self) -> bool:
        return self.type == "subprocess" or (self.type == "auto" and self.n_envs > 1)


@dataclass
class NormalizeConfig:
    """VecNormalize: running mean/std of observations and of the discounted return."""

    observation: bool = True
    reward: bool = True
    clip_observation: float = 10.0
    clip_reward: float = 10.0

    def __post_init__(self):
        for name in ("clip_observation", "clip_reward"):
            value = getattr(self, name)
            _require(f"normalize.{name}", value, "> 0", _finite(value) and value > 0)


ACTIVATIONS = ("tanh", "relu", "elu", "leaky_relu", "gelu", "silu")


@dataclass
class PolicyConfig:
    """SB3 MlpPolicy: separate actor (pi) and critic (vf) networks."""

    pi: list[int] = field(default_factory=lambda: [256, 256])
    vf: list[int] = field(default_factory=lambda: [256, 256])
    activation: Literal["tanh", "relu", "elu", "leaky_relu", "gelu", "silu"] = "tanh"
    log_std_init: float = 0.0
    ortho_init: bool = True
    zero_init_action_net: bool = False
    """Zero the last layer of the action mean, so that training starts at the zero action (in a
    residual action mode: the reference motion) instead of a random one. A hybrid run's
    ``hybrid.zero_init_action_net`` does the same (default there: true)."""
    critic_privileged: bool = False
    """An asymmetric actor-critic: the value function also sees the task's parameters and the
    elapsed share of the episode (`agents.privileged_critic`); the actor still sees only the
    sensor observation."""
    score_read_actions_only: bool = False
    """PPO's likelihood counts an action value only on the steps where the env reads it (an env
    that reads some values only on some steps names them in ``action_read_flags``, such as the
    ditch's stride value, and those it never reads in ``inert_actions``, such as its residuals
    with a range of 0): an ignored value's sample adds noise and no signal to the gradient
    (`agents.read_actions`). Training only; a trained model acts as any other."""

    def __post_init__(self):
        for name in ("pi", "vf"):
            sizes = getattr(self, name)
            _require(
                f"policy.{name}", sizes, "a list of layer sizes >= 1", all(n >= 1 for n in sizes)
            )
        _require("policy.log_std_init", self.log_std_init, "finite", _finite(self.log_std_init))

    def policy_kwargs(self) -> dict[str, Any]:
        from torch import nn

        activation = {
            "tanh": nn.Tanh,
            "relu": nn.ReLU,
            "elu": nn.ELU,
            "leaky_relu": nn.LeakyReLU,
            "gelu": nn.GELU,
            "silu": nn.SiLU,
        }[self.activation]
        return {
            "net_arch": {"pi": list(self.pi), "vf": list(self.vf)},
            "activation_fn": activation,
            "log_std_init": self.log_std_init,
            "ortho_init": self.ortho_init,
        }


@dataclass
class PPOConfig:
    """stable-baselines3 PPO hyperparameters (same names); schedules as in `schedules`."""

    learning_rate: Schedule = field(
        default_factory=lambda: Schedule("constant", 3e-4), metadata={"parse": parse_schedule}
    )
    n_steps: int = 2048  # per env, per rollout
    batch_size: int = 64
    n_epochs: int = 10
    gamma: float = 0.99
    gae_lambda: float = 0.95
    clip_range: Schedule = field(
        default_factory=lambda: Schedule("constant", 0.2), metadata={"parse": parse_schedule}
    )
    clip_range_vf: Schedule | None = field(
        default=None, metadata={"parse": parse_optional_schedule}
    )
    normalize_advantage: bool = True
    ent_coef: float = 0.0
    vf_coef: float = 0.5
    max_grad_norm: float = 0.5
    use_sde: bool = False
    sde_sample_freq: int = -1
    target_kl: float | None = None

    def __post_init__(self):
        _require_schedule("ppo.learning_rate", self.learning_rate)
        _require_schedule("ppo.clip_range", self.clip_range)
        if self.clip_range_vf is not None:
            _require_schedule("ppo.clip_range_vf", self.clip_range_vf)
        for name in ("n_steps", "batch_size", "n_epochs"):
            _require(f"ppo.{name}", getattr(self, name), ">= 1", getattr(self, name) >= 1)
        g, lam = self.gamma, self.gae_lambda
        _require("ppo.gamma", g, "in (0, 1]", _finite(g) and 0 < g <= 1)
        _require("ppo.gae_lambda", lam, "in [0, 1]", _finite(lam) and 0 <= lam <= 1)
        for name in ("ent_coef", "vf_coef"):
            value = getattr(self, name)
            _require(f"ppo.{name}", value, ">= 0", _finite(value) and value >= 0)
        mgn = self.max_grad_norm
        _require("ppo.max_grad_norm", mgn, "> 0", _finite(mgn) and mgn > 0)
        freq = self.sde_sample_freq
        _require("ppo.sde_sample_freq", freq, ">= -1", freq >= -1)
        if self.target_kl is not None:
            kl = self.target_kl
            _require("ppo.target_kl", kl, "> 0 or null", _finite(kl) and kl > 0)

    def sb3_kwargs(self) -> dict[str, Any]:
        return {
            "learning_rate": self.learning_rate,
            "n_steps": self.n_steps,
            "batch_size": self.batch_size,
            "n_epochs": self.n_epochs,
            "gamma": self.gamma,
            "gae_lambda": self.gae_lambda,
            "clip_range": self.clip_range,
            "clip_range_vf": self.clip_range_vf,
            "normalize_advantage": self.normalize_advantage,
            "ent_coef": self.ent_coef,
            "vf_coef": self.vf_coef,
            "max_grad_norm": self.max_grad_norm,
            "use_sde": self.use_sde,
            "sde_sample_freq": self.sde_sample_freq,
            "target_kl": self.target_kl,
        }


@dataclass
class TrainingConfig:
    total_timesteps: int = 1_000_000
    seed: int = 0
    device: str = "cpu"
    num_threads: int = 1
    """torch intra-op threads. 1 by default: with subprocess envs on a small CPU machine, more
    threads oversubscribe the cores (three runs on 2 cores fell from ~290 to ~30 steps/s)."""

    def __post_init__(self):
        for name in ("num_threads", "total_timesteps"):
            _require(f"train.{name}", getattr(self, name), ">= 1", getattr(self, name) >= 1)
        _require("train.seed", self.seed, ">= 0", self.seed >= 0)
        if self.device != "auto":  # SB3's "auto": CUDA when available
            import torch  # here, not at import: the config is read where torch is not needed

            try:
                torch.device(self.device)
            except (RuntimeError, TypeError):
                valid = '"auto" or a torch device ("cpu", "cuda", "cuda:<n>", ...)'
                _require("train.device", self.device, valid, False)


@dataclass
class EvalConfig:
    """Periodic evaluation (SB3 EvalCallback) that keeps the best model; freq 0 disables it."""

    freq: int = 20_000
    n_episodes: int = 5
    deterministic: bool = True
    same_tasks: bool = False
    """Reseed the evaluation env before every evaluation, so that every checkpoint (and step 0)
    is scored on the same `n_episodes` tasks; false: each evaluation draws new tasks (the task
    mix then adds to the differences between checkpoints)."""
    select: Literal["reward", "success"] = "reward"
    """What ``best/`` keeps: the highest mean evaluation return (SB3's rule), or the highest
    success rate with the mean return breaking ties."""

    def __post_init__(self):
        _require("eval.freq", self.freq, ">= 0 (0 disables evaluation)", self.freq >= 0)
        _require("eval.n_episodes", self.n_episodes, ">= 1", self.n_episodes >= 1)


@dataclass
class CheckpointConfig:
    """Periodic checkpoints (model + VecNormalize); freq 0 keeps only final/interrupt ones."""

    freq: int = 50_000

    def __post_init__(self):
        _require("checkpoint.freq", self.freq, ">= 0 (0: only final/interrupt)", self.freq >= 0)


@dataclass
class LoggingConfig:
    tensorboard: bool = True
    progress_bar: bool = True
    verbose: int = 0  # 1: also print SB3's log table to stdout

    def __post_init__(self):
        _require("logging.verbose", self.verbose, "0, 1 or 2", self.verbose in (0, 1, 2))


@dataclass
class HybridConfig(HybridSettings):
    """``hybrid:`` section: train the policy on top of the env's analytical controller.

    The fields of `agents.hybrid.HybridSettings` (mode, scale, safety_filter, threshold_deg,
    release_margin_deg) plus how the network starts. Absent (null): plain PPO on the env.
    """

    zero_init_action_net: bool = True
    """Zero the action mean's last layer so that training starts from the analytical controller
    (SB3's policy_kwargs have no such option: ortho_init only scales that layer by 0.01)."""
    mask_overridden: bool = False
    """Give the steps whose learned action the safety override discarded no advantage, so that
    PPO learns only from actions that acted (`agents.pipeline.override_mask`); needs the
    override (``mode: safety`` or ``safety_filter: true``)."""

    def __post_init__(self):
        super().__post_init__()
        if self.mask_overridden and not self.overrides:
            raise ValueError(
                "hybrid.mask_overridden needs the safety override: set hybrid.mode=safety or "
                "hybrid.safety_filter=true (in residual mode every learned action acts)"
            )


@dataclass
class KnobConfig(KnobSettings):
    """``knobs:`` section: train a policy that sets the tipping recovery's knobs once per tipping
    event, or the ditch planner's once per episode (`agents.knobs`, `agents.plan_knobs`: names,
    event_margin_deg, reward, course). Absent (null): no knobs."""

    zero_init_action_net: bool = True
    """Zero the action mean's last layer so that training starts from the controller's own
    settings."""


@dataclass
class TrainConfig:
    env: EnvConfig
    vec_env: VecEnvConfig = field(default_factory=VecEnvConfig)
    normalize: NormalizeConfig = field(default_factory=NormalizeConfig)
    policy: PolicyConfig = field(default_factory=PolicyConfig)
    ppo: PPOConfig = field(default_factory=PPOConfig)
    train: TrainingConfig = field(default_factory=TrainingConfig)
    eval: EvalConfig = field(default_factory=EvalConfig)
    checkpoint: CheckpointConfig = field(default_factory=CheckpointConfig)
    logging: LoggingConfig = field(default_factory=LoggingConfig)
    hybrid: HybridConfig | None = None  # None: plain PPO; see agents/hybrid.py
    knobs: KnobConfig | None = None  # None: no controller knobs; see agents/knobs.py
    warm_start: WarmStartSettings | None = None  # None: PPO from its initial actor; see
    # agents/warm_start.py (behaviour cloning of a teacher into the actor first)

    @property
    def starts_at_zero_action(self) -> bool:
        """Whether training zeroes the actor's output layer first (``zero_init_action_net`` of
        ``policy``, ``hybrid`` or ``knobs``): a deterministic step-0 action of exactly 0."""
        hybrid = self.hybrid is not None and self.hybrid.zero_init_action_net
        knobs = self.knobs is not None and self.knobs.zero_init_action_net
        return hybrid or knobs or self.policy.zero_init_action_net

    def _check_stride_choices(self) -> None:
        """``env.stride_choices`` replaces the env's action with one categorical choice, taken
        once per platform step, whose first value is the untrained model's (its step 0)."""
        choices = self.env.stride_choices
        if not choices or choices[0] != 0.0:
            raise ValueError(
                "env.stride_choices must start with 0.0, the full stride: an untrained model "
                f"takes the first choice, its step 0 (the zero action); got {choices}"
            )
        conflicts = {
            "a hybrid section": self.hybrid is not None,
            "a knobs section": self.knobs is not None,
            "a warm_start section": self.warm_start is not None,
            f"env.decision: {self.env.decision} (use gait_cycle)": self.env.decision
            != "gait_cycle",
            "env.vectorization: batched": self.env.vectorization == "batched",
            "policy.score_read_actions_only: true (the choice is the only value)": (
                self.policy.score_read_actions_only
            ),
            "ppo.use_sde: true (gSDE is for continuous actions)": self.ppo.use_sde,
        }
        found = [name for name, present in conflicts.items() if present]
        if found:
            raise ValueError(
                "env.stride_choices replaces the env's action with one categorical choice per "
                f"platform step; it does not go with {'; '.join(found)}"
            )

    def __post_init__(self):
        rollout = self.ppo.n_steps * self.vec_env.n_envs
        if rollout < 2:
            raise ValueError(f"ppo.n_steps x vec_env.n_envs must be > 1, got {rollout}")
        if self.ppo.batch_size > rollout:
            raise ValueError(
                f"ppo.batch_size={self.ppo.batch_size} exceeds the rollout size "
                f"ppo.n_steps x vec_env.n_envs = {rollout}"
            )
        if self.env.vectorization == "batched" and (
            self.hybrid is not None or self.env.decision != "step"
        ):
            raise ValueError(
                "env.vectorization: batched applies the learner's action before each env steps, "
                "so it needs env.decision: step and no hybrid section (both change the action "
                "between the learner and the env); use env.vectorization: vec_env"
            )
        if not (self.env.stability_penalty >= 0 and math.isfinite(self.env.stability_penalty)):
            raise ValueError(
                f"env.stability_penalty must be a number >= 0 (0: off), got "
                f"{self.env.stability_penalty}"
            )
        if not (self.env.progress_penalty >= 0 and math.isfinite(self.env.progress_penalty)):
            raise ValueError(
                f"env.progress_penalty must be a number >= 0 (0: off), got "
                f"{self.env.progress_penalty}"
            )
        if self.env.progress_penalty and not self.env.stability_penalty:
            raise ValueError(
                "env.progress_penalty is a term of the stability-rule penalty's wrapper: set "
                "env.stability_penalty > 0 too (or env.progress_penalty: 0)"
            )
        if self.env.vectorization == "batched" and self.vec_env.type == "subprocess":
            raise ValueError(
                "env.vectorization: batched runs every env in this process (its physics on "
                "vec_env.physics_threads threads), so vec_env.type: subprocess does not apply; "
                "set vec_env.type: auto or dummy, or env.vectorization: vec_env"
            )
        if self.knobs is not None and (
            self.hybrid is not None
            or self.env.decision != "step"
            or self.env.vectorization == "batched"
            or self.env.reward_exclude
        ):
            raise ValueError(
                "knobs: one learner step per tipping event or episode, rewarded by the "
                "episode's outcome; "
                "it needs no hybrid section, env.decision: step, env.vectorization: vec_env and "
                "no env.reward_exclude"
            )
        if self.env.decision == "episode" and self.env.episode_reward == "margin_success":
            raise ValueError(
                'env.episode_reward: "margin_success" grades a success by the static margin of '
                "the ditch crossing, whose planner's settings a knobs section learns "
                '(knobs.reward); with env.decision: episode use "success", "stable_success" or '
                '"return"'
            )
        if self.env.stride_choices is not None:
            self._check_stride_choices()
        elif self.env.stride_clearances:
            raise ValueError(
                "env.stride_clearances appends one value per stride choice; it needs "
                "env.stride_choices"
            )
        if self.policy.score_read_actions_only and (
            self.hybrid is not None
            or self.knobs is not None
            or self.env.decision == "episode"
            or self.ppo.use_sde
        ):
            raise ValueError(
                "policy.score_read_actions_only scores the env's own action values, one per "
                "control step or gait cycle, with a diagonal Gaussian; it needs no hybrid or "
                "knobs section, env.decision: step or gait_cycle (the others change the action "
                "and the observation) and ppo.use_sde: false"
            )
        if self.warm_start is not None and (
            self.hybrid is not None or self.knobs is not None or self.env.decision != "step"
        ):
            raise ValueError(
                "warm_start clones a teacher's actions into the actor, one per control step of "
                "the env as configured; it needs no hybrid or knobs section and env.decision: step"
            )
        planner_knobs = self.knobs is not None and self.knobs.controller == "planner"
        if planner_knobs and self.policy.critic_privileged:
            raise ValueError(
                "policy.critic_privileged appends the task to the env's observation, but a "
                "policy of the ditch planner's knobs sees the course instead (agents.plan_knobs); "
                "set policy.critic_privileged: false"
            )
        if self.hybrid is not None and self.hybrid.mask_overridden and self.env.decision != "step":
            raise ValueError(
                "hybrid.mask_overridden needs env.decision: step (one learner step per gait "
                "cycle spans control steps with and without the override)"
            )


def load_train_config(
    path: str | Path | None = None,
    overrides: list[str] | tuple[str, ...] = (),
    data: dict[str, Any] | None = None,
) -> TrainConfig:
    """Read a training config from `path` (or raw `data`), apply ``key=value`` overrides, check."""
    if (path is None) == (data is None):
        raise ConfigError("give either a config path or config data")
    raw = load_yaml(path) if path is not None else data
    return from_mapping(TrainConfig, apply_overrides(raw, list(overrides)))
