"""Zhang et al. 2024's tipping judgment and recovery controller (no MuJoCo import anywhere).

The closed-loop controller and its policies:

- :mod:`.controller` - :class:`TippingRecoveryController` (the method of §3-4 as a state machine
  over control periods, sensors only) and :class:`TippingRecoveryPolicy` for the heavy-duty envs.
- :mod:`.gait_with_recovery` - :class:`GaitWithRecoveryPolicy`: the tripod gait with the
  controller taking over when tipping is judged.
- :mod:`.body_model` - feet, CoG and inertia from the encoders; forces into the body frame.
- :mod:`.margin_rate` - the margin's rate and acceleration for eq. (15).

The pure-math pieces:

- :mod:`.judgment` - threshold ξ_f, effective support legs, tipping edge, Table II.
- :mod:`.foothold` - terrain plane, reachable region of the adjustment leg, foothold (eqs. 10-14).
- :mod:`.trajectory` - time budget t_s (eq. 15) and the quintic foot trajectory.
- :mod:`.force_distribution` - desired wrench (eq. 16) and the QP with the stability cone
  (eqs. 17-24).
"""

from agents.tipping.body_model import HeavyDutyBodyModel
from agents.tipping.controller import (
    RecoveryConfig,
    SensorReading,
    TippingRecoveryController,
    TippingRecoveryPolicy,
)
from agents.tipping.foothold import (
    FootholdChoice,
    ReachableRegion,
    reachable_region,
    select_foothold,
    terrain_plane,
)
from agents.tipping.force_distribution import (
    ForceDistributionConfig,
    ForceDistributionResult,
    ForceDistributor,
    StabilityCone,
    desired_wrench,
    stability_cone,
)
from agents.tipping.gait_with_recovery import GaitWithRecoveryPolicy
from agents.tipping.judgment import (
    XI_F_DEG,
    TippingJudgment,
    effective_support_legs,
    is_tipping,
    judge,
    select_adjustment_leg,
    tipping_edge,
)
from agents.tipping.margin_rate import MarginHistory
from agents.tipping.trajectory import QuinticTrajectory, time_budget, zero_crossing_time

__all__ = [
    "XI_F_DEG",
    "GaitWithRecoveryPolicy",
    "HeavyDutyBodyModel",
    "MarginHistory",
    "RecoveryConfig",
    "SensorReading",
    "TippingRecoveryController",
    "TippingRecoveryPolicy",
    "FootholdChoice",
    "ForceDistributionConfig",
    "ForceDistributionResult",
    "ForceDistributor",
    "QuinticTrajectory",
    "ReachableRegion",
    "StabilityCone",
    "TippingJudgment",
    "desired_wrench",
    "effective_support_legs",
    "is_tipping",
    "judge",
    "reachable_region",
    "select_adjustment_leg",
    "select_foothold",
    "stability_cone",
    "terrain_plane",
    "time_budget",
    "tipping_edge",
    "zero_crossing_time",
]
