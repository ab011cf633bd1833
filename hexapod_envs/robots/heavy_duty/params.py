"""Parameters of the 5 t heavy-duty hexapod of Zhang et al. 2024 (Zhang et al., Robotica 2024),
§2.1.

The paper gives the overall size (4.7 x 2.5 x 2 m), the masses (4.4 t body, 0.1 t per leg), the
pantograph scale factors K_x = 5, K_z = 4 and, through the footholds of §5.2, the standing
geometry: feet near (±2.4, ±1.9, −1.75) m from the centre of gravity. The remaining lengths
(L1, L2, joint ranges, mass split inside a leg) are chosen here to reproduce that geometry; each
choice is documented beside its field.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

LEG_NAMES: tuple[str, ...] = ("LF", "LM", "LR", "RF", "RM", "RR")
"""Zhang et al. 2024 numbers legs 1-3 left front->rear and 4-6 right front->rear."""

PAPER_LEG_NUMBER: dict[str, int] = {name: i + 1 for i, name in enumerate(LEG_NAMES)}

TRIPODS: tuple[tuple[str, ...], tuple[str, ...]] = (("LF", "LR", "RM"), ("LM", "RF", "RR"))

JOINT_NAMES: tuple[str, ...] = ("horizontal", "vertical", "swing")
"""Per-leg joints in the paper's order J = [J_x, J_z, J_theta]."""


@dataclass(frozen=True)
class HeavyDutyParams:
    """Geometry, masses and servo properties of the heavy-duty hexapod (SI units)."""

    body_size: tuple[float, float, float] = (4.7, 2.5, 0.6)
    """Body box length, width, height [m]; length and width from §2.1, the box height is chosen
    so that the standing robot is ~2 m tall like the paper's."""
    body_mass: float = 4400.0
    """[kg], §2.1."""
    leg_mass: float = 100.0
    """[kg] per leg, §2.1; split hip 40 %, carriage 30 %, shank 28 %, foot 2 %."""
    hip_x: float = 2.4
    """Coxa-frame origins l_i sit at x = ±hip_x (front/rear legs) and 0 (middle legs) [m]."""
    hip_y: float = 1.25
    """Coxa-frame origins at y = ±hip_y, the body's side faces [m]."""
    hip_z: float = 0.0
    """Coxa-frame origins at the height of the body centre [m]."""
    l1: float = 0.65
    """|L1| [m]: offset of the leg plane from the coxa origin (left +, right −), so the feet
    stand at y = ±(hip_y + l1) = ±1.9 m with the swing joint at zero."""
    l2: float = 1.0
    """L2 [m]: distance from the coxa origin to the horizontal joint's axis."""
    k_x: float = 5.0
    """Pantograph scale of the horizontal joint, eq. (1)."""
    k_z: float = 4.0
    """Pantograph scale of the vertical joint, eq. (1)."""
    j_x_range: tuple[float, float] = (-0.1, 0.1)
    """Horizontal joint range [m of actuator travel]; the foot moves K_x times as far (±0.5 m)."""
    j_z_range: tuple[float, float] = (0.05, 0.3)
    """Vertical joint range [m]; the leg length K_z J_z + L2 spans 1.2-2.2 m."""
    j_theta_range: tuple[float, float] = (-0.35, 0.35)
    """Swing joint range [rad]."""
    stand_height: float = 1.75
    """Feet below the coxa origin when standing [m] (§5.2 footholds: z ≈ −1.74 to −1.78)."""
    foot_radius: float = 0.12
    """Foot sphere radius [m]."""
    foot_stiffness: tuple[float, float, float] = (2.0e6, 4.0e6, 5.0e7)
    """Servo stiffness of each joint expressed at the foot: x [N/m], leg length [N/m],
    swing [N·m/rad]. The force distribution controller uses these "known stiffnesses" to make
    planned foot forces act (Zhang et al. 2024 §4.3)."""
    foot_damping: tuple[float, float, float] = (1.0e5, 1.5e5, 1.0e6)
    """Joint damping at the foot: [N·s/m], [N·s/m], [N·m·s/rad]."""
    joint_armature: tuple[float, float, float] = (100.0, 100.0, 250.0)
    """Rotor inertia of each servo reflected to its joint: x [kg], leg length [kg], swing
    [kg·m²]. The paper gives none. The legs' fastest motions are the servo damping acting on the
    light legs; this inertia slows them enough for the 2 ms physics step to reproduce what the
    former model, (20, 20, 50) at 1 ms, does in the paper scenarios' fidelity rows. Near a
    cliff's edge the two differ."""
    force_limit: tuple[float, float, float] = (6.0e4, 1.2e5, 2.0e5)
    """Servo force limits at the foot: [N], [N], [N·m]."""
    friction: float = 0.8
    """Foot-ground sliding friction coefficient."""
    hip_offsets: dict[str, np.ndarray] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        offsets = {}
        for name in LEG_NAMES:
            x = {"F": self.hip_x, "M": 0.0, "R": -self.hip_x}[name[1]]
            y = self.hip_y if name[0] == "L" else -self.hip_y
            offsets[name] = np.array([x, y, self.hip_z])
        object.__setattr__(self, "hip_offsets", offsets)

    @property
    def total_mass(self) -> float:
        return self.body_mass + 6 * self.leg_mass

    def signed_l1(self, leg: str) -> float:
        """L1 with the paper's sign convention: positive for left legs, negative for right."""
        return self.l1 if leg[0] == "L" else -self.l1

    @property
    def joint_ranges(self) -> np.ndarray:
        """(3, 2) ranges of [J_x, J_z, J_theta] in the paper's joint units (m, m, rad)."""
        return np.array([self.j_x_range, self.j_z_range, self.j_theta_range])

    @property
    def max_leg_length(self) -> float:
        """L_max of §4.2: the longest foot distance from the coxa origin in the y-z plane [m]."""
        return float(np.hypot(self.l1, self.k_z * self.j_z_range[1] + self.l2))
