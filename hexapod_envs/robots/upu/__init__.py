"""The 3-UPU hexapod walking robot of Li et al. 2018 (Li et al., Robotics 2018, 7, 48).

`params` (paper numbers and documented choices), `kinematics` and `workspace` (pure numpy) and
`model` (MuJoCo, imported lazily so the pure math works without building a model).
"""

from .kinematics import (
    check_limits,
    forward_kinematics,
    hooke_angles,
    inverse_kinematics,
    is_reachable,
)
from .params import LEG_NAMES, LIMB_NAMES, LOWER_LEGS, UPPER_LEGS, UpuParams
from .workspace import WorkspaceResult, search_workspace

__all__ = [
    "LEG_NAMES",
    "LIMB_NAMES",
    "LOWER_LEGS",
    "UPPER_LEGS",
    "UpuParams",
    "WorkspaceResult",
    "check_limits",
    "forward_kinematics",
    "hooke_angles",
    "inverse_kinematics",
    "is_reachable",
    "search_workspace",
]
