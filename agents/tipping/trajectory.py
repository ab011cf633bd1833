"""Adjustment time budget (Zhang et al. 2024 eq. 15) and the quintic foot trajectory of §4.2.

Time budget. When the margin S [deg] has fallen below ξ_f, its rate v_s [deg/s] and acceleration
a_s [deg/s²] give a quadratic forecast S(t) = S + v_s t + ½ a_s t², and the leg must land before
the forecast reaches 0. Eq. (15) prints t_s = ϰ (-v_s + sqrt(v_s² - 4 a_s ξ_f)) / (2 a_s), the
root formula of ξ_f + v_s t + a_s t² = 0. Two readings are fixed here:

- a_s is taken as the margin's second derivative, so the forecast carries the Taylor factor ½
  (the printed formula is recovered by passing 2 a_s);
- the root used is the *first* positive zero crossing. For a falling margin (v_s < 0) the
  printed "+" branch is the later root when a_s > 0 and a negative time when a_s < 0; the first
  crossing is the "-" branch, evaluated in the cancellation-free form
  t = 2 S / (-v_s + sqrt(v_s² - 2 a_s S)), which also tends to S / (-v_s) as a_s -> 0.

Fallbacks (documented behaviour, never an exception for finite inputs): S <= 0 (already at or past
the tipping point) -> t_min; no zero crossing ahead (the forecast turns round before 0, or the
margin is not falling) -> t_max; otherwise ϰ t clamped to [t_min, t_max].

Foot trajectory. A quintic polynomial per coordinate from the start position, velocity and
acceleration to the target with given end velocity and acceleration over t_s. An optional
clearance adds h·64 s³(1-s)³ along a direction (peak h at mid-swing), which keeps all six
boundary conditions exact, so that a foot starting near the ground does not drag through it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

KAPPA: float = 0.7
"""ϰ (0 < ϰ < 1) of eq. (15): fraction of the forecast time to tipping used for the swing."""

T_MIN: float = 0.5
"""Shortest allowed adjustment time [s] (a 100 kg leg cannot be thrown faster)."""

T_MAX: float = 3.0
"""Longest allowed adjustment time [s] (the paper's times are 0.74-2.31 s)."""

_A_EPS = 1e-9  # |a_s| [deg/s²] below which the forecast is treated as linear


def zero_crossing_time(margin_deg: float, rate_deg_s: float, accel_deg_s2: float) -> float:
    """First t > 0 with margin + rate t + ½ accel t² = 0 [s]; inf when there is none ahead.

    A margin already <= 0 gives 0.
    """
    s, v, a = float(margin_deg), float(rate_deg_s), float(accel_deg_s2)
    if not all(map(math.isfinite, (s, v, a))):
        raise ValueError(f"margin, rate and acceleration must be finite, got {(s, v, a)}")
    if s <= 0.0:
        return 0.0
    if abs(a) < _A_EPS:
        return s / -v if v < 0.0 else math.inf
    disc = v * v - 2.0 * a * s
    if disc < 0.0:
        return math.inf  # a > 0 and the decline turns round before reaching 0
    denom = -v + math.sqrt(disc)
    if denom <= 0.0:
        return math.inf  # v >= 0 and a > 0: never falls to 0
    return 2.0 * s / denom


def time_budget(
    margin_deg: float,
    rate_deg_s: float,
    accel_deg_s2: float,
    kappa: float = KAPPA,
    t_min: float = T_MIN,
    t_max: float = T_MAX,
) -> float:
    """Adjustment time t_s [s] of eq. (15): ϰ times the forecast time to S = 0, clamped.

    Args:
        margin_deg: current FASM margin S [deg] (the paper uses ξ_f, the margin at detection).
        rate_deg_s: dS/dt [deg/s] (negative while the robot tips).
        accel_deg_s2: d²S/dt² [deg/s²].
        kappa: ϰ in (0, 1).
        t_min, t_max: clamp [s], 0 < t_min <= t_max.
    """
    if not 0.0 < kappa < 1.0:
        raise ValueError(f"kappa must lie in (0, 1), got {kappa}")
    if not 0.0 < t_min <= t_max:
        raise ValueError(f"need 0 < t_min <= t_max, got t_min={t_min}, t_max={t_max}")
    t_cross = zero_crossing_time(margin_deg, rate_deg_s, accel_deg_s2)
    if t_cross == 0.0:
        return t_min
    return min(t_max, max(t_min, kappa * t_cross))


def _quintic_coefficients(p0, v0, a0, p1, v1, a1, duration: float) -> np.ndarray:
    """(6, d) coefficients c_0..c_5 of p(t) = Σ c_n t^n meeting the six boundary conditions."""
    t = duration
    c0, c1, c2 = p0, v0, 0.5 * a0
    # Remaining conditions at t = T solved in closed form for c3, c4, c5.
    dp = p1 - (c0 + c1 * t + c2 * t * t)
    dv = v1 - (c1 + 2.0 * c2 * t)
    da = a1 - 2.0 * c2
    c3 = (20.0 * dp - 8.0 * dv * t + da * t * t) / (2.0 * t**3)
    c4 = (-30.0 * dp + 14.0 * dv * t - 2.0 * da * t * t) / (2.0 * t**4)
    c5 = (12.0 * dp - 6.0 * dv * t + da * t * t) / (2.0 * t**5)
    return np.array([c0, c1, c2, c3, c4, c5])


@dataclass(frozen=True)
class QuinticTrajectory:
    """Quintic foot trajectory from a start state to a target state in ``duration`` seconds.

    Build it with :meth:`plan`. Evaluation clamps t to [0, duration]: before the start it gives
    the start state, after the end the end state (position, and the end velocity/acceleration).

    Attributes:
        coefficients: (6, d) polynomial coefficients, row n multiplies t^n.
        duration: T [s].
        clearance: peak of the added lift bump [m] (0 for none).
        lift_direction: (d,) unit direction of the bump.
    """

    coefficients: np.ndarray
    duration: float
    clearance: float = 0.0
    lift_direction: np.ndarray | None = None

    @classmethod
    def plan(
        cls,
        start: np.ndarray,
        target: np.ndarray,
        duration: float,
        start_velocity: np.ndarray | None = None,
        start_acceleration: np.ndarray | None = None,
        end_velocity: np.ndarray | None = None,
        end_acceleration: np.ndarray | None = None,
        clearance: float = 0.0,
        lift_direction: np.ndarray | None = None,
    ) -> QuinticTrajectory:
        """Plan from ``start`` (position [m], velocity [m/s], acceleration [m/s²]) to ``target``.

        Unspecified velocities and accelerations are zero. ``clearance`` [m] >= 0 lifts the
        path by up to that much along ``lift_direction`` (default +z), without changing any
        boundary condition.
        """
        p0 = np.asarray(start, dtype=float)
        p1 = np.asarray(target, dtype=float)
        if p0.ndim != 1 or p0.shape != p1.shape:
            raise ValueError(
                f"start and target must be vectors of one shape, got {p0.shape}, {p1.shape}"
            )
        if not duration > 0.0:
            raise ValueError(f"duration must be > 0 s, got {duration}")
        if clearance < 0.0:
            raise ValueError(f"clearance must be >= 0 m, got {clearance}")

        def vec(v, name):
            if v is None:
                return np.zeros_like(p0)
            v = np.asarray(v, dtype=float)
            if v.shape != p0.shape:
                raise ValueError(f"{name} must have shape {p0.shape}, got {v.shape}")
            return v

        coeffs = _quintic_coefficients(
            p0,
            vec(start_velocity, "start_velocity"),
            vec(start_acceleration, "start_acceleration"),
            p1,
            vec(end_velocity, "end_velocity"),
            vec(end_acceleration, "end_acceleration"),
            float(duration),
        )
        direction = None
        if clearance > 0.0:
            if lift_direction is None:
                if p0.shape != (3,):
                    raise ValueError("lift_direction is required unless positions are 3-D")
                lift_direction = np.array([0.0, 0.0, 1.0])
            direction = vec(lift_direction, "lift_direction")
            direction = direction / np.linalg.norm(direction)
        return cls(coeffs, float(duration), float(clearance), direction)

    def _eval(self, t, order: int) -> np.ndarray:
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        n = np.arange(6)
        if order == 0:
            basis = t[..., None] ** n
        elif order == 1:
            basis = n * t[..., None] ** np.maximum(n - 1, 0)
        else:
            basis = n * (n - 1) * t[..., None] ** np.maximum(n - 2, 0)
        out = basis @ self.coefficients
        if self.clearance > 0.0:
            s = t / self.duration
            if order == 0:
                bump = 64.0 * s**3 * (1.0 - s) ** 3
            elif order == 1:
                bump = 192.0 * s**2 * (1.0 - s) ** 2 * (1.0 - 2.0 * s) / self.duration
            else:
                bump = 384.0 * s * (1.0 - s) * (1.0 - 5.0 * s + 5.0 * s * s) / self.duration**2
            out = out + self.clearance * bump[..., None] * self.lift_direction
        return out

    def position(self, t) -> np.ndarray:
        """Position(s) [m] at time(s) t [s]: shape t.shape + (d,)."""
        return self._eval(t, 0)

    def velocity(self, t) -> np.ndarray:
        """Velocity [m/s] at time(s) t [s]."""
        return self._eval(t, 1)

    def acceleration(self, t) -> np.ndarray:
        """Acceleration [m/s²] at time(s) t [s]."""
        return self._eval(t, 2)

    def evaluate(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(position, velocity, acceleration) at time(s) t [s]."""
        return self.position(t), self.velocity(t), self.acceleration(t)
