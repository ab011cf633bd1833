"""The Stewart platform's actuator lengths as a compiled call (private; numba):
:func:`stewart_actuator_lengths`, which the tilt env reports every step, with the arithmetic of
`hexapod_envs.terrain.stewart_kinematics` (the tests compare them bit for bit)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["stewart_actuator_lengths"]


@njit(cache=True)
def stewart_actuator_lengths(base_joints, platform_joints, centre, roll, pitch, yaw):
    """(6,) actuator lengths [m] of a Stewart platform whose centre is at ``centre`` (3,) [m]
    with orientation (``roll``, ``pitch``, ``yaw``) [rad]: the arithmetic of
    `hexapod_envs.terrain.stewart_kinematics.StewartPlatform.actuator_lengths` for joints
    ``base_joints`` and ``platform_joints`` (6, 3) [m] - `rpy_matrix`, the platform joints
    rotated by ``np.dot`` with the matrix's transposed view as numpy's ``@``, and each leg's
    norm as numpy's (its squares summed left to right)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    rotation = np.empty((3, 3))
    rotation[0, 0] = cy * cp
    rotation[0, 1] = cy * sp * sr - sy * cr
    rotation[0, 2] = cy * sp * cr + sy * sr
    rotation[1, 0] = sy * cp
    rotation[1, 1] = sy * sp * sr + cy * cr
    rotation[1, 2] = sy * sp * cr - cy * sr
    rotation[2, 0] = -sp
    rotation[2, 1] = cp * sr
    rotation[2, 2] = cp * cr
    moved = np.dot(platform_joints, rotation.T)
    lengths = np.empty(platform_joints.shape[0])
    for i in range(platform_joints.shape[0]):
        x = (centre[0] + moved[i, 0]) - base_joints[i, 0]
        y = (centre[1] + moved[i, 1]) - base_joints[i, 1]
        z = (centre[2] + moved[i, 2]) - base_joints[i, 2]
        lengths[i] = math.sqrt((x * x + y * y) + z * z)
    return lengths
