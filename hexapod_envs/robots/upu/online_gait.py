"""The 3-3 gait one platform step at a time, each stride chosen as its step begins; pure numpy.

`gait_plan.plan_ditch_crossing` plans a whole crossing before the robot moves, from the ditch's
known geometry (the paper's planner, §7). A policy that decides each stride from what it senses
needs the gait built step by step instead. `OnlineGait` keeps where the two platform centres
stand (nominally: the gait's world x, which the robot follows open loop), which platform moves
next and each leg's extension, and turns a stride into the next `PlatformStep`: the moving
platform travels on its quadratic path (eqs. 19-21) and its legs land at the ground under each
foot (the ditch's depth for a foot over the ditch, as the planner's do). The stride limit
(eq. 17) also caps how far the upper platform may lead the lower, and the lower never passes
the upper, as in the planner's search.

Full strides reproduce `gait_plan.plan_flat_walk`'s steps exactly (the same floating-point
expressions), so on flat ground the online gait at full stride is the flat reference gait.
"""

from __future__ import annotations

from .gait_plan import (
    Ditch,
    GaitPlan,
    GaitSettings,
    PlatformStep,
    landing_extensions,
    platform_step,
    stride_limit,
)
from .params import PLATFORM_LEGS, UpuParams

STRIDE_TOLERANCE = 1e-12
"""[m]: a wanted stride this close above the room left counts as fitting it, so that full
strides keep the flat gait's exact positions despite rounding in the centres' difference."""


def stride_of(action: float, max_stride: float, min_stride: float, room: float) -> float:
    """The stride of a normalised action a [m]: `max_stride` for a >= 0, shortened in
    proportion below, at least `min_stride`; a stride beyond `room` (what the other platform
    leaves) becomes `room` (0 if none is left)."""
    wanted = max(max_stride * (1.0 + min(float(action), 0.0)), min_stride)
    return wanted if wanted <= room + STRIDE_TOLERANCE else max(room, 0.0)


class OnlineGait:
    """The gait's state between platform steps and the step a stride makes (SI units).

    Args:
        params: the robot.
        settings: planner settings (stride limit, swing retraction, lift, min_margin).
        x_start: world x of both platform centres at the start [m] (standing together).
        ditch: the ditch the legs land into; None on flat ground.
    """

    def __init__(
        self,
        params: UpuParams,
        settings: GaitSettings,
        x_start: float = 0.0,
        ditch: Ditch | None = None,
    ):
        self.params, self.settings, self.ditch = params, settings, ditch
        self.max_stride = stride_limit(params, settings)
        """The longest step [m] (eq. 17)."""
        self.min_stride = settings.grid
        """The shortest step [m] (the planner's grid: a step needs distinct path ends)."""
        self.x_upper = self.x_lower = float(x_start)
        """Nominal world x of the platform centres after the steps so far [m]."""
        self.moving = "upper"
        """The platform that moves next (the gait starts with the upper one, as the plans do)."""
        self.extension = {leg: 0.0 for legs in PLATFORM_LEGS.values() for leg in legs}
        """Leg -> its extension since its last landing [m]."""
        self.steps: list[PlatformStep] = []

    @property
    def room(self) -> float:
        """The longest stride the next mover may take [m]: the upper platform may lead the
        lower by at most the stride limit, and the lower may not pass the upper."""
        lead = self.x_upper - self.x_lower
        return self.max_stride - lead if self.moving == "upper" else lead

    def stride_for(self, action: float) -> float:
        """The stride of a normalised action a in [-1, 1] [m]: the full stride for a >= 0,
        shortened in proportion below (a = -0.5: half of it), at least `min_stride`, and
        within `room`."""
        return stride_of(action, self.max_stride, self.min_stride, self.room)

    def next_step(self, stride: float) -> PlatformStep:
        """The step of `stride` [m] from the current state (not taken: see `advance`)."""
        mover = self.moving
        start = self.x_upper if mover == "upper" else self.x_lower
        support = self.x_lower if mover == "upper" else self.x_upper
        other = "lower" if mover == "upper" else "upper"
        end = start + stride
        step = platform_step(
            self.params,
            self.settings,
            mover,
            start,
            end,
            support,
            landing_extension=landing_extensions(self.params, mover, end, self.ditch),
            support_extension={leg: self.extension[leg] for leg in PLATFORM_LEGS[other]},
        )
        if isinstance(step, str):  # the stride limit keeps every step inside the workspace
            raise RuntimeError(f"no {mover} step of {stride:.4f} m: {step}")
        return step

    def advance(self, stride: float) -> PlatformStep:
        """Take the step of `stride` [m]: record it and move the state past it."""
        step = self.next_step(stride)
        self.steps.append(step)
        self.extension.update(step.landing_extension)
        if step.moving == "upper":
            self.x_upper = step.end_x
        else:
            self.x_lower = step.end_x
        self.moving = step.support
        return step

    def plan(self, pending: PlatformStep | None = None) -> GaitPlan:
        """The steps taken so far (and `pending`, a step not yet taken) as a `GaitPlan`, for
        `gait_schedule.GaitSchedule`."""
        steps = tuple(self.steps) + ((pending,) if pending is not None else ())
        return GaitPlan(
            "ok", "strides decided online, one platform step at a time", steps, self.ditch
        )
