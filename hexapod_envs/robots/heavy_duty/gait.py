"""Reference tripod gait of Zhang et al. 2024 §5.1, as foot targets in the body frame. Pure numpy.

Duty factor beta = 14/24, stroke (foot travel relative to the body during stance) 0.5 m, cycle
T = 6 s, 3 s of standing first. Stance feet move backwards linearly; a swing foot returns with a
quintic smooth-step in x and a lift profile 64 u^3 (1-u)^3 in z (zero velocity and acceleration
at lift-off and touch-down).

Phases are fractions of the cycle in [0, 1): stance for phase < beta, swing after. The tripods
are half a cycle apart. At the end of standing tripod {LM, RF, RR} has just touched down and
{LF, LR, RM} is mid-stance, so walking starts with (beta - 1/2) T = 0.5 s of six-leg support
before {LF, LR, RM} lifts, as in the paper's Fig. 5 (six legs at 9.4 s, tripod at 9.7 s).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kinematics import joints_for_foot, standing_feet
from .params import LEG_NAMES, TRIPODS, HeavyDutyParams


@dataclass(frozen=True)
class TripodGaitParams:
    duty_factor: float = 14.0 / 24.0
    stroke: float = 0.5
    """Foot travel relative to the body during stance [m] (the paper's step length)."""
    period: float = 6.0
    """Gait cycle T [s]."""
    stand_time: float = 3.0
    """Standing before walking [s]."""
    swing_height: float = 0.3
    """Peak foot lift during swing [m] (not given in the paper)."""
    stance_offset: float | None = None
    """x of the stance stroke's midpoint relative to the neutral foothold [m]. Default: the value
    that puts a tripod exactly on its neutral footholds when the six-leg overlap ends, i.e.
    touch-down at +body_speed (beta - 1/2) T. The paper's figures imply this: 31.41° at the switch
    to three legs (the neutral tripod's margin) and the minimum (~21°) when the stance legs reach
    their rear limit, which needs the stroke to lie mostly behind the neutral foothold."""

    def __post_init__(self) -> None:
        if not 0.5 <= self.duty_factor < 1.0:
            raise ValueError(
                f"duty_factor must be in [0.5, 1) for a tripod gait, got {self.duty_factor}"
            )
        if self.period <= 0 or self.stroke < 0 or self.stand_time < 0:
            raise ValueError("period must be > 0, stroke and stand_time >= 0")

    @property
    def body_speed(self) -> float:
        """Forward body speed while walking [m/s]: stroke / stance time."""
        return self.stroke / (self.duty_factor * self.period)

    @property
    def stance_center(self) -> float:
        """Resolved `stance_offset` [m]."""
        if self.stance_offset is not None:
            return self.stance_offset
        overlap = (self.duty_factor - 0.5) * self.period
        return self.body_speed * overlap - self.stroke / 2


INITIAL_PHASE: dict[str, float] = {
    **dict.fromkeys(TRIPODS[0], 0.5),
    **dict.fromkeys(TRIPODS[1], 0.0),
}


class TripodGait:
    """Foot targets and joint targets of the reference tripod gait as functions of time."""

    def __init__(self, params: HeavyDutyParams | None = None, gait: TripodGaitParams | None = None):
        self.robot = params or HeavyDutyParams()
        self.gait = gait or TripodGaitParams()
        self._neutral = standing_feet(self.robot)

    def leg_phase(self, leg: str, t: float) -> float:
        """Phase of `leg` in [0, 1) at time t [s] since reset (frozen while standing)."""
        walk = max(0.0, t - self.gait.stand_time)
        return (INITIAL_PHASE[leg] + walk / self.gait.period) % 1.0

    def phase(self, t: float) -> float:
        """The gait clock: phase of tripod {LM, RF, RR} (0 at the start of walking)."""
        return self.leg_phase("LM", t)

    def leg_phase_at(self, leg: str, phase: float) -> float:
        """Phase of `leg` in [0, 1) when the gait clock (tripod {LM, RF, RR}) reads `phase`."""
        return (phase + INITIAL_PHASE[leg] - INITIAL_PHASE["LM"]) % 1.0

    def in_stance(self, leg: str, phase_of_leg: float) -> bool:
        return phase_of_leg < self.gait.duty_factor

    def foot_offset(self, phase_of_leg: float) -> np.ndarray:
        """Foot offset from the neutral foothold [m] at a leg phase."""
        g = self.gait
        beta, s = g.duty_factor, g.stroke
        c = g.stance_center
        if phase_of_leg < beta:
            return np.array([c + s / 2 - s * phase_of_leg / beta, 0.0, 0.0])
        u = (phase_of_leg - beta) / (1.0 - beta)
        smooth = u**3 * (10.0 - 15.0 * u + 6.0 * u**2)
        lift = 64.0 * u**3 * (1.0 - u) ** 3
        return np.array([c - s / 2 + s * smooth, 0.0, g.swing_height * lift])

    def feet_at_phase(self, phase: float) -> dict[str, np.ndarray]:
        """Body-frame foot targets when the gait clock (tripod {LM,RF,RR}) reads `phase`."""
        out = {}
        for leg in LEG_NAMES:
            out[leg] = self._neutral[leg] + self.foot_offset(self.leg_phase_at(leg, phase))
        return out

    def joints_at_phase(self, phase: float) -> np.ndarray:
        """(6, 3) joint targets [J_x, J_z, J_theta] in LEG_NAMES order at a gait-clock phase."""
        feet = self.feet_at_phase(phase)
        return np.array([joints_for_foot(leg, feet[leg], self.robot) for leg in LEG_NAMES])

    def joints(self, t: float) -> np.ndarray:
        """(6, 3) joint targets at time t [s] since reset."""
        return self.joints_at_phase(self.phase(t))

    def stance_legs(self, t: float) -> tuple[str, ...]:
        """Legs the reference gait has on the ground at time t."""
        return tuple(leg for leg in LEG_NAMES if self.in_stance(leg, self.leg_phase(leg, t)))
