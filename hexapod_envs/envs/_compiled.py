"""Compiled per-step measurements of the envs (private; numba).

Every control step ends with the sensor model: foot forces rotated to the world frame, the
contact test, the CoG, the FASM over the loaded feet and the actuator power. As a dozen numpy
calls right after MuJoCo's physics (which leaves the caches cold) it cost 35-50 µs per step,
about a tenth of the cliff walk's physics. :func:`heavy_duty_measure` (the heavy-duty and
ATHENA envs, through `RobotSensors.support`) does it in one call with the same arithmetic in the
same order: the rotations are ``np.dot`` calls, i.e. the BLAS routine numpy's ``@`` calls (numba
binds it through scipy's BLAS; the same bits where the two libraries agree, as they do on the
machines this was measured on), the power is summed in numpy's pairwise order
(`hexapod_envs._compiled.actuator_power`), and the FASM is the stability module's kernel. It
writes into the caller's buffers rather than returning new arrays.

The rest of a step's Python is compiled the same way where it is element-wise work on a few
dozen numbers: the action check and clip (:func:`clip_action`), the residual modes' servo
targets (:func:`filtered_residual_targets` with the heavy-duty envs' filter,
:func:`offset_targets` on ATHENA's controller), the observation's sensor pieces
(:func:`sensor_observation`), each with numpy's arithmetic (the tests compare them bit for
bit). Kernels of one robot or terrain live with it: the 3-UPU robot's measurement
(`hexapod_envs.robots.upu._compiled.upu_measure`) and the Stewart platform's actuator lengths
that the tilt env reports (`hexapod_envs.terrain._compiled`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hexapod_envs._compiled import actuator_power, numpy_sum
from hexapod_envs.stability._compiled import OK, fasm_from_feet, zmp_margin


@njit(cache=True)
def heavy_duty_measure(
    sensordata,
    force_idx,
    site_xmat,
    site_xpos,
    foot_site,
    subtree_com,
    torso,
    actuator_force,
    actuator_velocity,
    actuators,
    contact_force_sq,
    forces,
    loaded,
    cog,
    feet,
):
    """One step's measurements of a legged robot's env (see `RobotSensors.support`), written
    into the caller's buffers: foot forces (n, 3) world frame [N], loaded (n,), CoG (3,) [m],
    and as scratch the feet (n, 3). A foot's force is
    minus its force sensor's reading (site frame) rotated by its site's orientation.

    Returns (FASM status, margin [deg], edge i, edge j, actuator power Σ|F v| [W]). Writing
    into preallocated arrays instead of returning new ones saves the boxing of three arrays
    per step.
    """
    n = foot_site.shape[0]
    local = np.empty(3)
    for i in range(n):
        site = foot_site[i]
        for j in range(3):
            local[j] = sensordata[force_idx[i, j]]
            feet[i, j] = site_xpos[site, j]
        world = np.dot(site_xmat[site].reshape(3, 3), local)
        f0, f1, f2 = -world[0], -world[1], -world[2]
        forces[i, 0], forces[i, 1], forces[i, 2] = f0, f1, f2
        loaded[i] = f0 * f0 + f1 * f1 + f2 * f2 > contact_force_sq
    for j in range(3):
        cog[j] = subtree_com[torso, j]
    status, margin, edge_i, edge_j = fasm_from_feet(feet, forces, cog, loaded)
    power = actuator_power(actuator_force[actuators], actuator_velocity[actuators])
    return status, margin, edge_i, edge_j, power


@njit(cache=True)
def sensor_observation(
    out, actuator_length, actuator_velocity, actuators, forces, loaded, fasm_deg, sensordata, imu
):
    """Write the observation's sensor pieces into ``out`` in the order of
    `RobotSensors.OBSERVED`: joint positions and velocities (``actuators``' lengths and
    velocities), foot forces (n, 3) row by row, the loaded flags as 0 / 1, the FASM [deg] and
    the IMU readings at the ``imu`` addresses of ``sensordata`` (gyro, accelerometer,
    quaternion)."""
    k = 0
    for i in range(actuators.shape[0]):
        out[k] = actuator_length[actuators[i]]
        k += 1
    for i in range(actuators.shape[0]):
        out[k] = actuator_velocity[actuators[i]]
        k += 1
    for i in range(forces.shape[0]):
        for j in range(3):
            out[k] = forces[i, j]
            k += 1
    for i in range(loaded.shape[0]):
        out[k] = 1.0 if loaded[i] else 0.0
        k += 1
    out[k] = fasm_deg
    k += 1
    for i in range(imu.shape[0]):
        out[k] = sensordata[imu[i]]
        k += 1


@njit(cache=True)
def torso_frame_zmp(site_xpos, foot_site, torso_pos, torso_xmat, forces, loaded, min_force):
    """The ZMP (2,) [m] and its margin [m] in the torso frame (Coelho et al. 2024 eqs. 32-33;
    see `RobotSensors.torso_frame_zmp`).

    The loaded feet (world frame, relative to the torso, rotated into the torso frame by
    ``np.dot`` as numpy's ``@``) weigh in with their force's non-negative vertical component.
    The ZMP is numpy's ``normal @ feet[:, :2] / normal.sum()`` (for that strided view numpy
    takes one BLAS dot per column, which the kernel repeats), NaN without any weight; the
    margin is the stability kernel's :func:`~hexapod_envs.stability._compiled.zmp_margin`
    (summed in the feet's order, as the Python ``zmp_margin``), 0 without weight or without a
    foot above ``min_force`` [N].
    """
    n = foot_site.shape[0]
    relative = np.empty((n, 3))
    normal = np.empty(n)
    for i in range(n):
        for j in range(3):
            relative[i, j] = site_xpos[foot_site[i], j] - torso_pos[j]
        f = forces[i, 2]
        normal[i] = (f if f > 0.0 else 0.0) if loaded[i] else 0.0  # np.maximum(f, 0.0)
    feet = np.dot(relative, torso_xmat.reshape(3, 3))
    total = numpy_sum(normal)
    if not total > 0.0:
        return np.full(2, np.nan), 0.0
    zmp = np.empty(2)
    column = np.empty(n)
    for j in range(2):  # numpy's ``normal @ feet[:, :2]``: a contiguous dot per column
        for i in range(n):
            column[i] = feet[i, j]
        zmp[j] = np.dot(normal, column) / total
    status, _, _, margin = zmp_margin(feet[:, 0], feet[:, 1], normal, min_force)
    return zmp, (margin if status == OK else 0.0)


@njit(cache=True)
def clip_action(action, low, high, out):
    """``out`` = the ``action`` (any real dtype, as float64) clipped to [``low``, ``high``], as
    ``np.minimum(np.maximum(action, low), high)``; False (``out`` unfinished) at the first NaN or
    infinite value."""
    for i in range(action.shape[0]):
        x = np.float64(action[i])
        if not np.isfinite(x):
            return False
        x = x if x > low[i] else low[i]  # strict, as numpy's: a signed zero at a zero bound
        out[i] = x if x < high[i] else high[i]  # takes the bound's sign
    return True


@njit(cache=True)
def filtered_residual_targets(action, gain, alpha, residual, reference, ctrl, actuators):
    """The residual action modes' servo targets, in numpy's arithmetic: the residual's low-pass
    ``residual += alpha * (gain * action - residual)`` (in place), then
    ``ctrl[actuators] = reference + residual``."""
    for i in range(action.shape[0]):
        residual[i] += alpha * (gain[i] * action[i] - residual[i])
        ctrl[actuators[i]] = reference[i] + residual[i]


@njit(cache=True)
def offset_targets(targets, gain, action, ctrl, actuators):
    """``ctrl[actuators] = targets + gain * action`` (``targets`` flattened in C order), in
    numpy's arithmetic: ATHENA's residual mode, the controller's joint targets plus the scaled
    action."""
    flat = targets.reshape(-1)
    for i in range(action.shape[0]):
        ctrl[actuators[i]] = flat[i] + gain[i] * action[i]
