"""Closed-loop tipping recovery of Zhang et al. 2024 (§3-4) for the heavy-duty hexapod, from
sensors only.

Every control period the controller reads the joint encoders, the 3-D foot force sensors (world
frame) and the IMU, and works in the body frame:

1. **State from sensors** (:mod:`.body_model`): feet by forward kinematics, the CoG from the known
   link masses, foot forces and gravity rotated into the body frame with the IMU quaternion.
2. **Judgment** (§3): FASM from the measured foot forces (f_r, n_r = minus the support wrench
   about the CoG) over the loaded feet; tipping when it falls below ξ_f = 20°. The effective
   support legs are the two with the largest vertical foot force, the tipping edge their line
   and the adjustment leg comes from Table II (:mod:`.judgment`). For a stance that is not a
   tripod (e.g. five legs while walking), Table II's leg is used when its edge is in the table
   and the leg is free, otherwise the free leg whose hip lies farthest outside the edge.
3. **Foothold** (§4.2): least-squares terrain plane through the stance feet, reachable region of
   the adjustment leg on it and the selection rule of eq. (14) (:mod:`.foothold`).
4. **Time budget and trajectory** (eq. 15): the margin's rate and acceleration from a quadratic fit
   of its last `rate_window` seconds (:mod:`.margin_rate`); t_s = ϰ times the forecast time to
   S = 0, clamped to [t_min, t_max]; a quintic from the foot's measured position and velocity to
   the foothold, lifted by `swing_clearance` along the plane normal (:mod:`.trajectory`).
5. **Touch-down**: if the trajectory ends without ground contact, the foot keeps descending along
   the plane normal at `touchdown_speed` until its force sensor reports contact (the ground may
   lie lower than the plane fitted through the feet) or `max_search_depth` is exhausted
   (then the attempt has failed, the leg is pulled back and the posture held).
6. **Force distribution** (§4.3, eqs. 16-24) once the leg has landed: the desired wrench from the
   accelerometer (low-pass filtered specific force, F_b = m (a_b - g_b)) and the gyro
   (T_b = I ω̇ + ω × I ω); the QP with friction, minimum normal force and stability cone solved
   through qpsolvers (daqp by default, :mod:`.force_distribution`) every control period, over
   the support feet in contact. The cone (base radius λ d_min round the support centroid) makes
   the QP infeasible when the centroid lies far from below the CoG, as after a rear or side leg
   lands; λ is then widened step by step (`cone_ratios`) and, if nothing is feasible, the cone
   dropped; a narrower λ is retried every 25 solves.
7. **Making the planned forces act**: the servos are position servos of known stiffness at the foot
   (x, leg length, swing), so a target offset Δq = -K⁻¹ Jᵀ ΔF adds ΔF to a foot held by the
   ground. ΔF = planned - measured is first projected onto the null space of the wrench map A
   (eq. 17): the part of a plan that statics contradicts (the wrench error the stability cone
   allows, or body accelerations) cannot be imposed through foot positions without moving the
   body, while the internal part (how the load is shared, e.g. how much the new leg carries)
   can. The offsets integrate that error with gain `force_gain` per period (the loop converges
   geometrically; a proportional offset would only go half-way) and are clamped. They are only
   adjusted while every support foot is loaded: near lift-off the feet are no longer held and
   pushing a foot down would roll the body instead.

The controller then holds the new stance. It never reads simulator state; the policy wrappers
(:class:`TippingRecoveryPolicy`, and :mod:`.gait_with_recovery` for walking) give it the
observation only. Constants not in the paper are documented on :class:`RecoveryConfig`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from itertools import compress
from typing import Any

import gymnasium as gym
import numpy as np

from agents.policy import EnvBound, ObservationReader
from agents.tipping import _compiled
from agents.tipping.body_model import (
    GRAVITY,
    HeavyDutyBodyModel,
    gravity_in_body,
    quat_to_matrix,
)
from agents.tipping.foothold import (
    AXIS_ANGLE_THRESHOLD_DEG,
    REACH_MODELS,
    RHO,
    FootholdChoice,
    select_foothold,
)
from agents.tipping.force_distribution import (
    SOLVERS,
    ForceDistributionConfig,
    ForceDistributionResult,
    ForceDistributor,
    desired_wrench,
)
from agents.tipping.judgment import ADJUSTMENT_LEG, XI_F_DEG, judge
from agents.tipping.margin_rate import MarginHistory
from agents.tipping.trajectory import (
    KAPPA,
    T_MAX,
    T_MIN,
    QuinticTrajectory,
    time_budget,
    zero_crossing_time,
)
from hexapod_envs.checks import check_number
from hexapod_envs.envs.actions import JointActionMap
from hexapod_envs.robots.heavy_duty.kinematics import joints_for_foot
from hexapod_envs.robots.heavy_duty.params import LEG_NAMES, HeavyDutyParams
from hexapod_envs.stability import fasm_from_feet, plane_normal

PHASES: tuple[str, ...] = ("monitor", "swing", "touchdown", "supported", "holding")
"""Controller phases: watching the margin; adjustment leg on its quintic; descending until
contact; landed and distributing forces; holding the posture without a landed adjustment leg
(no usable leg, no reachable ground, or no ground found: ``diagnostics["failure"]`` says which)."""

_LEG_INDEX = {leg: i for i, leg in enumerate(LEG_NAMES)}
_RETRY_NARROWER = 25  # QP solves between attempts at a narrower stability cone

try:  # the LAPACK gesv gufunc behind np.linalg.solve: the same numbers, minus its Python wrapper
    from numpy.linalg._umath_linalg import solve1 as _gesv
except ImportError:  # pragma: no cover - a numpy without it
    _gesv = None


def _solve(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """np.linalg.solve(a, b) for a square float64 `a` and a vector `b`, bit for bit.

    Why: in the recovery's supported phase np.linalg.solve's wrapper (type and shape checks, an
    errstate context) cost about 10 µs of the median 190 µs controller step
    (benchmarks/bench_recovery_controller.py); the gufunc is the same LAPACK call. A singular
    `a` makes it return non-finite values (with numpy's RuntimeWarning) where the wrapper raises
    LinAlgError; the error is raised here too.
    """
    if _gesv is None:  # pragma: no cover
        return np.linalg.solve(a, b)
    x = _gesv(a, b, signature="dd->d")
    if not math.isfinite(x.sum()):
        raise np.linalg.LinAlgError("Singular matrix")
    return x


@dataclass(frozen=True)
class RecoveryConfig:
    """Settings of the recovery controller (paper values where it gives them).

    Attributes:
        threshold_deg: ξ_f [deg] (paper: 20).
        reach_model: foothold reach model, "kinematic" (the leg's real reach) or "paper"
            (eqs. 10-12 as printed, which finds no foothold outside a side tipping edge of the
            standing robot); see :mod:`.foothold`.
        rho: safety factor ρ of eqs. (11)-(13) (not given in the paper).
        angle_threshold_deg: segment/axis angle threshold of the selection rule [deg].
        kappa, t_min, t_max: eq. (15)'s ϰ and the clamp on t_s [s].
        rate_window: history used for the margin's rate and acceleration [s].
        arm_after: no judgment during the first seconds of an episode (filters start-up).
        swing_clearance: lift of the quintic at mid-swing along the plane normal [m].
        touchdown_speed: descent speed after the trajectory ends without contact [m/s].
        max_search_depth: how far below the fitted plane the foot may search for ground [m].
        contact_fraction: a foot carrying more than this fraction of the robot's weight is in
            contact (the envs use 0.02).
        force_gain: integral gain of the force-offset loop per control period, in (0, 1].
        max_offset: clamp on the force offsets [J_x m, J_z m, J_θ rad] (actuator units; the
            default allows 40 kN along x, 64 kN along the leg, 2e5 N·m about the swing axis).
        accel_filter_time: time constant of the low-pass on accelerometer and gyro [s].
        qp_period: solve the QP every this many control periods (1 = every period).
        cone_ratios: λ values tried in turn when the stability cone makes the QP infeasible
            (it does whenever the support centroid G_s lies farther from below the CoG than
            λ d_min, as after a rear or side leg lands); the first is the configured
            ``qp.cone_ratio`` and, if none is feasible, the QP is solved without the cone.
        force_control: apply the offsets (False: plan and log the forces only).
        min_normal_fraction: QP's minimum normal force per stance foot as a fraction of the
            weight (kept above contact_fraction so that every planned foot counts as loaded).
        qp: the remaining QP settings (solver, weights, friction, cone ratio λ).
    """

    threshold_deg: float = XI_F_DEG
    reach_model: str = "kinematic"
    rho: float = RHO
    angle_threshold_deg: float = AXIS_ANGLE_THRESHOLD_DEG
    kappa: float = KAPPA
    t_min: float = T_MIN
    t_max: float = T_MAX
    rate_window: float = 0.4
    arm_after: float = 0.2
    swing_clearance: float = 0.1
    touchdown_speed: float = 0.15
    max_search_depth: float = 0.5
    contact_fraction: float = 0.02
    force_gain: float = 0.5
    max_offset: tuple[float, float, float] = (0.004, 0.004, 0.004)
    accel_filter_time: float = 0.2
    qp_period: int = 1
    cone_ratios: tuple[float, ...] = (0.65, 0.8, 0.95)
    force_control: bool = True
    min_normal_fraction: float = 0.04
    qp: ForceDistributionConfig = field(default_factory=ForceDistributionConfig)

    def __post_init__(self) -> None:
        if self.reach_model not in REACH_MODELS:
            raise ValueError(f"reach_model must be one of {REACH_MODELS}, got {self.reach_model!r}")
        if self.qp.solver not in SOLVERS:
            raise ValueError(f"solver must be one of {SOLVERS}, got {self.qp.solver!r}")
        if not 0.0 < self.force_gain <= 1.0:
            raise ValueError(f"force_gain must lie in (0, 1], got {self.force_gain}")
        if self.qp_period < 1:
            raise ValueError(f"qp_period must be >= 1, got {self.qp_period}")
        limits = np.asarray(self.max_offset, dtype=float)
        if limits.shape != (3,) or not np.all(np.isfinite(limits) & (limits >= 0.0)):
            raise ValueError(
                f"max_offset must be 3 finite limits >= 0 (J_x m, J_z m, J_θ rad), "
                f"got {self.max_offset!r}"
            )
        if not 0.0 < self.contact_fraction < self.min_normal_fraction:
            raise ValueError(
                "need 0 < contact_fraction < min_normal_fraction, got "
                f"{self.contact_fraction}, {self.min_normal_fraction}"
            )
        for name in ("touchdown_speed", "max_search_depth", "rate_window", "accel_filter_time"):
            check_number(name, getattr(self, name), strict=True)
        # Checked here, not first at the episode's first tipping judgment that uses them:
        check_number("threshold_deg", self.threshold_deg, low=-90.0, high=90.0)
        check_number("angle_threshold_deg", self.angle_threshold_deg, high=180.0)
        check_number("rho", self.rho, strict=True, high=1.0)
        check_number("swing_clearance", self.swing_clearance)
        check_number("arm_after", self.arm_after)
        if not 0.0 < check_number("kappa", self.kappa, strict=True) < 1.0:
            raise ValueError(f"kappa must lie in (0, 1), got {self.kappa}")
        if not 0.0 < check_number("t_min", self.t_min, strict=True) <= self.t_max:
            raise ValueError(f"need 0 < t_min <= t_max, got t_min={self.t_min}, t_max={self.t_max}")
        ratios = np.asarray(self.cone_ratios, dtype=float)  # () : the configured λ alone
        if ratios.ndim != 1 or not np.all((ratios > 0.0) & (ratios < 1.0)):
            raise ValueError(f"cone_ratios must be values in (0, 1), got {self.cone_ratios!r}")


@dataclass
class SensorReading:
    """One control period's measurements, in the env's units.

    Attributes:
        joints: (6, 3) encoder readings [J_x m, J_z m, J_θ rad], LEG_NAMES order.
        joint_velocities: (6, 3) their rates.
        foot_forces: (6, 3) ground reaction on each foot, WORLD frame [N].
        quat: (4,) IMU orientation (w, x, y, z), body -> world.
        gyro: (3,) body angular velocity [rad/s] (body frame).
        accel: (3,) accelerometer specific force [m/s²] (body frame).
    """

    joints: np.ndarray
    joint_velocities: np.ndarray
    foot_forces: np.ndarray
    quat: np.ndarray
    gyro: np.ndarray
    accel: np.ndarray

    @classmethod
    def from_observation(cls, pieces: dict[str, np.ndarray]) -> SensorReading:
        return cls(
            joints=pieces["joint_pos"].reshape(6, 3),
            joint_velocities=pieces["joint_vel"].reshape(6, 3),
            foot_forces=pieces["foot_force"].reshape(6, 3),
            quat=pieces["imu_quat"],
            gyro=pieces["imu_gyro"],
            accel=pieces["imu_accel"],
        )


class TippingRecoveryController:
    """The recovery method as a state machine over control periods (see the module docstring).

    Call :meth:`step` once per control period with the sensor reading, the nominal joint targets
    (what the robot would do without the controller) and the time; it returns the (6, 3) joint
    targets. The nominal targets are latched when tipping is judged: from then on the controller
    holds that posture (plus the adjustment leg and the force offsets).

    ``diagnostics`` (a dict updated every period; body frame, SI units, margins in degrees):
    phase; fasm_deg, fasm_edge, stance_legs (this period's FASM from the sensors); at judgment:
    judgment_time, margin_at_judgment_deg, margin_rate_deg_s, margin_accel_deg_s2,
    tipping_edge, support_legs, adjustment_leg, t_s, time_to_zero_s (eq. 15's forecast before
    ϰ and the clamp), foothold, foothold_point, foothold_status, foothold_reason,
    foothold_within_limits; at landing: landing_time, recovery_time (landing - judgment),
    fasm_before_landing_deg, supported_legs; in support: qp_status, qp_legs, qp_cone_ratio
    (λ used; nan = cone dropped), planned_forces and measured_forces ((k, 3) ground reactions
    on qp_legs), qp_wrench_residual; failure (why the posture is only held).
    """

    def __init__(
        self,
        params: HeavyDutyParams | None = None,
        config: RecoveryConfig | None = None,
        control_dt: float = 0.02,
    ):
        self.params = params or HeavyDutyParams()
        self.config = config or RecoveryConfig()
        self.control_dt = float(control_dt)
        self.body = HeavyDutyBodyModel(self.params)
        weight = self.body.total_mass * GRAVITY
        self._contact_sq = (self.config.contact_fraction * weight) ** 2
        self._qp_config = replace(
            self.config.qp, min_normal_force=self.config.min_normal_fraction * weight
        )
        self._distributors: dict[tuple[int, int], ForceDistributor] = {}
        self._cone_ladder = (self.config.qp.cone_ratio, *self.config.cone_ratios)
        ranges = self.params.joint_ranges
        self._j_low, self._j_high = ranges[:, 0], ranges[:, 1]
        self._max_offset = np.asarray(self.config.max_offset, dtype=float)
        self.history = MarginHistory(self.config.rate_window)
        self.reset()

    # --- episode ---------------------------------------------------------------------------
    def reset(self) -> None:
        self.history.clear()
        self.phase = "monitor"
        self._t0: float | None = None
        self._nominal: np.ndarray | None = None
        self._leg: str | None = None
        self._traj: QuinticTrajectory | None = None
        self._choice: FootholdChoice | None = None
        self._command: np.ndarray | None = None  # adjustment foot's commanded body position
        self._search_start: float | None = None
        self._support: list[int] = []
        self._landing_joints: np.ndarray | None = None
        self._offsets: np.ndarray | None = None
        self._accel_f: np.ndarray | None = None
        self._gyro_f: np.ndarray | None = None
        self._gyro_prev: np.ndarray | None = None
        self._steps_supported = 0
        self._last_qp: ForceDistributionResult | None = None
        self._previous_margin = math.nan
        self._cone_level = 0
        self._qp_solves = 0
        self._inertia: np.ndarray | None = None
        self._last_qp_a: np.ndarray | None = None
        self.diagnostics: dict[str, Any] = {
            "phase": "monitor",
            "fasm_deg": math.nan,
            "fasm_edge": None,
            "stance_legs": (),
            "judgment_time": None,
            "margin_at_judgment_deg": None,
            "margin_rate_deg_s": None,
            "margin_accel_deg_s2": None,
            "tipping_edge": None,
            "support_legs": None,
            "adjustment_leg": None,
            "t_s": None,
            "time_to_zero_s": None,
            "foothold": None,
            "foothold_point": None,
            "foothold_status": None,
            "foothold_reason": None,
            "foothold_within_limits": None,
            "landing_time": None,
            "recovery_time": None,
            "fasm_before_landing_deg": None,
            "supported_legs": None,
            "planned_forces": None,
            "measured_forces": None,
            "qp_status": None,
            "qp_legs": None,
            "qp_cone_ratio": None,
            "qp_wrench_residual": None,
            "failure": None,
        }

    @property
    def active(self) -> bool:
        """True once tipping has been judged (the controller owns the posture)."""
        return self.phase != "monitor"

    # --- sensing ---------------------------------------------------------------------------
    def _filter(self, reading: SensorReading) -> None:
        alpha = min(1.0, self.control_dt / self.config.accel_filter_time)
        accel = np.asarray(reading.accel, dtype=float)
        gyro = np.asarray(reading.gyro, dtype=float)
        if self._accel_f is None:
            self._accel_f, self._gyro_f = accel.copy(), gyro.copy()
            self._gyro_prev = self._gyro_f.copy()
        else:
            self._gyro_prev = self._gyro_f.copy()
            self._accel_f += alpha * (accel - self._accel_f)
            self._gyro_f += alpha * (gyro - self._gyro_f)

    # --- main step -------------------------------------------------------------------------
    def step(self, reading: SensorReading, nominal: np.ndarray, time: float) -> np.ndarray:
        """(6, 3) joint targets for this control period."""
        cfg = self.config
        self._filter(reading)
        quat = np.asarray(reading.quat, dtype=float)
        if quat.shape != (4,) or not float(quat @ quat) > 0.0:
            quat_to_matrix(quat)  # raises the error that names the problem
        # quat_to_matrix, forces_to_body and |f|² > threshold, compiled into one call
        rot, forces, loaded = _compiled.body_sensing(
            quat, np.asarray(reading.foot_forces, dtype=float).reshape(6, 3), self._contact_sq
        )
        joints = np.asarray(reading.joints, dtype=float).reshape(6, 3)
        feet, cog = self.body.feet_and_cog(joints)
        # FASM [deg] over the loaded feet (body frame), (0, None) without a support polygon; f_r
        # and n_r are minus the measured support wrench about the CoG (Zhang et al. 2024 eq. 4).
        margin, edge = fasm_from_feet(feet, forces, cog, loaded)
        self.history.add(time, margin)
        d = self.diagnostics
        self._previous_margin = d["fasm_deg"]
        d["fasm_deg"] = margin
        d["fasm_edge"] = None if edge is None else (LEG_NAMES[edge[0]], LEG_NAMES[edge[1]])
        d["stance_legs"] = tuple(compress(LEG_NAMES, loaded.tolist()))

        if self.phase == "monitor":
            if margin < cfg.threshold_deg and time >= cfg.arm_after and loaded.sum() >= 3:
                self._judge(time, margin, joints, feet, forces, loaded, nominal, reading)
            else:
                return np.asarray(nominal, dtype=float).reshape(6, 3).copy()

        targets = self._nominal.copy()
        if self.phase == "swing":
            self._swing(time, targets, loaded)
        if self.phase == "touchdown":
            self._touchdown(time, targets, loaded)
        if self.phase == "supported":
            self._supported(targets, joints, feet, forces, cog, rot, loaded)
        d["phase"] = self.phase
        return np.minimum(np.maximum(targets, self._j_low), self._j_high)

    # --- judgment and planning -------------------------------------------------------------
    def _pick_leg(self, edge: tuple[str, str], stance: tuple[str, ...], feet: np.ndarray):
        """Adjustment leg for a stance that is not a tripod (see the module docstring)."""
        free = [leg for leg in LEG_NAMES if leg not in stance]
        table = ADJUSTMENT_LEG.get(frozenset(edge))
        if table in free:
            return table
        if not free:
            return None
        p, q = feet[_LEG_INDEX[edge[0]], :2], feet[_LEG_INDEX[edge[1]], :2]
        axis = (q - p) / np.linalg.norm(q - p)

        def outside(leg):  # < 0 right of the counter-clockwise edge, i.e. outside the polygon
            h = self.params.hip_offsets[leg][:2] - p
            return axis[0] * h[1] - axis[1] * h[0]

        best = min(free, key=outside)
        return best if outside(best) < 0.0 else None

    def _judge(self, time, margin, joints, feet, forces, loaded, nominal, reading) -> None:
        cfg, d = self.config, self.diagnostics
        self.phase = "holding"  # until a plan exists
        self._t0 = time
        self._nominal = np.asarray(nominal, dtype=float).reshape(6, 3).copy()
        stance = tuple(leg for leg, on in zip(LEG_NAMES, loaded, strict=True) if on)
        feet_map = {leg: feet[_LEG_INDEX[leg]] for leg in stance}
        vertical = {leg: float(forces[_LEG_INDEX[leg], 2]) for leg in stance}
        judgment = judge(margin, vertical, stance, feet_map, cfg.threshold_deg)
        leg = judgment.adjustment_leg
        if leg is None:  # not a tripod stance: Table II does not cover it
            leg = self._pick_leg(judgment.edge, stance, feet)
        rate, accel = self.history.rate_and_acceleration()
        d.update(
            judgment_time=time,
            margin_at_judgment_deg=margin,
            margin_rate_deg_s=rate,
            margin_accel_deg_s2=accel,
            tipping_edge=judgment.edge,
            support_legs=judgment.support_legs,
            adjustment_leg=leg,
        )
        if leg is None:
            d["failure"] = "no free leg lies outside the tipping edge"
            return
        choice = select_foothold(
            leg,
            feet_map,
            judgment.edge,
            self.params,
            rho=cfg.rho,
            angle_threshold_deg=cfg.angle_threshold_deg,
            model=cfg.reach_model,
        )
        self._choice = choice
        d.update(
            foothold=None if choice.foothold is None else choice.foothold.copy(),
            foothold_point=choice.point,
            foothold_status=choice.status,
            foothold_reason=choice.reason,
            foothold_within_limits=choice.within_joint_limits,
        )
        if choice.foothold is None:
            d["failure"] = choice.reason
            return
        t_s = time_budget(margin, rate, accel, cfg.kappa, cfg.t_min, cfg.t_max)
        i = _LEG_INDEX[leg]
        velocity = self.body.foot_velocities(joints, reading.joint_velocities)[i]
        self._traj = QuinticTrajectory.plan(
            feet[i],
            choice.foothold,
            t_s,
            start_velocity=velocity,
            clearance=cfg.swing_clearance,
            lift_direction=choice.plane.normal,
        )
        self._leg = leg
        self._support = sorted(_LEG_INDEX[x] for x in (*stance, leg))
        self._support_idx = np.array(self._support, dtype=np.intp)
        self.phase = "swing"
        d["t_s"] = t_s
        d["time_to_zero_s"] = zero_crossing_time(margin, rate, accel)

    # --- adjustment leg --------------------------------------------------------------------
    def _ik(self, leg: str, position: np.ndarray) -> np.ndarray | None:
        try:
            return joints_for_foot(leg, position, self.params)
        except ValueError:
            return None

    def _command_leg(self, targets: np.ndarray, position: np.ndarray) -> bool:
        """Put the adjustment leg's target at ``position``; False when out of reach."""
        joints = self._ik(self._leg, position)
        if joints is None:
            return False
        i = _LEG_INDEX[self._leg]
        targets[i] = joints
        self._command = position
        tol = 1e-9
        return bool(np.all(joints >= self._j_low - tol) and np.all(joints <= self._j_high + tol))

    def _swing(self, time: float, targets: np.ndarray, loaded: np.ndarray) -> None:
        tau = time - self._t0
        self._command_leg(targets, self._traj.position(tau + self.control_dt))
        if loaded[_LEG_INDEX[self._leg]] and tau > 0.5 * self._traj.duration:
            self._land(time)
        elif tau + self.control_dt >= self._traj.duration:
            self.phase = "touchdown"
            self._search_start = time

    def _touchdown(self, time: float, targets: np.ndarray, loaded: np.ndarray) -> None:
        if loaded[_LEG_INDEX[self._leg]]:
            self._command_leg(targets, self._command)
            self._land(time)
            return
        depth = self.config.touchdown_speed * (time - self._search_start + self.control_dt)
        position = self._choice.foothold - depth * self._choice.plane.normal
        reachable = self._command_leg(targets, position)
        if depth > self.config.max_search_depth or not reachable:
            self.phase = "holding"
            self.diagnostics["failure"] = (
                f"no ground under {self._leg} within {depth:.2f} m below the fitted plane"
            )
            i = _LEG_INDEX[self._leg]
            targets[i] = self._nominal[i]

    def _land(self, time: float) -> None:
        d = self.diagnostics
        i = _LEG_INDEX[self._leg]
        self._landing_joints = self._ik(self._leg, self._command)
        self._nominal[i] = self._landing_joints
        self._offsets = np.zeros((6, 3))
        self.phase = "supported"
        d.update(
            landing_time=time,
            recovery_time=time - d["judgment_time"],
            fasm_before_landing_deg=self._previous_margin,
            supported_legs=tuple(LEG_NAMES[j] for j in self._support),
        )

    # --- force distribution ----------------------------------------------------------------
    def _distributor(self, k: int, level: int) -> ForceDistributor:
        """QP for k feet at cone level ``level`` (index into the λ ladder; past its end: no
        cone)."""
        key = (k, level)
        if key not in self._distributors:
            ladder = self._cone_ladder
            if level < len(ladder):
                config = replace(self._qp_config, cone_ratio=ladder[level])
            else:
                config = replace(self._qp_config, stability_cone=False)
            self._distributors[key] = ForceDistributor(k, config)
        return self._distributors[key]

    def _solve_qp(self, feet_k, cog, wrench, normal) -> tuple[ForceDistributionResult, float]:
        """Solve at the narrowest feasible cone, starting from the last level that worked and
        trying one level narrower every `_RETRY_NARROWER` solves. Returns (result, λ or nan)."""
        k = len(feet_k)
        ladder = self._cone_ladder
        level = self._cone_level
        if level > 0 and self._qp_solves % _RETRY_NARROWER == 0:
            level -= 1
        self._qp_solves += 1
        while True:
            distributor = self._distributor(k, level)
            try:
                qp = distributor.build(feet_k, cog, wrench, normal)
            except ValueError:  # degenerate geometry (e.g. CoG on an edge line): no plan
                qp, result = None, None
            else:
                result = distributor.solve_qp(qp)
            if (result is not None and result.ok) or level >= len(ladder):
                break
            level += 1
        self._cone_level = level
        self._last_qp_a = None if qp is None else qp.A
        return result, (ladder[level] if level < len(ladder) else math.nan)

    def _supported(self, targets, joints, feet, forces, cog, rot, loaded) -> None:
        """Distribute the forces over the supporting feet that are in contact and make the
        plan's internal part act through the servo stiffness (see the module docstring)."""
        cfg, d = self.config, self.diagnostics
        # Contact is unilateral: a support foot that has lifted off cannot be loaded by pushing
        # it (that would only tilt the body), so the plan covers the feet in contact, and the
        # offsets are only adjusted while every support foot is loaded (the stiffness model
        # assumes feet held by the ground).
        held = self._support_idx
        in_contact = loaded[held]
        support = held[in_contact]
        complete = bool(np.logical_and.reduce(in_contact))  # .all(), minus its wrapper
        self._steps_supported += 1
        d["qp_legs"] = tuple(LEG_NAMES[i] for i in support.tolist())
        measured = d["measured_forces"] = forces[support]
        if len(support) < 3:
            d.update(qp_status="too_few_feet", planned_forces=None)
        elif (self._steps_supported - 1) % cfg.qp_period == 0:
            feet_k = feet[support]
            if self._inertia is None:  # the posture is held from here on: compute it once
                self._inertia = self.body.inertia(joints, cog)
            g_body = gravity_in_body(rot)
            wrench = desired_wrench(
                self.body.total_mass,
                self._inertia,
                g_body,
                accel_body=self._accel_f + g_body,
                omega=self._gyro_f,
                omega_dot=(self._gyro_f - self._gyro_prev) / self.control_dt,
            )
            # None when the loaded feet lie on a line in (x, y): no plane to fit
            normal = plane_normal(feet_k)
            result, cone_ratio = (
                (None, None) if normal is None else self._solve_qp(feet_k, cog, wrench, normal)
            )
            self._last_qp = result
            d["qp_cone_ratio"] = cone_ratio
            if result is None:
                d.update(qp_status="degenerate_geometry", planned_forces=None)
            else:
                d.update(  # fresh arrays of this solve: no copies needed
                    qp_status=result.status,
                    planned_forces=result.forces,
                    qp_wrench_residual=result.wrench_residual,
                )
            if result is not None and result.ok and cfg.force_control and complete:
                # Internal part: error - Aᵀ (A Aᵀ)⁻¹ A error (A has full row rank, k >= 3).
                a_mat = self._last_qp_a
                error, a_at, a_error = _compiled.force_error_system(result.forces, measured, a_mat)
                internal = _compiled.internal_part(error, a_mat, _solve(a_at, a_error))
                change = self.body.target_change_for_force(
                    joints, internal.reshape(-1, 3), legs=support
                )
                _compiled.add_offsets(
                    self._offsets, support, change, cfg.force_gain, self._max_offset
                )
        _compiled.offset_targets(targets, self._nominal, self._offsets, held)


class TippingRecoveryPolicy(EnvBound):
    """Zhang et al. 2024's tipping recovery as a policy for the heavy-duty hexapod envs.

    Works in either action mode: the joint targets of :class:`TippingRecoveryController` become
    normalised targets ("joint") or offsets from the env's reference posture ("residual"; the
    Stewart env's default residual_scale 2 reaches every target). An action beyond the 18
    joints (``landing_action``, ``clock_action``) is 0: no landing, the gait's own pace.
    Everything comes from the env's declared task description (robot, action mapping, timing,
    and the reference: the Stewart env's ``hold_posture`` of the episode, or the walking envs'
    gait table at the observed ``gait_phase``, the definition of the residual action) and from
    the observation.
    The description is read again on the first call after `reset` (the held tripod is drawn
    at the env's reset, which may come before or after the policy's).

    Args:
        env: a heavy-duty hexapod env (e.g. HexapodStewartTilt-v0).
        config: :class:`RecoveryConfig`; keyword overrides of its fields may be given instead,
            e.g. ``TippingRecoveryPolicy(env, reach_model="paper", solver="quadprog")``. Without
            a config, the tipping threshold ξ is the env's (``tipping_threshold_deg``).
    """

    def __init__(self, env: gym.Env, config: RecoveryConfig | None = None, **overrides):
        self.env = env
        base = env.unwrapped
        task = getattr(base, "task_description", None)
        if task is None or not isinstance(task.robot, HeavyDutyParams):
            raise ValueError(f"{type(base).__name__} is not a heavy-duty hexapod env")
        if config is None and "threshold_deg" not in overrides:
            overrides = {"threshold_deg": float(task.tipping_threshold_deg), **overrides}
        self.config = _config_with(config, overrides)
        self.read = ObservationReader(task.observation_structure)
        self.action_map = JointActionMap(np.column_stack([task.joint_low, task.joint_high]))
        self.action_mode = task.action_mode
        self.control_dt = float(task.control_dt)
        if self.action_mode == "residual":
            self._gain = task.reference["residual_scale"] * self.action_map.half
        self._dtype = env.action_space.dtype
        # An env's actions beyond the 18 joints (the Stewart tilt's landing_action, the cliff
        # walk's clock_action) get 0, their neutral value: no landing, the gait's own pace.
        self._extra = np.zeros(int(env.action_space.shape[0]) - 18, dtype=self._dtype)
        self._reference_gait = TripodGaitReference(task)
        self._hold: np.ndarray | None = None
        self.controller = TippingRecoveryController(task.robot, self.config, self.control_dt)
        self.reset()

    def reset(self) -> None:
        self.controller.reset()
        self._steps = 0
        self._saturated = False

    @property
    def diagnostics(self) -> dict[str, Any]:
        """The controller's state (phase, adjustment leg, foothold, t_s, forces, QP status...)
        plus ``saturated``: a target was clipped by the action's residual range."""
        return {**self.controller.diagnostics, "saturated": self._saturated}

    def reference(self, observation: np.ndarray) -> np.ndarray:
        """(18,) joint targets of the env's reference (the zero residual action) now."""
        if self._hold is not None:
            return self._hold
        return self._reference_gait(self.read(observation))

    def nominal(self, observation: np.ndarray) -> np.ndarray:
        """Joint targets without recovery: the env's reference posture."""
        return self.reference(observation).reshape(6, 3)

    def to_action(self, targets: np.ndarray, observation: np.ndarray) -> np.ndarray:
        joints = np.asarray(targets).reshape(-1)
        if self.action_mode == "residual":
            raw = (joints - self.reference(observation)) / self._gain
            # np.maximum.reduce / np.minimum(np.maximum()) are np.abs().max() / np.clip minus
            # their Python wrappers (the same numbers; this runs every control period).
            peak = float(np.maximum.reduce(np.abs(raw)))
            self._saturated = self._saturated or peak > 1.0 + 1e-9
            action = np.minimum(np.maximum(raw, -1.0), 1.0)
        else:
            action = self.action_map.to_action(joints)
        action = action.astype(self._dtype)
        return np.concatenate([action, self._extra]) if self._extra.size else action

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        if self._steps == 0:  # the episode's reference (the env has been reset by now)
            hold = self.env.unwrapped.task_description.reference.get("hold_posture")
            self._hold = None if hold is None else np.asarray(hold, dtype=float)
        reading = SensorReading.from_observation(self.read(observation))
        time = self._steps * self.control_dt
        self._steps += 1
        targets = self.controller.step(reading, self.nominal(observation), time)
        return self.to_action(targets, observation)


class TripodGaitReference:
    """The walking heavy-duty envs' reference joint targets at the observed gait phase: the
    row of the declared ``reference_table`` that the env's gait clock points at."""

    def __init__(self, task):
        self._table = task.reference.get("reference_table")
        self._steps = task.reference.get("steps_per_cycle")

    def __call__(self, pieces: dict[str, np.ndarray]) -> np.ndarray:
        if self._table is None or "gait_phase" not in pieces:
            raise ValueError("this env declares neither a hold posture nor a gait phase")
        s, c, _ = pieces["gait_phase"]
        k = round(float(np.arctan2(s, c)) / (2 * np.pi) * self._steps) % self._steps
        return self._table[k]


def _config_with(config: RecoveryConfig | None, overrides: dict[str, Any]) -> RecoveryConfig:
    """``config`` (default RecoveryConfig()) with keyword overrides; ``solver`` sets qp.solver."""
    config = config or RecoveryConfig()
    overrides = dict(overrides)
    if "solver" in overrides:
        config = replace(config, qp=replace(config.qp, solver=overrides.pop("solver")))
    valid = set(RecoveryConfig.__dataclass_fields__)
    unknown = sorted(set(overrides) - valid)
    if unknown:
        raise ValueError(f"unknown setting(s) {unknown}; valid: {sorted(valid | {'solver'})}")
    return replace(config, **overrides)
