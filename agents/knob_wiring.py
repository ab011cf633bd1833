"""What a ``knobs:`` section builds, per controller: the env a learner trains on, the per-step
policy of a trained model, and what that policy sees.

The tipping recovery's knobs (`agents.knobs`) are set at the controller's tipping judgment from
the env's observation; the ditch planner's (`agents.plan_knobs`) once per episode from the
course. `KnobSettings.controller` tells which.
"""

from __future__ import annotations

import gymnasium as gym

from .knobs import KnobPolicy, KnobSettings, KnobsPerEvent
from .plan_knobs import PlanKnobPolicy, PlanKnobsPerEpisode, course_space
from .policy import Policy


def knobs_env(env: gym.Env, settings: KnobSettings) -> gym.Env:
    """The env a learner of `settings` trains on: `KnobsPerEvent` for the recovery's knobs,
    `PlanKnobsPerEpisode` for the ditch planner's."""
    if settings.controller == "planner":
        return PlanKnobsPerEpisode(env, settings)
    return KnobsPerEvent(env, settings)


def knobs_policy(learned: Policy, env: gym.Env, settings: KnobSettings) -> Policy:
    """A trained knob policy with the controller it tunes, as a per-step `Policy` on `env`."""
    if settings.controller == "planner":
        return PlanKnobPolicy(learned, env, settings)
    return KnobPolicy(learned, env, settings)


def knobs_observation_space(env: gym.Env, settings: KnobSettings) -> gym.spaces.Box:
    """What the knob policy sees: the env's observation at the tipping event (recovery), or the
    course the planner plans for (`agents.plan_knobs.COURSE_FEATURES`)."""
    if settings.controller == "planner":
        return course_space()
    return env.observation_space
