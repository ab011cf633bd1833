"""Compiled per-step measurement of the 3-UPU hexapod (private; numba).

The ditch crossing env (`hexapod_envs.envs.ditch_crossing`) ends every control step with the
robot's sensor model: foot forces to the world frame, the pressure switches, the CoG, the FASM
over the loaded feet, the static margin and the actuator power. :func:`upu_measure` does it in
one call with the arithmetic of the numpy code it replaced, in the same order (the rotation is an
``np.dot``, i.e. the BLAS routine numpy's ``@`` calls; the power is summed in numpy's pairwise
order, `hexapod_envs._compiled.actuator_power`; the FASM and the static margin are the stability
module's kernels), so that the episodes stay the same to the bit. The kernels that serve every
legged robot's env stay in `hexapod_envs.envs._compiled`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hexapod_envs._compiled import actuator_power
from hexapod_envs.stability._compiled import fasm_from_feet, hull_distance, signed_distance_2d


@njit(cache=True)
def upu_measure(
    sensordata,
    force_idx,
    torso_xmat,
    foot_weight,
    touch_idx,
    contact_force,
    xpos,
    foot_body,
    torso_com,
    actuator_force,
    actuator_velocity,
):
    """One step's measurements of the 3-UPU hexapod (see HexapodDitchCrossingEnv._measure).

    Returns (foot forces (6, 3) world frame [N], loaded (6,), CoG (3,) [m], FASM status,
    margin [deg], edge i, edge j, static margin [m], actuator power Σ|F v| [W]). The foot sites
    stay parallel to the torso, so its rotation takes every force reading to the world frame:
    ground reaction = foot weight - R s. The static margin is the CoG's signed distance to the
    loaded soles' polygon seen from above (0 without one); a tripod's hull is its triangle.
    """
    n = foot_body.shape[0]
    local = np.empty((n, 3))
    soles = np.empty((n, 3))
    loaded = np.empty(n, dtype=np.bool_)
    for i in range(n):
        for j in range(3):
            local[i, j] = sensordata[force_idx[i, j]]
            soles[i, j] = xpos[foot_body[i], j]
        loaded[i] = sensordata[touch_idx[i]] > contact_force
    forces = foot_weight - np.dot(local, torso_xmat.reshape(3, 3).T)
    cog = torso_com.copy()
    status, margin, edge_i, edge_j = fasm_from_feet(soles, forces, cog, loaded)
    static = _static_margin(soles, loaded, cog[0], cog[1])
    power = actuator_power(actuator_force, actuator_velocity)
    return forces, loaded, cog, status, margin, edge_i, edge_j, static, power


@njit(cache=True)
def _static_margin(soles, loaded, px, py):
    """Signed distance [m] of (px, py) to the loaded soles' support polygon seen from above;
    0 with fewer than 3 loaded soles or when they lie on a line."""
    count = 0
    for i in range(loaded.shape[0]):
        count += loaded[i]
    if count < 3:
        return 0.0
    xs, ys = np.empty(count), np.empty(count)
    count = 0
    for i in range(loaded.shape[0]):
        if loaded[i]:
            xs[count], ys[count] = soles[i, 0], soles[i, 1]
            count += 1
    if count == 3:  # a tripod (most steps): its hull is the triangle, ordered ccw
        area2 = (xs[1] - xs[0]) * (ys[2] - ys[0]) - (ys[1] - ys[0]) * (xs[2] - xs[0])
        if area2 != 0.0:
            hull = np.array((0, 1, 2)) if area2 > 0 else np.array((0, 2, 1))
            return signed_distance_2d(xs, ys, hull, px, py)
    return hull_distance(xs, ys, px, py)


@njit(cache=True)
def fewest_steps(upper_targets, lower_targets, ok_upper, ok_lower, n_x, n_goal):
    """Breadth-first search of the ditch planner (`gait_plan._fewest_steps`), one state at a time.

    A state is (mover, i, j): the platform that moves next (0 upper, 1 lower), the lower
    centre's grid index i < n_x and the upper centre's offset j = x_upper - x_lower in grid
    cells. From the start (0, 0, 0) it tries each state's moves in the order of the target
    tables (longest first), marks a state when it is first reached and stops at the first
    state reached with j = 0 and i >= n_goal.

    Args:
        upper_targets, lower_targets: (n_d + 1, k) int64, the offsets j1 reachable from each j
            by a step of that platform, in the search's order, padded with -1.
        ok_upper, ok_lower: (n_x + n_d + 1,) bool, a platform centred at that grid index has
            every foot on ground it may land on.

    Returns:
        (m, 3) int64: the states (i, j, mover) from the start to the goal; (0, 3) if none.
    """
    width = upper_targets.shape[0]
    plane = n_x * width
    parent = np.full(2 * plane, -1, dtype=np.int64)
    queue = np.empty(2 * plane, dtype=np.int64)
    queue[0] = 0
    parent[0] = 0
    head, tail = 0, 1
    while head < tail:
        state = queue[head]
        head += 1
        mover, rest = state // plane, state % plane
        i, j = rest // width, rest % width
        targets = upper_targets if mover == 0 else lower_targets
        for k in range(targets.shape[1]):
            j1 = targets[j, k]
            if j1 < 0:
                continue
            if mover == 0:
                i1 = i
                if not ok_upper[i + j1]:
                    continue
            else:
                i1 = i + j - j1
                if i1 >= n_x or not ok_lower[i1]:
                    continue
            reached = (1 - mover) * plane + i1 * width + j1
            if parent[reached] >= 0:
                continue
            parent[reached] = state
            queue[tail] = reached
            tail += 1
            if j1 == 0 and i1 >= n_goal:
                count = 1
                s = reached
                while s != 0:
                    s = parent[s]
                    count += 1
                chain = np.empty((count, 3), dtype=np.int64)
                s = reached
                for c in range(count - 1, -1, -1):
                    chain[c, 0] = (s % plane) // width
                    chain[c, 1] = (s % plane) % width
                    chain[c, 2] = s // plane
                    s = parent[s]
                return chain
    return np.empty((0, 3), dtype=np.int64)
