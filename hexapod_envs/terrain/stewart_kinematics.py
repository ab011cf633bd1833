"""Inverse kinematics of the 6-UPS Stewart platform of Zhang et al. 2024 §5.2. Pure numpy.

The paper gives the moving platform's radius (3.5 m), the fixed base's (5.5 m) and the actuator
stroke (9-14 m); the joint layout and neutral height are chosen here (a standard 6-6 layout):

- Base joints b_i on the 5.5 m circle in three pairs centred at 0°, 120°, 240°, the two joints
  of a pair ``base_pair_angle_deg`` = 20° apart (angles ∓10°, 110°/130°, 230°/250°).
- Platform joints a_i on the 3.5 m circle in three pairs centred at 60°, 180°, 300°, 20° apart.
  Actuator i joins base joint i to the nearest platform joint of the neighbouring pair (b at
  +10° to a at 50°, b at 110° to a at 70°, ...), the usual crossed-triangle arrangement.
- Angles are measured from the base frame's +x towards +y; z points up; the platform frame's
  origin is the platform centre, its joints lie in its z = 0 plane.
- Neutral pose: platform level at height ``neutral_height`` = 11.0 m above the base centre, where
  every actuator is 11.58 m long (mid-stroke 11.5 m). From there the platform tilts at least
  43.9° about every horizontal axis through its centre before an actuator reaches a limit
  (45.7° either way about x, 46.0° / 58.5° about +y / -y; see :meth:`StewartPlatform.max_tilt`);
  10.5 m or 11.5 m would leave only 42° or 34°.

Orientation is given as roll-pitch-yaw (rad): R = Rz(yaw) Ry(pitch) Rx(roll), i.e. rotations about
the base frame's fixed x, then y, then z axes. Only actuator length limits are modelled (no joint
angle limits, no actuator collisions).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

AXIS_NAMES: dict[str, tuple[float, float, float]] = {
    "x": (1.0, 0.0, 0.0),
    "y": (0.0, 1.0, 0.0),
    "z": (0.0, 0.0, 1.0),
    "roll": (1.0, 0.0, 0.0),
    "pitch": (0.0, 1.0, 0.0),
}


def rpy_matrix(rpy) -> np.ndarray:
    """Rotation matrix R = Rz(yaw) Ry(pitch) Rx(roll) from (roll, pitch, yaw) [rad]."""
    roll, pitch, yaw = np.asarray(rpy, dtype=float).reshape(3).tolist()
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def axis_angle_matrix(axis, angle: float) -> np.ndarray:
    """Rotation by ``angle`` [rad] about unit ``axis`` (Rodrigues)."""
    k = np.asarray(axis, dtype=float)
    k = k / np.linalg.norm(k)
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * kx + (1.0 - math.cos(angle)) * kx @ kx


def _circle_points(radius: float, angles_deg: np.ndarray) -> np.ndarray:
    a = np.radians(angles_deg)
    return np.column_stack([radius * np.cos(a), radius * np.sin(a), np.zeros_like(a)])


@dataclass(frozen=True)
class StewartPlatform:
    """Geometry of a 6-UPS Stewart platform (SI units) and its inverse kinematics.

    Attributes:
        base_radius: radius of the fixed base's joint circle [m] (paper: 5.5).
        platform_radius: radius of the moving platform's joint circle [m] (paper: 3.5).
        base_pair_angle_deg: angle between the two base joints of a pair [deg] (chosen: 20).
        platform_pair_angle_deg: angle between the two platform joints of a pair [deg] (20).
        length_range: actuator length limits [m] (paper: 9-14).
        neutral_height: platform centre above the base centre in the neutral pose [m] (11.0).
    """

    base_radius: float = 5.5
    platform_radius: float = 3.5
    base_pair_angle_deg: float = 20.0
    platform_pair_angle_deg: float = 20.0
    length_range: tuple[float, float] = (9.0, 14.0)
    neutral_height: float = 11.0
    base_joints: np.ndarray = field(init=False, repr=False)
    platform_joints: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        lo, hi = self.length_range
        if not 0.0 < lo < hi:
            raise ValueError(f"length_range must satisfy 0 < min < max, got {self.length_range}")
        for name in ("base_pair_angle_deg", "platform_pair_angle_deg"):
            if not 0.0 < getattr(self, name) < 120.0:
                raise ValueError(f"{name} must lie in (0, 120) degrees, got {getattr(self, name)}")
        i = np.arange(6)
        sign = np.where(i % 2 == 0, -1.0, 1.0)
        centre = 120.0 * (i // 2)
        base_angles = centre + sign * self.base_pair_angle_deg / 2.0
        platform_angles = centre + sign * (60.0 - self.platform_pair_angle_deg / 2.0)
        object.__setattr__(self, "base_joints", _circle_points(self.base_radius, base_angles))
        object.__setattr__(
            self, "platform_joints", _circle_points(self.platform_radius, platform_angles)
        )
        neutral = self.actuator_lengths(self.neutral_position, (0.0, 0.0, 0.0))
        if not np.all((neutral >= lo) & (neutral <= hi)):
            raise ValueError(
                f"neutral_height {self.neutral_height} m gives actuator lengths "
                f"{neutral.round(3).tolist()} outside {self.length_range} m"
            )

    @property
    def neutral_position(self) -> np.ndarray:
        """Platform centre in the neutral pose, base frame [m]."""
        return np.array([0.0, 0.0, self.neutral_height])

    def joint_positions(self, position, rotation: np.ndarray) -> np.ndarray:
        """(6, 3) platform joints a_i in the base frame for a pose (position [m], rotation)."""
        return np.asarray(position, dtype=float) + self.platform_joints @ np.asarray(rotation).T

    def lengths_for_rotation(self, position, rotation: np.ndarray) -> np.ndarray:
        """(6,) actuator lengths ‖p + R a_i - b_i‖ [m]."""
        legs = self.joint_positions(position, rotation) - self.base_joints
        return np.sqrt(np.add.reduce(legs * legs, axis=1))  # np.linalg.norm's, without its checks

    def actuator_lengths(self, position, rpy) -> np.ndarray:
        """(6,) actuator lengths [m] for the platform centre at ``position`` (base frame, m) and
        orientation ``rpy`` = (roll, pitch, yaw) [rad]. Limits are not checked."""
        position = np.asarray(position, dtype=float)
        if position.shape != (3,):
            raise ValueError(f"position must be a 3-vector, got shape {position.shape}")
        return self.lengths_for_rotation(position, rpy_matrix(rpy))

    def check_pose(self, position, rpy) -> np.ndarray:
        """Actuator lengths [m] of a pose; ValueError naming the first actuator out of range."""
        lengths = self.actuator_lengths(position, rpy)
        self._check_lengths(
            lengths,
            f"pose position={np.round(position, 4).tolist()}, rpy={np.round(rpy, 4).tolist()}",
        )
        return lengths

    def _check_lengths(self, lengths: np.ndarray, what: str) -> None:
        lo, hi = self.length_range
        for i, length in enumerate(lengths):
            if not lo <= length <= hi:
                raise ValueError(
                    f"{what} needs actuator {i + 1} at {length:.4f} m, outside its range "
                    f"[{lo:g}, {hi:g}] m"
                )

    def in_range(self, position, rotation: np.ndarray) -> bool:
        """True when every actuator length of the pose lies within ``length_range``."""
        lengths = self.lengths_for_rotation(position, rotation)
        lo, hi = self.length_range
        return bool(np.all((lengths >= lo) & (lengths <= hi)))

    def max_tilt(
        self, axis, position=None, step: float = math.radians(0.5), tol: float = 1e-7
    ) -> float:
        """Largest angle [rad] the platform turns about ``axis`` (through its centre) from level.

        Every angle between 0 and the result is reachable. ``axis``: a 3-vector in the base
        frame or one of "x", "y", "z", "roll", "pitch"; the sense follows the right-hand rule
        (pass the negated axis for the other sense). ``position``: platform centre (default:
        neutral). Scans in ``step`` increments up to π, then bisects to ``tol``.
        """
        if isinstance(axis, str):
            if axis not in AXIS_NAMES:
                raise ValueError(f"unknown axis {axis!r}; valid names: {sorted(AXIS_NAMES)}")
            axis = AXIS_NAMES[axis]
        axis = np.asarray(axis, dtype=float)
        if axis.shape != (3,) or not np.linalg.norm(axis) > 0.0:
            raise ValueError(f"axis must be a non-zero 3-vector, got {axis}")
        position = self.neutral_position if position is None else np.asarray(position, float)
        if not self.in_range(position, np.eye(3)):
            raise ValueError(f"the level pose at {position.tolist()} is already out of range")
        good = 0.0
        bad = None
        angle = step
        while angle <= math.pi:
            if not self.in_range(position, axis_angle_matrix(axis, angle)):
                bad = angle
                break
            good = angle
            angle += step
        if bad is None:
            return math.pi
        while bad - good > tol:
            mid = 0.5 * (good + bad)
            if self.in_range(position, axis_angle_matrix(axis, mid)):
                good = mid
            else:
                bad = mid
        return good


DEFAULT_PLATFORM = StewartPlatform()
"""The Zhang et al. 2024 platform with the layout chosen above."""


def actuator_lengths(position, rpy, platform: StewartPlatform = DEFAULT_PLATFORM) -> np.ndarray:
    """(6,) actuator lengths [m] of ``platform`` (default: Zhang et al. 2024's) for a pose."""
    return platform.actuator_lengths(position, rpy)


def check_pose(position, rpy, platform: StewartPlatform = DEFAULT_PLATFORM) -> np.ndarray:
    """Actuator lengths [m]; ValueError naming the actuator when one is outside its stroke."""
    return platform.check_pose(position, rpy)


def max_tilt(axis, platform: StewartPlatform = DEFAULT_PLATFORM, position=None) -> float:
    """Largest reachable tilt [rad] about ``axis`` from the level pose (see the method)."""
    return platform.max_tilt(axis, position)
