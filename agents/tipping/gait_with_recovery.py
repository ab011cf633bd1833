"""The reference tripod gait with Zhang et al. 2024's tipping recovery taking over when tipping is
judged.

`GaitWithRecoveryPolicy` walks the paper's tripod gait
(:class:`agents.tripod_gait.TripodGaitPolicy`) while the tipping-recovery controller
(:mod:`.controller`) watches the FASM computed from the sensors. When the margin falls below ξ_f
the controller takes over: it freezes the posture the gait commanded at that moment (the stance
legs stop pushing the body forward), puts the adjustment leg down at the foothold of §4.2 (Table
II's leg, or for a non-tripod stance the free leg on the far side of the tipping edge),
distributes the foot forces once it has landed and then holds that stance. As in the paper it
does not resume walking by default: after a tipping event on unknown terrain (here a cliff) the
safe continuation is to stop and let a planner or an operator decide.

``resume_margin_deg`` (not in the paper) resumes the gait once the recovery has restored the
margin: when the measured FASM has stayed at or above ξ_f + `resume_margin_deg` for
`resume_hold_s` seconds after the controller took over, the controller is re-armed (its plan
cleared) and the gait's current targets are commanded again, so that a later tipping event is
judged and recovered anew. This is the reference of the cliff walk's benchmark task
(``HexapodCliffWalk-v1``, docs/benchmark.md), where a controller that stops for good cannot
reach the goal.

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
from hexapod_envs.checks import check_number

RECOVERED = ("supported", "holding")
"""Controller phases after a take-over in which the recovered stance is held."""

FULL_AUTHORITY_RESIDUAL_SCALE = 2.0
"""A residual scale from which any joint target is reachable from any reference."""


class GaitWithRecoveryPolicy(TippingRecoveryPolicy):
    """Tripod gait + tipping recovery for the walking heavy-duty envs (HexapodCliffWalk-v0).

    The recovery policy with the reference gait, instead of a fixed posture, as the nominal
    motion; ``diagnostics["saturated"]`` tells when the residual range clipped a target.

    Args:
        env: a walking heavy-duty hexapod env (with the ``gait_phase`` observation).
        config: :class:`RecoveryConfig` or keyword overrides of its fields.
        resume_margin_deg: resume the gait once the FASM has been at least ξ_f + this [deg]
            for `resume_hold_s` [s] after a take-over (None: hold the recovered stance for
            good, as the paper does).
        resume_hold_s: how long the margin must stay restored before the gait resumes [s].
    """

    def __init__(
        self,
        env: gym.Env,
        config: RecoveryConfig | None = None,
        resume_margin_deg: float | None = None,
        resume_hold_s: float = 1.0,
        **overrides,
    ):
        base = env.unwrapped
        task = getattr(base, "task_description", None)
        if task is None or "gait_phase" not in task.observation_structure:
            raise ValueError(
                f"{type(base).__name__} has no gait_phase observation; GaitWithRecoveryPolicy "
                "needs a walking heavy-duty hexapod env such as HexapodCliffWalk-v0"
            )
        self.gait = TripodGaitPolicy(env)
        if resume_margin_deg is not None:
            check_number("resume_margin_deg", resume_margin_deg)
        check_number("resume_hold_s", resume_hold_s)
        self.resume_margin_deg = resume_margin_deg
        self.resume_hold_s = float(resume_hold_s)
        super().__init__(env, config, **overrides)
        self.full_authority = (
            self.action_mode == "joint"
            or task.reference["residual_scale"] >= FULL_AUTHORITY_RESIDUAL_SCALE
        )

    def reset(self) -> None:
        super().reset()
        self.gait.reset()
        self._restored_steps = 0
        self.resumptions = 0
        """Times the gait resumed after a recovery in this episode."""

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        action = super().__call__(observation)
        if self.resume_margin_deg is not None and self.controller.phase in RECOVERED:
            margin = self.controller.diagnostics["fasm_deg"]
            restored = margin >= self.config.threshold_deg + self.resume_margin_deg
            self._restored_steps = self._restored_steps + 1 if restored else 0
            if self._restored_steps * self.control_dt >= self.resume_hold_s:
                self.controller.reset()  # re-armed: back to monitoring, the gait's targets next
                self._restored_steps = 0
                self.resumptions += 1
        return action

    def nominal(self, observation: np.ndarray) -> np.ndarray:
        """Joint targets without recovery: the reference tripod gait at the observed phase."""
        return self.gait.joint_targets(observation).reshape(6, 3)
