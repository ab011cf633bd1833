"""Parameters of the 3-UPU hexapod walking robot of Li et al. 2018 (Li et al., Robotics 2018, 7,
48).

The paper gives the parallel mechanism (Table 2): Hooke-joint circumradii r = 125 mm (upper
platform) and R = 160 mm (lower), limb length l in [365, 465] mm, Hooke-joint angles within
±pi/4, the initial upper-platform centre (0, 0, 363) mm, and the maximum stride
l_max1 = 2 (x_G3 - R_T) = 160 mm (eq. 17). It gives no masses, no leg geometry and no leg
stroke; those are chosen here (documented beside each field) so that the paper's numbers come
out of the geometry rather than being typed in.

Frames (paper §3.1, Fig. 1b). Lower-platform frame O-xyz: origin at the centre of the lower
Hooke joints A_i, x forward (the walking direction), z up; A_1 on the negative x axis. The
upper-platform frame O'-x'y'z' is parallel to it (the 3-UPU mechanism only translates), with B_1
on its negative x' axis. Limb i joins A_i to B_i.

Leg names. The robot has three retractable legs on each platform; a leg's name says which
platform carries it: ``U1 U2 U3`` on the upper platform, ``L1 L2 L3`` on the lower one (the
paper's legs 2, 4, 6 and 1, 3, 5). Index 1 lies on the x axis, 2 on the left (+y), 3 on the
right (-y). The lower legs sit beside the lower Hooke joints (L_i at the azimuth of A_i:
180°, 60°, -60°); the upper legs sit on arms between the upper Hooke joints (U1 at 0°, U2 at
120°, U3 at 240°). Seen from above the six feet form a regular hexagon of radius
`leg_circle_radius` whose vertices alternate between the two platforms, as in the paper's
Fig. 8a (triangles LMN and EFH), and each platform's three feet form an equilateral support
triangle. Walking forward (+x) the upper platform's rear legs U2/U3 approach the lower
platform's front legs L2/L3 (paper: "the leg of L, M and the leg of F, H"), which sets the
stride limit of eq. (17).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from ...checks import check_number

UPPER_LEGS: tuple[str, ...] = ("U1", "U2", "U3")
"""Legs on the upper (smaller, r = 125 mm) platform: the paper's legs 2, 4, 6."""
LOWER_LEGS: tuple[str, ...] = ("L1", "L2", "L3")
"""Legs on the lower (R = 160 mm) platform, the robot's torso: the paper's legs 1, 3, 5."""
LEG_NAMES: tuple[str, ...] = UPPER_LEGS + LOWER_LEGS
PLATFORMS: tuple[str, ...] = ("upper", "lower")
PLATFORM_LEGS: dict[str, tuple[str, ...]] = {"upper": UPPER_LEGS, "lower": LOWER_LEGS}
LIMB_NAMES: tuple[str, ...] = ("limb1", "limb2", "limb3")

HOOKE_AZIMUTHS: tuple[float, float, float] = (math.pi, math.pi / 3, -math.pi / 3)
"""Azimuth of A_i and B_i (i = 1, 2, 3) in their platform frames, eq. (4) [rad]."""
LEG_AZIMUTHS: dict[str, float] = {
    "U1": 0.0,
    "U2": 2 * math.pi / 3,
    "U3": -2 * math.pi / 3,
    "L1": math.pi,
    "L2": math.pi / 3,
    "L3": -math.pi / 3,
}
"""Azimuth of each leg's foot about its platform centre [rad] (see the module docstring)."""


_NON_NEGATIVE = frozenset({"limit_tolerance", "limb_integral_gain", "upper_slide_damping"})


def leg_platform(leg: str) -> str:
    """'upper' or 'lower': the platform that carries `leg`."""
    if leg in UPPER_LEGS:
        return "upper"
    if leg in LOWER_LEGS:
        return "lower"
    raise ValueError(f"unknown 3-UPU leg {leg!r}; valid legs are {LEG_NAMES}")


def check_platform(platform: str, name: str = "platform") -> str:
    """Return `platform` if it is 'upper' or 'lower', else raise a ValueError naming both
    (`name`: the argument's name for the message)."""
    if platform not in PLATFORMS:
        raise ValueError(f"{name} must be one of {PLATFORMS}, got {platform!r}")
    return platform


@dataclass(frozen=True)
class UpuParams:
    """Geometry, masses and servo properties of the 3-UPU hexapod (SI units: m, kg, rad, N).

    Paper values (Table 2 and §7) are marked "paper"; everything else is a documented choice.
    """

    upper_radius: float = 0.125
    """r: circumradius of the upper Hooke joints B_i [m] (paper)."""
    lower_radius: float = 0.160
    """R: circumradius of the lower Hooke joints A_i [m] (paper)."""
    limb_min: float = 0.365
    """l_min: shortest equivalent limb length |A_i B_i| [m] (paper)."""
    limb_max: float = 0.465
    """l_max: longest equivalent limb length [m] (paper)."""
    hooke_limit: float = math.pi / 4
    """Hooke-joint angle limit: theta_1, theta_2 in [-hooke_limit, hooke_limit] [rad] (paper)."""
    initial_height: float = 0.363
    """z of the upper platform centre O' above the lower one O in the initial assembly [m]
    (paper §7), also the height of the paper's gait paths (eqs. 20-21). At (0, 0, 0.363) every
    limb is sqrt(0.035² + 0.363²) = 0.36468 m, and moving along x at this height limbs 2 and 3
    shrink to sqrt((sqrt(3)/2 * 0.035)² + 0.363²) = 0.36426 m at x = Delta/2: 0.32 and 0.74 mm
    short of limb_min. The paper rounds; limit checks accept `limit_tolerance` of slack, and the
    MuJoCo limb servos (ctrlrange = limits) then hold the platform < 1 mm higher."""
    limit_tolerance: float = 1e-3
    """Slack [m] allowed on the limb-length limits (and, divided by limb_min, [rad] on the Hooke
    angles) by the limit checks, so that the paper's own initial pose and gait count as
    reachable (see `initial_height`); below the resolution of the paper's figures."""
    step_lift: float = 0.08
    """Apex height of the upper platform's quadratic step path above its start [m]: the paper's
    80 mm maximum obstacle height, apex (80, 443) mm of eq. (20)."""

    # --- Retractable legs (not in the paper's tables) -------------------------------------
    leg_circle_radius: float = 0.200
    """rho: horizontal distance of every foot from its platform centre [m]. Chosen so that
    eq. (17) gives the paper's 160 mm: the support triangle's inradius is rho/2 = x_G3 = 0.1 m
    and l_max1 = 2 (x_G3 - R_T) = rho - 2 R_T = 0.16 m. It also puts the lower feet 40 mm
    outside the lower Hooke joints, as the paper's Fig. 1a shows the legs at the corners."""
    leg_radius: float = 0.020
    """R_T: equivalent radius of a leg's cross-section [m] (eq. 17); a 40 mm telescopic tube."""
    foot_radius: float = 0.020
    """Radius of the spherical foot [m] (same as the leg tube)."""
    lower_leg_length: float = 0.250
    """Nominal (zero-extension) distance from the lower platform's Hooke-joint plane down to the
    soles of its legs [m]: the lower platform stands 0.25 m above flat ground, the proportions
    of the paper's Fig. 1a / Fig. 11 (platform height ~ 2/3 of the limb length)."""
    leg_retract: float = 0.080
    """How far a leg can retract above its nominal length [m]: lifts a swing foot by the
    paper's 80 mm obstacle height when the platform itself cannot rise (see the gait planner)."""
    leg_extend: float = 0.160
    """How far a leg can extend below its nominal length [m]: reaches the bottom of the paper's
    140 mm ditch with 20 mm to spare. Stroke = leg_retract + leg_extend = 0.24 m."""

    # --- Masses (not in the paper) --------------------------------------------------------
    upper_platform_mass: float = 2.5
    """Upper platform plate with its three leg housings and servos, the limb halves attached to
    it and the electronics [kg]. The paper gives no masses (eqs. 12-13 use m_1, m_2); a
    desktop-size aluminium prototype of this size weighs a few kg per half."""
    lower_platform_mass: float = 3.0
    """Lower platform (larger plate, R = 160 mm vs r = 125 mm) with leg housings, servos and
    the limb halves attached to it [kg]."""
    leg_mass: float = 0.30
    """Moving (telescopic) part of one leg without its foot [kg]."""
    foot_mass: float = 0.05
    """Foot with its pressure sensor [kg]."""

    # --- Servo properties for the MuJoCo model (not in the paper) -------------------------
    limb_stiffness: float = 5.0e5
    """Position-servo stiffness of a limb's prismatic pair [N/m]. High because the three limbs
    are nearly parallel near the initial pose, so the platform's horizontal stiffness is only
    ~1.4 % of this (sum of squared limb slopes): the weight of the upper half then shifts the
    platform by <= ~3 mm horizontally at the edges of the gait (a screw-driven limb is stiffer
    still; MuJoCo's explicit stiffness needs timestep <= 2 ms at this value)."""
    limb_damping: float = 1.0e4
    """Limb servo damping [N s/m] (integrated implicitly by MuJoCo's implicitfast)."""
    limb_integral_gain: float = 0.0
    """Integral gain of the limb servo [N/(m s)]. 0 (default): PD position servo. > 0: MuJoCo's
    PID actuator (needs MuJoCo >= 4), which removes the static error (2e6 brings it below
    1 mm within 0.6 s with upper_slide_damping = 5 N s/m; with the default 300 N s/m that
    gain winds up against the force limit on large moves and needs retuning). Off by default
    so that the model is the same on every supported MuJoCo version; the PD servo's sag is
    predictable (closed-form compliance)."""
    limb_integral_limit: float = 400.0
    """Anti-windup clamp of the integral term [N] (PID mode only)."""
    upper_slide_damping: float = 300.0
    """Viscous damping of the upper platform's x/y/z slide joints [N s/m] (friction in the
    mechanism's joints). The nearly parallel limbs give the platform a horizontal stiffness of
    only ~7e3 N/m (see `limb_stiffness`); with the limb servos' share (~140 N s/m) this value
    makes that sway mode of the 3.55 kg upper half about critically damped. Lightly damped
    (5 N s/m), the platform keeps swaying by a few mm after each transfer, enough (at 7 Hz) to
    rock the robot off a foot when the CoG is 15 mm from a support edge."""
    limb_force_limit: float = 400.0
    """Limb servo force limit [N] (the robot weighs ~75 N)."""
    limb_speed_limit: float = 0.25
    """Fastest limb-length change [m/s] of the interpolated command mode (`model.add_upu`
    with ``command="interpolated"``); the reference gait needs <= ~0.1 m/s."""
    leg_speed_limit: float = 1.0
    """Fastest leg-extension change [m/s] of the interpolated command mode; the reference
    gait's lift needs <= ~0.55 m/s (0.22 m out of the ditch in 0.8 s)."""
    leg_stiffness: float = 5.0e4
    """Leg-length servo stiffness [N/m]: < 1 mm sag with the robot on three legs."""
    leg_damping: float = 1.0e3
    """Leg-length servo damping [N s/m]."""
    leg_force_limit: float = 300.0
    """Leg servo force limit [N]."""
    friction: float = 1.0
    """Foot sliding friction coefficient (rubber feet)."""

    def __post_init__(self) -> None:
        for f in fields(self):
            strict = f.name not in _NON_NEGATIVE
            check_number(f"UpuParams.{f.name}", getattr(self, f.name), strict=strict)
        if self.upper_radius == self.lower_radius:
            raise ValueError(
                "UpuParams needs upper_radius != lower_radius: with equal circumradii "
                "(Delta = R - r = 0) the limbs are parallel and the forward kinematics is singular"
            )
        if not self.limb_min < self.limb_max:
            raise ValueError(f"limb_min {self.limb_min} must be < limb_max {self.limb_max}")
        if not self.hooke_limit < math.pi / 2:
            raise ValueError(f"hooke_limit must be < pi/2 rad, got {self.hooke_limit}")

    # --- Derived geometry ---------------------------------------------------------------
    @property
    def delta(self) -> float:
        """Delta = R - r of eq. (5) [m]."""
        return self.lower_radius - self.upper_radius

    @property
    def initial_position(self) -> np.ndarray:
        """(0, 0, initial_height): the upper centre O' in the lower frame at assembly [m]."""
        return np.array([0.0, 0.0, self.initial_height])

    @property
    def lower_hooke_points(self) -> np.ndarray:
        """(3, 3) rows OA_i of eq. (4), lower-platform frame [m]."""
        return _ring(self.lower_radius, HOOKE_AZIMUTHS)

    @property
    def upper_hooke_points(self) -> np.ndarray:
        """(3, 3) rows O'B_i of eq. (4), upper-platform frame [m]."""
        return _ring(self.upper_radius, HOOKE_AZIMUTHS)

    @property
    def upper_leg_length(self) -> float:
        """Nominal distance from the upper platform's plane to its soles [m]: with the upper
        platform at `initial_height` all six soles are level."""
        return self.lower_leg_length + self.initial_height

    def leg_length(self, leg: str) -> float:
        """Nominal (zero-extension) platform-plane-to-sole distance of `leg` [m]."""
        if leg_platform(leg) == "upper":
            return self.upper_leg_length
        return self.lower_leg_length

    def foot_offset(self, leg: str) -> np.ndarray:
        """(x, y) of `leg`'s foot relative to its platform centre [m]."""
        leg_platform(leg)  # validates the name
        a = LEG_AZIMUTHS[leg]
        return self.leg_circle_radius * np.array([math.cos(a), math.sin(a)])

    @property
    def extension_range(self) -> tuple[float, float]:
        """Leg extension range (-leg_retract, leg_extend) [m]; + is longer (foot lower)."""
        return (-self.leg_retract, self.leg_extend)

    @property
    def support_inradius(self) -> float:
        """Inradius of one platform's support triangle, rho/2 [m]: the paper's x_G3 = OJ."""
        return self.leg_circle_radius / 2

    @property
    def upper_half_mass(self) -> float:
        """m_1 of eq. (12): upper platform with its three legs and feet [kg]."""
        return self.upper_platform_mass + 3 * (self.leg_mass + self.foot_mass)

    @property
    def lower_half_mass(self) -> float:
        """m_2 of eq. (12): lower platform with its three legs and feet [kg]."""
        return self.lower_platform_mass + 3 * (self.leg_mass + self.foot_mass)

    @property
    def total_mass(self) -> float:
        """m_1 + m_2 [kg]."""
        return self.upper_half_mass + self.lower_half_mass

    def half_mass(self, platform: str) -> float:
        """m_1 ('upper') or m_2 ('lower') [kg]."""
        check_platform(platform)
        return self.upper_half_mass if platform == "upper" else self.lower_half_mass


def _ring(radius: float, azimuths) -> np.ndarray:
    return np.array([[radius * math.cos(a), radius * math.sin(a), 0.0] for a in azimuths])
