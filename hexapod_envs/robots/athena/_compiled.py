"""ATHENA's six-leg kinematics as compiled calls (private; numba): the IK (`solve_legs`), a
posture-controller tick (`tick_legs`: its feet and their IK), a phase's foot paths
(`phase_plan`), eq. (12) for all legs (`feet_closed_form`) and the candidate ground-plane
triples of a phase start (`plane_triples`).

The posture controller solves the IK of all six feet at every control tick (50 ms);
:func:`solve_legs` is `LegIK.solve` for the six legs at once, with the same operations in the
same order. ``math.atan2``, ``sin``,
``cos`` and ``acos`` are the C library's in CPython and in numba alike; ``math.hypot`` is not
(CPython computes it with its own correctly rounded algorithm, libm's ``hypot`` differs in the
last bit for about 0.3 % of inputs), so the IK uses
:func:`hexapod_envs.stability._compiled.cpython_hypot`, which reproduces CPython's. A leg that
is out of reach or outside a joint range is flagged, with `LegIK.solve`'s clamped pose (its
message is `LegIK.solve`'s to give).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from hexapod_envs.stability._compiled import cpython_hypot


@njit(cache=True)
def _wrap(angle):
    return math.atan2(math.sin(angle), math.cos(angle))


@njit(cache=True)
def solve_legs(constants, feet):
    """(joint angles (6, 3) [rad], solved (6,)) for body-frame feet (6, 3) [m]: `LegIK.solve`
    for the six legs, its angles to the bit.

    ``constants`` (6, 18) holds each leg's `LegIK.packed_constants`. ``solved[i]`` is False where
    `LegIK.solve` reports a problem (out of reach, or a joint range exceeded by more than
    1e-9 rad); that row then holds its nearest pose, as `LegIK.solve` clamps it (the distance
    to the reachable annulus, the angles to the joint ranges).
    """
    n = feet.shape[0]
    angles = np.empty((n, 3))
    solved = np.empty(n, dtype=np.bool_)
    for i in range(n):
        hx, hy, hz, theta1, l2, l3, l4 = constants[i, 0:7]
        lo2, hi2, lo3, hi3, lo4, hi4 = constants[i, 7:13]
        l3_sq, l4_sq, two_l3_l4, s_low, s_high = constants[i, 13:18]
        dx, dy, dz = feet[i, 0] - hx, feet[i, 1] - hy, feet[i, 2] - hz
        t2 = _wrap(math.atan2(dy, dx) - theta1)  # eq. (14)
        horizontal = cpython_hypot(dx, dy)
        if not lo2 <= t2 <= hi2 and lo2 <= _wrap(t2 + math.pi) <= hi2:
            t2, horizontal = _wrap(t2 + math.pi), -horizontal  # foot behind the hip
        rho, zz = horizontal - l2, dz
        s = cpython_hypot(rho, zz)
        reachable = s_low <= s <= s_high
        if not reachable:  # LegIK.solve's nearest point of the reachable annulus
            s_new = _python_min(_python_max(s, abs(l3 - l4) + 1e-9), l3 + l4 - 1e-9)
            if s > 0:
                rho, zz = rho * s_new / s, zz * s_new / s
            else:
                rho, zz = s_new, 0.0
            s = s_new
        c4 = (s * s - l3_sq - l4_sq) / two_l3_l4  # eqs. (17)-(18), knee up
        t4 = -math.acos(c4 if -1.0 <= c4 <= 1.0 else min(1.0, max(-1.0, c4)))
        t3 = _wrap(math.atan2(zz, rho) - math.atan2(l4 * math.sin(t4), l3 + l4 * math.cos(t4)))
        solved[i] = (
            reachable
            and lo2 - 1e-9 <= t2 <= hi2 + 1e-9
            and lo3 - 1e-9 <= t3 <= hi3 + 1e-9
            and lo4 - 1e-9 <= t4 <= hi4 + 1e-9
        )
        if not solved[i]:
            t2 = _python_min(_python_max(t2, lo2), hi2)
            t3 = _python_min(_python_max(t3, lo3), hi3)
            t4 = _python_min(_python_max(t4, lo4), hi4)
        angles[i, 0], angles[i, 1], angles[i, 2] = t2, t3, t4
    return angles, solved


@njit(cache=True)
def _python_max(a, b):
    """CPython's ``max(a, b)`` of two floats: ``a`` unless ``b`` is greater (ties keep ``a``,
    which decides the sign of a zero)."""
    return b if b > a else a


@njit(cache=True)
def _python_min(a, b):
    """CPython's ``min(a, b)`` of two floats: ``a`` unless ``b`` is smaller."""
    return b if b < a else a


@njit(cache=True)
def tick_legs(constants, command, u, swing, swing_points, stance, stance_start, stance_delta):
    """One control tick of the posture controller: write the commanded feet (body frame, m) at
    phase fraction ``u`` into ``command`` (6, 3) and return :func:`solve_legs` of it.

    The swing rows ``swing`` follow their cubic Bezier curves (control points (k, 4, 3), eqs.
    20-21), the stance rows ``stance`` their straight lines ``start + u delta`` (eq. 31); the
    arithmetic is the Python controller's: the Bernstein weights with CPython's ``pow``
    (``math.pow``; ``v**3`` would compile to two multiplications), each leg's curve a BLAS
    ``np.dot`` as numpy's stacked ``@``.
    """
    v = 1.0 - u
    weights = np.array((math.pow(v, 3.0), 3 * v * v * u, 3 * v * u * u, math.pow(u, 3.0)))
    for k in range(swing.shape[0]):
        command[swing[k]] = np.dot(weights, swing_points[k])
    for k in range(stance.shape[0]):
        for j in range(3):
            command[stance[k], j] = stance_start[k, j] + u * stance_delta[k, j]
    return solve_legs(constants, command)


@njit(cache=True)
def feet_closed_form(q, theta1, l1, l2, l3, l4):
    """(6, 3) body-frame feet [m] of joint angles ``q`` (6, 3) [rad]: eq. (12) written out, the
    arithmetic of `kinematics.foot_position_closed_form` per row (``theta1``, ``l1``: each leg's
    mounting angle [rad] and hip distance [m]; ``l2``-``l4``: link lengths [m])."""
    n = q.shape[0]
    feet = np.empty((n, 3))
    for i in range(n):
        t2, t3, t4 = q[i, 0], q[i, 1], q[i, 2]
        t1, a1 = theta1[i], l1[i]
        reach = l4 * math.cos(t3 + t4) + l3 * math.cos(t3) + l2
        feet[i, 0] = math.cos(t1 + t2) * reach + a1 * math.cos(t1)
        feet[i, 1] = math.sin(t1 + t2) * reach + a1 * math.sin(t1)
        feet[i, 2] = l4 * math.sin(t3 + t4) + l3 * math.sin(t3)
    return feet


@njit(cache=True)
def phase_plan(start, swing, stance, stride, swing_height, height_correction, rotation):
    """One phase's foot paths from its start feet ``start`` (6, 3) (body frame, m): the
    ``swing`` rows' Bezier control points (k, 4, 3) (`gait.swing_control_points`: eqs. 20-22
    and 27) and the ``stance`` rows' start points and straight-line deltas (k, 3) each
    (`gait.stance_end_point`: eqs. 28-30, p_f = R (p0 + (-stride, 0, k_z Δz)) minus p0), with
    their arithmetic: element-wise sums and the rotation as a BLAS ``np.dot`` as numpy's ``@``.
    """
    offsets = np.array(
        (
            (0.0, 0.0, 0.0),
            (stride / 4, 0.0, swing_height / 3),
            (3 * stride / 4, 0.0, swing_height / 3),
            (stride, 0.0, height_correction),
        )
    )
    swing_points = np.empty((swing.shape[0], 4, 3))
    for k in range(swing.shape[0]):
        for r in range(4):
            for j in range(3):
                swing_points[k, r, j] = start[swing[k], j] + offsets[r, j]
    shift = np.array((-stride, 0.0, height_correction))
    stance_start = np.empty((stance.shape[0], 3))
    stance_delta = np.empty((stance.shape[0], 3))
    moved = np.empty(3)
    for k in range(stance.shape[0]):
        for j in range(3):
            stance_start[k, j] = start[stance[k], j]
            moved[j] = start[stance[k], j] + shift[j]
        end = np.dot(rotation, moved)
        for j in range(3):
            stance_delta[k, j] = end[j] - stance_start[k, j]
    return swing_points, stance_start, stance_delta


@njit(cache=True)
def plane_triples(feet, contact, min_area):
    """The triples of feet in ``contact`` (6,) whose x-y support triangle is larger than
    ``min_area`` [m²]: (leg indices (k, 3), areas (k,)), in ``itertools.combinations`` order of
    the contact legs. Each area is `gait.triangle_area_xy` of the body-frame ``feet`` (6, 3)
    [m], the same operations in the same order."""
    legs = np.flatnonzero(contact)
    n = legs.size
    triples = np.empty((n * (n - 1) * (n - 2) // 6, 3), dtype=np.int64)  # 0 below 3 legs
    areas = np.empty(triples.shape[0])
    k = 0
    for a in range(n):
        for b in range(a + 1, n):
            for c in range(b + 1, n):
                i, j, m = legs[a], legs[b], legs[c]
                cross = (feet[j, 0] - feet[i, 0]) * (feet[m, 1] - feet[i, 1]) - (
                    feet[j, 1] - feet[i, 1]
                ) * (feet[m, 0] - feet[i, 0])
                area = 0.5 * abs(cross)
                if area > min_area:
                    triples[k, 0], triples[k, 1], triples[k, 2] = i, j, m
                    areas[k] = area
                    k += 1
    return triples[:k], areas[:k]
