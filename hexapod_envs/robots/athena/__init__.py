"""ATHENA, the hexapod of Coelho et al. 2024: parameters, DH kinematics (pure numpy), MuJoCo model.

`add_athena` and `AthenaHandles` live in `model` (which imports mujoco) and are loaded lazily, so
that `params` and `kinematics` stay importable without MuJoCo (the gait controller in `agents`
uses them).
"""

from .kinematics import (
    forward_kinematics,
    forward_kinematics_all,
    inverse_kinematics,
    inverse_kinematics_all,
    is_reachable,
    standing_foot_positions,
    standing_joint_angles,
    within_limits,
)
from .params import (
    ATHENA,
    JOINT_NAMES,
    LEG_FROM_PAPER_NUMBER,
    LEG_NAMES,
    PAPER_LEG_NUMBER,
    TRIPODS,
    AthenaParams,
)

__all__ = [
    "ATHENA",
    "JOINT_NAMES",
    "LEG_FROM_PAPER_NUMBER",
    "LEG_NAMES",
    "PAPER_LEG_NUMBER",
    "TRIPODS",
    "AthenaHandles",
    "AthenaParams",
    "add_athena",
    "forward_kinematics",
    "forward_kinematics_all",
    "inverse_kinematics",
    "inverse_kinematics_all",
    "is_reachable",
    "standing_foot_positions",
    "standing_joint_angles",
    "within_limits",
]


def __getattr__(name: str):
    if name in ("add_athena", "AthenaHandles"):
        from . import model

        return getattr(model, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
