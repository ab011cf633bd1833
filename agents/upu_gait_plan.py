"""Re-export of the 3-UPU gait planner, which lives in `hexapod_envs.robots.upu.gait_plan` so
that the env's reference gait and `agents.upu_gait.UpuGaitPolicy` share one copy of the code
(the env package must not import `agents`)."""

from hexapod_envs.robots.upu.gait_plan import (
    PLAN_STATUSES,
    Ditch,
    GaitPlan,
    GaitSettings,
    MarginProfile,
    PlatformStep,
    QuadraticPath,
    case_study_path,
    combined_cog,
    foot_positions,
    margin_profile,
    max_stride,
    max_stride_diagonal,
    plan_ditch_crossing,
    plan_flat_walk,
    stance_margin,
    step_path,
    support_margin,
)

__all__ = [
    "PLAN_STATUSES",
    "Ditch",
    "GaitPlan",
    "GaitSettings",
    "MarginProfile",
    "PlatformStep",
    "QuadraticPath",
    "case_study_path",
    "combined_cog",
    "foot_positions",
    "margin_profile",
    "max_stride",
    "max_stride_diagonal",
    "plan_ditch_crossing",
    "plan_flat_walk",
    "stance_margin",
    "step_path",
    "support_margin",
]
