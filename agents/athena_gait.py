"""ATHENA's tripod gait and posture controller (seed 002, Section 4) for `agents` users.

The code lives in `hexapod_envs.robots.athena.gait` (pure numpy), because the
``HexapodIrregularTerrain-v0`` env runs it internally as the reference gait of its "residual"
and "gains" action modes and `hexapod_envs` must not import `agents`. This module re-exports it
so that controllers and scripts can keep importing it from here; there is one copy of the code.
"""

from hexapod_envs.robots.athena.gait import (
    AthenaPostureController,
    AthenaSensors,
    PostureEstimate,
    cubic_bezier,
    cubic_bezier_derivative,
    posture_rotation,
    rotation_xyz,
    stance_end_point,
    swing_control_points,
    torso_deviation_from_plane,
    triangle_area_xy,
)

__all__ = [
    "AthenaPostureController",
    "AthenaSensors",
    "PostureEstimate",
    "cubic_bezier",
    "cubic_bezier_derivative",
    "posture_rotation",
    "rotation_xyz",
    "stance_end_point",
    "swing_control_points",
    "torso_deviation_from_plane",
    "triangle_area_xy",
]
