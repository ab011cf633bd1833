"""The 5 t heavy-duty hexapod of Zhang et al. 2024: parameters, pantograph-leg kinematics, MuJoCo
model."""

from .kinematics import (
    foot_in_body,
    foot_in_coxa,
    joints_for_foot,
    joints_from_coxa,
    standing_feet,
    within_limits,
)
from .params import JOINT_NAMES, LEG_NAMES, PAPER_LEG_NUMBER, TRIPODS, HeavyDutyParams

__all__ = [
    "JOINT_NAMES",
    "LEG_NAMES",
    "PAPER_LEG_NUMBER",
    "TRIPODS",
    "HeavyDutyParams",
    "foot_in_body",
    "foot_in_coxa",
    "joints_for_foot",
    "joints_from_coxa",
    "standing_feet",
    "within_limits",
]
