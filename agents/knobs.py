"""Learned controller knobs: a policy that tunes an analytical controller's settings per situation.

Two controllers have knobs. The ditch planner's (`agents.plan_knobs`, `PLANNER_KNOB_RANGES`) are
set once per episode from the ditch the planner plans for. The heavy-duty robot's tipping
recovery's are set at its tipping judgment, as follows.

The heavy-duty robot's recovery (Zhang et al. 2024, `agents.tipping`) plans its rescue step when
it judges tipping: the foothold's safety factor ρ, the swing time's share ϰ of the forecast
time to tip and its clamp, the swing's clearance. The paper fixes them for every situation. Here
a learned policy sets them from what the robot senses at that moment: at the control step on
which the controller judges tipping (found by running a copy of the controller on the step's
observation, while the measured FASM is below ξ + `event_margin_deg`), the policy is asked,
and the controller then plans and recovers with those settings. It is asked once per episode:
a controller that resumes walking and judges again keeps the first event's settings.

A knob's learned action ``a`` lies in [-1, 1]. ``a = 0`` is the controller's own setting, and
``a = ±1`` the ends of the knob's range (`KNOB_RANGES`; linear on each side of the default), so
an untrained policy that outputs 0 is the analytical controller exactly.

Two ways to run it, sharing `KnobCore`:

- `KnobsPerEvent`: the env a learner trains on. One learner step per episode: reset runs the
  controller to the event and returns that observation; step applies the knobs and runs the
  controller to the episode's end. The reward is the episode's ``info["is_success"]`` (the
  benchmark's rule) or the env's return from the event on.
- `KnobPolicy`: a trained policy as a per-step `Policy` on the plain env (`evaluate.py`), asked
  at the same event.

The config section ``knobs:`` of a training run (docs/training.md) builds both.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, replace
from typing import Any, Literal

import gymnasium as gym
import numpy as np

from hexapod_envs.wrappers import EPISODE_REWARDS, EpisodeReward, episode_reward_of

from .policy import LearnedWithController, Policy, settings_from_section
from .registry import analytical_policy
from .tipping.controller import TippingRecoveryPolicy

KNOB_RANGES: dict[str, tuple[float, float]] = {
    "rho": (0.4, 1.0),
    "angle_threshold_deg": (20.0, 60.0),
    "kappa": (0.3, 0.95),
    "t_min": (0.2, 1.5),
    "t_max": (1.5, 4.0),
    "swing_clearance": (0.03, 0.3),
    "touchdown_speed": (0.05, 0.4),
    "force_gain": (0.1, 1.0),
}
"""`RecoveryConfig` fields a policy may set per event, with the range a learned knob spans (units
of the field: ρ, ϰ and the force gain dimensionless, angles in deg, times in s, the clearance in
m, the touchdown speed in m/s). Only fields the controller reads when it uses them (at judgment,
in the swing, at touchdown, in support) are here, so a setting made at the event takes effect."""

PLANNER_KNOB_RANGES: dict[str, tuple[float, float]] = {
    "edge_clearance": (0.0, 0.05),
    "min_margin": (0.0, 0.03),
    "max_stride": (0.10, 0.16),
    "lift": (0.04, 0.10),
}
"""`hexapod_envs.robots.upu.gait_plan.GaitSettings` fields a policy may set per episode on the
ditch crossing (`agents.plan_knobs`), with the range a learned knob spans [m]: the gap a landing
foot keeps from a ditch edge, the static margin every three-leg support must keep, the longest
platform step (eq. 17's 0.16 m is the most the mechanism allows) and the upper platform's lift."""

REWARDS = EPISODE_REWARDS


@dataclass
class KnobSettings:
    """What the learned policy tunes and when (see the module docstring).

    Attributes:
        names: the knobs, all keys of `KNOB_RANGES` (the recovery's) or all of
            `PLANNER_KNOB_RANGES` (the ditch planner's); the learned action has one value per
            name.
        event_margin_deg: recovery knobs only: while the measured FASM (observation
            ``fasm_margin_deg``) is below ξ + this [deg] (ξ: the controller's threshold), every
            step is checked for the controller's judgment (its own FASM, from its body model,
            may differ a little).
        reward: training only: "success" (1 when the episode meets the env's success rule, else
            0), "stable_success" (a success graded by its largest tilt, -v1 ids),
            "margin_success" (planner knobs: graded by its smallest static margin;
            `hexapod_envs.wrappers.episode_reward`) or "return" (the env's reward summed from
            the event (recovery knobs) or the start (planner knobs) to the episode's end).
        course: planner knobs only: the policy sees the course it plans (the ditch's distance,
            width and depth, `agents.plan_knobs.COURSE_FEATURES`); False: it sees zeros, so it
            learns one setting for every ditch, which cannot carry a trend over the training
            ditches past them (the -v1 test ditches are wider, deeper and farther than any
            training ditch).
    """

    names: tuple[str, ...] = ("rho", "kappa", "t_min")
    event_margin_deg: float = 5.0
    reward: EpisodeReward = "success"
    course: bool = True

    def __post_init__(self):
        self.names = names = tuple(self.names)
        one_controller = any(set(names) <= set(t) for t in (KNOB_RANGES, PLANNER_KNOB_RANGES))
        if not names or not one_controller or len(set(names)) != len(names):
            raise ValueError(
                f"knobs.names must be distinct names, all of the tipping recovery's "
                f"{sorted(KNOB_RANGES)} or all of the ditch planner's "
                f"{sorted(PLANNER_KNOB_RANGES)}, got {list(names)}"
            )
        if not np.isfinite(self.event_margin_deg) or self.event_margin_deg < 0:
            raise ValueError(
                f"knobs.event_margin_deg must be a finite number >= 0, got {self.event_margin_deg}"
            )
        if self.reward not in REWARDS:
            raise ValueError(f"knobs.reward must be one of {REWARDS}, got {self.reward!r}")
        if self.reward == "margin_success" and self.controller != "planner":
            raise ValueError(
                'knobs.reward: "margin_success" grades a success by the ditch crossing\'s static '
                "margin, for the ditch planner's knobs; the recovery's knobs take "
                '"success", "stable_success" or "return"'
            )
        if not isinstance(self.course, bool):
            raise ValueError(f"knobs.course must be true or false, got {self.course!r}")
        if not self.course and self.controller != "planner":
            raise ValueError(
                "knobs.course: false is for the ditch planner's knobs (set once per episode from "
                "the course); the recovery's knobs see the robot's state at the tipping event"
            )

    @property
    def action_space(self) -> gym.spaces.Box:
        """The learned action: one value in [-1, 1] per knob."""
        return gym.spaces.Box(-1.0, 1.0, shape=(len(self.names),), dtype=np.float32)

    @property
    def controller(self) -> Literal["recovery", "planner"]:
        """Whose knobs these are: the tipping recovery's or the ditch planner's."""
        return "recovery" if set(self.names) <= set(KNOB_RANGES) else "planner"


def knob_values(
    default: Any,
    names: tuple[str, ...],
    action,
    ranges: dict[str, tuple[float, float]] = KNOB_RANGES,
) -> dict[str, float]:
    """The settings a learned action means: ``a = 0`` the default (attribute of `default`),
    ``±1`` the ends of the knob's range in `ranges`.

    Values of ``a`` outside [-1, 1] are clipped. A default outside a knob's range widens the
    range to it, so the mapping stays monotone.
    """
    action = np.clip(np.asarray(action, dtype=float).reshape(-1), -1.0, 1.0)
    if action.shape != (len(names),) or not np.all(np.isfinite(action)):
        raise ValueError(
            f"the knob action must be {len(names)} finite values (one per knob {list(names)}), "
            f"got {np.asarray(action).tolist()}"
        )
    values = {}
    for name, a in zip(names, action, strict=True):
        low, high = ranges[name]
        base = float(getattr(default, name))
        end = max(high, base) if a >= 0 else min(low, base)
        values[name] = base + abs(float(a)) * (end - base)
    return values


class KnobCore:
    """The env's recovery controller and when, and how, its knobs are set.

    Args:
        env: a heavy-duty hexapod env (any wrapper of it) whose analytical controller
            (`agents.registry`) is a `TippingRecoveryPolicy`.
        settings: `KnobSettings`.
        base: the controller to tune instead of the registry's (tests, variants).
    """

    def __init__(self, env: gym.Env, settings: KnobSettings, base: Policy | None = None):
        base = base if base is not None else analytical_policy(env)
        if not isinstance(base, TippingRecoveryPolicy):
            raise ValueError(
                f"knobs tune the tipping recovery's settings; the analytical controller of "
                f"{env.spec.id if env.spec else type(env.unwrapped).__name__} is "
                f"{type(base).__name__}, which has none (envs with the recovery: the cliff walk "
                "and the Stewart tilt)"
            )
        structure = env.unwrapped.observation_structure
        self._fasm = structure["fasm_margin_deg"]
        self.settings = settings
        self.base = base
        self.default = base.controller.config
        self.probe_below_deg = self.default.threshold_deg + settings.event_margin_deg
        self.decided = False
        self.values: dict[str, float] = {}

    def reset(self) -> None:
        self.base.reset()
        self.base.controller.config = self.default
        self.decided = False
        self.values = {}

    def at_event(self, observation: np.ndarray) -> bool:
        """Whether the policy is to be asked now: no knobs set yet this episode, and the
        controller judges tipping on this observation (a copy of it is run on the observation
        while the measured FASM is below ξ + event_margin_deg; 0.3 ms a copy)."""
        if self.decided or self.base.controller.phase != "monitor":
            return False
        if float(np.asarray(observation)[self._fasm][0]) >= self.probe_below_deg:
            return False
        probe = copy.deepcopy(self.base)  # shares the env (`agents.policy.EnvBound`)
        probe(observation)
        return probe.controller.active

    def set_knobs(self, action) -> dict[str, float]:
        """Apply a learned action for the rest of the episode; returns the settings."""
        self.values = knob_values(self.default, self.settings.names, action)
        self.base.controller.config = replace(self.default, **self.values)
        self.decided = True
        return self.values

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        """The controller's env action (with the knobs set so far)."""
        return self.base(observation)


class KnobsPerEvent(gym.Wrapper):
    """The env seen by a learner of knobs: one step per episode, at the tipping event.

    ``reset`` resets the env and runs the controller until the event; an episode that ends first
    (the controller never judged tipping) has nothing to decide, and the env is reset again, up
    to `max_skipped` times. ``step(a)`` sets the knobs and runs the controller to the episode's
    end. Its reward is `KnobSettings.reward`, and it ends the learner's episode as terminated:
    nothing follows the outcome, so a learner must not bootstrap a value after it (the env's own
    flags are ``info["env_terminated"]`` and ``info["env_truncated"]``). ``info`` is the env's
    last step's, plus ``knobs`` (the settings), ``env_steps`` (control steps the episode took),
    ``episode_return`` (the env's) and ``skipped_episodes`` (episodes without an event before
    this one). The training logs' per-episode metrics see only that last step's ``info``.
    """

    def __init__(
        self,
        env: gym.Env,
        settings: KnobSettings,
        base: Policy | None = None,
        max_skipped: int = 100,
    ):
        super().__init__(env)
        self.core = KnobCore(env, settings, base)
        self._reward = episode_reward_of(env, settings.reward)
        self.action_space = settings.action_space
        self.max_skipped = int(max_skipped)
        self._obs: np.ndarray | None = None
        self._skipped = 0
        self._steps = 0
        self._return = 0.0

    def _run(self, obs: np.ndarray, until_event: bool):
        """Step the env with the controller from `obs` until the episode ends or, with
        `until_event`, the policy is to be asked; returns (obs, summed reward, steps,
        terminated, truncated, info of the last step; None without a step)."""
        total, steps, terminated, truncated, info = 0.0, 0, False, False, None
        while not (until_event and self.core.at_event(obs)):
            obs, reward, terminated, truncated, info = self.env.step(self.core(obs))
            total, steps = total + float(reward), steps + 1
            if terminated or truncated:
                break
        return obs, total, steps, terminated, truncated, info

    def reset(self, **kwargs: Any):
        for skipped in range(self.max_skipped + 1):
            obs, info = self.env.reset(**kwargs)
            kwargs.pop("seed", None)  # a skipped task: the next one from the env's generator
            self.core.reset()
            obs, self._return, self._steps, terminated, truncated, last = self._run(obs, True)
            if not (terminated or truncated):
                self._obs, self._skipped = obs, skipped
                return obs, info if last is None else last
        raise RuntimeError(
            f"{self.max_skipped + 1} episodes in a row ended without a tipping judgment: no "
            "event to tune the recovery for"
        )

    def step(self, action: np.ndarray):
        if self._obs is None:
            raise RuntimeError("call reset() before step()")
        values = self.core.set_knobs(action)
        obs, after_event, steps, terminated, truncated, info = self._run(self._obs, False)
        self._obs = None
        learner_reward = self._reward(info, after_event)
        info = {
            **info,
            "knobs": values,
            "env_steps": self._steps + steps,
            "episode_return": self._return + after_event,
            "skipped_episodes": self._skipped,
            "env_terminated": terminated,
            "env_truncated": truncated,
        }
        return obs, learner_reward, True, False, info


class KnobPolicy(LearnedWithController):
    """A trained knob policy (actions in [-1, 1]) with the env's recovery controller, as a
    per-step `Policy`: asked once per episode at the event, the controller acts every step."""

    def __init__(self, learned: Policy, env: gym.Env, settings: KnobSettings):
        self.learned = learned
        self.core = KnobCore(env, settings)

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        if self.core.at_event(observation):
            self.core.set_knobs(self.learned(observation))
        return self.core(observation)


def settings_from_config(section: Any) -> KnobSettings | None:
    """`KnobSettings` from a config's ``knobs`` section (a dataclass or a mapping), or None."""
    return settings_from_section(KnobSettings, section)
