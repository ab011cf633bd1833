"""How far from a ditch's edges the moving platform's feet land for each candidate stride; pure
numpy.

The ditch crossing's stride action (``stride_action=True``) sets each platform step's stride as
it begins. Where a stride lands a foot depends only on where the ditch's edges lie relative to
both platform centres (the other platform caps the stride) and on the robot's constants, all
known at the decision: this is
the geometry of the clear-stride rule (`agents.upu_stride.ClearStridePolicy`) and of the
stride-choices observation (`hexapod_envs.wrappers.StrideClearances`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .gait_plan import GaitSettings, edge_clearance, stride_limit
from .online_gait import stride_of
from .params import PLATFORM_LEGS, UpuParams


@dataclass(frozen=True)
class StrideClearance:
    """The robot's constants the clearances need (SI units)."""

    feet_x: dict[str, np.ndarray]
    """Platform ("upper", "lower") -> its feet's x relative to its centre [m]."""
    band: float
    """How far from an edge a foot's centre must land to be clear [m]."""
    reach: float
    """The deepest ditch a foot can stand in [m]; a deeper one may not take a foot at all."""
    max_stride: float
    """The longest stride [m] (`gait_plan.stride_limit`: eq. 17 or the settings' cap)."""
    grid: float
    """The shortest stride and the planner's stride grid [m]."""

    @classmethod
    def of(cls, params: UpuParams, settings: GaitSettings) -> StrideClearance:
        feet = {
            m: np.array([params.foot_offset(leg)[0] for leg in PLATFORM_LEGS[m]])
            for m in PLATFORM_LEGS
        }
        band = params.foot_radius + settings.edge_clearance
        return cls(feet, band, params.leg_extend, stride_limit(params, settings), settings.grid)

    def candidates(
        self, ahead: np.ndarray, upper_next: bool, values: Sequence[float] | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """(strides [m], clearance [m]) of the next platform step: each candidate stride and
        the signed clearance of its worst-placed moving foot from the nearer edge
        (`gait_plan.edge_clearance`; clear at `band` or more).

        Args:
            ahead: the observation's ``ditch_ahead``: near and far edge x relative to the upper
                platform's centre, the same relative to the lower's [m], the depth [m].
            upper_next: whether the upper platform moves next.
            values: stride action values (0 the full stride, -0.5 half of it; what the other
                platform leaves caps each, `online_gait.stride_of`); None: every stride on the
                planner's grid from the longest that fits down to the shortest.
        """
        near_u, far_u, near_l, far_l, depth = ahead
        lead = near_l - near_u  # x_upper - x_lower
        room = self.max_stride - lead if upper_next else lead
        near, far = (near_u, far_u) if upper_next else (near_l, far_l)
        if values is None:
            strides = np.arange(max(room, self.grid), self.grid - 1e-9, -self.grid)
        else:
            strides = np.array([stride_of(v, self.max_stride, self.grid, room) for v in values])
        feet = strides[:, None] + self.feet_x["upper" if upper_next else "lower"][None, :]
        clear = edge_clearance(feet, near, far, self.band, depth <= self.reach)
        return strides, clear.min(axis=1)
