"""HexapodDitchCrossing-v0: the 3-UPU parallel-mechanism hexapod walks forward across a ditch.

Li et al. 2018 §6-7 (Li et al., Robotics 2018): the robot walks with the "3-3" gait, one platform
standing on its three legs while the other lifts its legs, travels along a quadratic path
(eqs. 19-21) and lands; strides are at most l_max1 = 160 mm (eq. 17) and are shortened near
the ditch, and legs extend into it (Fig. 13). The default ditch is the paper's: 140 mm deep,
350 mm wide, its near edge 0.6 m ahead of the robot's centre (front feet at x = 0.2 m).
``terrain="flat"`` removes the ditch and keeps the same finish line.

The env carries a reference gait: the plan of `hexapod_envs.robots.upu.gait_plan` for the
episode's terrain (made at reset, after any randomisation), timed by
`hexapod_envs.robots.upu.gait_schedule`. A ditch the mechanism cannot cross gets no plan: the
reference stands still and ``info["planner_status"]`` says why ("too_deep", "too_wide",
"no_plan").

Task distributions (``task_distribution=``): "paper" (default) is the ditch above (or the
``ditch_*_range`` draws); "train" / "test" draw the ditch's start, width, depth and the ground
friction at every reset from `DITCH_TRAIN` / `DITCH_TEST` (held out: wider, deeper, farther,
lower friction). ``info["task"]`` holds the values; the stability criterion is a positive
static margin (`tipping_threshold_deg` = 0 on the FASM).

| Observation piece | size | unit |
|---|---|---|
| joint_pos | 9 | limb lengths l_1..l_3, then leg extensions U1..L3 (+ = longer) [m] |
| joint_vel | 9 | [m/s], same order |
| foot_force | 18 | ground reaction on each foot (U1..L3), world frame [N] |
| foot_contact | 6 | 1 when the foot's pressure switch reads > contact_threshold x weight |
| fasm_margin_deg | 1 | force-angle stability margin of the loaded feet [deg] (0 with < 3) |
| static_margin_m | 1 | CoG projection to the loaded feet's support polygon [m] (0 with < 3) |
| imu_gyro | 3 | lower-platform angular velocity [rad/s] |
| imu_accel | 3 | accelerometer [m/s²] |
| imu_quat | 4 | lower-platform orientation (w, x, y, z) |
| reference_action | 9 | the reference gait's command now, normalised like a "joint" action |
| residual_state | 9 | the filtered residual now, in units of the residual gains (0 if "joint") |

The CoG is that of the kinematic model with the known masses (MuJoCo's subtree centre of mass,
which is exactly that), so static_margin_m is the paper's d of Fig. 5 (eqs. 12-14).

Actions: 9 values in [-1, 1], in the order of joint_pos. ``action_mode="joint"``: each is a
target normalised over its range (limb length over [l_min, l_max] = [0.365, 0.465] m, leg
extension over [-leg_retract, leg_extend] = [-0.08, 0.16] m). ``"residual"`` (default): an
offset from the reference gait's targets of up to residual_limb_m (limbs) and residual_leg_m
(legs), low-pass filtered with time constant residual_filter_tau (observation piece
residual_state); the zero action walks (and crosses) with the reference gait. The defaults
(2 mm, 5 mm, 0.5 s) are small because the paper's gait is fragile: at the full stride the
CoG passes 15 mm from a support edge at 0.4 m height, the nearly vertical limbs turn 1 mm of
length into ~10 mm of platform travel, and 1 mm of leg-length difference tilts the body by
0.2 degrees; uniformly random actions with these defaults still cross in most episodes.

Control runs at 10 Hz (control_dt = 0.1 s, physics 2 ms); the servo drives interpolate: each
target is approached linearly over the control period, at most 0.25 m/s for a limb and 1 m/s
for a leg (`model.add_upu`, ``command="interpolated"``), as the stiff limb servos would
otherwise jerk the feet into slipping on every step of the command.

The reference gait (`hexapod_envs.robots.upu.gait_schedule.GaitTiming`) takes 5.1 s per
platform step: unload 0.4, lift 0.8, hold 0.2, transfer 2.5, hold 0.3, land 0.6, hold 0.3.
Crossing the default ditch takes 20 steps, 102 s (1017 control steps); the time limit is 1500.

| Reward term (info key) | meaning |
|---|---|
| reward_progress | progress_weight x CoG speed along x, clipped to ±0.1 m/s [m/s] |
| reward_stability | stability_weight x clip(static_margin_m / 0.1 m, -1, 1) (0.1 m = rho/2) |
| reward_alive | the largest cost of a step (bounds of progress, stability, effort), while up |
| reward_success | on crossing: (horizon_steps - steps taken) x the largest reward of a step |
| reward_tip_over | -tip_over_penalty on the step the robot tips over (episode ends) |
| reward_effort | -effort_weight x min(sum of |actuator power| / (robot weight x 0.1 m/s), 10) |

Every term is bounded: an episode that ends by tipping over returns less than staying up, and
one that stands still on the near side until the time limit returns less than crossing.

The episode ends (terminated) when the robot tips over (body tilt > tip_over_angle_deg) or
succeeds: every foot past the far edge of the ditch (the finish line on flat ground), all six
feet loaded, not tipped. `info`: the reward terms, fasm_margin_deg, static_margin_m,
stance_legs, is_tipping (static_margin_m <= 0: the CoG projection is not inside the loaded
feet's polygon), is_tipped_over, is_success, sim_unstable, distance (CoG advance [m]), tilt_deg,
planner_status, planner_reason, ditch (start_x, width, depth [m]; None on flat ground),
finish_x [m], gait_step and gait_phase (the reference's plan step and phase), time, cog.
"""

from __future__ import annotations

import dataclasses
import math
from itertools import compress

import mujoco
import numpy as np
from gymnasium import spaces

from ..checks import check_number
from ..robots.upu.gait_plan import (
    Ditch,
    GaitPlan,
    GaitSettings,
    plan_ditch_crossing,
    plan_flat_past,
)
from ..robots.upu.gait_schedule import (
    COMMAND_NAMES,
    GaitSchedule,
    GaitTiming,
    standing_command,
    walking_height,
)
from ..robots.upu.model import add_upu
from ..robots.upu.params import LEG_NAMES, UpuParams
from ..stability import fasm_from_feet
from ..stability._geometry import hull_2d, signed_distance_2d
from ..terrain.ditch import add_ditch
from ..terrain.flat import add_flat
from .base import HexapodEnv, check_choice
from .sensors import RobotSensors

TERRAINS = ("ditch", "flat")
ACTION_MODES = ("joint", "residual")
GRAVITY = 9.81
_RANGE_KWARGS = ("ditch_start_x_range", "ditch_width_range", "ditch_depth_range")


@dataclasses.dataclass(frozen=True)
class DitchTaskRanges:
    """Ranges of one task distribution (uniform draws) [m], friction coefficient.

    Held-out test ranges (`DITCH_TEST`) extrapolate beyond training: wider ditches (0.40-0.50
    m against 0.25-0.40), deeper (0.12-0.15 m against 0.06-0.12; the planner refuses depths
    above ~0.16 m), farther ahead, lower friction.
    """

    start_x: tuple[float, float]
    width: tuple[float, float]
    depth: tuple[float, float]
    friction: tuple[float, float]


DITCH_TRAIN = DitchTaskRanges(
    start_x=(0.6, 0.9), width=(0.25, 0.40), depth=(0.06, 0.12), friction=(0.8, 1.2)
)
DITCH_TEST = DitchTaskRanges(
    start_x=(0.9, 1.1), width=(0.40, 0.50), depth=(0.12, 0.15), friction=(0.5, 0.8)
)
DITCH_RANGES = {"train": DITCH_TRAIN, "test": DITCH_TEST}


def _check_range(name: str, value) -> tuple[float, float] | None:
    if value is None:
        return None
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be None or a (low, high) pair [m], got {value!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
        raise ValueError(f"{name} must be a finite (low, high) pair with low <= high, got {value}")
    return (lo, hi)


def _as_slice(index: np.ndarray):
    """A contiguous ascending index array as a slice (a view instead of a copy), else as is."""
    index = np.asarray(index)
    if index.size and np.array_equal(index, np.arange(index[0], index[0] + index.size)):
        return slice(int(index[0]), int(index[0]) + index.size)
    return index


PROGRESS_CLIP_M_S = 0.1
"""Bound of the progress term's CoG speed [m/s] (the reference gait peaks near 0.065 m/s)."""
EFFORT_CAP = 10.0
"""Bound of the effort term's power ratio [-] (the reference gait peaks near 5.5)."""


class DitchCrossingEnv(HexapodEnv):
    """The 3-UPU hexapod crossing a ditch (or walking on flat ground); see the module docstring.

    Keyword arguments (SI units): terrain ("ditch" | "flat"); ditch_start_x, ditch_width,
    ditch_depth [m] (defaults 0.6, 0.35, 0.14); ditch_start_x_range, ditch_width_range,
    ditch_depth_range ((low, high) [m] or None): when given, sampled uniformly from np_random at
    every reset; action_mode ("residual" | "joint"), residual_limb_m, residual_leg_m [m],
    residual_filter_tau [s] (0: no filter); control_dt, physics_dt [s];
    progress_weight, stability_weight, tip_over_penalty, effort_weight; horizon_steps (the
    episode's step budget, as the registered time limit, that the success bonus counts the
    remaining steps of); contact_threshold
    (fraction of the weight); tip_over_angle_deg; reset_noise_scale [m] (the robot starts
    shifted by up to this along x and y, and turned so that its feet move up to this much);
    friction; gait_timing (GaitTiming), gait_settings (GaitSettings), params (UpuParams);
    rendering: render_mode, width, height, camera_name (default the tracking camera "track").

    Public attributes for controllers that know the course (as the paper's robot knows the
    ditch): ``ditch`` (the episode's `Ditch`), ``terrain``, ``start_x``, ``params``,
    ``finish_x``, ``command_low`` / ``command_high`` (actuator ranges), ``plan`` and
    ``schedule`` (the reference gait), ``gait_settings``, ``gait_timing``.
    """

    tipping_threshold_deg = 0.0
    """The paper judges this robot by its static margin (observation ``static_margin_m``), not
    by a FASM threshold; 0 deg only marks a net force outside the support polygon."""
    stability_criterion = "static margin > 0 mm (CoG projection inside the support triangle)"

    def __init__(
        self,
        *,
        terrain: str = "ditch",
        ditch_start_x: float = 0.6,
        ditch_width: float = 0.35,
        ditch_depth: float = 0.14,
        ditch_start_x_range: tuple[float, float] | None = None,
        ditch_width_range: tuple[float, float] | None = None,
        ditch_depth_range: tuple[float, float] | None = None,
        action_mode: str = "residual",
        residual_limb_m: float = 0.002,
        residual_leg_m: float = 0.005,
        residual_filter_tau: float = 0.5,
        control_dt: float = 0.1,
        physics_dt: float = 0.002,
        progress_weight: float = 20.0,
        stability_weight: float = 0.05,
        tip_over_penalty: float = 100.0,
        effort_weight: float = 0.02,
        horizon_steps: int = 1500,
        contact_threshold: float = 0.005,
        tip_over_angle_deg: float = 20.0,
        reset_noise_scale: float = 0.005,
        friction: float = 1.0,
        gait_timing: GaitTiming | None = None,
        gait_settings: GaitSettings | None = None,
        params: UpuParams | None = None,
        render_mode: str | None = None,
        width: int = 640,
        height: int = 480,
        camera_name: str | None = "track",
        task_distribution: str = "paper",
        sensor_noise: float = 0.0,
    ):
        super().__init__(
            control_dt=control_dt,
            physics_dt=physics_dt,
            render_mode=render_mode,
            width=width,
            height=height,
            camera_name=camera_name,
            task_distribution=task_distribution,
            sensor_noise=sensor_noise,
        )
        check_choice("terrain", terrain, TERRAINS)
        check_choice("action_mode", action_mode, ACTION_MODES)
        for name, value in (
            ("residual_limb_m", residual_limb_m),
            ("residual_leg_m", residual_leg_m),
            ("residual_filter_tau", residual_filter_tau),
        ):
            check_number(name, value)
        if not 0 < contact_threshold < 1:
            raise ValueError(f"contact_threshold must be in (0, 1), got {contact_threshold}")
        if not 0 < tip_over_angle_deg < 90:
            raise ValueError(f"tip_over_angle_deg must be in (0, 90), got {tip_over_angle_deg}")
        check_number("reset_noise_scale", reset_noise_scale)
        self.terrain = terrain
        self.action_mode = action_mode
        self.residual_gain = np.array([residual_limb_m] * 3 + [residual_leg_m] * 6)
        """Residual per unit action [m] (limbs, then legs)."""
        self.residual_filter_alpha = control_dt / (residual_filter_tau + control_dt)
        """Weight of a new residual action in the first-order filter (1: no filter)."""
        gain = self.residual_gain
        self._inv_residual_gain = np.divide(1.0, gain, out=np.zeros(9), where=gain > 0)
        self.params = params or UpuParams()
        self.gait_timing = gait_timing or GaitTiming()
        self.gait_settings = gait_settings or GaitSettings()
        self.friction = friction
        self._paper_friction = friction
        self.reset_noise_scale = reset_noise_scale
        self.weights = {
            "progress": progress_weight,
            "stability": stability_weight,
            "tip_over": tip_over_penalty,
            "effort": effort_weight,
        }
        self.horizon_steps = int(horizon_steps)
        self.ditch_ranges = {
            name.removesuffix("_range"): _check_range(name, value)
            for name, value in zip(
                _RANGE_KWARGS,
                (ditch_start_x_range, ditch_width_range, ditch_depth_range),
                strict=True,
            )
        }
        self.ditch_defaults = {
            "ditch_start_x": ditch_start_x,
            "ditch_width": ditch_width,
            "ditch_depth": ditch_depth,
        }
        self.start_x = 0.0
        """World x of both platform centres at the start [m]."""
        self._check_geometry(ditch_start_x, ditch_width, ditch_depth)
        for key, rng in self.ditch_ranges.items():
            if rng is not None:
                values = dict(self.ditch_defaults)
                for v in rng:
                    values[key] = v
                    self._check_geometry(**values)
        self.ditch = Ditch(ditch_start_x, ditch_width, ditch_depth)
        """The episode's ditch geometry (public: a controller that knows the ditch, as the
        paper's robot does, plans from it). On flat ground it marks the finish line only."""

        p = self.params
        self.weight_n = p.total_mass * GRAVITY
        self.contact_force = contact_threshold * self.weight_n
        """Normal force above which a foot counts as in contact [N]."""
        self.tip_over_cos = math.cos(math.radians(tip_over_angle_deg))
        self.inradius = p.support_inradius
        low = np.array([p.limb_min] * 3 + [p.extension_range[0]] * 6)
        high = np.array([p.limb_max] * 3 + [p.extension_range[1]] * 6)
        self.command_low, self.command_high = low, high
        self._center = (low + high) / 2
        self._half = (high - low) / 2
        self.action_space = spaces.Box(-1.0, 1.0, shape=(len(COMMAND_NAMES),), dtype=np.float32)
        self._reference_power = self.weight_n * 0.1
        self._inv_dt = 1.0 / control_dt
        self._plans: dict[tuple, GaitPlan] = {}
        self._built_for: tuple | None = None
        self._build(self.ditch)
        self._set_observation_layout(
            {
                "joint_pos": 9,
                "joint_vel": 9,
                "foot_force": 18,
                "foot_contact": 6,
                "fasm_margin_deg": 1,
                "static_margin_m": 1,
                "imu_gyro": 3,
                "imu_accel": 3,
                "imu_quat": 4,
                "reference_action": 9,
                "residual_state": 9,
            }
        )
        self._set_plan(self.ditch)
        # The three IMU pieces are adjacent in the observation and in sensordata: one copy.
        o = self.observation_layout.slices
        self._imu_obs = slice(o["imu_gyro"].start, o["imu_quat"].stop)
        sensors = self.sensors
        self._imu_sensors = slice(sensors._gyro.start, sensors._quat.stop)
        if not (
            sensors._accel.start == sensors._gyro.stop
            and sensors._quat.start == sensors._accel.stop
            and o["imu_accel"].start == o["imu_gyro"].stop
        ):  # pragma: no cover - the model builder adds the IMU sensors in this order
            raise RuntimeError("IMU sensors are expected to be adjacent in sensordata")

    # --- geometry, model, plan -----------------------------------------------------------------
    def _check_geometry(self, ditch_start_x: float, ditch_width: float, ditch_depth: float):
        Ditch(ditch_start_x, ditch_width, ditch_depth)  # finite, width and depth > 0
        # The planner needs every foot a foot radius plus the edge clearance from the ditch.
        band = self.params.foot_radius + self.gait_settings.edge_clearance
        front = self.start_x + self.params.leg_circle_radius
        if ditch_start_x - band < front:
            raise ValueError(
                f"ditch_start_x = {ditch_start_x} m puts the ditch under or right in front of "
                f"the robot: its front feet stand at x = {front} m, so the ditch must start at "
                f"x >= {front + band:.3f} m"
            )

    @property
    def finish_x(self) -> float:
        """x every foot (sphere included) must pass for success: the ditch's far edge [m]."""
        return self.ditch.end_x

    def _geometry_key(self, ditch: Ditch) -> tuple:
        geometry = (ditch.start_x, ditch.width, ditch.depth) if self.terrain == "ditch" else ()
        return (*geometry, self.friction)

    def _build(self, ditch: Ditch) -> None:
        key = self._geometry_key(ditch)
        if key == self._built_for:
            return
        spec = mujoco.MjSpec()
        spec.compiler.degree = False  # MjSpec defaults to degrees; the builders use radians
        spec.modelname = type(self).__name__
        if self.terrain == "ditch":
            add_ditch(spec, ditch.start_x, ditch.width, ditch.depth, friction=self.friction)
        else:
            add_flat(spec, friction=self.friction)
        p = self.params
        self.handles = add_upu(
            spec, p, pos=(self.start_x, 0.0, p.lower_leg_length + 0.001), command="interpolated"
        )
        self._compile(spec)
        self._built_for = key
        m = self.model
        self.sensors = RobotSensors(m, self.data, LEG_NAMES, COMMAND_NAMES)
        self._act = _as_slice(np.array([m.actuator(name).id for name in COMMAND_NAMES]))
        # Servo targets of the interpolated commands (MuJoCo activations).
        self._act_state = _as_slice(m.actuator_actadr[self._act])
        self._foot_body = np.array([m.body(f"{leg}_foot").id for leg in LEG_NAMES])
        self._force_idx = np.array(
            [m.sensor_adr[m.sensor(f"{leg}_foot_force").id] + np.arange(3) for leg in LEG_NAMES]
        )
        self._foot_weight = np.array(
            [0.0, 0.0, p.foot_mass * GRAVITY]
        )  # added to -sensor (see model.py)
        self._leg_qpos = np.array(
            [m.jnt_qposadr[m.joint(self.handles.leg_joint(leg)).id] for leg in LEG_NAMES]
        )
        self._upper_qpos = np.array(
            [m.jnt_qposadr[m.joint(j).id] for j in self.handles.upper_joints]
        )
        self._torso = m.body("torso").id
        self._root_qpos = int(m.jnt_qposadr[m.joint(self.handles.root_joint).id])
        self._touch = np.array(
            [m.sensor_adr[m.sensor(name).id] for name in self.handles.foot_touch_sensors]
        )

    def _plan_for(self, ditch: Ditch) -> GaitPlan:
        key = self._geometry_key(ditch) or ("flat", ditch.end_x)
        if key not in self._plans:
            p, s = self.params, self.gait_settings
            if self.terrain == "ditch":
                plan = plan_ditch_crossing(p, ditch, self.start_x, s)
            else:
                plan = plan_flat_past(p, ditch.end_x, self.start_x, s)
            if len(self._plans) > 256:  # randomised geometry: keep the cache bounded
                self._plans.clear()
            self._plans[key] = plan
        return self._plans[key]

    def _set_plan(self, ditch: Ditch) -> None:
        self.plan = self._plan_for(ditch)
        """The reference gait's plan for the current episode (`GaitPlan`)."""
        self.schedule = GaitSchedule(self.plan, self.params, self.control_dt, self.gait_timing)
        """The reference gait's timed commands (`GaitSchedule`)."""
        self._reference_actions = np.clip(
            (self.schedule.commands - self._center) / self._half, -1.0, 1.0
        )

    @property
    def _ditch_info(self) -> dict | None:
        if self.terrain != "ditch":
            return None
        return {"start_x": self.ditch.start_x, "width": self.ditch.width, "depth": self.ditch.depth}

    def _sample_ditch(self) -> Ditch:
        values = dict(self.ditch_defaults)
        for key in ("ditch_start_x", "ditch_width", "ditch_depth"):
            rng = self.ditch_ranges[key]
            if rng is not None:
                values[key] = float(self.np_random.uniform(rng[0], rng[1]))
        return Ditch(values["ditch_start_x"], values["ditch_width"], values["ditch_depth"])

    # --- task description ----------------------------------------------------------------------
    def _robot_params(self):
        return self.params

    def _joint_limits(self):
        return self.command_low, self.command_high

    def _reference_description(self) -> dict:
        """The reference gait: plan and timed schedule for this episode's ditch, timing and
        planner settings, start and finish x [m], residual gains [m]."""
        return {
            "plan": self.plan,
            "schedule": self.schedule,
            "gait_timing": self.gait_timing,
            "gait_settings": self.gait_settings,
            "start_x": self.start_x,
            "finish_x": self.finish_x,
            "residual_gain": tuple(float(g) for g in self.residual_gain),
        }

    def paper_task(self) -> dict:
        return {
            "terrain": self.terrain,
            "ditch_start_x": float(self.ditch_defaults["ditch_start_x"]),
            "ditch_width": float(self.ditch_defaults["ditch_width"]),
            "ditch_depth": float(self.ditch_defaults["ditch_depth"]),
            "friction": float(self._paper_friction),
        }

    def sample_task(self, rng: np.random.Generator, distribution: str) -> dict:
        r = DITCH_RANGES[distribution]
        return {
            "terrain": self.terrain,
            "ditch_start_x": float(rng.uniform(*r.start_x)),
            "ditch_width": float(rng.uniform(*r.width)),
            "ditch_depth": float(rng.uniform(*r.depth)),
            "friction": float(rng.uniform(*r.friction)),
        }

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed, options=options)
        if self.task_distribution != "paper":
            t = self.task
            self.friction = t["friction"]
            self.ditch = Ditch(t["ditch_start_x"], t["ditch_width"], t["ditch_depth"])
            self._build(self.ditch)
            self._set_plan(self.ditch)
        elif any(r is not None for r in self.ditch_ranges.values()):
            self.ditch = self._sample_ditch()
            self.task.update(
                ditch_start_x=self.ditch.start_x,
                ditch_width=self.ditch.width,
                ditch_depth=self.ditch.depth,
            )
            self._build(self.ditch)
            self._set_plan(self.ditch)
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        # Start in the standing pose with the servo targets at it, so nothing jumps: a limb
        # started a few mm off its target would hit the 400 N force limit and throw the robot.
        stand = standing_command(self.params)
        d.act[self._act_state] = stand
        d.ctrl[self._act] = 0.0
        d.qpos[self._leg_qpos] = stand[3:]
        d.qpos[self._upper_qpos[2]] = walking_height(self.params) - self.params.initial_height
        noise = self.reset_noise_scale
        if noise > 0:  # seed-dependent start: the robot stands a little shifted and turned
            dx, dy = self.np_random.uniform(-noise, noise, 2)
            yaw = self.np_random.uniform(-noise, noise) / self.params.leg_circle_radius
            d.qpos[self._root_qpos : self._root_qpos + 2] += (dx, dy)
            d.qpos[self._root_qpos + 3 : self._root_qpos + 7] = (
                np.cos(yaw / 2),
                0.0,
                0.0,
                np.sin(yaw / 2),
            )
        mujoco.mj_forward(m, d)
        # Settle onto the feet under the standing command (not part of the episode).
        for _ in range(int(round(0.5 / self.control_dt))):
            self._simulate()
        self._residual = np.zeros(len(COMMAND_NAMES))
        self._episode_info = {  # info entries fixed for the episode
            "planner_status": self.plan.status,
            "planner_reason": self.plan.reason,
            "finish_x": self.finish_x,
        }
        self._tick = 0
        self._tipped = False
        self._success = False
        self._prev_cog_x = float(self.sensors.cog()[0])
        self._start_cog_x = self._prev_cog_x
        self._update_stability()
        self._last_obs = self._observation()
        return self._last_obs, self._info({}, unstable=False)

    def reference_command(self, tick: int | None = None) -> np.ndarray:
        """The reference gait's command (`COMMAND_NAMES`, [m]) at control step `tick` (default:
        the current one)."""
        return self.schedule.command(self._tick if tick is None else tick)

    def step(self, action):
        action = self._validate_action(action, self.action_space)
        if self.action_mode == "joint":
            target = self._center + self._half * action
        else:
            r = self._residual
            r += self.residual_filter_alpha * (self.residual_gain * action - r)
            target = self.schedule.command(self._tick) + r
        # Interpolated commands: the servo targets (act) move linearly to `target` during the
        # control period; MuJoCo clamps the rate to the speed limits, the target to the ranges.
        d = self.data
        d.ctrl[self._act] = (target - d.act[self._act_state]) * self._inv_dt
        stable = self._simulate()
        self._tick += 1
        if not stable:
            return self._last_obs.copy(), 0.0, False, True, self._info({}, unstable=True)
        self._update_stability()
        # The penalty is paid once; stepping on after termination keeps `terminated` True.
        tipped = bool(d.xmat[self._torso, 8] < self.tip_over_cos) and not self._tipped
        self._tipped = self._tipped or tipped
        self._success = not self._tipped and self._all_feet_past_finish()
        cog_x = float(d.subtree_com[self._torso, 0])
        terms = self._reward_terms(cog_x, tipped)
        self._prev_cog_x = cog_x
        self._last_obs = self._observation()
        reward = float(sum(terms.values()))
        terminated = self._tipped or self._success
        return self._last_obs, reward, terminated, False, self._info(terms, unstable=False)

    # --- measurements ------------------------------------------------------------------------
    def _update_stability(self) -> None:
        d = self.data
        sd = d.sensordata
        # Every foot site is parallel to its platform and the platforms stay parallel (the
        # mechanism only translates), so one rotation takes all six force readings to the world
        # frame. Ground reaction = -R s + m_foot g (see model.py).
        rot = d.xmat[self._torso].reshape(3, 3)
        forces = self._foot_weight - sd[self._force_idx] @ rot.T
        self._forces = forces
        # The per-leg pressure switch (paper §2): the touch sensor's normal contact force, free
        # of the foot's own inertia that the 3-D force sensor also measures.
        loaded = sd[self._touch] > self.contact_force
        self._loaded = loaded
        soles = d.xpos[self._foot_body]
        cog = d.subtree_com[self._torso]
        self._fasm_deg, _ = fasm_from_feet(soles, forces, cog, loaded)
        self._static_margin = 0.0
        if loaded.sum() >= 3:
            pts = soles[loaded].tolist()
            xs = [q[0] for q in pts]
            ys = [q[1] for q in pts]
            px, py = float(cog[0]), float(cog[1])
            if len(xs) == 3:  # a tripod (most steps): its hull is the triangle, ordered ccw
                area2 = (xs[1] - xs[0]) * (ys[2] - ys[0]) - (ys[1] - ys[0]) * (xs[2] - xs[0])
                if area2 != 0.0:
                    hull = [0, 1, 2] if area2 > 0 else [0, 2, 1]
                    self._static_margin = signed_distance_2d(xs, ys, hull, px, py)
                    return
            try:  # same computation as stability.static_stability_margin, gravity along -z
                hull = hull_2d(xs, ys)
            except ValueError:  # loaded feet on a line: no polygon
                return
            self._static_margin = signed_distance_2d(xs, ys, hull, px, py)

    def _all_feet_past_finish(self) -> bool:
        if not self._loaded.all():
            return False
        rear = self.data.xpos[self._foot_body, 0].min() - self.params.foot_radius
        return bool(rear > self.finish_x)

    def _observation_pieces(self) -> dict[str, np.ndarray]:
        s = self.sensors
        d = self.data
        return {
            "joint_pos": d.actuator_length[self._act],
            "joint_vel": d.actuator_velocity[self._act],
            "foot_force": self._forces.reshape(-1),
            "foot_contact": self._loaded,
            "fasm_margin_deg": self._fasm_deg,
            "static_margin_m": self._static_margin,
            "imu_gyro": s.gyro(),
            "imu_accel": s.accelerometer(),
            "imu_quat": s.orientation(),
            "reference_action": self._reference_actions[
                min(self._tick, len(self._reference_actions) - 1)
            ],
            "residual_state": self._residual_units(),
        }

    def _residual_units(self) -> np.ndarray:
        return self._residual * self._inv_residual_gain

    def _observation(self) -> np.ndarray:
        """`_observation_pieces` written straight into the flat vector (the per-step path)."""
        b, o, d = self._obs_buffer, self.observation_layout.slices, self.data
        b[o["joint_pos"]] = d.actuator_length[self._act]
        b[o["joint_vel"]] = d.actuator_velocity[self._act]
        b[o["foot_force"]] = self._forces.reshape(-1)
        b[o["foot_contact"]] = self._loaded
        b[o["fasm_margin_deg"]] = self._fasm_deg
        b[o["static_margin_m"]] = self._static_margin
        b[self._imu_obs] = d.sensordata[self._imu_sensors]  # gyro, accel, quat
        b[o["reference_action"]] = self._reference_actions[
            min(self._tick, len(self._reference_actions) - 1)
        ]
        b[o["residual_state"]] = self._residual_units()
        if self.sensor_noise:
            self._add_sensor_noise(b)
        return b.copy()

    def step_cost_bound(self) -> float:
        """The largest cost one step can carry (bounded negative parts of progress, stability
        and effort); the ``alive`` term pays it on every step the robot is up."""
        w = self.weights
        return w["progress"] * PROGRESS_CLIP_M_S + w["stability"] + w["effort"] * EFFORT_CAP

    def step_reward_bound(self) -> float:
        """The largest reward one step can earn (alive + the bounded positive terms)."""
        w = self.weights
        return self.step_cost_bound() + w["progress"] * PROGRESS_CLIP_M_S + w["stability"]

    def _reward_terms(self, cog_x: float, tipped: bool) -> dict[str, float]:
        w = self.weights
        speed = (cog_x - self._prev_cog_x) / self.control_dt
        r = self.inradius
        margin = min(max(self._static_margin, -r), r) / r
        d = self.data
        power = float(np.abs(d.actuator_force[self._act] * d.actuator_velocity[self._act]).sum())
        # Crossing ends the episode: the bonus pays what the remaining steps could at most have
        # earned, so that standing still on the near side never returns more than crossing.
        remaining = max(self.horizon_steps - self._tick, 0)
        return {
            "progress": w["progress"] * min(max(speed, -PROGRESS_CLIP_M_S), PROGRESS_CLIP_M_S),
            "stability": w["stability"] * margin,
            "alive": 0.0 if self._tipped else self.step_cost_bound(),
            "success": remaining * self.step_reward_bound() if self._success else 0.0,
            "tip_over": -w["tip_over"] if tipped else 0.0,
            "effort": -w["effort"] * min(power / self._reference_power, EFFORT_CAP),
        }

    def _info(self, terms: dict[str, float], unstable: bool) -> dict:
        step, phase = self.schedule.phase(self._tick)
        cog = self.data.subtree_com[self._torso]
        up_z = min(1.0, max(-1.0, float(self.data.xmat[self._torso, 8])))
        return {
            **{f"reward_{name}": value for name, value in terms.items()},
            "fasm_margin_deg": self._fasm_deg,
            "static_margin_m": self._static_margin,
            "stance_legs": tuple(compress(LEG_NAMES, self._loaded.tolist())),
            "is_tipping": self._static_margin <= 0.0,
            "is_tipped_over": self._tipped,
            "is_success": self._success and not unstable,
            "sim_unstable": unstable,
            "distance": float(cog[0]) - self._start_cog_x,
            "tilt_deg": math.degrees(math.acos(up_z)),
            **self._episode_info,
            "ditch": self._ditch_info,  # a new dict every step (callers may keep infos)
            "gait_step": step,
            "gait_phase": phase,
            "time": self._tick * self.control_dt,
            "cog": cog.copy(),
            "task": dict(self.task),
        }
