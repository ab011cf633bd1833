"""Leg kinematics of the heavy-duty hexapod, Zhang et al. 2024 eqs. (1)-(2). Pure numpy.

Each leg is a pantograph with three joints J = [J_x, J_z, J_theta] (horizontal, vertical, swing).
In the coxa frame {B_i} (parallel to the body frame, origin at l_i):

    P_x = K_x J_x
    P_y = L1 cos J_theta + (K_z J_z + L2) sin J_theta
    P_z = L1 sin J_theta − (K_z J_z + L2) cos J_theta

with L1 signed (left +, right −). The printed inverse, eq. (2), is garbled in the extraction; it
is re-derived here: with d = K_z J_z + L2, P_y² + P_z² = L1² + d², and (P_y, P_z) is (L1, −d)
rotated by J_theta.
"""

from __future__ import annotations

import numpy as np

from .params import LEG_NAMES, HeavyDutyParams


def foot_in_coxa(joints: np.ndarray, l1: float, params: HeavyDutyParams) -> np.ndarray:
    """Forward kinematics, eq. (1): joint vector(s) [J_x, J_z, J_theta] -> foot position in the
    coxa frame [m]. `joints` may be (3,) or (n, 3)."""
    joints = np.asarray(joints, dtype=float)
    j_x, j_z, theta = joints[..., 0], joints[..., 1], joints[..., 2]
    d = params.k_z * j_z + params.l2
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([params.k_x * j_x, l1 * c + d * s, l1 * s - d * c], axis=-1)


def joints_from_coxa(foot: np.ndarray, l1: float, params: HeavyDutyParams) -> np.ndarray:
    """Inverse kinematics, eq. (2) re-derived: foot position(s) in the coxa frame -> joints.

    Raises ValueError when the point is closer to the swing axis than |L1| (no real solution).
    """
    foot = np.asarray(foot, dtype=float)
    p_x, p_y, p_z = foot[..., 0], foot[..., 1], foot[..., 2]
    d_sq = p_y**2 + p_z**2 - l1**2
    if np.any(d_sq < 0.0):
        raise ValueError(
            f"foot point {foot.tolist()} lies within |L1| = {abs(l1)} m of the swing axis; "
            "no leg configuration reaches it"
        )
    d = np.sqrt(d_sq)
    theta = np.arctan2(p_z, p_y) - np.arctan2(-d, l1)
    theta = (theta + np.pi) % (2.0 * np.pi) - np.pi
    return np.stack([p_x / params.k_x, (d - params.l2) / params.k_z, theta], axis=-1)


def foot_in_body(leg: str, joints: np.ndarray, params: HeavyDutyParams) -> np.ndarray:
    """Foot position of `leg` in the body frame [m] (coxa frames are parallel to the body's)."""
    return params.hip_offsets[leg] + foot_in_coxa(joints, params.signed_l1(leg), params)


def joints_for_foot(leg: str, foot_body: np.ndarray, params: HeavyDutyParams) -> np.ndarray:
    """Joints that put the foot of `leg` at `foot_body` (body frame) [J_x m, J_z m, J_theta rad]."""
    return joints_from_coxa(
        np.asarray(foot_body) - params.hip_offsets[leg], params.signed_l1(leg), params
    )


def within_limits(joints: np.ndarray, params: HeavyDutyParams, tol: float = 1e-9) -> bool:
    """True when every joint of a (3,) or (6, 3) array lies inside its range."""
    r = params.joint_ranges
    j = np.asarray(joints)
    return bool(np.all(j >= r[:, 0] - tol) and np.all(j <= r[:, 1] + tol))


def standing_feet(params: HeavyDutyParams) -> dict[str, np.ndarray]:
    """Neutral standing footholds in the body frame: (±hip_x | 0, ±(hip_y+L1), −stand_height)."""
    return {
        leg: params.hip_offsets[leg] + np.array([0.0, params.signed_l1(leg), -params.stand_height])
        for leg in LEG_NAMES
    }
