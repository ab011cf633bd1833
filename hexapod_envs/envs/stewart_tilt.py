"""HexapodStewartTilt-v0 / -v1: the heavy-duty hexapod on a tilting 6-UPS Stewart platform.

## Description
Zhang et al. 2024 §5.2. The robot stands on one tripod with the other tripod lifted in swing
posture. After `tilt_start_time` (3 s) the platform tilts at `tilt_rate_deg` [deg/s] up to
`max_tilt_deg` and holds there. Held on its tripod the robot tips over; a controller that lands
a swing leg in time keeps it up. Scenarios are defined by what the robot feels:

| scenario | platform motion | the held tripod tips |
|---|---|---|
| climb | nose up (pitch) | backward |
| descend | nose down | forward |
| side | roll toward the tripod's two-foot side (1) | about that long edge |
| random | axis, rate and stance sampled from np_random at reset | (training) |

(1) left for LF-LR-RM, right for LM-RF-RR.

The hold posture is a little taller and narrower than the walking stance (feet at |y| = 1.7 m,
`hold_depth` = 1.95 m below the hips) so that the side case tips within the platform's reach
(the 6-UPS platform tilts at most ~44-46 deg; the walking stance would need 48.5 deg).

The paper gives neither its tilt rate nor its final tilt. At the default 2 deg/s the FASM falls
too slowly for the recovery's time budget (eq. 15) to come off its 3 s clamp, and the platform
keeps tilting after the robot has tipped. `paper_scenario(scenario, stance)` gives the settings
of the reproduction report (the paper's start times and stance width, 8 deg/s, and
``stop_on_tipping``: the platform comes to rest once the robot's FASM first falls below ξ; t_s
1.7-1.9 s against the paper's 0.74-2.31 s; docs/reproduction.md). ``hold_depth=1.79`` puts the
foothold of the paper's own reach model (eqs. 10-12) at the paper's height.

## Action Space
18 values in [-1, 1]: ``"residual"`` (default) offsets the hold posture by residual_scale x half
range (default 2, so any joint target is reachable), ``"joint"`` gives targets directly.
With ``landing_action=True`` (residual mode) a 19th value lowers the lifted tripod: the
reference moves from the hold posture toward the landed posture (the lifted feet straight down
by `SWING_LIFT`, onto the plane of the stance feet) by clip(a, 0, 1), low-pass filtered like the
residual; 0 or below keeps the hold posture, 1 sets the lifted feet down where they are.

## Observation Space
As HexapodCliffWalk-v0 without the gait phase: joint_pos, joint_vel, foot_force, foot_contact,
fasm_margin_deg, imu_gyro, imu_accel, imu_quat.

## Rewards
The terms of HexapodCliffWalk-v0 without forward: stability, alive, tip_over, effort.

## Starting State
The robot stands on its held tripod in the hold posture on the level platform, its joints
perturbed by up to ``reset_noise_scale`` of their half range. Task distributions
(``task_distribution=``): "paper" (default) runs `scenario`; "train" / "test" draw the held
tripod, the tilt axis (one of the six paper cases or an arbitrary axis), the tilt rate, the
platform friction and a payload at every reset from the ``train_ranges`` / ``test_ranges``
settings (defaults `TILT_TRAIN` / `TILT_TEST`; held out: rates 4-8 and 12-20 deg/s).
``info["task"]`` holds the values and their ``difficulty``.

## Episode End
Terminated when the body leans more than ``tip_over_angle_deg`` (10°) relative to the platform;
truncated at 1600 steps (32 s). ``info["is_success"]``: no tip-over to the end; -v1 also needs
the lean within 2.5° and the lifted tripod kept up until the robot first tips.

`info` adds scenario and stance (the episode's: on the train/test distributions the sampled
case), platform_tilt_deg, platform_rpy, actuator_lengths (6, m), adjustment_leg (the first lifted
leg to land after tipping was flagged), early_landing (a lifted foot touched down before the
robot first tipped) and recovery_time [s].

## Arguments
`StewartTiltSettings` and `HeavyDutySettings`.

## Version History
- v1: success needs the lifted tripod kept up until the robot first tips
  (``swing_until_tipping``) and the lean relative to the platform within 2.5°
  (docs/benchmark.md).
- v0: the papers' reproduction.
"""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
from gymnasium import spaces

from ..robots.heavy_duty import LEG_NAMES, TRIPODS, joints_for_foot, within_limits
from ..terrain._compiled import stewart_actuator_lengths
from ..terrain.stewart import add_stewart_platform
from ..terrain.stewart_kinematics import DEFAULT_PLATFORM
from .base import Measurement
from .difficulty import DifficultySpan
from .heavy_duty import (
    TEST_PAYLOAD,
    TRAIN_PAYLOAD,
    HeavyDutyEnv,
    HeavyDutySettings,
    HeavyDutyTaskRanges,
)
from .settings import bounded, choice, number, option

SCENARIOS = ("climb", "descend", "side", "random")
STANCES = {"LF-LR-RM": TRIPODS[0], "LM-RF-RR": TRIPODS[1]}

HOLD_FOOT_Y = 1.7
"""|y| of the feet in the hold posture [m]."""
HOLD_DEPTH = 1.95
"""Feet below the coxa origins in the hold posture [m]."""
SWING_LIFT = 0.45
"""Lift of the swing tripod's feet in the hold posture [m]."""
DEFAULT_MAX_TILT_DEG = {"climb": 38.0, "descend": 38.0, "side": 44.0}
RAMP_TIME = 1.0
"""Time to reach (and leave) the tilt rate [s]."""


CASES = tuple((scenario, stance) for scenario in ("climb", "descend", "side") for stance in STANCES)
"""The paper's six cases: three tilt directions for each held tripod."""

PAPER_TILT_START = {"LF-LR-RM": 7.0, "LM-RF-RR": 5.0}
"""Time at which the platform starts tilting in Zhang et al. 2024 §5.2 [s] ("from 0 to 7 s is
the robot status adjustment stage" with legs 1, 3, 5 in stance; 5 s with legs 2, 4, 6)."""
PAPER_TILT_RATE_DEG = 8.0
"""Tilt rate of `paper_scenario` [deg/s], in every case. The paper gives none; this rate makes
the FASM fall fast enough that eq. 15's adjustment time comes off its clamp and the adjustment
foot lands loaded (how other rates behave, and why the paper's judgment times and adjustment
times cannot both be met: docs/reproduction.md)."""
PAPER_FOOT_Y = 1.9
"""|y| of the stance feet in Zhang et al. 2024 §5.2 [m]: its footholds lie at |y| = 1.89-1.91 m,
e.g. (-2390, -1908, -1741) mm. The env's default hold posture is narrower (`HOLD_FOOT_Y`) so that
the held robot tips sideways within the platform's reach, which a platform that stops once the
robot tips does not need."""


def paper_scenario(scenario: str, stance: str) -> dict:
    """Settings of HexapodStewartTilt-v0 for one of the six cases of Zhang et al. 2024 §5.2 as
    the paper runs it: the robot holds its tripod with the feet as wide as the paper's
    (`PAPER_FOOT_Y`), the platform starts tilting after the paper's adjustment stage
    (`PAPER_TILT_START`), at `PAPER_TILT_RATE_DEG`, and stops once the robot has tipped
    (``stop_on_tipping``), so the margin after the adjustment leg lands holds as the paper
    reports. Use: ``gym.make("HexapodStewartTilt-v0", **paper_scenario("climb", "LF-LR-RM"))``.
    """
    if (scenario, stance) not in CASES:
        raise ValueError(f"(scenario, stance) must be one of {CASES}, got {(scenario, stance)}")
    return {
        "scenario": scenario,
        "stance": stance,
        "tilt_start_time": PAPER_TILT_START[stance],
        "tilt_rate_deg": PAPER_TILT_RATE_DEG,
        "stop_on_tipping": True,
        "hold_foot_y": PAPER_FOOT_Y,
    }


@dataclasses.dataclass(frozen=True)
class TiltTaskRanges(HeavyDutyTaskRanges):
    """Ranges of one task distribution. Each reset holds a random tripod and tilts either about
    one of the six paper cases' axes (probability `case_probability`) or about an arbitrary
    horizontal axis, at a rate drawn uniformly from one of `rates_deg_s` (chosen at random).

    Held-out test ranges (`TILT_TEST`): tilt rates interleaved with and beyond training (4-8 and
    12-20 deg/s against 1-4 and 8-12), where the time budget of Zhang et al. 2024 eq. 15 binds;
    lower platform friction; a heavier payload farther off centre.
    """

    rates_deg_s: tuple[tuple[float, float], ...] = bounded(strict=True)
    friction: tuple[float, float] = bounded()
    case_probability: float = 0.5

    def __post_init__(self) -> None:
        super().__post_init__()
        if not 0.0 <= self.case_probability <= 1.0:
            raise ValueError(
                f"TiltTaskRanges.case_probability must be in [0, 1], got {self.case_probability!r}"
            )


TILT_TRAIN = TiltTaskRanges(
    rates_deg_s=((1.0, 4.0), (8.0, 12.0)), friction=(1.2, 1.8), **TRAIN_PAYLOAD
)
TILT_TEST = TiltTaskRanges(
    rates_deg_s=((4.0, 8.0), (12.0, 20.0)), friction=(0.9, 1.2), **TEST_PAYLOAD
)


def tilt_axis(scenario: str, stance: tuple[str, ...]) -> np.ndarray:
    """Unit axis (platform frame, horizontal) about which a positive tilt gives the scenario."""
    if scenario == "climb":
        return np.array([0.0, -1.0, 0.0])  # nose up: rotate about -y
    if scenario == "descend":
        return np.array([0.0, 1.0, 0.0])
    if scenario == "side":
        two_foot_side_left = sum(leg[0] == "L" for leg in stance) == 2
        return np.array([-1.0, 0.0, 0.0]) if two_foot_side_left else np.array([1.0, 0.0, 0.0])
    raise ValueError(f"scenario must be one of {SCENARIOS}, got {scenario!r}")


@dataclasses.dataclass(frozen=True)
class StewartTiltSettings(HeavyDutySettings):
    """Settings of HexapodStewartTilt-v0: the "paper" scenario's tilt, and the ranges."""

    scenario: str = choice("random", SCENARIOS)
    stance: str = choice("LF-LR-RM", tuple(STANCES))
    """The tripod the robot stands on (the other is lifted)."""
    tilt_rate_deg: float = number(2.0, strict=True)
    """Platform tilt rate [deg/s]."""
    max_tilt_deg: float | None = number(None, strict=True, high=90.0, optional=True)
    """Tilt at which the platform stops [deg] (None: the scenario's default)."""
    tilt_start_time: float = number(3.0)
    """Episode time at which the platform starts tilting [s]."""
    stop_on_tipping: bool = choice(False, (False, True))
    """The platform stops once the robot first tips (its FASM below ξ): from then on it
    decelerates at the ramp's rate (`tilt_rate_deg` per RAMP_TIME) and holds the tilt it comes
    to rest at. Zhang et al. 2024 §5.2 use the platform to bring the robot to tipping and report
    the margin after the landing as holding (≈ 40 / 45 / 21.5°); a platform that keeps tilting
    makes it fall back (docs/reproduction.md). Default False: the tilt runs to `max_tilt_deg`."""
    platform_friction: float = number(1.5)
    hold_depth: float = number(HOLD_DEPTH, strict=True)
    """Feet below the coxa origins in the hold posture [m] (the paper does not give it; 1.79
    puts the foothold of the paper's reach model at the paper's height, docs/reproduction.md)."""
    hold_foot_y: float = number(HOLD_FOOT_Y, strict=True)
    """|y| of the feet in the hold posture [m] (the paper's stance feet lie at about 1.9 m)."""
    residual_scale: float = number(2.0)
    """Residual action 1 = this fraction of each joint's half range (2: any target)."""
    tip_over_angle_deg: float = number(10.0, strict=True, high=90.0)
    """Tip-over: the body leans more than this relative to the platform [deg]."""
    swing_until_tipping: bool = choice(False, (False, True))
    """The lifted tripod is in swing, so a success also needs every lifted foot off the
    platform until the robot first tips (FASM below ξ): landing a leg is a recovery, not a
    posture to take before the need (True in -v1; `info["early_landing"]`)."""
    landing_action: bool = choice(False, (False, True))
    """Residual mode: add the lifted tripod's landing as a 19th action (see the module
    docstring). Landing is the one motion the recovery needs, and in 18 per-joint residuals it
    is nine joints moved together at the right moment, which per-step exploration does not
    find (docs/results.md, "Pure PPO on the Stewart tilt")."""
    train_ranges: TiltTaskRanges = option(TILT_TRAIN, kind=TiltTaskRanges, optional=False)
    test_ranges: TiltTaskRanges = option(TILT_TEST, kind=TiltTaskRanges, optional=False)


class StewartTiltEnv(HeavyDutyEnv):
    """See the module docstring."""

    Settings = StewartTiltSettings
    walks = False
    difficulty_spans = {
        "tilt_rate_deg": DifficultySpan(easy=1.0, hard=20.0),
        "platform_friction": DifficultySpan(easy=1.8, hard=0.9),
        "payload_mass": DifficultySpan(easy=0.0, hard=800.0),
    }
    """What makes a tilt task hard: a fast tilt (less time from the alarm to tipping, eq. 15's
    budget), a slippery platform, a heavy payload."""

    def _setup(self) -> None:
        s = self.settings
        self.scenario, self.stance_name = s.scenario, s.stance
        self.tilt_rate = np.radians(s.tilt_rate_deg)
        self.tilt_start_time = s.tilt_start_time
        self.platform_friction = s.platform_friction
        self.hold_depth = s.hold_depth
        self.hold_foot_y = s.hold_foot_y
        self._max_tilt_arg = s.max_tilt_deg
        self._first_tipping_time = None  # set per episode at reset; `tilt_at` reads it
        self.platform = DEFAULT_PLATFORM
        self._platform_centre = self.platform.neutral_position  # read-only: never moves
        self._platform_centre.flags.writeable = False
        self.task_ranges = {"train": s.train_ranges, "test": s.test_ranges}
        if s.landing_action and s.action_mode != "residual":
            raise ValueError(
                "landing_action=True adds the lifted tripod's landing to the residual action; got "
                f"action_mode={s.action_mode!r}"
            )
        self.landing_action = s.landing_action
        super()._setup()
        if self.landing_action:
            self.action_space = spaces.Box(-1.0, 1.0, shape=(19,), dtype=np.float32)
        self._set_postures(STANCES[self.stance_name])  # set per episode at reset
        # Validate the fixed scenarios' whole motion up front: a pose the actuators cannot reach
        # is refused here, not discovered mid-episode.
        if self.scenario != "random":
            self._configure(self.scenario, STANCES[self.stance_name], self.tilt_rate)
            self._check_reachable()

    def _bind_model(self) -> None:
        super()._bind_model()
        m = self.model
        self._platform_act = np.array([m.actuator(j).id for j in self.platform_handles.joints])
        self._platform_qpos = np.array(
            [m.jnt_qposadr[m.joint(j).id] for j in self.platform_handles.joints]
        )
        self._platform_body = m.body("platform").id

    # --- scenario ------------------------------------------------------------------------
    def _configure(self, scenario: str, stance: tuple[str, ...], rate: float, axis=None) -> None:
        self.stance = stance
        self.swing = tuple(leg for leg in LEG_NAMES if leg not in stance)
        self._swing_ids = [LEG_NAMES.index(leg) for leg in self.swing]
        self.axis = tilt_axis(scenario, stance) if axis is None else axis
        self.rate = rate
        if self._max_tilt_arg is not None:
            self.max_tilt = np.radians(self._max_tilt_arg)
        elif scenario in DEFAULT_MAX_TILT_DEG:
            self.max_tilt = np.radians(DEFAULT_MAX_TILT_DEG[scenario])
        else:
            self.max_tilt = np.radians(40.0)
        self._set_postures(stance)

    def _set_postures(self, stance: tuple[str, ...]) -> None:
        """The hold posture for `stance` and, with `landing_action`, the landed one."""
        self._hold = self._hold_posture(stance)
        if self.landing_action:
            self._landed = self._hold_posture(stance, lift=0.0)

    def _check_reachable(self) -> None:
        for tilt in np.linspace(0.0, self.max_tilt, 25):
            self.platform.check_pose(self.platform.neutral_position, self._rpy(tilt))

    def _hold_posture(self, stance: tuple[str, ...], lift: float = SWING_LIFT) -> np.ndarray:
        """(18,) joint targets with the `stance` feet at the hold's footholds and the other feet
        `lift` [m] above theirs."""
        joints = []
        for leg in LEG_NAMES:
            side = 1.0 if leg[0] == "L" else -1.0
            foot = self.robot.hip_offsets[leg] + np.array([0.0, 0.0, -self.hold_depth])
            foot[1] = side * self.hold_foot_y
            if leg not in stance:
                foot[2] += lift
            unreachable = (
                f"hold_depth={self.hold_depth} m, hold_foot_y={self.hold_foot_y} m: leg {leg} "
                "cannot reach its foothold"
            )
            try:
                leg_joints = joints_for_foot(leg, foot, self.robot)
            except ValueError as err:
                raise ValueError(f"{unreachable} ({err})") from None
            if not within_limits(leg_joints, self.robot):
                raise ValueError(f"{unreachable} (the joints would leave their ranges)")
            joints.append(leg_joints)
        return np.concatenate(joints)

    def _rpy(self, tilt: float) -> np.ndarray:
        """Roll and pitch for a tilt about the scenario axis (R = Ry(pitch) Rx(roll)): exact for
        the paper's six cases (an axis along x or y), while an oblique axis's roll and pitch
        are its components, which tilt the platform slightly less than `tilt` about no fixed
        axis (a 45° axis at 40°: 39.15°; the reach and the rate are computed for `tilt`)."""
        return np.array([tilt * self.axis[0], tilt * self.axis[1], 0.0])

    def tilt_at(self, t: float) -> float:
        """Platform tilt [rad] at time t: the scheduled tilt (`scheduled_tilt_at`), or with
        ``stop_on_tipping`` once the robot has tipped, the tilt at that moment carried on with
        the ramp's deceleration until the platform rests (never beyond the scheduled tilt)."""
        stop = self._first_tipping_time if self.settings.stop_on_tipping else None
        if stop is None or t <= stop:
            return self.scheduled_tilt_at(t)
        decel = self.rate / RAMP_TIME
        rate = self._scheduled_rate_at(stop)
        tau = min(t - stop, rate / decel)
        stopping = self.scheduled_tilt_at(stop) + rate * tau - 0.5 * decel * tau**2
        return min(stopping, self.scheduled_tilt_at(t))

    def _scheduled_rate_at(self, t: float) -> float:
        """d/dt of `scheduled_tilt_at` [rad/s] (central difference over 1 ms; the schedule is
        piecewise quadratic, so this is its exact slope away from the ramps' joints)."""
        h = 5e-4
        return (self.scheduled_tilt_at(t + h) - self.scheduled_tilt_at(t - h)) / (2.0 * h)

    def scheduled_tilt_at(self, t: float) -> float:
        """Platform tilt [rad] at time t as scheduled: level while settling, then the scenario
        rate reached and left with a constant (de)celeration over RAMP_TIME so the plate never
        jerks. A tilt too small to reach the rate (max_tilt < rate x RAMP_TIME) accelerates and
        decelerates only, with the same (de)celeration, and stops at max_tilt."""
        ramp = RAMP_TIME
        tau = t - self.tilt_start_time
        if tau <= 0.0:
            return 0.0
        accel = self.rate / ramp
        if self.max_tilt >= self.rate * ramp:
            total = self.max_tilt / self.rate + ramp  # time to reach max_tilt with both ramps
        else:  # the ramps would overlap: half the time speeding up, half slowing down
            ramp = math.sqrt(self.max_tilt / accel)
            total = 2.0 * ramp
        if tau >= total:
            return self.max_tilt
        if tau < ramp:
            return 0.5 * accel * tau**2
        if tau > total - ramp:
            return self.max_tilt - 0.5 * accel * (total - tau) ** 2
        return self.rate * (tau - ramp / 2)

    # --- model hooks ---------------------------------------------------------------------
    def _add_terrain(self, spec: mujoco.MjSpec) -> None:
        self.platform_handles = add_stewart_platform(
            spec, self.platform, friction=self.platform_friction
        )

    def _robot_start_height(self) -> float:
        return self.platform.neutral_height + self.hold_depth + 0.005

    def reference_joints(self) -> np.ndarray:
        """The hold posture; with `landing_action`, moved toward the landed posture by the
        filtered landing action."""
        if self.landing_action:
            return self._hold + self._landing * (self._landed - self._hold)
        return self._hold

    def _start_episode(self) -> None:
        super()._start_episode()
        self._landing = 0.0
        """With `landing_action`: the low-pass filtered landing fraction in [0, 1]."""

    def _apply_action(self, action: np.ndarray) -> None:
        """With `landing_action`, first the landing fraction (filtered like the residual), then
        the heavy-duty residual on the reference it gives."""
        if self.landing_action:
            target = min(max(float(action[18]), 0.0), 1.0)
            self._landing += self._filter_alpha * (target - self._landing)
        super()._apply_action(action)

    def _reference_description(self) -> dict:
        """As the heavy-duty envs', plus ``hold_posture``: the episode's (18,) joint targets of
        the hold posture, the zero residual action (the held tripod depends on the task); with
        `landing_action` also ``landed_posture``, the targets of landing fraction 1."""
        landed = {"landed_posture": self._landed.copy()} if self.landing_action else {}
        return {
            **super()._reference_description(),
            "hold_posture": self._hold.copy(),
            "landing_action": self.landing_action,
            **landed,
        }

    def _initial_joints(self) -> np.ndarray:
        return self._hold

    # --- task distribution -----------------------------------------------------------------
    def paper_task(self) -> dict:
        axis = {}
        if self.scenario != "random":
            a = tilt_axis(self.scenario, STANCES[self.stance_name])
            axis = {"tilt_axis_x": float(a[0]), "tilt_axis_y": float(a[1])}
        return {
            "scenario": self.scenario,
            "stance": self.stance_name,
            **axis,
            "tilt_rate_deg": float(np.degrees(self.tilt_rate)),
            "platform_friction": float(self.settings.platform_friction),
            **self.NO_PAYLOAD,
        }

    def sample_task(self, rng: np.random.Generator, distribution: str) -> dict:
        r = self.task_ranges[distribution]
        if rng.uniform() < r.case_probability:
            scenario, stance = CASES[int(rng.integers(len(CASES)))]
            axis = tilt_axis(scenario, STANCES[stance])
        else:
            scenario, stance = "random", sorted(STANCES)[int(rng.integers(2))]
            angle = rng.uniform(0, 2 * np.pi)
            axis = np.array([np.cos(angle), np.sin(angle), 0.0])
        band = r.rates_deg_s[int(rng.integers(len(r.rates_deg_s)))]
        return {
            "scenario": scenario,
            "stance": stance,
            "tilt_axis_x": float(axis[0]),
            "tilt_axis_y": float(axis[1]),
            "tilt_rate_deg": float(rng.uniform(*band)),
            "platform_friction": float(rng.uniform(*r.friction)),
            **self._sample_payload(rng, r),
        }

    def _set_terrain(self, task: dict) -> bool:
        if task["platform_friction"] == self.platform_friction:
            return False
        self.platform_friction = task["platform_friction"]
        return True

    def _configure_sampled(self, task: dict) -> None:
        axis = np.array([task["tilt_axis_x"], task["tilt_axis_y"], 0.0])
        scenario = task["scenario"]
        self._configure(scenario, STANCES[task["stance"]], np.radians(task["tilt_rate_deg"]), axis)
        self.max_tilt = min(self.max_tilt, 0.95 * self.platform.max_tilt(axis))

    def _apply_task(self, task: dict) -> None:
        """The platform friction and payload (see `HeavyDutyEnv`), then the episode's tilt:
        the sampled one, or with the "random" paper scenario an axis, rate and stance drawn
        here from `np_random` (added to ``info["task"]``)."""
        super()._apply_task(task)
        if self.task_distribution != "paper":
            self._configure_sampled(self.task)
        elif self.scenario == "random":
            rng = self.np_random
            stance = STANCES[sorted(STANCES)[int(rng.integers(2))]]
            angle = rng.uniform(0, 2 * np.pi)
            rate = np.radians(rng.uniform(1.0, 3.0))
            axis = np.array([np.cos(angle), np.sin(angle), 0.0])
            self._configure("random", stance, rate, axis)
            reach = self.platform.max_tilt(axis)
            self.max_tilt = min(self.max_tilt, 0.95 * reach)
            self.task.update(
                stance="-".join(stance),
                tilt_axis_x=float(axis[0]),
                tilt_axis_y=float(axis[1]),
                tilt_rate_deg=float(np.degrees(rate)),
            )

    def _set_initial_state(self) -> None:
        self.data.qpos[self._platform_qpos] = 0.0
        self.data.ctrl[self._platform_act] = 0.0
        self.data.act[self.model.actuator_actadr[self._platform_act]] = 0.0
        self._first_tipping_time = None
        self._adjustment_leg = None
        self._recovery_time = None
        self._early_landing = False
        super()._set_initial_state()

    def _before_physics(self) -> None:
        """Command the tilt rate that carries the platform to tilt_at(t + dt) within the period."""
        t = self.time
        rate = (self.tilt_at(t + self.control_dt) - self.tilt_at(t)) / self.control_dt
        roll_rate, pitch_rate = rate * self.axis[0], rate * self.axis[1]  # `_rpy(rate)`
        self.data.ctrl[self._platform_act] = (pitch_rate, roll_rate)

    # --- stability, termination, reward ---------------------------------------------------
    def _tilt_cos(self) -> float:
        """The body's tilt is measured from the platform's up axis (tipping about the feet)."""
        platform_up = self.data.xmat[self._platform_body, 2::3]
        return float(self.sensors.torso_up() @ platform_up)

    def _is_success(self) -> bool:
        """Standing to the end (no tip-over), without an early landing if
        ``swing_until_tipping``."""
        return not (self.settings.swing_until_tipping and self._early_landing)

    def _measure(self) -> Measurement:
        measured = super()._measure()
        if self._step_count == 0:
            return measured
        loaded = measured.loaded
        if self._first_tipping_time is None and measured.fasm_deg < self.tipping_threshold_deg:
            self._first_tipping_time = self.time
        if self._first_tipping_time is None and not self._early_landing:
            self._early_landing = any(loaded[i] for i in self._swing_ids)
        if self._first_tipping_time is not None and self._adjustment_leg is None:
            for i, leg in enumerate(LEG_NAMES):
                if leg in self.swing and loaded[i]:
                    self._adjustment_leg = leg
                    self._recovery_time = self.time - self._first_tipping_time
                    break
        return measured

    def _extra_info(self, unstable: bool) -> dict:
        pitch, roll = self.data.qpos[self._platform_qpos].tolist()
        up_z = min(1.0, self.data.xmat[self._platform_body, 8])  # the platform's up axis' z
        rpy = np.array([roll, pitch, 0.0])
        platform = self.platform  # its actuator lengths, in one compiled call:
        lengths = stewart_actuator_lengths(
            platform.base_joints, platform.platform_joints, self._platform_centre, roll, pitch, 0.0
        )
        return {
            **super()._extra_info(unstable),
            "scenario": self.task.get("scenario", self.scenario),  # the episode's case
            "stance": self.stance,
            "platform_tilt_deg": float(np.degrees(np.arccos(up_z))),
            "platform_rpy": rpy,
            "actuator_lengths": lengths,
            "adjustment_leg": self._adjustment_leg,
            "early_landing": self._early_landing,
            "recovery_time": self._recovery_time,
        }
