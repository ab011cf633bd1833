"""The reference tripod gait with Zhang et al. 2024's tipping recovery taking over when tipping is
judged.

`GaitWithRecoveryPolicy` walks the paper's tripod gait
(:class:`agents.tripod_gait.TripodGaitPolicy`) while the tipping-recovery controller
(:mod:`.controller`) watches the FASM computed from the sensors. When the margin falls below ξ_f
the controller takes over: it freezes the posture the gait commanded at that moment (the stance
legs stop pushing the body forward), puts the adjustment leg down at the foothold of §4.2 (Table
II's leg, or for a non-tripod stance the free leg on the far side of the tipping edge),
distributes the foot forces once it has landed and then holds that stance. It does not resume
walking: after a tipping event on unknown terrain (here a cliff) the safe continuation is to stop
and let a planner or an operator decide.

If the foothold turns out to have no ground (the adjustment leg descends `max_search_depth` below
the plane fitted through the stance feet without touching anything, as over a cliff), the leg is
pulled back to its frozen gait target and the robot holds the remaining stance.

The controller needs full authority over the joint targets once it has taken over, because the
env's residual reference keeps walking: use ``action_mode="joint"``, or ``"residual"`` with a
``residual_scale`` of at least 2 (every target reachable from any reference). With a smaller
residual scale the targets are clipped to what the action can express and the policy is told so
through ``diagnostics["saturated"]``.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np

from agents.tipping.controller import RecoveryConfig, TippingRecoveryPolicy
from agents.tripod_gait import TripodGaitPolicy

FULL_AUTHORITY_RESIDUAL_SCALE = 2.0
"""A residual scale from which any joint target is reachable from any reference."""


class GaitWithRecoveryPolicy(TippingRecoveryPolicy):
    """Tripod gait + tipping recovery for the walking heavy-duty envs (HexapodCliffWalk-v0).

    The recovery policy with the reference gait, instead of a fixed posture, as the nominal
    motion; ``diagnostics["saturated"]`` tells when the residual range clipped a target.

    Args:
        env: a walking heavy-duty hexapod env (with the ``gait_phase`` observation).
        config: :class:`RecoveryConfig` or keyword overrides of its fields.
    """

    def __init__(self, env: gym.Env, config: RecoveryConfig | None = None, **overrides):
        base = env.unwrapped
        task = getattr(base, "task_description", None)
        if task is None or "gait_phase" not in task.observation_structure:
            raise ValueError(
                f"{type(base).__name__} has no gait_phase observation; GaitWithRecoveryPolicy "
                "needs a walking heavy-duty hexapod env such as HexapodCliffWalk-v0"
            )
        self.gait = TripodGaitPolicy(env)
        super().__init__(env, config, **overrides)
        self.full_authority = (
            self.action_mode == "joint"
            or task.reference["residual_scale"] >= FULL_AUTHORITY_RESIDUAL_SCALE
        )

    def reset(self) -> None:
        super().reset()
        self.gait.reset()

    def nominal(self, observation: np.ndarray) -> np.ndarray:
        """Joint targets without recovery: the reference tripod gait at the observed phase."""
        return self.gait.joint_targets(observation).reshape(6, 3)
