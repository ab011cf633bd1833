"""Learned planner knobs: a policy that sets the ditch planner's settings for each ditch.

The 3-UPU robot's planner (Li et al. 2018 §7, `agents.upu_gait.UpuGaitPolicy`) plans the whole
crossing at the start of an episode from the ditch's geometry, with fixed settings
(`hexapod_envs.robots.upu.gait_plan.GaitSettings`): how far a landing foot keeps from an edge,
the static margin every three-leg support keeps, the longest step, the lift. No one setting is
best for every ditch: on the -v1 test ditches a larger margin turns the planner's tip-overs at
the far edge into crossings, but refuses ditches the default crosses, and a smaller edge
clearance plans ditches the default refuses, but tips over on others. Here a learned policy
chooses the settings from what the planner plans from, once per episode.

What the policy sees is the course (`COURSE_FEATURES`: the ditch's near edge ahead of the
robot's centre, its width and depth [m]; the task description the planner reads, not the sensor
observation, which says nothing about the ditch before the robot reaches it). Its action ``a``
in [-1, 1] per knob maps to the knob's range as `agents.knobs.knob_values` does (``a = 0``: the
env's own setting), so an untrained policy that outputs 0 is the analytical controller exactly.
Settings with which the planner finds no plan fall back to the env's own
(``info["planner_fallback"]``): a knob never makes the planner refuse a ditch it would plan.

Two ways to run it, sharing `PlanKnobCore`:

- `PlanKnobsPerEpisode`: the env a learner trains on. One learner step per episode: reset
  returns the course (zeros with ``course=False``); step plans with the chosen settings and
  walks the plan to the episode's end. The reward is the episode's ``info["is_success"]``
  (the benchmark's rule), that success graded by its largest tilt ("stable_success") or by its
  smallest static margin ("margin_success"), or its return.
- `PlanKnobPolicy`: a trained policy as a per-step `Policy` on the plain env (`evaluate.py`).

A training config's ``knobs:`` section with the planner's knob names builds both
(docs/training.md); the env must run in ``action_mode: joint``, as the analytical planner is
evaluated.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import gymnasium as gym
import numpy as np

from hexapod_envs.robots.upu.gait_plan import GaitSettings, max_stride
from hexapod_envs.wrappers import episode_reward_of

from .knobs import PLANNER_KNOB_RANGES, KnobSettings, knob_values
from .policy import EnvBound, LearnedWithController, Policy
from .registry import analytical_policy
from .upu_gait import UpuGaitPolicy

COURSE_FEATURES = ("ditch_ahead_m", "ditch_width_m", "ditch_depth_m")
"""What a planner-knob policy sees: the ditch's near edge ahead of the robot's centre at the
start, the ditch's width and its depth [m]."""


def course_space() -> gym.spaces.Box:
    """The observation space of a planner-knob policy (`COURSE_FEATURES`)."""
    return gym.spaces.Box(-np.inf, np.inf, shape=(len(COURSE_FEATURES),), dtype=np.float32)


def observed_course(env: gym.Env, settings: KnobSettings) -> np.ndarray:
    """What a planner-knob policy sees of `env`'s episode: `course_features`, or zeros where
    ``settings.course`` is False (one setting for every ditch)."""
    if settings.course:
        return course_features(env)
    return np.zeros(len(COURSE_FEATURES), dtype=np.float32)


def course_features(env: gym.Env) -> np.ndarray:
    """`COURSE_FEATURES` of `env`'s episode, from its task description (read after reset)."""
    task = env.unwrapped.task_description
    course = task.course
    ahead = course["ditch_start_x"] - task.reference["start_x"]
    return np.array([ahead, course["ditch_width"], course["ditch_depth"]], dtype=np.float32)


def resolved_settings(settings: GaitSettings, params: Any) -> GaitSettings:
    """`settings` with its "None: the robot's own" fields made explicit (the lift of eq. 20,
    the stride limit of eq. 17), so that a knob has a default value to move from."""
    return replace(
        settings,
        lift=params.step_lift if settings.lift is None else settings.lift,
        max_stride=(
            max_stride(params.support_inradius, params.leg_radius)
            if settings.max_stride is None
            else settings.max_stride
        ),
    )


class PlanKnobCore(EnvBound):
    """The env's ditch planner, and the settings a learned action gives it for one episode.

    Args:
        env: a HexapodDitchCrossing env (any wrapper of it) in ``action_mode="joint"``, whose
            analytical controller (`agents.registry`) is a `UpuGaitPolicy`.
        settings: `KnobSettings` naming planner knobs (`PLANNER_KNOB_RANGES`).
    """

    def __init__(self, env: gym.Env, settings: KnobSettings):
        if settings.controller != "planner":
            raise ValueError(
                f"planner knobs are {sorted(PLANNER_KNOB_RANGES)}, got {list(settings.names)}"
            )
        base = analytical_policy(env)
        if not isinstance(base, UpuGaitPolicy):
            raise ValueError(
                f"planner knobs tune the ditch planner; the analytical controller of "
                f"{env.spec.id if env.spec else type(env.unwrapped).__name__} is "
                f"{type(base).__name__} (envs with the planner: the ditch crossing)"
            )
        terrain = getattr(env.unwrapped, "terrain", None)
        if terrain != "ditch":
            raise ValueError(
                "planner knobs are set from the ditch the planner plans for; the env has "
                f"terrain={terrain!r} (use terrain='ditch')"
            )
        if base.task.action_mode != "joint":
            raise ValueError(
                "planner knobs need the env in action_mode='joint' (the planner's closed-loop "
                f"gait, as the analytical controller is evaluated), got {base.task.action_mode!r}"
            )
        self.env = env
        self.settings = settings
        self.base = base
        self.default = base.settings
        self._resolved = resolved_settings(self.default, base.task.robot)
        """The env's settings with every knob's value explicit (what action 0 means)."""
        self.values: dict[str, float] = {}
        self.fallback = False

    def reset(self) -> None:
        self.base.settings = self.default
        self.base.reset()
        self.values, self.fallback = {}, False

    def set_knobs(self, action) -> dict[str, float]:
        """Plan this episode's course with the settings of `action`; where the planner finds no
        plan with them but does with the env's own, keep the env's own (`fallback`)."""
        self.values = knob_values(self._resolved, self.settings.names, action, PLANNER_KNOB_RANGES)
        self.base.settings = replace(self.default, **self.values)
        self.base.reset()
        self.fallback = False
        if self.base.status != "ok":
            self.base.settings = self.default
            self.base.reset()
            self.fallback = self.base.status == "ok"
            if not self.fallback:  # refused either way: report the learned settings' verdict
                self.base.settings = replace(self.default, **self.values)
                self.base.reset()
        return self.values

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        return self.base(observation)


class PlanKnobsPerEpisode(gym.Wrapper):
    """The env seen by a learner of planner knobs: one step per episode.

    ``reset`` resets the env and returns what the policy sees (`observed_course`: the course,
    `COURSE_FEATURES`, or zeros with ``course=False``). ``step(a)`` plans with
    the settings of ``a`` and walks the plan to the episode's end. Its reward is
    `KnobSettings.reward`, and it ends the learner's episode as terminated: nothing follows the
    outcome (the env's own flags are ``info["env_terminated"]`` and ``info["env_truncated"]``).
    ``info`` is the env's last step's, plus ``knobs`` (the settings the policy chose),
    ``planner_fallback`` (True: they gave no plan, and the planner walked with the env's own),
    ``env_steps`` (control steps the episode took) and ``episode_return`` (the env's).
    """

    def __init__(self, env: gym.Env, settings: KnobSettings):
        super().__init__(env)
        self.core = PlanKnobCore(env, settings)
        self._reward = episode_reward_of(env, settings.reward)
        self.observation_space = course_space()
        self.action_space = settings.action_space
        self._obs: np.ndarray | None = None

    def reset(self, **kwargs: Any):
        obs, info = self.env.reset(**kwargs)
        self.core.reset()
        self._obs = obs
        return observed_course(self.env, self.core.settings), info

    def step(self, action: np.ndarray):
        if self._obs is None:
            raise RuntimeError("call reset() before step()")
        values = self.core.set_knobs(action)
        obs, total, steps = self._obs, 0.0, 0
        terminated = truncated = False
        while not (terminated or truncated):
            obs, reward, terminated, truncated, info = self.env.step(self.core(obs))
            total, steps = total + float(reward), steps + 1
        self._obs = None
        learner_reward = self._reward(info, total)
        info = {
            **info,
            "knobs": values,
            "planner_fallback": self.core.fallback,
            "env_steps": steps,
            "episode_return": total,
            "env_terminated": terminated,
            "env_truncated": truncated,
        }
        return observed_course(self.env, self.core.settings), learner_reward, True, False, info


class PlanKnobPolicy(LearnedWithController):
    """A trained planner-knob policy with the env's planner, as a per-step `Policy`: asked once
    per episode at its first step with what it saw in training (`observed_course`), the planner
    acts every step."""

    def __init__(self, learned: Policy, env: gym.Env, settings: KnobSettings):
        self.learned = learned
        self.core = PlanKnobCore(env, settings)
        self._decided = False

    def reset(self) -> None:
        super().reset()
        self._decided = False

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        if not self._decided:  # the course is sampled at env.reset(), before the first call
            self.core.set_knobs(self.learned(observed_course(self.core.env, self.core.settings)))
            self._decided = True
        return self.core(observation)
