"""Hybrid policies: a learned action on top of, or guarded by, the env's analytical controller.

Two ways of combining a learned policy with the env's reference controller
(``agents.registry.analytical_policy``), both available as a Gymnasium wrapper for training
(`HybridWrapper`) and as a `Policy` for evaluation (`HybridPolicy`); they share `HybridCore`,
so training and evaluation compute the same env action from the same observation.

``mode="residual"`` (residual RL over a model-based controller)
    env action = clip(analytical(obs) + scale x a). A zero learned action ``a`` reproduces the
    analytical controller exactly: the controller is reset at every env reset and called once
    per step on the observation the env returned, exactly as when it runs on its own.

``mode="safety"`` (a learned policy with a model-based safety fallback)
    env action = clip(scale x a) while the robot is stable, and the analytical controller's
    action while the force-angle stability margin (observation ``fasm_margin_deg``) is below
    ξ (`threshold_deg`, default ``env.unwrapped.tipping_threshold_deg``, else 20°). Hysteresis:
    the controller keeps control until the FASM is back above ξ + `release_margin_deg`. The
    controller is stepped at every step, also while the learned policy acts, so that its
    internal state (clock, gait phase, tipping judgment) is current when it takes over. Meant
    for residual action modes, where a zero env action is the env's reference motion.

    The heavy-duty robot's recovery (Zhang et al. 2024) acts once per episode: after judging
    tipping it lands a leg, distributes the foot forces and then holds that stance until the env
    resets; handing control back does not re-arm it. Every later override in the episode applies
    that recovery's supported or held posture, not a new judgment. Re-arming the controller at
    every hand-back (its plan cleared, its filters kept) is not done because it succeeded less
    often on the cliff's test tasks (CHANGELOG.md, Findings).

``safety_filter=True`` adds the same override to the residual mode: the learned residual is
dropped (the pure analytical action is applied) while the FASM is below ξ, so a residual cannot
spoil a recovery. ``info["safety_override"]`` tells, at every step, whether the analytical
controller alone chose the action.

Action modes: the learned action ``a`` has the shape of the env's action, in [-1, 1]. The
analytical action is in the env's own action mode, whatever it is: in ``"residual"`` mode it is
an offset from the env's reference motion, in ``"joint"`` mode normalised joint targets, in the
irregular terrain's ``"gains"`` mode the posture gains (k_z, k_α, k_β) in [0, 1]. ``scale`` is in
the units of that action (a fraction of each joint's normalised half range in the joint and
residual modes; gain units in the gains mode). The sum is clipped to the env's action space. Use
an action mode in which the analytical controller has full authority: the joint mode for the
cliff walk (the recovery needs targets beyond a 0.25 residual), the ditch crossing (the residual
filter cannot make up a wait at a gate) and the irregular terrain's blocks; the Stewart tilt's
default residual mode (scale 2 reaches every target) is fine.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import gymnasium as gym
import numpy as np

from .env_kwargs import POLICY_SETTINGS, constructor_defaults
from .policy import LearnedWithController, Policy, settings_from_section
from .registry import analytical_policy

MODES = ("residual", "safety")
DEFAULT_THRESHOLD_DEG = 20.0
"""ξ when the env does not say (the heavy-duty robot's FASM threshold)."""


@dataclass
class HybridSettings:
    """How the learned action and the analytical controller are combined (see module doc).

    Attributes:
        mode: "residual" (analytical + scale x a) or "safety" (scale x a, analytical below ξ).
        scale: multiplier of the learned action, in env action units (> 0); or one per action
            dimension (>= 0, not all 0: a 0 keeps that dimension at the analytical
            controller's, e.g. the paper's gains while a learner sets the body height).
        safety_filter: residual mode: drop the residual while the FASM is below ξ.
        threshold_deg: ξ [deg]; None: ``env.unwrapped.tipping_threshold_deg`` or 20 (an env
            that declares None, judged by another criterion, needs it for the override).
        release_margin_deg: hysteresis [deg]: the override ends when FASM >= ξ + this.
        override_cost: training only: reward subtracted on every step the override chose the
            action (`HybridWrapper`; info ``reward_safety_override``), so that the learned
            policy is paid to keep the robot out of the recovery; 0: off.
    """

    mode: Literal["residual", "safety"] = "residual"
    scale: float | list[float] = 0.1
    safety_filter: bool = False
    threshold_deg: float | None = None
    release_margin_deg: float = 5.0
    override_cost: float = 0.0

    def __post_init__(self):
        if self.mode not in MODES:
            raise ValueError(f"hybrid mode must be one of {MODES}, got {self.mode!r}")
        if isinstance(self.scale, list | tuple):
            scales = np.asarray(self.scale, dtype=float)
            if not (scales.size and np.all(np.isfinite(scales)) and (scales >= 0).all()):
                raise ValueError(
                    f"hybrid scale per action dimension must be finite numbers >= 0, "
                    f"got {self.scale}"
                )
            if not scales.any():
                raise ValueError(f"hybrid scale must not be 0 in every dimension: {self.scale}")
        elif not np.isfinite(self.scale) or self.scale <= 0:
            raise ValueError(f"hybrid scale must be a finite number > 0, got {self.scale}")
        if not np.isfinite(self.release_margin_deg) or self.release_margin_deg < 0:
            raise ValueError(
                f"hybrid release_margin_deg must be a finite number >= 0, got "
                f"{self.release_margin_deg}"
            )
        if not np.isfinite(self.override_cost) or self.override_cost < 0:
            raise ValueError(
                f"hybrid override_cost must be a finite number >= 0, got {self.override_cost}"
            )
        if self.override_cost and not self.overrides:
            raise ValueError(
                "hybrid override_cost needs the safety override: set mode=safety or "
                "safety_filter=true"
            )
        if self.threshold_deg is not None and not np.isfinite(self.threshold_deg):
            raise ValueError(
                f"hybrid threshold_deg must be finite or None, got {self.threshold_deg}"
            )

    @property
    def overrides(self) -> bool:
        """Whether the analytical controller takes over below ξ."""
        return self.mode == "safety" or self.safety_filter


def _action_box(env: gym.Env) -> gym.spaces.Box:
    space = env.action_space
    if not isinstance(space, gym.spaces.Box):
        raise ValueError(f"hybrid policies need a Box action space, got {space}")
    return space


class HybridCore:
    """The env action from an observation and a learned action; owns the analytical controller.

    Args:
        env: the env (any wrapper of it) the actions are for; its analytical controller is
            built from ``env.spec.id`` through `agents.registry`.
        settings: `HybridSettings`.
        base: the analytical controller to use instead of the registry's (tests, variants).
    """

    def __init__(self, env: gym.Env, settings: HybridSettings, base: Policy | None = None):
        self.settings = settings
        self.space = _action_box(env)
        structure = getattr(env.unwrapped, "observation_structure", None)
        if not structure or "fasm_margin_deg" not in structure:
            raise ValueError(
                f"{type(env.unwrapped).__name__} has no 'fasm_margin_deg' observation piece "
                "(env.unwrapped.observation_structure); the hybrid policies need it"
            )
        self._fasm = structure["fasm_margin_deg"]
        threshold = settings.threshold_deg
        if threshold is None:
            threshold = getattr(env.unwrapped, "tipping_threshold_deg", DEFAULT_THRESHOLD_DEG)
        if threshold is None and settings.overrides:
            raise ValueError(
                f"{type(env.unwrapped).__name__} declares no FASM threshold (its stability "
                "criterion is another one); give the hybrid section a threshold_deg to use the "
                "safety override"
            )
        self.threshold_deg = None if threshold is None else float(threshold)
        self.base = base if base is not None else analytical_policy(env)
        self.overriding = False
        self.scale = np.asarray(settings.scale, dtype=self.space.dtype)
        if self.scale.ndim and self.scale.shape != self.space.shape:
            raise ValueError(
                f"hybrid scale has {self.scale.size} values, one per action dimension, but "
                f"the action space is {self.space}"
            )

    def reset(self) -> None:
        self.base.reset()
        self.overriding = False

    def _update_override(self, observation: np.ndarray) -> bool:
        if not self.settings.overrides:
            return False
        fasm = float(np.asarray(observation)[self._fasm][0])
        if self.overriding:
            self.overriding = fasm < self.threshold_deg + self.settings.release_margin_deg
        else:
            self.overriding = fasm < self.threshold_deg
        return self.overriding

    def base_action(self, observation: np.ndarray) -> np.ndarray:
        """The analytical controller's action; checked against the env's action space."""
        action = np.asarray(self.base(observation), dtype=self.space.dtype)
        if action.shape != self.space.shape or not np.all(np.isfinite(action)):
            raise ValueError(
                f"the analytical controller returned an action of shape {action.shape} "
                f"(finite: {bool(np.all(np.isfinite(action)))}); the env's action space is "
                f"{self.space}"
            )
        return action

    def __call__(self, observation: np.ndarray, learned: np.ndarray) -> tuple[np.ndarray, bool]:
        """(env action, override): override is True when the analytical action alone applies."""
        learned = np.asarray(learned, dtype=self.space.dtype).reshape(self.space.shape)
        base = self.base_action(observation)  # every step: keeps the controller's state current
        override = self._update_override(observation)
        if override:
            action = base
        elif self.settings.mode == "residual":
            action = base + self.scale * learned
        else:
            action = self.scale * learned
        return np.clip(action, self.space.low, self.space.high).astype(self.space.dtype), override


class HybridWrapper(gym.Wrapper):
    """The env seen by a learning agent: actions in [-1, 1] combined by `HybridCore`.

    Observations, rewards and termination are the env's (the reward less
    ``settings.override_cost`` on the override's steps). ``info["safety_override"]`` says
    whether the analytical controller alone chose the step's action, ``info["hybrid_action"]``
    is the env action that was applied.
    """

    def __init__(self, env: gym.Env, settings: HybridSettings, base: Policy | None = None):
        super().__init__(env)
        self.core = HybridCore(env, settings, base)
        space = self.core.space
        self.action_space = gym.spaces.Box(-1.0, 1.0, shape=space.shape, dtype=space.dtype)
        self._obs: np.ndarray | None = None

    def reset(self, **kwargs: Any):
        obs, info = self.env.reset(**kwargs)
        self.core.reset()  # after the env's reset: controllers may read the new episode's course
        self._obs = obs
        return obs, info

    def step(self, action: np.ndarray):
        if self._obs is None:
            raise RuntimeError("call reset() before step()")
        env_action, override = self.core(self._obs, action)
        obs, reward, terminated, truncated, info = self.env.step(env_action)
        self._obs = obs
        info = {**info, "safety_override": override, "hybrid_action": env_action}
        cost = self.core.settings.override_cost
        if cost:
            info["reward_safety_override"] = -cost if override else 0.0
            reward = float(reward) + info["reward_safety_override"]
        return obs, reward, terminated, truncated, info


class HybridPolicy(LearnedWithController):
    """A learned `Policy` (actions in [-1, 1]) combined with the env's analytical controller."""

    def __init__(self, learned: Policy, env: gym.Env, settings: HybridSettings):
        self.learned = learned
        self.core = HybridCore(env, settings)
        self.last_override = False

    def reset(self) -> None:
        super().reset()
        self.last_override = False

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        action, self.last_override = self.core(observation, self.learned(observation))
        return action


def settings_from_config(section: Any) -> HybridSettings | None:
    """`HybridSettings` from a config's ``hybrid`` section (a dataclass or a mapping), or None."""
    return settings_from_section(HybridSettings, section)


def wrap(env: gym.Env, section: Any) -> gym.Env:
    """`env` wrapped as the ``hybrid`` config section says (unchanged when it is None)."""
    settings = settings_from_config(section)
    return env if settings is None else HybridWrapper(env, settings)


def zero_init_action_net(model: Any) -> None:
    """Zero the last layer of an SB3 actor-critic's action mean: training starts at a = 0,
    which in the residual mode is exactly the analytical controller."""
    import torch

    net = model.policy.action_net
    with torch.no_grad():
        net.weight.zero_()
        net.bias.zero_()


def from_run_config(learned: Policy, env: gym.Env, config: dict[str, Any]) -> Policy:
    """`learned` as its training run used it: wrapped in `HybridPolicy` when the run's resolved
    config has a ``hybrid`` section, unchanged otherwise (`agents.ppo.PPOPolicy.load`'s hook).

    A hybrid's learned action only means something with the env settings that say how an action
    is read or what the observation holds (`agents.env_kwargs.POLICY_SETTINGS`: the
    action mode, the residual scale and filter, ...), so one that differs on `env` is an error
    (ValueError) naming both values.
    """
    settings = settings_from_config(config.get("hybrid"))
    if settings is None:
        return learned
    trained_kwargs = (config.get("env") or {}).get("kwargs") or {}
    defaults = constructor_defaults(env)
    env_settings = getattr(env.unwrapped, "settings", None)
    for key in POLICY_SETTINGS:
        if env_settings is not None and hasattr(env_settings, key):
            current = getattr(env_settings, key)
        elif key == "action_mode":
            current = getattr(env.unwrapped, "action_mode", None)
        else:
            continue  # a setting this env does not have
        trained = trained_kwargs.get(key, defaults.get(key, current))
        if trained != current:
            raise ValueError(
                f"this hybrid model was trained with {key}={trained!r} but the env has "
                f"{key}={current!r}; evaluate it with env kwargs {key}: {trained}"
            )
    return HybridPolicy(learned, env, settings)
