"""HexapodDitchCrossing-v0 / -v1: the 3-UPU parallel-mechanism hexapod walks across a ditch.

## Description
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

## Starting State
The robot stands on its six legs in the standing pose, shifted and turned by up to
``reset_noise_scale``. Task distributions (``task_distribution=``): "paper" (default) is the
ditch above (or the ``ditch_*_range`` draws); "train" / "test" draw the ditch's start, width,
depth and the ground friction at every reset from the ``train_ranges`` / ``test_ranges``
settings (defaults `DITCH_TRAIN` / `DITCH_TEST`; held out: wider, deeper, farther, lower
friction). ``info["task"]`` holds the values and their ``difficulty``; the stability criterion
is a positive static margin (`tipping_threshold_deg` = 0 on the FASM).

## Observation Space

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

## Action Space
9 values in [-1, 1], in the order of joint_pos. ``action_mode="joint"``: each is a
target normalised over its range (limb length over [l_min, l_max] = [0.365, 0.465] m, leg
extension over [-leg_retract, leg_extend] = [-0.08, 0.16] m). ``"residual"`` (default): an
offset from the reference gait's targets of up to residual_limb_m (limbs) and residual_leg_m
(legs), low-pass filtered with time constant residual_filter_tau (observation piece
residual_state); the zero action walks (and crosses) with the reference gait. The defaults
(2 mm, 5 mm, 0.5 s) are small because the paper's gait is fragile: at the full stride the
CoG passes 15 mm from a support edge at 0.4 m height, the nearly vertical limbs turn 1 mm of
length into ~10 mm of platform travel, and 1 mm of leg-length difference tilts the body by
0.2 degrees; uniformly random actions with these defaults still cross in most episodes.

``stride_action=True`` (residual mode, ``reference_plan="flat"``) adds a 10th value: the stride
of each platform step, read on the step's first control step (observation piece
``stride_decision``), the full 160 mm for a >= 0 and (1 + a) x 160 mm below, at least 5 mm and
within the room the other platform leaves (`hexapod_envs.robots.upu.online_gait`). The
reference gait is then built online, one step at a time, and its legs land at the ground under
each foot (the ditch's depth over the ditch), as the paper's planner's do. Two observation
pieces follow the others: ``ditch_ahead`` (5: the near and far edge x relative to the upper,
then the lower platform centre where the decided steps leave them [m], then the depth [m]; on
flat ground both edges at the finish line and depth 0) and ``stride_decision`` (2: 1 if the
upper platform moves next; 1 if the next action's stride value decides that step). The zero
action walks full strides; on flat ground that is the flat reference, bit for bit, to the end
of the flat reference's plan (which then stands, where the online gait walks on). A ditch
deeper than a leg's reach (0.16 m) gets the leg's full extension. ``action_read_flags`` names
the stride value and its flag, for learners that score a value only where it is read
(`agents.read_actions`).

Control runs at 10 Hz (control_dt = 0.1 s, physics 2 ms); the servo drives interpolate: each
target is approached linearly over the control period, at most 0.25 m/s for a limb and 1 m/s
for a leg (`model.add_upu`, ``command="interpolated"``), as the stiff limb servos would
otherwise jerk the feet into slipping on every step of the command.

The reference gait (`hexapod_envs.robots.upu.gait_schedule.GaitTiming`) takes 5.1 s per
platform step: unload 0.4, lift 0.8, hold 0.2, transfer 2.5, hold 0.3, land 0.6, hold 0.3.
Crossing the default ditch takes 20 steps, 102 s (1017 control steps); the time limit is 1500.

## Rewards

| Reward term (info key) | meaning |
|---|---|
| reward_forward | forward_weight x CoG speed along x, clipped to ±0.1 m/s [m/s] |
| reward_stability | stability_weight x clip(static_margin_m / 0.1 m, -1, 1) (0.1 m = rho/2) |
| reward_alive | the largest cost of a step (bounds of forward, stability, effort), while up |
| reward_success | on crossing: (horizon_steps - steps taken) x the largest reward of a step |
| reward_tip_over | -tip_over_penalty on the step the robot tips over (episode ends) |
| reward_effort | -effort_weight x min(sum of |actuator power| / (robot weight x 0.1 m/s), 10) |
| reward_foothold | -foothold_weight x sum over the feet landing now of max(1 - gap / band, 0) |
| reward_landing | -landing_weight x sum over the moving feet of clip(1 - clear / band, 0, 1) |

The foothold term's gap is a landing foot's centre's x distance to the nearer ditch edge, band
the foot radius plus the planner's edge clearance (the clear-stride rule's margin); a foot
lands on every step its contact switch turns on, so a foot that rocks on an edge (or a stance
foot whose load flickers there) pays again. The landing term (``stride_action`` only) charges
the stride a step decides, on the step it is decided: clear is each moving foot's planned
landing x's clearance from the edges (`gait_plan.edge_clearance`: the distance to the nearer
edge, negative over a ditch too deep to stand in), where the nominal gait puts it; the planner
and the clear-stride rule want clear >= band. Both are off by default and, like the success and
tip-over terms, not in the alive term's bound.

Every term is bounded. With the foothold and landing terms off (the default), an episode that
ends by tipping over returns less than staying up, and one that stands still on the near side
until the time limit returns less than crossing.

## Episode End
The episode ends (terminated) when the robot tips over (body tilt > tip_over_angle_deg) or
succeeds: every foot past the far edge of the ditch (the finish line on flat ground), all six
feet loaded, not tipped. `info`: the reward terms, fasm_margin_deg, static_margin_m,
stance_legs, is_tipping (static_margin_m <= 0: the CoG projection is not inside the loaded
feet's polygon), min_static_margin_m (the smallest static_margin_m since reset [m]: how close
the crossing came to tipping), is_tipped_over, is_success, sim_unstable, distance (CoG advance
[m]), tilt_deg, planner_status, planner_reason, ditch (start_x, width, depth [m]; None on flat
ground), finish_x [m], gait_step and gait_phase (the reference's plan step and phase), time, cog.

## Arguments
`DitchCrossingSettings` (``gym.make(id, **kwargs)``).

## Version History
- v1: the reference gait is the flat-ground one (``reference_plan="flat"``: the zero action
  walks into the ditch blind); the residual reaches 50 mm on the limbs and 160 mm on the legs so
  that a policy can adapt the steps; termination at a 10° tilt; a crossing is a success only
  with the tilt within 2° and at most 2 % of the episode at a static margin <= 0; test ditches
  up to 0.55 m wide (docs/benchmark.md).
- v0: the papers' reproduction.
"""

from __future__ import annotations

import dataclasses
import warnings

import mujoco
import numpy as np
from gymnasium import spaces

from ..robots.upu._compiled import upu_measure
from ..robots.upu.gait_plan import (
    Ditch,
    GaitPlan,
    GaitSettings,
    PlatformStep,
    edge_clearance,
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
from ..robots.upu.online_gait import OnlineGait
from ..robots.upu.params import LEG_NAMES, PLATFORM_LEGS, UpuParams
from ..stability import _compiled as _stability
from ..terrain.ditch import add_ditch
from ..terrain.flat import add_flat
from .base import HexapodEnv, Measurement
from .difficulty import DifficultySpan
from .sensors import RobotSensors
from .settings import (
    EnvSettings,
    RewardScales,
    TaskRanges,
    bounded,
    choice,
    number,
    numbers,
    option,
)

TERRAINS = ("ditch", "flat")
ACTION_MODES = ("joint", "residual")
STRIDE_ACTION = len(COMMAND_NAMES)
"""With `stride_action`: the index of the stride value, after the nine `COMMAND_NAMES`."""
GRAVITY = 9.81


@dataclasses.dataclass(frozen=True)
class DitchTaskRanges(TaskRanges):
    """Ranges of one task distribution (uniform draws) [m], friction coefficient.

    Held-out test ranges (`DITCH_TEST`) extrapolate beyond training: wider ditches (0.40-0.50
    m against 0.25-0.40), deeper (0.12-0.15 m against 0.06-0.12; the planner refuses depths
    above ~0.16 m), farther ahead, lower friction.
    """

    start_x: tuple[float, float] = bounded(None)
    width: tuple[float, float] = bounded(strict=True)
    depth: tuple[float, float] = bounded(strict=True)
    friction: tuple[float, float] = bounded(strict=True)  # the ditch's geoms need > 0


DITCH_TRAIN = DitchTaskRanges(
    start_x=(0.6, 0.9), width=(0.25, 0.40), depth=(0.06, 0.12), friction=(0.8, 1.2)
)
DITCH_TEST = DitchTaskRanges(
    start_x=(0.9, 1.1), width=(0.40, 0.50), depth=(0.12, 0.15), friction=(0.5, 0.8)
)


def _as_slice(index: np.ndarray):
    """A contiguous ascending index array as a slice (a view instead of a copy), else as is."""
    index = np.asarray(index)
    if index.size and np.array_equal(index, np.arange(index[0], index[0] + index.size)):
        return slice(int(index[0]), int(index[0]) + index.size)
    return index


FORWARD_CLIP_M_S = 0.1
"""Bound of the forward term's CoG speed [m/s] (the reference gait peaks near 0.065 m/s)."""
EFFORT_CAP = 10.0
"""Bound of the effort term's power ratio [-] (the reference gait peaks near 5.5)."""


@dataclasses.dataclass(frozen=True)
class DitchCrossingRewardScales(RewardScales):
    """Weights of HexapodDitchCrossing-v0's reward terms (see the module docstring)."""

    forward_weight: float = number(20.0)
    stability_weight: float = number(0.05)
    tip_over_penalty: float = number(100.0)
    effort_weight: float = number(0.02)
    foothold_weight: float = number(0.0)
    """Per foot that lands near a ditch edge (term ``foothold``); 0 in v0 and v1, whose
    returns it leaves as they are. A shaping term for learners of the stride action: it pays
    on the step a foot lands, where a tip-over at the edge may come only strides later."""
    landing_weight: float = number(0.0)
    """Per moving foot whose planned landing is near a ditch edge (term ``landing``, with
    ``stride_action``); 0 in v0 and v1. A shaping term for learners of the stride action: it
    charges a stride on the step that decides it, from the nominal gait (no contact noise)."""


REFERENCE_PLANS = ("course", "flat")
"""``reference_plan`` values: the plan for the episode's ditch, or the flat-ground gait."""


@dataclasses.dataclass(frozen=True)
class DitchCrossingSettings(EnvSettings):
    """Settings of HexapodDitchCrossing-v0 (SI units; see the module docstring)."""

    reward_class = DitchCrossingRewardScales
    control_dt: float = number(0.1, strict=True)
    physics_dt: float = number(0.002, strict=True)
    """MuJoCo timestep [s]. The reference gait crosses the paper's ditch at every step from
    2.5 down to 0.8 ms (4 ms tips early) and tips at 0.667 ms and finer
    (experiments/physics_settings): its 14 mm margin while the lower platform lifts is held by
    this step's numerical damping of the servos."""
    contact_threshold: float = number(0.005, strict=True, high=1.0)
    """A foot's pressure switch reads loaded above this fraction of the weight."""
    tipping_threshold_deg: float = number(0.0, high=90.0)
    """The paper judges this robot by its static margin (observation ``static_margin_m``), not
    by a FASM threshold; 0 deg only marks a net force outside the support polygon."""
    reset_noise_scale: float = number(0.005)
    """The robot starts shifted by up to this along x and y, and turned so that its feet move
    up to this much [m]."""
    camera_name: str | None = option("track", kind=str)
    terrain: str = choice("ditch", TERRAINS)
    ditch_start_x: float = number(0.6, low=None)
    """x of the ditch's near edge [m]."""
    ditch_width: float = number(0.35, strict=True)
    ditch_depth: float = number(0.14, strict=True)
    ditch_start_x_range: tuple[float, float] | None = numbers(
        None, size=2, low=None, ordered=True, optional=True
    )
    """(low, high) [m]: with the "paper" task, the start is drawn from it at every reset."""
    ditch_width_range: tuple[float, float] | None = numbers(
        None, size=2, ordered=True, optional=True
    )
    ditch_depth_range: tuple[float, float] | None = numbers(
        None, size=2, ordered=True, optional=True
    )
    reference_plan: str = choice("course", REFERENCE_PLANS)
    """The reference gait (the residual's base, the zero action's motion, the observation's
    ``reference_action``): "course" plans for the episode's ditch (-v0: the zero action crosses
    like the paper's planner), "flat" is the flat-ground gait to the same finish line, blind to
    the ditch (-v1: crossing needs the ditch sensed and the steps adapted)."""
    action_mode: str = choice("residual", ACTION_MODES)
    stride_action: bool = choice(False, (False, True))
    """Residual mode with the flat reference plan: a 10th action value sets the stride of each
    platform step as it begins (`OnlineGait.stride_for`: the full stride for a >= 0, shortened
    in proportion below), the legs land at the ground under each foot, and the observation
    gains ``ditch_ahead`` and ``stride_decision`` (see the module docstring)."""
    residual_limb_m: float = number(0.002)
    """Residual action 1 on a limb [m]."""
    residual_leg_m: float = number(0.005)
    """Residual action 1 on a leg [m]."""
    residual_filter_tau: float = number(0.5)
    """Time constant of the residual's first-order filter [s] (0: no filter)."""
    horizon_steps: int = number(1500, strict=True, integer=True)
    """The episode's step budget (the registered time limit) whose remaining steps the
    success bonus pays for; set it to the time limit when ``max_episode_steps`` raises that
    (the env warns when an episode runs past it)."""
    friction: float = number(1.0, strict=True)
    gait_timing: GaitTiming | None = option(None, kind=GaitTiming)
    gait_settings: GaitSettings | None = option(None, kind=GaitSettings)
    params: UpuParams | None = option(None, kind=UpuParams)
    train_ranges: DitchTaskRanges = option(DITCH_TRAIN, kind=DitchTaskRanges, optional=False)
    test_ranges: DitchTaskRanges = option(DITCH_TEST, kind=DitchTaskRanges, optional=False)


class DitchCrossingEnv(HexapodEnv):
    """The 3-UPU hexapod crossing a ditch (or walking on flat ground); see the module docstring
    and `DitchCrossingSettings`.

    Public attributes for controllers that know the course (as the paper's robot knows the
    ditch): ``ditch`` (the episode's `Ditch`), ``terrain``, ``start_x``, ``params``,
    ``finish_x``, ``command_low`` / ``command_high`` (actuator ranges), ``plan`` and
    ``schedule`` (the reference gait), ``gait_settings``, ``gait_timing``.
    """

    Settings = DitchCrossingSettings
    ends_on_success = True
    difficulty_spans = {
        "ditch_width": DifficultySpan(easy=0.25, hard=0.55),
        "ditch_depth": DifficultySpan(easy=0.06, hard=0.15),
        "friction": DifficultySpan(easy=1.2, hard=0.5),
    }
    """What makes a ditch hard: wide (shorter steps, the legs reach farther), deep (the legs
    extend further into it), slippery ground."""
    stability_criterion = "static margin > 0 mm (CoG projection inside the support triangle)"

    def _setup(self) -> None:
        s = self.settings
        self.terrain = s.terrain
        self.action_mode = s.action_mode
        self.residual_gain = np.array([s.residual_limb_m] * 3 + [s.residual_leg_m] * 6)
        """Residual per unit action [m] (limbs, then legs)."""
        self.residual_filter_alpha = self.control_dt / (s.residual_filter_tau + self.control_dt)
        """Weight of a new residual action in the first-order filter (1: no filter)."""
        gain = self.residual_gain
        self._inv_residual_gain = np.divide(1.0, gain, out=np.zeros(9), where=gain > 0)
        self.params = s.params or UpuParams()
        self.gait_timing = s.gait_timing or GaitTiming()
        self.gait_settings = s.gait_settings or GaitSettings()
        self.friction = s.friction
        r = s.reward
        self.weights = {
            "forward": r.forward_weight,
            "stability": r.stability_weight,
            "tip_over": r.tip_over_penalty,
            "effort": r.effort_weight,
            "foothold": r.foothold_weight,
            "landing": r.landing_weight,
        }
        self.horizon_steps = int(s.horizon_steps)
        self.task_ranges = {"train": s.train_ranges, "test": s.test_ranges}
        self.ditch_ranges = {
            "ditch_start_x": s.ditch_start_x_range,
            "ditch_width": s.ditch_width_range,
            "ditch_depth": s.ditch_depth_range,
        }
        self.ditch_defaults = {
            "ditch_start_x": s.ditch_start_x,
            "ditch_width": s.ditch_width,
            "ditch_depth": s.ditch_depth,
        }
        self.start_x = 0.0
        """World x of both platform centres at the start [m]."""
        self._check_geometry(s.ditch_start_x, s.ditch_width, s.ditch_depth)
        for key, rng in self.ditch_ranges.items():
            if rng is not None:
                values = dict(self.ditch_defaults)
                for v in rng:
                    values[key] = v
                    self._check_geometry(**values)
        for name, r in (("train_ranges", s.train_ranges), ("test_ranges", s.test_ranges)):
            try:  # the nearest ditch a task distribution can draw
                self._check_geometry(r.start_x[0], r.width[0], r.depth[0])
            except ValueError as err:
                raise ValueError(f"{name}.start_x: {err}") from None
        self.ditch = Ditch(s.ditch_start_x, s.ditch_width, s.ditch_depth)
        """The episode's ditch geometry (public: a controller that knows the ditch, as the
        paper's robot does, plans from it). On flat ground it marks the finish line only."""

        p = self.params
        self.weight_n = p.total_mass * GRAVITY
        self.contact_force = s.contact_threshold * self.weight_n
        """Normal force above which a foot counts as in contact [N]."""
        self.inradius = p.support_inradius
        low = np.array([p.limb_min] * 3 + [p.extension_range[0]] * 6)
        high = np.array([p.limb_max] * 3 + [p.extension_range[1]] * 6)
        self.command_low, self.command_high = low, high
        self._center = (low + high) / 2
        self._half = (high - low) / 2
        if s.stride_action and (s.action_mode != "residual" or s.reference_plan != "flat"):
            raise ValueError(
                "stride_action=True builds the reference gait online, one platform step at a "
                "time from the full-stride flat gait, under the residual action; it needs "
                f"action_mode='residual' and reference_plan='flat', got {s.action_mode!r} and "
                f"{s.reference_plan!r}"
            )
        self.stride_action = s.stride_action
        n_actions = len(COMMAND_NAMES) + (1 if s.stride_action else 0)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(n_actions,), dtype=np.float32)
        self._reference_power = self.weight_n * 0.1
        self._inv_dt = 1.0 / self.control_dt
        self._plans: dict[tuple, GaitPlan] = {}
        self._built_for: tuple | None = None
        self._build(self.ditch)
        self._set_plan(self.ditch)

    # --- geometry, model, plan -----------------------------------------------------------------
    def _check_geometry(self, ditch_start_x: float, ditch_width: float, ditch_depth: float):
        Ditch(ditch_start_x, ditch_width, ditch_depth)  # finite, width and depth > 0
        band = self.edge_band  # the planner needs every foot this far from the ditch
        front = self.start_x + self.params.leg_circle_radius
        if ditch_start_x - band < front:
            raise ValueError(
                f"ditch_start_x = {ditch_start_x} m puts the ditch under or right in front of "
                f"the robot: its front feet stand at x = {front} m, so the ditch must start at "
                f"x >= {front + band:.3f} m"
            )

    @property
    def edge_band(self) -> float:
        """How far from a ditch edge a foot's centre must land [m]: the foot radius plus the
        planner's edge clearance (the planner's, the clear-stride rule's and the foothold
        term's margin)."""
        return self.params.foot_radius + self.gait_settings.edge_clearance

    @property
    def finish_x(self) -> float:
        """x every foot (sphere included) must pass for success: the ditch's far edge [m]."""
        return self.ditch.end_x

    def _geometry_key(self, ditch: Ditch) -> tuple:
        geometry = (ditch.start_x, ditch.width, ditch.depth) if self.terrain == "ditch" else ()
        return (*geometry, self.friction)

    def _build(self, ditch: Ditch) -> None:
        """Build the model for `ditch` unless the current one already has its geometry."""
        key = self._geometry_key(ditch)
        if key == self._built_for:
            return
        self._build_ditch = ditch
        self._build_model()
        self._built_for = key

    def _build_spec(self, spec: mujoco.MjSpec) -> None:
        ditch = self._build_ditch
        if self.terrain == "ditch":
            add_ditch(spec, ditch.start_x, ditch.width, ditch.depth, friction=self.friction)
        else:
            add_flat(spec, friction=self.friction)
        p = self.params
        self.handles = add_upu(
            spec, p, pos=(self.start_x, 0.0, p.lower_leg_length + 0.001), command="interpolated"
        )

    def _bind_model(self) -> None:
        m = self.model
        self.sensors = RobotSensors(m, self.data, LEG_NAMES, COMMAND_NAMES)
        self._act = _as_slice(np.array([m.actuator(name).id for name in COMMAND_NAMES]))
        # Servo targets of the interpolated commands (MuJoCo activations).
        self._act_state = _as_slice(m.actuator_actadr[self._act])
        self._foot_body = np.array([m.body(f"{leg}_foot").id for leg in LEG_NAMES])
        self._force_idx = np.array(
            [m.sensor_adr[m.sensor(f"{leg}_foot_force").id] + np.arange(3) for leg in LEG_NAMES]
        )
        # Added to -sensor (see model.py): the foot's own weight.
        self._foot_weight = np.array([0.0, 0.0, self.params.foot_mass * GRAVITY])
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
        """The reference plan of `ditch` (cached by what it depends on: the ditch's geometry, or
        on flat ground the finish line `end_x`; not the friction)."""
        on_ditch = self.terrain == "ditch" and self.settings.reference_plan == "course"
        key = (ditch.start_x, ditch.width, ditch.depth) if on_ditch else ("flat", ditch.end_x)
        if key not in self._plans:
            p, s = self.params, self.gait_settings
            if on_ditch:
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
        planner settings, start and finish x [m], residual gains [m] and filter weight."""
        return {
            "plan": self.plan,
            "schedule": self.schedule,
            "gait_timing": self.gait_timing,
            "gait_settings": self.gait_settings,
            "start_x": self.start_x,
            "finish_x": self.finish_x,
            "residual_gain": tuple(float(g) for g in self.residual_gain),
            "residual_filter_alpha": float(self.residual_filter_alpha),
            "stride_action": self.stride_action,
        }

    def paper_task(self) -> dict:
        return {
            "terrain": self.terrain,
            "ditch_start_x": float(self.ditch_defaults["ditch_start_x"]),
            "ditch_width": float(self.ditch_defaults["ditch_width"]),
            "ditch_depth": float(self.ditch_defaults["ditch_depth"]),
            "friction": float(self.settings.friction),
        }

    def sample_task(self, rng: np.random.Generator, distribution: str) -> dict:
        r = self.task_ranges[distribution]
        return {
            "terrain": self.terrain,
            "ditch_start_x": float(rng.uniform(*r.start_x)),
            "ditch_width": float(rng.uniform(*r.width)),
            "ditch_depth": float(rng.uniform(*r.depth)),
            "friction": float(rng.uniform(*r.friction)),
        }

    def _apply_task(self, task: dict) -> None:
        if self.task_distribution != "paper":
            self.friction = task["friction"]
            self.ditch = Ditch(task["ditch_start_x"], task["ditch_width"], task["ditch_depth"])
        elif any(r is not None for r in self.ditch_ranges.values()):
            self.ditch = self._sample_ditch()
            task.update(
                ditch_start_x=self.ditch.start_x,
                ditch_width=self.ditch.width,
                ditch_depth=self.ditch.depth,
            )
        else:
            return
        self._build(self.ditch)
        self._set_plan(self.ditch)

    def _set_initial_state(self) -> None:
        # Start in the standing pose with the servo targets at it, so nothing jumps: a limb
        # started a few mm off its target would hit the 400 N force limit and throw the robot.
        d = self.data
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

    def _start_episode(self) -> None:
        self._residual = np.zeros(len(COMMAND_NAMES))
        self._was_loaded = np.ones(len(LEG_NAMES), dtype=bool)
        """With a ``foothold`` weight: each foot's contact switch on the previous step (the
        settled robot stands on all six); a foot loaded now and not then has landed."""
        self._min_static_margin = np.inf
        self._landing_cost = 0.0
        """With `stride_action`: the landing term's count for the stride decided this step."""
        if self.stride_action:
            ditch = self.ditch if self.terrain == "ditch" else None
            self.online_gait = OnlineGait(self.params, self.gait_settings, self.start_x, ditch)
            """With `stride_action`: the online gait's state and the steps decided so far."""
            self._set_online_schedule()
        self._episode_info = {  # info entries fixed for the episode
            "planner_status": self.plan.status,
            "planner_reason": self.plan.reason,
            "finish_x": self.finish_x,
        }

    def _set_online_schedule(self) -> None:
        """With `stride_action`: the reference gait is the decided steps and, pending, the
        full-stride step from where they end. The pending step's first phases (unload, lift,
        unloaded) do not depend on its stride, so its rows before the transfer are exact; its
        first row is the control step whose action decides the stride (`_decide_at`)."""
        gait = self.online_gait
        pending = gait.next_step(gait.stride_for(0.0))
        self.plan = gait.plan(pending)
        self.schedule = GaitSchedule(self.plan, self.params, self.control_dt, self.gait_timing)
        self._reference_actions = np.clip(
            (self.schedule.commands - self._center) / self._half, -1.0, 1.0
        )
        self._decide_at = self.schedule.n_ticks - sum(self.schedule.phase_ticks)
        """The control step whose action sets the pending step's stride."""

    def reference_command(self, tick: int | None = None) -> np.ndarray:
        """The reference gait's command (`COMMAND_NAMES`, [m]) at control step `tick` (default:
        the current one)."""
        return self.schedule.command(self._step_count if tick is None else tick)

    def _apply_action(self, action: np.ndarray) -> None:
        self._landing_cost = 0.0  # an unstable step never paid the last decision's
        if self.stride_due:
            step = self.online_gait.advance(self.online_gait.stride_for(action[STRIDE_ACTION]))
            if self.weights["landing"]:
                self._landing_cost = self._planned_landing_near_edges(step)
            self._set_online_schedule()
        if self.action_mode == "joint":
            target = self._center + self._half * action
        else:
            r = self._residual
            r += self.residual_filter_alpha * (self.residual_gain * action[:9] - r)
            target = self.schedule.command(self._step_count) + r
        # Interpolated commands: the servo targets (act) move linearly to `target` during the
        # control period; MuJoCo clamps the rate to the speed limits, the target to the ranges.
        d = self.data
        d.ctrl[self._act] = (target - d.act[self._act_state]) * self._inv_dt

    # --- measurements ------------------------------------------------------------------------
    def _measure(self) -> Measurement:
        d = self.data
        act = self._act
        # One compiled call (hexapod_envs.robots.upu._compiled.upu_measure). Every foot site is
        # parallel to its platform and the platforms stay parallel (the mechanism only
        # translates), so one rotation takes all six force readings to the world frame: ground
        # reaction = -R s + m_foot g (see model.py). The contacts are the per-leg pressure
        # switch (paper §2): the touch sensor's normal contact force, free of the foot's own
        # inertia that the 3-D force sensor also measures.
        forces, loaded, cog, status, margin, i, j, static, power = upu_measure(
            d.sensordata,
            self._force_idx,
            d.xmat[self._torso],
            self._foot_weight,
            self._touch,
            self.contact_force,
            d.xpos,
            self._foot_body,
            d.subtree_com[self._torso],
            d.actuator_force[act],
            d.actuator_velocity[act],
        )
        if status == _stability.NOT_FINITE:
            raise ValueError("foot forces, feet or CoG contain NaN or infinite values")
        self._power = power
        # Same computation as stability.static_stability_margin, gravity along -z.
        self._static_margin = static
        self._min_static_margin = min(self._min_static_margin, static)
        return Measurement(forces, loaded, margin, (i, j) if status == _stability.OK else None, cog)

    def _is_success(self) -> bool:
        """Every foot past the far edge of the ditch (the finish line), all six loaded."""
        if not self._loaded.all():
            return False
        rear = self.data.xpos[self._foot_body, 0].min() - self.params.foot_radius
        return bool(rear > self.finish_x)

    def _is_tipping(self) -> bool:
        """The paper's criterion: the CoG projection is not inside the loaded feet's polygon."""
        return self._static_margin <= 0.0

    def _observation_pieces(self) -> dict:
        # Readers look the data up at call time: a task may rebuild the model (and its data).
        pieces = {
            "joint_pos": (9, lambda: self.data.actuator_length[self._act]),
            "joint_vel": (9, lambda: self.data.actuator_velocity[self._act]),
            "foot_force": (18, lambda: self._forces.reshape(-1)),
            "foot_contact": (6, lambda: self._loaded),
            "fasm_margin_deg": (1, lambda: self._fasm_deg),
            "static_margin_m": (1, lambda: self._static_margin),
            "imu_gyro": (3, lambda: self.sensors.gyro()),
            "imu_accel": (3, lambda: self.sensors.accelerometer()),
            "imu_quat": (4, lambda: self.sensors.orientation()),
            "reference_action": (9, self._reference_action),
            "residual_state": (9, lambda: self._residual * self._inv_residual_gain),
        }
        if self.stride_action:
            pieces["ditch_ahead"] = (5, self._ditch_ahead)
            pieces["stride_decision"] = (2, self._stride_decision)
        return pieces

    def _ditch_ahead(self) -> np.ndarray:
        """With `stride_action`: the ditch's near and far edges relative to the upper, then
        the lower platform centre where the decided steps leave them [m], and its depth [m]
        (on flat ground both edges at the finish line, depth 0)."""
        g, d = self.online_gait, self.ditch
        if self.terrain == "ditch":
            near, far, depth = d.start_x, d.end_x, d.depth
        else:
            near = far = self.finish_x
            depth = 0.0
        return np.array(
            [near - g.x_upper, far - g.x_upper, near - g.x_lower, far - g.x_lower, depth]
        )

    @property
    def action_read_flags(self) -> dict[int, int]:
        """With `stride_action`: the stride value (action 9) is read when ``stride_decision``'s
        second value is 1, on a platform step's first control step."""
        if not self.stride_action:
            return {}
        return {STRIDE_ACTION: self.observation_layout.slices["stride_decision"].start + 1}

    @property
    def inert_actions(self) -> tuple[int, ...]:
        """In residual mode, the residuals whose range is 0 (``residual_limb_m`` or
        ``residual_leg_m`` = 0): their filter state decays to 0 whatever they are."""
        if self.action_mode != "residual":
            return ()
        return tuple(int(i) for i in np.flatnonzero(self.residual_gain == 0.0))

    @property
    def stride_due(self) -> bool:
        """True when the next `step` reads its stride value (action 9): with `stride_action`,
        on each platform step's first control step. `hexapod_envs.wrappers.GainsPerCycle`
        makes one env step of each platform step with it (when the residuals are off)."""
        return self.stride_action and self._step_count == self._decide_at

    def _stride_decision(self) -> np.ndarray:
        """With `stride_action`: (1 if the upper platform moves next, 1 if the next action's
        stride value decides that step)."""
        return np.array([float(self.online_gait.moving == "upper"), float(self.stride_due)])

    def _reference_action(self) -> np.ndarray:
        """The reference gait's command now, normalised like a "joint" action."""
        ref = self._reference_actions
        return ref[min(self._step_count, len(ref) - 1)]

    def step_cost_bound(self) -> float:
        """The largest cost one step can carry (bounded negative parts of forward, stability
        and effort); the ``alive`` term pays it on every step the robot is up."""
        w = self.weights
        return w["forward"] * FORWARD_CLIP_M_S + w["stability"] + w["effort"] * EFFORT_CAP

    def step_reward_bound(self) -> float:
        """The largest reward one step can earn (alive + the bounded positive terms)."""
        w = self.weights
        return self.step_cost_bound() + w["forward"] * FORWARD_CLIP_M_S + w["stability"]

    def _reward_terms(self, tipped: bool) -> dict[str, float]:
        w = self.weights
        speed = (float(self._cog[0]) - self._prev_cog_x) / self.control_dt
        r = self.inradius
        margin = min(max(self._static_margin, -r), r) / r
        # Crossing ends the episode: the bonus pays what the remaining steps could at most have
        # earned, so that standing still on the near side never returns more than crossing.
        remaining = max(self.horizon_steps - self._step_count, 0)
        if self._step_count == self.horizon_steps + 1:
            warnings.warn(
                f"{type(self).__name__}: the episode ran past horizon_steps="
                f"{self.horizon_steps}, the step budget whose remaining steps the success bonus "
                "pays for; a crossing now earns no bonus. Set horizon_steps to the time limit "
                "(max_episode_steps) when you raise it.",
                stacklevel=2,
            )
        return {
            "forward": w["forward"] * min(max(speed, -FORWARD_CLIP_M_S), FORWARD_CLIP_M_S),
            "stability": w["stability"] * margin,
            "alive": 0.0 if self._tipped else self.step_cost_bound(),
            "success": remaining * self.step_reward_bound() if self._new_success else 0.0,
            "tip_over": -w["tip_over"] if tipped else 0.0,
            "effort": -w["effort"] * min(self._power / self._reference_power, EFFORT_CAP),
            "foothold": -w["foothold"] * self._landing_near_edges() if w["foothold"] else 0.0,
            "landing": -w["landing"] * self._take_landing_cost() if w["landing"] else 0.0,
        }

    def _planned_landing_near_edges(self, step: PlatformStep) -> float:
        """The moving feet of `step` (just decided), each counted by how far inside `edge_band`
        its planned landing's clearance is: 0 at the band or beyond, 1 on an edge or over a
        ditch too deep to stand in, linear between (0 on flat ground)."""
        if self.terrain != "ditch":
            return 0.0
        p, d = self.params, self.ditch
        feet = step.end_x + np.array([p.foot_offset(leg)[0] for leg in PLATFORM_LEGS[step.moving]])
        clear = edge_clearance(feet, d.start_x, d.end_x, self.edge_band, d.depth <= p.leg_extend)
        return float(np.clip(1.0 - clear / self.edge_band, 0.0, 1.0).sum())

    def _take_landing_cost(self) -> float:
        """The landing term's count of this step's decision, once."""
        cost, self._landing_cost = self._landing_cost, 0.0
        return cost

    def _landing_near_edges(self) -> float:
        """The feet that landed this step, each counted by how far inside `edge_band` of the
        nearer ditch edge its centre is: 1 on the edge, 0 at the band or beyond, linear between
        (0 on flat ground)."""
        landed = self._loaded & ~self._was_loaded
        self._was_loaded = self._loaded.copy()
        if self.terrain != "ditch" or not landed.any():
            return 0.0
        x = self.data.xpos[self._foot_body[landed], 0]
        gap = np.minimum(np.abs(x - self.ditch.start_x), np.abs(x - self.ditch.end_x))
        return float(np.clip(1.0 - gap / self.edge_band, 0.0, None).sum())

    def _extra_info(self, unstable: bool) -> dict:
        step, phase = self.schedule.phase(self._step_count)
        return {
            "static_margin_m": self._static_margin,
            "min_static_margin_m": self._min_static_margin,
            "actuator_power_w": self._power,
            **self._episode_info,
            "ditch": self._ditch_info,  # a new dict every step (callers may keep infos)
            "gait_step": step,
            "gait_phase": phase,
        }
