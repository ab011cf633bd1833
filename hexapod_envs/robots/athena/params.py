"""ATHENA's numbers from Coelho et al. 2024 (Coelho et al.), in SI units, plus the few choices we
made.

Sources in the paper: Table 2 (simplified simulation model: sizes, masses, inertias), Section 3.2
(joint names, ranges, DH table 3, mounting angles eq. 13), Section 2.2 (servo torque 1.89 N·m),
Section 3.1 (friction 0.9), Section 5.1 (standing posture). Everything the paper does not give is
marked "our choice" with the reason.

Frames. The paper's body frame B has x to the right, y forward (the stride axis of eqs. 20-23),
z up. Ours (docs/architecture.md) has x forward, y left, z up, so (x, y, z)_ours = (y, -x, z)_paper
and every
azimuth in ours is the paper's minus pi/2. The DH table does not care which horizontal axis is x:
it only needs the per-leg mounting angle theta_1, which `mounting_angle` gives in our frame.

Inertia units. Table 2 labels its moments "kg·mm²", but its numbers are those of uniform boxes of
the listed size and mass in units of 1e-3 kg·m² (= 1e3 kg·mm²): e.g. the body, 0.7 kg and
200x120x56 mm, has I = m (200² + 56²)/12 = 2516 kg·mm² = 2.52e-3 kg·m² about its lateral axis,
and the table says 2.52. Read literally as kg·mm² the inertias would be 1000x too small for the
boxes. We therefore convert with `TABLE2_INERTIA_UNIT = 1e-3` kg·m² per table unit (a test checks
every row against the box formula). The table's axes (xi, eta, zeta) are (lateral, long/forward,
vertical); in our link frames (x along the link) that is (y, x, z).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

LEG_NAMES: tuple[str, ...] = ("LF", "LM", "LR", "RF", "RM", "RR")
"""Project-wide leg order (docs/architecture.md): arrays of per-leg data use this row order."""

JOINT_NAMES: tuple[str, ...] = ("TC", "CTr", "FTi")
"""Thorax-Coxa (yaw), Coxa-Trochanterofemur (pitch), Femur-Tibia (pitch): the paper's names."""

TRIPODS: tuple[tuple[str, ...], tuple[str, ...]] = (("LF", "LR", "RM"), ("LM", "RF", "RR"))
"""The two tripods (docs/architecture.md). In the paper's numbers these are {3, 5, 1} and {4, 2,
6}."""

# --- The one place where the paper's leg numbers are translated -----------------------------
# Eq. (13) gives the mounting angle theta_1 of leg i in the paper's frame (x right, y forward):
#   i=1: 0, i=2: atan(l0/w), i=3: pi - atan(l0/w), i=4: pi, i=5: pi + atan(l0/w),
#   i=6: -atan(l0/w).
# Angle 0 points to the right, so leg 1 is the right middle leg; the angles then increase
# counter-clockwise seen from above: 2 = right front, 3 = left front, 4 = left middle,
# 5 = left rear, 6 = right rear. This matches the paper's "counter-clockwise from the right middle"
# numbering, and puts the corner legs radially outward through the body corners (l0, w).
PAPER_LEG_NUMBER: dict[str, int] = {"RM": 1, "RF": 2, "LF": 3, "LM": 4, "LR": 5, "RR": 6}
LEG_FROM_PAPER_NUMBER: dict[int, str] = {n: leg for leg, n in PAPER_LEG_NUMBER.items()}

TABLE2_INERTIA_UNIT = 1e-3
"""kg·m² per unit of Table 2's inertia columns (see the module docstring)."""


@dataclass(frozen=True)
class BoxLink:
    """One rigid link of the simplified model (Table 2): a uniform box along its own x axis.

    `size` is (length, width, height) in m; `inertia_table` holds Table 2's (I_xi, I_eta, I_zeta)
    exactly as printed (units of `TABLE2_INERTIA_UNIT`), products of inertia are zero in Table 2.
    """

    size: tuple[float, float, float]
    mass: float
    inertia_table: tuple[float, float, float]

    @property
    def length(self) -> float:
        """Length along the link's x axis, m."""
        return self.size[0]

    @property
    def inertia(self) -> np.ndarray:
        """Principal moments about the CoM in the link/body frame (x, y, z), kg·m²."""
        i_xi, i_eta, i_zeta = self.inertia_table
        return np.array([i_eta, i_xi, i_zeta]) * TABLE2_INERTIA_UNIT


@dataclass(frozen=True)
class SphereLink:
    """The foot: a uniform sphere (Table 2, p_i)."""

    radius: float
    mass: float
    inertia_table: float

    @property
    def inertia(self) -> np.ndarray:
        """Principal moments about the centre, kg·m²."""
        return np.full(3, self.inertia_table * TABLE2_INERTIA_UNIT)


@dataclass(frozen=True)
class AthenaParams:
    """ATHENA's simplified simulation model (Coelho et al. 2024), SI units.

    The leg is the DH chain of Table 3: l1 (body centre to hip, per leg), l2 = coxa, l3 = femur,
    l4 = tibia; the foot sphere's centre is the chain's end point p_i of eq. (12).
    """

    body: BoxLink = BoxLink((0.200, 0.120, 0.056), 0.7000, (2.52, 1.02, 3.17))
    coxa: BoxLink = BoxLink((0.064, 0.040, 0.040), 0.0810, (3.84e-2, 2.16e-2, 3.84e-2))
    femur: BoxLink = BoxLink((0.080, 0.040, 0.040), 0.1360, (9.07e-2, 3.63e-2, 9.07e-2))
    tibia: BoxLink = BoxLink((0.084, 0.040, 0.040), 0.0134, (9.38e-3, 3.47e-3, 9.38e-3))
    foot: SphereLink = SphereLink(0.020, 0.0089, 1.43e-3)

    hip_offset_x: float = 0.100
    """Paper's l0 in eq. (13): forward distance of the corner hips from the body centre, m.
    Our choice: the paper gives no number; we put the corner hips at the corners of the 200 mm
    long body (so theta_1 = atan(l0/w) is the direction of the corner from the centre)."""
    hip_offset_y: float = 0.060
    """Paper's w in eq. (13): lateral distance of every hip from the body's mid-plane, m.
    Our choice: half of the 120 mm body width (the hips sit on the body's sides)."""

    servo_half_range: tuple[float, float, float] = (0.612, 1.484, 1.484)
    """Paper Section 3.2: TC in [-0.612, 0.612], CTr and FTi in [-1.484, 1.484] rad.
    The paper's standing posture has theta_4 = -pi/2, outside its own FTi range. We read the
    ranges as servo ranges about the standing posture (servo neutral = standing, the usual
    hobby-servo set-up): joint range = standing angle +- half range. For TC and CTr (standing 0)
    this is exactly the paper's range; FTi becomes [-pi/2 - 1.484, -pi/2 + 1.484]."""
    standing_posture: tuple[float, float, float] = (0.0, 0.0, -math.pi / 2)
    """theta_2, theta_3, theta_4 of the standing posture (Section 5.1), rad."""

    stall_torque: float = 1.89
    """Servo stall torque = actuator force limit, N·m (Section 2.2)."""
    friction: float = 0.9
    """Foot-ground Coulomb friction coefficient (Section 3.1)."""

    # Our choices for the simulated servo (the paper's Gazebo joints are not specified further).
    servo_kp: float = 20.0
    """Position-servo stiffness, N·m/rad. With a tripod carrying the 2.14 kg robot a CTr joint
    holds about 0.6 N·m, i.e. a 0.03 rad (2 mm foot height) steady error; the torque limit is
    reached at 0.095 rad error, like a stiff hobby servo."""
    servo_damping: float = 0.2
    """Joint viscous damping, N·m·s/rad: damping ratio ~0.5 on the swinging leg."""
    servo_armature: float = 0.002
    """Reflected rotor inertia of the geared servo, kg·m² (typical for a ~200:1 hobby servo);
    it also keeps the light tibia joint well conditioned at the 2-2.5 ms time steps used."""
    servo_delay: float = 0.0
    """Control latency of the servos, s: each servo acts on the target it was sent this long
    ago (MuJoCo's actuator delay; 0: none)."""
    contact_solref: tuple[float, float] | None = None
    """MuJoCo solref (time constant s, damping ratio) of the robot's contacts with the terrain
    (None: MuJoCo's default, (0.02, 1)): how soft the feet and torso are."""
    contact_solimp: tuple[float, float, float, float, float] | None = None
    """MuJoCo solimp of the robot's contacts with the terrain (None: MuJoCo's default,
    (0.9, 0.95, 0.001, 0.5, 2))."""

    # ----- derived quantities --------------------------------------------------------------
    @property
    def l2(self) -> float:
        """Coxa length (DH a_2), m."""
        return self.coxa.length

    @property
    def l3(self) -> float:
        """Femur length (DH a_3), m."""
        return self.femur.length

    @property
    def l4(self) -> float:
        """Tibia length (DH a_4) to the foot sphere's centre, m."""
        return self.tibia.length

    @property
    def total_mass(self) -> float:
        """Mass of the whole robot, kg."""
        leg = self.coxa.mass + self.femur.mass + self.tibia.mass + self.foot.mass
        return self.body.mass + 6 * leg

    @property
    def standing_torso_height(self) -> float:
        """Height of the torso centre (hip plane) above flat ground in the standing posture, m.

        theta_3 = 0, theta_4 = -pi/2 put the foot centre l4 below the hip; the sphere touches the
        ground one radius lower. This is the torso-height sensor's reference (Section 4.2).
        """
        return self.l4 + self.foot.radius

    def joint_range(self, joint: str) -> tuple[float, float]:
        """(lower, upper) limit of `joint` in the DH angle convention, rad."""
        k = _index(joint, JOINT_NAMES, "joint")
        centre, half = self.standing_posture[k], self.servo_half_range[k]
        return (centre - half, centre + half)

    @property
    def joint_ranges(self) -> np.ndarray:
        """(3, 2) array of [lower, upper] per joint in `JOINT_NAMES` order, rad."""
        return np.array([self.joint_range(j) for j in JOINT_NAMES])

    def hip_position(self, leg: str) -> np.ndarray:
        """Position of the TC joint axis in the body frame (x fwd, y left, z up), m."""
        _index(leg, LEG_NAMES, "leg")
        x = {"F": self.hip_offset_x, "M": 0.0, "R": -self.hip_offset_x}[leg[1]]
        y = self.hip_offset_y if leg[0] == "L" else -self.hip_offset_y
        return np.array([x, y, 0.0])

    def mounting_angle(self, leg: str) -> float:
        """DH theta_1 of eq. (13) in our frame: azimuth of the hip seen from the body centre, rad.

        Equals the paper's eq. (13) value minus pi/2 (frame change, see the module docstring):
        RM -pi/2, RF -(pi/2 - atan(l0/w)), LF pi/2 - atan(l0/w), LM pi/2, LR pi/2 + atan(l0/w),
        RR -(pi/2 + atan(l0/w)).
        """
        hip = self.hip_position(leg)
        return math.atan2(hip[1], hip[0])

    def hip_distance(self, leg: str) -> float:
        """DH a_1 = l1: distance from the body centre to the hip of `leg`, m."""
        return float(np.linalg.norm(self.hip_position(leg)))


def _index(name: str, valid: tuple[str, ...], what: str) -> int:
    if name not in valid:
        raise ValueError(f"unknown {what} {name!r}; valid: {', '.join(valid)}")
    return valid.index(name)


ATHENA = AthenaParams()
"""The default parameter set."""
