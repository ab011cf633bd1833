"""ATHENA leg kinematics (Coelho et al. 2024, Section 3.2), pure numpy.

Forward kinematics follows the Denavit-Hartenberg table 3 literally (T = Rz(theta) Tz(d) Tx(a)
Rx(alpha) per row) with the mounting angle theta_1 of eq. (13); `foot_position_closed_form` is
eq. (12) and must agree with the DH product. Inverse kinematics is the analytic solution of
eqs. (14)-(18): the TC angle from the foot's azimuth about the hip, then a planar two-link problem
for CTr and FTi on the "knee up" branch (theta_4 in (-pi, 0), the branch of the standing posture;
eq. (18)'s pi + acos(...) is the same angle modulo 2 pi).

All positions are in the body frame (x forward, y left, z up, origin at the torso centre), in m;
angles are the DH joint angles theta_2 (TC), theta_3 (CTr), theta_4 (FTi) in rad. Per-robot
arrays have shape (6, 3): rows in `LEG_NAMES` order, columns (TC, CTr, FTi) or (x, y, z). The
posture controller solves all six legs per tick with `_compiled.solve_legs`: `LegIK.solve`
compiled (the same bits, the clamped poses included; the messages are `LegIK.solve`'s).
"""

from __future__ import annotations

import functools
import math
from math import acos, atan2, cos, hypot, sin

import numpy as np

from . import _compiled
from .params import ATHENA, JOINT_NAMES, LEG_NAMES, AthenaParams


def dh_transform(alpha: float, a: float, theta: float, d: float = 0.0) -> np.ndarray:
    """Homogeneous 4x4 transform of one DH row: Rz(theta) Tz(d) Tx(a) Rx(alpha)."""
    ct, st = math.cos(theta), math.sin(theta)
    ca, sa = math.cos(alpha), math.sin(alpha)
    return np.array(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0.0, sa, ca, d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def dh_table(leg: str, q: np.ndarray, params: AthenaParams = ATHENA) -> list[tuple]:
    """Table 3 for `leg` at joint angles q = (theta_2, theta_3, theta_4): rows (alpha, a, theta)."""
    q = _leg_angles(q)
    return [
        (0.0, params.hip_distance(leg), params.mounting_angle(leg)),
        (math.pi / 2, params.l2, q[0]),
        (0.0, params.l3, q[1]),
        (0.0, params.l4, q[2]),
    ]


def leg_frames(leg: str, q: np.ndarray, params: AthenaParams = ATHENA) -> np.ndarray:
    """(5, 4, 4) transforms T_k^0 of the DH frames {0} (body) ... {4} (foot centre)."""
    frames = [np.eye(4)]
    for alpha, a, theta in dh_table(leg, q, params):
        frames.append(frames[-1] @ dh_transform(alpha, a, theta))
    return np.array(frames)


def forward_kinematics(leg: str, q: np.ndarray, params: AthenaParams = ATHENA) -> np.ndarray:
    """Foot-sphere centre of `leg` in the body frame (eq. 11, via the DH chain), m."""
    return leg_frames(leg, q, params)[-1][:3, 3].copy()


def foot_position_closed_form(leg: str, q: np.ndarray, params: AthenaParams = ATHENA) -> np.ndarray:
    """Eq. (12) written out: the same point as `forward_kinematics`, m."""
    t2, t3, t4 = _leg_angles(q)
    t1, l1 = params.mounting_angle(leg), params.hip_distance(leg)
    reach = params.l4 * math.cos(t3 + t4) + params.l3 * math.cos(t3) + params.l2
    return np.array(
        [
            math.cos(t1 + t2) * reach + l1 * math.cos(t1),
            math.sin(t1 + t2) * reach + l1 * math.sin(t1),
            params.l4 * math.sin(t3 + t4) + params.l3 * math.sin(t3),
        ]
    )


def feet_closed_form(q: np.ndarray, params: AthenaParams = ATHENA) -> np.ndarray:
    """(6, 3) body-frame feet [m] for (6, 3) joint angles (rows `LEG_NAMES`): eq. (12) of every
    leg in one compiled call, `foot_position_closed_form`'s numbers to the bit (what the posture
    controller reads from the encoders at every phase start)."""
    theta1, l1 = _closed_form_constants(params)
    q = np.ascontiguousarray(_robot_array(q, "joint angles"))
    return _compiled.feet_closed_form(q, theta1, l1, params.l2, params.l3, params.l4)


@functools.lru_cache(maxsize=16)
def _closed_form_constants(params: AthenaParams) -> tuple[np.ndarray, np.ndarray]:
    """Each leg's mounting angle [rad] and hip distance [m], as `foot_position_closed_form`
    computes them."""
    theta1 = np.array([params.mounting_angle(leg) for leg in LEG_NAMES])
    l1 = np.array([params.hip_distance(leg) for leg in LEG_NAMES])
    return theta1, l1


def forward_kinematics_all(q: np.ndarray, params: AthenaParams = ATHENA) -> np.ndarray:
    """(6, 3) foot positions in the body frame for (6, 3) joint angles (rows `LEG_NAMES`)."""
    q = _robot_array(q, "joint angles")
    return np.array([forward_kinematics(leg, q[i], params) for i, leg in enumerate(LEG_NAMES)])


def is_reachable(leg: str, p: np.ndarray, params: AthenaParams = ATHENA) -> bool:
    """True if the foot point `p` (body frame, m) has an IK solution inside the joint ranges."""
    try:
        inverse_kinematics(leg, p, params)
    except ValueError:
        return False
    return True


def inverse_kinematics(
    leg: str, p: np.ndarray, params: AthenaParams = ATHENA, *, clamp: bool = False
) -> np.ndarray:
    """Joint angles (theta_2, theta_3, theta_4) that put the foot centre of `leg` at `p`.

    `p` is in the body frame (m). Unreachable points (too far/near for the femur-tibia pair, or
    angles outside the joint ranges) raise ValueError, unless `clamp` is True: then the distance
    is clamped to the reachable annulus and the angles to the joint ranges, which gives the
    nearest pose the servos can take (what a controller wants to command).
    """
    p = np.asarray(p, dtype=float)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ValueError(f"foot position must be 3 finite numbers, got {p!r}")
    *q, problem = leg_ik(leg, params).solve(*p.tolist())
    if problem is not None and not clamp:
        raise ValueError(f"foot position {p.tolist()} {problem}")
    return np.array(q)


class LegIK:
    """The analytic inverse kinematics of one leg with its constants precomputed.

    `solve(x, y, z)` works on plain floats (a controller calls it for six legs at every tick) and
    is the one implementation behind `inverse_kinematics`.
    """

    def __init__(self, leg: str, params: AthenaParams = ATHENA):
        self.leg = leg
        self.hip = tuple(float(v) for v in params.hip_position(leg))
        self.theta1 = params.mounting_angle(leg)
        self.l2, self.l3, self.l4 = params.l2, params.l3, params.l4
        self.ranges = tuple(tuple(r) for r in params.joint_ranges.tolist())
        l2, l3, l4 = self.l2, self.l3, self.l4
        # Everything `solve` reads, unpacked in one go (it runs for six legs every tick); the
        # derived constants are the very expressions `solve` used to evaluate per call.
        self._constants = (
            *self.hip, self.theta1, l2, l3, l4, *(v for r in self.ranges for v in r),
            l3 * l3, l4 * l4, 2 * l3 * l4, abs(l3 - l4) + 1e-12, l3 + l4 - 1e-12,
        )  # fmt: skip

    @property
    def packed_constants(self) -> tuple[float, ...]:
        """The 18 numbers `solve` reads (hip, mounting angle, links, joint ranges, derived
        terms), in the order `_compiled.solve_legs` takes them."""
        return self._constants

    def solve(self, x: float, y: float, z: float) -> tuple[float, float, float, str | None]:
        """(theta_2, theta_3, theta_4, problem) for the foot centre at body-frame (x, y, z), m.

        `problem` is None for a reachable point; otherwise it says why the point is out of reach
        and the angles are the nearest pose the servos can take (distance clamped to the
        reachable annulus, angles to the joint ranges).
        """
        (
            hx, hy, hz, theta1, l2, l3, l4, lo2, hi2, lo3, hi3, lo4, hi4,
            l3_sq, l4_sq, two_l3_l4, s_low, s_high,
        ) = self._constants  # fmt: skip
        dx, dy, dz = x - hx, y - hy, z - hz

        # Eq. (14): TC angle = azimuth of the foot about the hip, relative to the mounting angle.
        a2 = atan2(dy, dx) - theta1
        t2 = atan2(sin(a2), cos(a2))  # _wrap, inlined (six legs every tick)
        horizontal = hypot(dx, dy)
        if not lo2 <= t2 <= hi2 and lo2 <= _wrap(t2 + math.pi) <= hi2:
            # Foot horizontally behind the hip (femur down, tibia folded back under the body):
            # the coxa points away from the foot and the foot's reach along it is negative.
            t2, horizontal = _wrap(t2 + math.pi), -horizontal
        # Planar problem in the leg's vertical plane, origin at the CTr joint (frame U, eq. 16).
        rho, zz = horizontal - l2, dz
        s = hypot(rho, zz)
        problem = None
        if not s_low <= s <= s_high:
            s_min, s_max = abs(l3 - l4), l3 + l4
            problem = (
                f"is out of reach of leg {self.leg}: distance {s:.4f} m from the CTr joint, "
                f"reachable [{s_min:.4f}, {s_max:.4f}] m"
            )
            s_new = min(max(s, s_min + 1e-9), s_max - 1e-9)
            if s > 0:
                rho, zz = rho * s_new / s, zz * s_new / s
            else:
                rho, zz = s_new, 0.0
            s = s_new
        # Eqs. (17)-(18), knee-up branch (theta_4 < 0).
        c4 = (s * s - l3_sq - l4_sq) / two_l3_l4
        t4 = -acos(c4 if -1.0 <= c4 <= 1.0 else min(1.0, max(-1.0, c4)))
        a3 = atan2(zz, rho) - atan2(l4 * sin(t4), l3 + l4 * cos(t4))
        t3 = atan2(sin(a3), cos(a3))  # _wrap, inlined

        if (
            problem is None
            and lo2 - 1e-9 <= t2 <= hi2 + 1e-9
            and lo3 - 1e-9 <= t3 <= hi3 + 1e-9
            and lo4 - 1e-9 <= t4 <= hi4 + 1e-9
        ):
            return t2, t3, t4, None  # the usual case, without building the lists below
        q = (t2, t3, t4)
        bounds = ((lo2, hi2), (lo3, hi3), (lo4, hi4))
        bad = [k for k in range(3) if not bounds[k][0] - 1e-9 <= q[k] <= bounds[k][1] + 1e-9]
        if bad and problem is None:
            problem = f"of leg {self.leg} needs joint angles outside the ranges: " + ", ".join(
                f"{JOINT_NAMES[k]}={q[k]:.4f} not in [{bounds[k][0]:.4f}, {bounds[k][1]:.4f}]"
                for k in bad
            )
        if problem is not None:
            q = tuple(min(max(q[k], bounds[k][0]), bounds[k][1]) for k in range(3))
        return (*q, problem)


@functools.lru_cache(maxsize=64)
def leg_ik(leg: str, params: AthenaParams = ATHENA) -> LegIK:
    """The (cached) `LegIK` of `leg` for `params`; ValueError for an unknown leg."""
    if leg not in LEG_NAMES:
        raise ValueError(f"unknown leg {leg!r}; valid: {', '.join(LEG_NAMES)}")
    return LegIK(leg, params)


def inverse_kinematics_all(
    p: np.ndarray, params: AthenaParams = ATHENA, *, clamp: bool = False
) -> np.ndarray:
    """(6, 3) joint angles for (6, 3) foot positions (rows in `LEG_NAMES` order)."""
    p = _robot_array(p, "foot positions")
    return np.array(
        [inverse_kinematics(leg, p[i], params, clamp=clamp) for i, leg in enumerate(LEG_NAMES)]
    )


def standing_joint_angles(params: AthenaParams = ATHENA) -> np.ndarray:
    """(6, 3) joint angles of the standing posture (Section 5.1), rad."""
    return np.tile(np.asarray(params.standing_posture, dtype=float), (6, 1))


def standing_foot_positions(params: AthenaParams = ATHENA) -> np.ndarray:
    """(6, 3) foot-centre positions of the standing posture in the body frame, m."""
    return forward_kinematics_all(standing_joint_angles(params), params)


def within_limits(q: np.ndarray, params: AthenaParams = ATHENA) -> np.ndarray:
    """Boolean mask (same shape as q, last axis = joints) of angles inside the joint ranges."""
    q = np.asarray(q, dtype=float)
    lo, hi = params.joint_ranges[:, 0], params.joint_ranges[:, 1]
    return (q >= lo) & (q <= hi)


def _leg_angles(q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.shape != (3,):
        raise ValueError(f"leg joint angles must have shape (3,) = {JOINT_NAMES}, got {q.shape}")
    return q


def _robot_array(a: np.ndarray, what: str) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    if a.shape != (6, 3):
        raise ValueError(f"{what} must have shape (6, 3) (rows {LEG_NAMES}), got {a.shape}")
    return a


def _wrap(angle: float) -> float:
    """Angle wrapped to (-pi, pi]."""
    return math.atan2(math.sin(angle), math.cos(angle))
