"""Seed 000's tipping judgment and recovery controller: the pure-math pieces (no MuJoCo).

- :mod:`.judgment` - threshold ξ_f, effective support legs, tipping edge, Table II.
- :mod:`.foothold` - terrain plane, reachable region of the adjustment leg, foothold (eqs. 10-14).
- :mod:`.trajectory` - time budget t_s (eq. 15) and the quintic foot trajectory.
- :mod:`.force_distribution` - desired wrench (eq. 16) and the QP with the stability cone
  (eqs. 17-24).
"""

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
from agents.tipping.judgment import (
    XI_F_DEG,
    TippingJudgment,
    effective_support_legs,
    is_tipping,
    judge,
    select_adjustment_leg,
    tipping_edge,
)
from agents.tipping.trajectory import QuinticTrajectory, time_budget, zero_crossing_time

__all__ = [
    "XI_F_DEG",
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
