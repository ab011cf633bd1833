"""What the heavy-duty hexapod knows about itself from its sensors: body-frame feet, CoG, forces.

NumPy and numba (no MuJoCo). Everything here is what the real robot computes from its joint
encoders, its IMU and its 3-D foot force sensors, with the robot's known geometry and masses
(`HeavyDutyParams`):

- feet in the body frame by forward kinematics (Zhang et al. 2024 eq. 1) of the encoders;
- the whole-robot centre of gravity (CoG) in the body frame from the link masses placed by the
  same kinematics (the body box at the body origin; per leg the hip link rotating with the swing
  joint, the carriage moved by the horizontal joint, the shank and the foot moved along the leg);
- the body's composite inertia about that CoG (box + legs as point masses), for eq. (16);
- world-frame foot forces and gravity rotated into the body frame with the IMU quaternion;
- the leg Jacobian and its stiffness, to turn a wanted change of foot force into a change of the
  position servo targets (the "known stiffness" of Zhang et al. 2024 §4.3).

Link mass split (params docstring): hip 40 %, carriage 30 %, shank 28 %, foot 2 % of the leg mass.
The link centres follow the robot's model (robots/heavy_duty/model.py): hip box centred half-way
along L1; carriage capsule from 0.15 m above to L2 below the leg-plane origin; shank capsule from
the sole up to 0.7 m above it; foot sphere one foot radius above the sole. A test checks the CoG
against the simulator's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from agents.tipping import _compiled
from hexapod_envs.robots.heavy_duty.params import LEG_NAMES, HeavyDutyParams

GRAVITY: float = 9.81
"""[m/s²]."""

LEG_MASS_SPLIT: dict[str, float] = {"hip": 0.40, "carriage": 0.30, "shank": 0.28, "foot": 0.02}
"""Fraction of each leg's mass in its links (HeavyDutyParams.leg_mass docstring)."""

CARRIAGE_TOP: float = 0.15
"""Carriage link extends this far above the leg-plane origin [m] (model geometry)."""
SHANK_TOP: float = 0.7
"""Shank link extends this far above the sole [m] (model geometry)."""

_ALL_LEGS = np.arange(6)


def quat_to_matrix(quat: np.ndarray) -> np.ndarray:
    """Rotation matrix (body -> world) of a unit quaternion (w, x, y, z)."""
    q = np.asarray(quat, dtype=float)
    if q.shape != (4,):
        raise ValueError(f"a quaternion is 4 values (w, x, y, z), got shape {q.shape}")
    w, x, y, z = q.tolist()
    if not w * w + x * x + y * y + z * z > 0.0:
        raise ValueError(f"quaternion {quat} has zero norm")
    return _compiled.rotation_from_quat(q)


@dataclass(frozen=True)
class LegState:
    """Generalised leg coordinates [x (m), d (m), θ (rad)] of all legs from the encoders.

    x = K_x J_x is the foot's travel along body x, d = K_z J_z + L2 the leg length, θ = J_θ the
    swing angle; these are the coordinates the foot stiffnesses of `HeavyDutyParams` refer to.
    """

    x: np.ndarray
    d: np.ndarray
    theta: np.ndarray


class HeavyDutyBodyModel:
    """Kinematic and mass model of the heavy-duty hexapod for its own controller (body frame)."""

    def __init__(self, params: HeavyDutyParams | None = None):
        self.params = p = params or HeavyDutyParams()
        self.hips = np.array([p.hip_offsets[leg] for leg in LEG_NAMES])  # (6, 3)
        self._hip_sums = self.hips.sum(axis=0)
        self.l1 = np.array([p.signed_l1(leg) for leg in LEG_NAMES])  # (6,)
        self.total_mass = p.total_mass
        m = p.leg_mass
        self._m_hip = m * LEG_MASS_SPLIT["hip"]
        self._m_carriage = m * LEG_MASS_SPLIT["carriage"]
        self._m_shank = m * LEG_MASS_SPLIT["shank"]
        self._m_foot = m * LEG_MASS_SPLIT["foot"]
        self._carriage_z = 0.5 * (CARRIAGE_TOP - p.l2)
        self._shank_up = 0.5 * (SHANK_TOP + p.foot_radius)
        self._foot_up = p.foot_radius
        lx, ly, lz = p.body_size
        mb = p.body_mass
        self._box_inertia = np.diag(
            [mb * (ly**2 + lz**2) / 12, mb * (lx**2 + lz**2) / 12, mb * (lx**2 + ly**2) / 12]
        )
        self.stiffness = np.array(p.foot_stiffness, dtype=float)
        self._joint_scale = np.array([p.k_x, p.k_z, 1.0])  # generalised = scale * J (+ L2 for d)
        m_moving = self._m_carriage + self._m_shank + self._m_foot
        self._cog_consts = np.array(  # the constants of _compiled.body_feet_and_cog
            [
                p.k_x,
                p.k_z,
                p.l2,
                m_moving,
                0.5 * self._m_hip + m_moving,
                self._m_carriage * self._carriage_z,
                self._m_shank,
                self._shank_up,
                self._m_foot,
                self._foot_up,
                p.leg_mass,
                self.total_mass,
            ]
        )

    # --- legs -------------------------------------------------------------------------------
    def leg_state(self, joints: np.ndarray) -> LegState:
        """(6, 3) encoder readings [J_x, J_z, J_θ] -> generalised coordinates."""
        j = np.asarray(joints, dtype=float).reshape(6, 3)
        p = self.params
        return LegState(p.k_x * j[:, 0], p.k_z * j[:, 1] + p.l2, j[:, 2].copy())

    def feet(self, joints: np.ndarray) -> np.ndarray:
        """(6, 3) sole points in the body frame [m] (eq. 1 plus the hip offsets)."""
        return self.feet_and_cog(joints)[0]

    def feet_and_cog(self, joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(:meth:`feet`, :meth:`cog`) from one pass over the legs (the controller needs both
        every period).

        A compiled kernel (:func:`agents.tipping._compiled.body_feet_and_cog`): on six legs
        numpy's per-call overhead cost more than the arithmetic. Its operations and summation
        order are those of the former array expressions, so the numbers are bit-identical to
        them (tests/agents/tipping/test_tipping_recovery.py).
        """
        j = np.asarray(joints, dtype=float).reshape(6, 3)
        return _compiled.body_feet_and_cog(j, self.hips, self.l1, self._cog_consts, self._hip_sums)

    def foot_velocities(self, joints: np.ndarray, joint_velocities: np.ndarray) -> np.ndarray:
        """(6, 3) sole velocities relative to the body [m/s] from encoder rates."""
        q = self.leg_state(joints)
        jd = np.asarray(joint_velocities, dtype=float).reshape(6, 3) * self._joint_scale
        jac = self.jacobians(q)
        return np.einsum("lij,lj->li", jac, jd)

    def jacobians(self, q: LegState) -> np.ndarray:
        """(6, 3, 3) ∂(foot position)/∂(x, d, θ) per leg."""
        c, s = np.cos(q.theta), np.sin(q.theta)
        jac = np.zeros((6, 3, 3))
        jac[:, 0, 0] = 1.0
        jac[:, 1, 1], jac[:, 2, 1] = s, -c
        jac[:, 1, 2] = -self.l1 * s + q.d * c
        jac[:, 2, 2] = self.l1 * c + q.d * s
        return jac

    def target_change_for_force(
        self, joints: np.ndarray, delta_force: np.ndarray, legs: np.ndarray | None = None
    ) -> np.ndarray:
        """Change of servo targets [ΔJ_x, ΔJ_z, ΔJ_θ] that adds ``delta_force`` to the ground
        reaction on each foot, with the foot held by the ground (the servos are springs of the
        known foot stiffness): Δq = -K⁻¹ Jᵀ ΔF in (x, d, θ), converted to joint units.

        Args:
            joints: (6, 3) encoder readings.
            delta_force: (n, 3) wanted change of ground reaction force on the feet of ``legs``,
                body frame [N] (n = 6 when ``legs`` is None).
            legs: indices of the legs in LEG_NAMES order (default: all six).

        Returns:
            (n, 3) target changes in joint units (m, m, rad).
        """
        legs = _ALL_LEGS if legs is None else np.asarray(legs, dtype=np.int64).reshape(-1)
        j = np.asarray(joints, dtype=float).reshape(6, 3)
        df = np.asarray(delta_force, dtype=float).reshape(len(legs), 3)
        p = self.params
        return _compiled.servo_change_for_force(
            j, df, legs, self.l1, p.k_z, p.l2, self.stiffness, self._joint_scale
        )

    # --- whole body ------------------------------------------------------------------------
    def cog(self, joints: np.ndarray) -> np.ndarray:
        """Whole-robot centre of gravity in the body frame [m] from the encoders."""
        return self.feet_and_cog(joints)[1]

    def inertia(self, joints: np.ndarray, cog: np.ndarray | None = None) -> np.ndarray:
        """(3, 3) inertia about the CoG, body frame [kg m²]: body box + feet-end leg masses.

        The legs are lumped as point masses at their feet's half-way point (a coarse but cheap
        estimate; the 4.4 t box dominates)."""
        cog = self.cog(joints) if cog is None else np.asarray(cog, dtype=float)
        feet = self.feet(joints)
        pts = 0.5 * (feet + self.hips) - cog
        m = self.params.leg_mass
        sq = (pts * pts).sum(axis=1)
        legs = m * (np.eye(3) * sq.sum() - pts.T @ pts)
        r = -cog  # body box centre relative to the CoG
        box = self._box_inertia + self.params.body_mass * (np.eye(3) * (r @ r) - np.outer(r, r))
        return box + legs


def forces_to_body(forces_world: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """(n, 3) world-frame forces -> body frame, with ``rotation`` body -> world (fᵇ = Rᵀ fʷ)."""
    return np.asarray(forces_world, dtype=float).reshape(-1, 3) @ rotation


def gravity_in_body(rotation: np.ndarray, g: float = GRAVITY) -> np.ndarray:
    """Gravity vector in the body frame [m/s²] (R_Wᶜ g of eq. 16)."""
    return -g * np.asarray(rotation)[2, :]


def tilt_deg(rotation: np.ndarray) -> float:
    """Angle between the body's z axis and the world vertical [deg]."""
    return math.degrees(math.acos(max(-1.0, min(1.0, float(rotation[2, 2])))))
