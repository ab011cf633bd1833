"""HexapodIrregularTerrain-v0: ATHENA walks a tripod gait across a 10° ramp or a bed of blocks.

Coelho et al. 2024 §5 (Coelho et al.): the 0.7 kg-body hexapod ATHENA walks forward (+x) with the
tripod
gait of eqs. (19)-(23) (t_g = 1 s per phase, control at 20 Hz) over

| terrain | what | robot starts |
|---|---|---|
| ``"ramp"`` | 10° slope along +x (`ramp_slope_deg`), 4.5 m run, flat top | on the slope (1) |
| ``"blocks"`` | test bed: grid of `block_size` blocks 0.04-0.13 m high | on the bed (2) |
| ``"flat"`` | plain ground | on the ground |

(1) body parallel to the slope, `ramp_start_x` = -0.4 m behind the slope's foot; a positive
`ramp_start_x` starts it on the flat approach instead. (2) dropped onto the blocks under its feet.

The block heights are drawn from the episode's ``np_random`` at every reset (one bed per seed);
``block_layout_seed=<int>`` fixes one bed for all episodes.

Task distributions (``task_distribution=``): "paper" (default) is the terrain above; "train" /
"test" draw the slope, the block bed's highest block and block size, friction and servo
stiffness at every reset from `TERRAIN_TRAIN` / `TERRAIN_TEST` (held out: slopes 8.5-11.5 deg,
taller and smaller blocks, lower friction, stiffness farther from nominal). ``info["task"]``
holds the values. ``sensor_noise`` adds Gaussian noise to the observed foot forces and IMU.

Servos and gait. The paper's joints are servos with a 1.89 N·m stall torque. Ours are
proportional position servos with that torque limit, a stiffness ``servo_kp`` and viscous damping
``servo_damping``. The default stiffness, 8 N·m/rad, reaches the stall torque at 0.24 rad (13.5°)
of position error, a hobby servo's proportional band; a stance leg carrying a third to a half of
the robot's weight sags by a few millimetres. The paper's own simple-control results (median torso
height 0.068 m on the ramp against 0.104 m standing) show that its simulated servos sagged too:
because every phase starts from the *measured* feet (eq. 12 on the encoders) the sag accumulates
and the torso slowly sinks unless the height correction k_z δz brings it back. The phase start
uses the measured heights but the commanded horizontal positions (``gait_start_from=
"measured_height"``, see `hexapod_envs.robots.athena.gait.START_FROM`): with measured x, y too
the stance legs' lag makes the footholds wander ~4 mm per cycle until the legs reach their limits.
`reports/athena_gain_sweep.md` shows how the ramp results depend on ``servo_kp`` and this rule.
Landing legs that found no ground are extended until they touch only in phases that use the
ground plane (k_α or k_β > 0; ``gait_ground_search``, see
`hexapod_envs.robots.athena.gait.GROUND_SEARCH`), so that all gains 0 is the paper's
non-adaptive "simple control".

| Observation piece | size | unit |
|---|---|---|
| joint_pos | 18 | encoder angles θ2 (TC), θ3 (CTr), θ4 (FTi) per leg (LF LM LR RF RM RR) [rad] |
| joint_vel | 18 | [rad/s] |
| foot_force | 18 | ground reaction on each foot, world frame [N] (3-D foot force sensors) |
| foot_contact | 6 | 1 when the foot force exceeds ``contact_threshold`` [N] |
| fasm_margin_deg | 1 | FASM from the measured foot forces [deg] (0 without a support polygon) |
| imu_gyro | 3 | torso angular velocity, torso frame: roll rate, pitch rate, yaw rate [rad/s] |
| imu_accel | 3 | accelerometer [m/s²] |
| imu_quat | 4 | torso orientation (w, x, y, z) |
| torso_height | 1 | infrared torso-height reading along the torso's -z [m] (-1: nothing below) |
| gait_phase | 3 | sin, cos of 2π x the gait-cycle phase; 1 if the next step starts a gait cycle |
| posture_gains | 3 | ("gains" mode only) (k_z, k_α, k_β) in effect this cycle |

Action modes (``action_mode=``):

- ``"residual"`` (default): 18 values in [-1, 1] added, times ``residual_scale`` x each joint's
  half range, to the joint targets of the reference gait that the env runs internally: the
  Coelho et al. 2024 tripod gait with posture control, gains ``reference_gains`` (default (0, 0,
  0), the
  paper's "simple control"). A zero action walks the reference gait.
- ``"joint"``: 18 joint targets, each normalised to [-1, 1] over its range; no internal gait
  (the gait phase then comes from a fixed clock of 2 t_g per cycle).
- ``"gains"``: 3 values (k_z, k_α, k_β) in [0, 1], the posture-control gains of eqs. (27)-(31),
  which the paper names as its future work for learning. The env runs the posture controller
  internally at every 20 Hz step; **the action is applied only at the start of a gait cycle**
  (the action passed to `step` when the current observation's ``gait_phase[2]`` is 1) and held
  for the cycle's two phases; the actions of the other steps are ignored. Gains start at
  ``reference_gains``.

| Reward term (info key) | meaning |
|---|---|
| reward_forward | forward_weight x torso CoG speed along +x, clipped to ±0.1 m/s [m/s] |
| reward_steadiness_rate | -rate_weight x min(pitch rate² + roll rate², 4) [rad²/s²] (IMU gyro) |
| reward_steadiness_height | -height_weight x (min(|torso height - standing|, 0.1 m) / 0.01 m)² |
| reward_torso_collision | -collision_penalty when the torso touched the terrain during the step |
| reward_alive | the largest cost of a step (the bounds above), paid while the robot is up |
| reward_tip_over | -tip_over_penalty on the step the robot tips over (episode ends) |

Every term is bounded and the alive term makes an upright step's reward >= 0, so an episode that
ends by tipping over returns less than staying up, however unsteadily the robot walks.

`info` keys: the reward terms; ``fasm_margin_deg``, ``fasm_edge``, ``stance_legs`` (feet in
contact), ``is_tipping`` (FASM below ``tipping_threshold_deg``), ``is_tipped_over`` (torso up axis
more than ``tip_over_angle_deg`` from vertical), ``is_success`` (no tip-over, no torso contact so
far, simulation stable, and at least `MIN_PROGRESS` of the gait's nominal distance walked:
stride / phase_time x time), ``sim_unstable``, ``time``, ``cog``, ``distance`` (CoG x travelled);
``zmp`` and ``zmp_margin`` (eqs. 32-33 in the torso frame from the feet's vertical forces,
`hexapod_envs.stability.zmp_margin`, m), ``torso_contact`` (this step), ``torso_collisions``
(steps with torso contact so far), ``torso_height`` (sensor, m), ``torso_clearance`` (true
distance torso bottom - terrain below the torso centre, privileged, m), ``pitch_rate``,
``roll_rate``, ``posture_gains``, ``gait_cycle`` (index of the current cycle); and
``cycle_stats``: on the first step of every new gait cycle a dict of per-cycle statistics of the
cycle just finished (``index``, ``steps``, ``height_rms``, ``pitch_rate_rms``, ``roll_rate_rms``,
``zmp_margin_mean``, ``zmp_margin_min``, ``torso_contact``, ``distance``, ``x_start``, ``x_end``,
``gains``), otherwise None. The seed's box plots are made from these. ``actuator_power_w``
(sum of |torque x joint speed|, W) and ``episode_metrics`` (at reset and whenever a cycle
finishes: the lists so far of this episode's per-cycle height, pitch-rate and roll-rate RMS and
mean ZMP margin) feed the evaluation pipeline (`evaluation_metrics`).
"""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
from gymnasium import spaces

from ..checks import check_number
from ..robots.athena.gait import AthenaPostureController, AthenaSensors
from ..robots.athena.kinematics import standing_foot_positions
from ..robots.athena.model import add_athena
from ..robots.athena.params import ATHENA, LEG_NAMES
from ..stability import fasm_from_feet
from ..stability.zmp import zmp_margin
from ..terrain.flat import add_flat
from ..terrain.irregular import PAPER_FRICTION, add_blocks, add_ramp
from .base import HexapodEnv, JointActionMap, check_choice
from .sensors import RobotSensors

TERRAINS = ("ramp", "blocks", "flat")
ACTION_MODES = ("residual", "joint", "gains")
DEFAULT_SWING_HEIGHT = {"ramp": 0.16, "flat": 0.16, "blocks": 0.32}
"""h of eqs. (20)-(21) per terrain [m]; the swing apex is h/4 (4 cm, and 8 cm to clear the
blocks' steps of up to 9 cm from one block to the next). The paper gives no value."""

RAMP_TOP_LENGTH = 2.0
"""Flat top after the slope [m], long enough that a 1200-step episode ends on it."""


@dataclasses.dataclass(frozen=True)
class TerrainTaskRanges:
    """Ranges of one task distribution (uniform draws; a tuple of ranges: one chosen at random).

    Held-out test ranges (`TERRAIN_TEST`): slopes interleaved with training (8.5-11.5 deg, which
    holds the paper's 10 deg, against 5-8.5 and 11.5-15), taller blocks and smaller blocks than
    in training (extrapolated), lower friction, servo stiffness farther from nominal.
    """

    slope_deg: tuple[tuple[float, float], ...]
    block_height_max: tuple[float, float]
    """Highest block [m] (blocks are drawn 0.04 m up to it)."""
    block_size: tuple[float, float]
    """Block edge length [m] (square blocks)."""
    friction: tuple[float, float]
    servo_kp_scale: tuple[tuple[float, float], ...]
    """Servo stiffness as a multiple of `servo_kp`."""


TERRAIN_TRAIN = TerrainTaskRanges(
    slope_deg=((5.0, 8.5), (11.5, 15.0)),
    block_height_max=(0.08, 0.12),
    block_size=(0.10, 0.14),
    friction=(0.7, 1.1),
    servo_kp_scale=((0.85, 1.15),),
)
TERRAIN_TEST = TerrainTaskRanges(
    slope_deg=((8.5, 11.5),),
    block_height_max=(0.12, 0.15),
    block_size=(0.08, 0.10),
    friction=(0.5, 0.7),
    servo_kp_scale=((0.7, 0.85), (1.15, 1.3)),
)
TERRAIN_RANGES = {"train": TERRAIN_TRAIN, "test": TERRAIN_TEST}


def _uniform_in(rng: np.random.Generator, ranges: tuple[tuple[float, float], ...]) -> float:
    low, high = ranges[int(rng.integers(len(ranges)))]
    return float(rng.uniform(low, high))


SPEED_CLIP_M_S = 0.1
"""Bound of the forward term's speed [m/s] (the reference gait walks about 0.06 m/s)."""
RATE_CAP = 4.0
"""Bound of the steadiness term's pitch² + roll² rate [rad²/s²] (random actions reach 20)."""
MIN_PROGRESS = 0.5
"""Share of the gait's nominal distance (stride / phase_time x time) a successful episode walks
(the heavy-duty envs' ``min_progress``); the reference gait walks 0.7-1.0 of it."""
HEIGHT_CLIP_M = 0.1
"""Bound of the steadiness term's torso-height deviation [m]."""

_CONTACT_CHECKS = 5
"""Torso-terrain contact is looked for this many times per control period (every 10 ms)."""


class IrregularTerrainEnv(HexapodEnv):
    """ATHENA on a ramp, a block test bed or flat ground; see the module docstring."""

    evaluation_metrics = {
        "torso_collisions": {
            "reduce": "last",
            "better": "lower",
            "description": "control steps with torso-terrain contact",
        },
        "zmp_margin": {
            "reduce": "mean",
            "better": "higher",
            "description": "ZMP stability margin, eqs. 32-33 [m]",
        },
        "torso_clearance": {
            "reduce": "min",
            "better": "higher",
            "description": "smallest true torso clearance [m]",
        },
        "cycle_height_rms": {
            "reduce": "episode",
            "description": "per-gait-cycle RMS torso height [m] (Coelho et al. 2024 Figs. 10-17)",
        },
        "cycle_pitch_rate_rms": {
            "reduce": "episode",
            "better": "lower",
            "description": "per-gait-cycle RMS pitch rate [rad/s]",
        },
        "cycle_roll_rate_rms": {
            "reduce": "episode",
            "better": "lower",
            "description": "per-gait-cycle RMS roll rate [rad/s]",
        },
        "cycle_zmp_margin": {
            "reduce": "episode",
            "better": "higher",
            "description": "per-gait-cycle mean ZMP margin [m]",
        },
    }
    """What the evaluation pipeline reduces over an episode (see agents/pipeline/episode.py)."""

    def __init__(
        self,
        *,
        terrain: str = "ramp",
        action_mode: str = "residual",
        residual_scale: float = 0.25,
        reference_gains: tuple[float, float, float] = (0.0, 0.0, 0.0),
        stride: float = 0.06,
        swing_height: float | None = None,
        phase_time: float = 1.0,
        gait_start_from: str = "measured_height",
        gait_ground_search: str = "auto",
        control_dt: float = 0.05,
        physics_dt: float = 0.002,
        servo_kp: float = 8.0,
        servo_damping: float = 0.2,
        friction: float = PAPER_FRICTION,
        ramp_slope_deg: float = 10.0,
        ramp_start_x: float = -0.4,
        ramp_length: float = 4.5,
        block_height_range: tuple[float, float] = (0.04, 0.13),
        block_size: tuple[float, float] = (0.1, 0.1),
        block_region: tuple[tuple[float, float], tuple[float, float]] = (
            (-0.4, 3.0),
            (-0.5, 0.5),
        ),
        block_layout_seed: int | None = None,
        contact_threshold: float = 0.5,
        forward_weight: float = 10.0,
        rate_weight: float = 0.5,
        height_weight: float = 0.02,
        collision_penalty: float = 1.0,
        tip_over_penalty: float = 50.0,
        tipping_threshold_deg: float = 10.0,
        tip_over_angle_deg: float = 60.0,
        reset_noise_scale: float = 0.01,
        settle_time: float = 0.5,
        render_mode: str | None = None,
        width: int = 640,
        height: int = 480,
        camera_name: str | None = None,
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
        if self.n_substeps % _CONTACT_CHECKS:
            raise ValueError(
                f"control_dt / physics_dt = {self.n_substeps} substeps must be a multiple of "
                f"{_CONTACT_CHECKS} (torso contact is checked {_CONTACT_CHECKS} times per step)"
            )
        for label, value in (("servo_kp", servo_kp), ("servo_damping", servo_damping)):
            check_number(label, value, strict=True)
        if terrain == "ramp" and -0.3 < ramp_start_x < 0.3:
            raise ValueError(
                f"ramp_start_x={ramp_start_x} m puts the foot of the slope under the robot; use "
                "<= -0.3 (start on the slope) or >= 0.3 (start on the flat approach)"
            )
        if block_layout_seed is not None and not isinstance(block_layout_seed, int):
            raise ValueError(f"block_layout_seed must be an int or None, got {block_layout_seed!r}")
        self.terrain = terrain
        self.action_mode = action_mode
        self.residual_scale = float(residual_scale)
        self.robot = dataclasses.replace(ATHENA, servo_kp=servo_kp, servo_damping=servo_damping)
        self.gait_config = {
            "stride": float(stride),
            "swing_height": float(
                DEFAULT_SWING_HEIGHT[terrain] if swing_height is None else swing_height
            ),
            "phase_time": float(phase_time),
            "control_dt": float(control_dt),
            "contact_threshold": float(contact_threshold),
            "start_from": gait_start_from,
            "ground_search": gait_ground_search,
        }
        """Keyword arguments of `AthenaPostureController` that match this env (policies use it)."""
        self.reference_gains = tuple(float(g) for g in reference_gains)
        # Validates the gait numbers (and the gains) with clear errors before anything is built.
        self.controller = AthenaPostureController(
            self.robot, **self.gait_config, **_gain_kwargs(self.reference_gains)
        )
        self.ticks_per_cycle = self.controller.ticks_per_cycle
        self.friction = float(friction)
        self.ramp = {
            "slope_deg": float(ramp_slope_deg),
            "start_x": float(ramp_start_x),
            "length": float(ramp_length),
        }
        self.blocks = {
            "height_range": tuple(block_height_range),
            "block_size": tuple(block_size),
            "region": tuple(tuple(r) for r in block_region),
        }
        self.block_layout_seed = block_layout_seed
        self.contact_threshold = float(contact_threshold)
        self.weights = {
            "forward": forward_weight,
            "steadiness_rate": rate_weight,
            "steadiness_height": height_weight,
            "torso_collision": collision_penalty,
            "tip_over": tip_over_penalty,
        }
        self.tipping_threshold_deg = float(tipping_threshold_deg)
        self.stability_criterion = f"FASM >= {self.tipping_threshold_deg:g} deg"
        self.tip_over_cos = float(np.cos(np.radians(tip_over_angle_deg)))
        self.reset_noise_scale = float(reset_noise_scale)
        self.settle_time = float(settle_time)
        self.reference_height = self.robot.standing_torso_height

        self.action_map = JointActionMap(np.tile(self.robot.joint_ranges, (6, 1)))
        self._residual_gain = self.residual_scale * self.action_map.half
        if action_mode == "gains":
            self.action_space = spaces.Box(0.0, 1.0, shape=(3,), dtype=np.float32)
        else:
            self.action_space = spaces.Box(-1.0, 1.0, shape=(18,), dtype=np.float32)
        self._contact_force_sq = self.contact_threshold**2
        self._paper = {
            "slope_deg": self.ramp["slope_deg"],
            "block_height_max": float(self.blocks["height_range"][1]),
            "block_size": float(self.blocks["block_size"][0]),
            "friction": self.friction,
            "servo_kp": float(servo_kp),
        }
        self._built_task = self.paper_task()
        self._build(np.random.default_rng(block_layout_seed or 0))
        self._set_observation_layout(
            {
                "joint_pos": 18,
                "joint_vel": 18,
                "foot_force": 18,
                "foot_contact": 6,
                "fasm_margin_deg": 1,
                "imu_gyro": 3,
                "imu_accel": 3,
                "imu_quat": 4,
                "torso_height": 1,
                "gait_phase": 3,
                **({"posture_gains": 3} if action_mode == "gains" else {}),
            }
        )

    # --- model ---------------------------------------------------------------------------
    def _build(self, terrain_rng: np.random.Generator) -> None:
        """Build and compile terrain + robot (blocks drawn from `terrain_rng`)."""
        spec = mujoco.MjSpec()
        spec.compiler.degree = False  # MjSpec defaults to degrees; our builders give radians
        spec.modelname = "HexapodIrregularTerrain"
        pos, quat = self._add_terrain(spec, terrain_rng)
        self.handles = add_athena(spec, pos=pos, quat=quat, params=self.robot)
        self._compile(spec)
        m = self.model
        actuators = tuple(a for leg in self.handles.actuators for a in leg)
        self.sensors = RobotSensors(m, self.data, LEG_NAMES, actuators)
        self._act_ids = np.array([m.actuator(a).id for a in actuators])
        self._joint_qpos = np.array([m.jnt_qposadr[m.actuator_trnid[i, 0]] for i in self._act_ids])
        self._root_qpos = m.jnt_qposadr[m.joint(self.handles.root_joint).id]
        adr = m.sensor(self.handles.torso_height_sensor).adr[0]
        self._height_adr = int(adr)
        self._torso_contact_adr = int(m.sensor(self.handles.torso_contact_sensor).adr[0])
        self._torso_half_height = self.robot.body.size[2] / 2

    def _add_terrain(self, spec: mujoco.MjSpec, rng: np.random.Generator):
        """Add the terrain; return the robot's start pose (torso position, quaternion)."""
        standing = self.robot.standing_torso_height + 0.002
        if self.terrain == "flat":
            add_flat(spec, friction=self.friction)
            self.terrain_info = None
            return (0.0, 0.0, standing), (1.0, 0.0, 0.0, 0.0)
        if self.terrain == "ramp":
            r = self.ramp
            self.terrain_info = add_ramp(
                spec,
                slope_deg=r["slope_deg"],
                start_x=r["start_x"],
                length=r["length"],
                top_length=RAMP_TOP_LENGTH,
                friction=self.friction,
            )
            if r["start_x"] > 0:  # on the flat approach
                return (0.0, 0.0, standing), (1.0, 0.0, 0.0, 0.0)
            slope = math.radians(r["slope_deg"])
            surface = -r["start_x"] * math.tan(slope)
            # Torso parallel to the slope, the standing height above it along its normal.
            pos = (-math.sin(slope) * standing, 0.0, surface + math.cos(slope) * standing)
            return pos, (math.cos(-slope / 2), 0.0, math.sin(-slope / 2), 0.0)
        b = self.blocks
        self.terrain_info = add_blocks(
            spec,
            rng,
            height_range=b["height_range"],
            block_size=b["block_size"],
            region=b["region"],
            friction=self.friction,
        )
        # Drop the robot from just above the highest block under its feet.
        feet = standing_foot_positions(self.robot)
        top = float(np.max(self.terrain_info.surface_height(feet[:, 0], feet[:, 1])))
        return (0.0, 0.0, top + standing + 0.003), (1.0, 0.0, 0.0, 0.0)

    # --- reset / step --------------------------------------------------------------------
    def _reference_description(self) -> dict:
        """The reference gait: `AthenaPostureController` settings, gains, ticks per cycle,
        residual scale and the ramp geometry."""
        return {
            "gait_config": dict(self.gait_config),
            "reference_gains": self.reference_gains,
            "ticks_per_cycle": self.ticks_per_cycle,
            "residual_scale": self.residual_scale,
            "ramp": dict(self.ramp),
        }

    # --- task distribution -----------------------------------------------------------------
    def paper_task(self) -> dict:
        return {
            "terrain": self.terrain,
            "slope_deg": self._paper["slope_deg"],
            "block_height_max": self._paper["block_height_max"],
            "block_size": self._paper["block_size"],
            "friction": self._paper["friction"],
            "servo_kp": self._paper["servo_kp"],
        }

    def sample_task(self, rng: np.random.Generator, distribution: str) -> dict:
        r = TERRAIN_RANGES[distribution]
        return {
            "terrain": self.terrain,
            "slope_deg": _uniform_in(rng, r.slope_deg),
            "block_height_max": float(rng.uniform(*r.block_height_max)),
            "block_size": float(rng.uniform(*r.block_size)),
            "friction": float(rng.uniform(*r.friction)),
            "servo_kp": self._paper["servo_kp"] * _uniform_in(rng, r.servo_kp_scale),
        }

    def _apply_task(self, task: dict) -> bool:
        """Set the terrain and servo parameters of `task`; True if the model must be rebuilt."""
        if task == self._built_task:
            return False
        self._built_task = dict(task)
        self.ramp["slope_deg"] = task["slope_deg"]
        low = self.blocks["height_range"][0]
        self.blocks["height_range"] = (low, max(low, task["block_height_max"]))
        self.blocks["block_size"] = (task["block_size"], task["block_size"])
        self.friction = task["friction"]
        self.robot = dataclasses.replace(self.robot, servo_kp=task["servo_kp"])
        return True

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed, options=options)
        rebuild = self._apply_task(self.task)
        if self.terrain == "blocks" and self.block_layout_seed is None:
            self._build(self.np_random)  # a new test bed per episode, from the episode's seed
        elif rebuild:
            self._build(np.random.default_rng(self.block_layout_seed or 0))
        mujoco.mj_resetData(self.model, self.data)
        standing = np.tile(self.robot.standing_posture, 6)
        noise = self.reset_noise_scale * self.action_map.half
        joints = standing + self.np_random.uniform(-noise, noise)
        low, high = self.action_map.low, self.action_map.high
        self.data.qpos[self._joint_qpos] = np.clip(joints, low, high)
        self.data.ctrl[self._act_ids] = standing
        mujoco.mj_forward(self.model, self.data)
        for _ in range(round(self.settle_time / self.control_dt)):  # not part of the episode
            self._physics()
        self.controller.reset()
        self.controller.set_gains(*self.reference_gains)
        self._step_count = 0
        self._tipped = False
        self._collisions = 0
        self._touched = False
        self._start_cog = self.sensors.cog().copy()
        self._prev_cog_x = float(self._start_cog[0])
        self._cycle_id = 0
        self._window: list[tuple] = []
        self._window_x0 = float(self._start_cog[0])
        self._episode_metrics = {
            "cycle_height_rms": [],
            "cycle_pitch_rate_rms": [],
            "cycle_roll_rate_rms": [],
            "cycle_zmp_margin": [],
        }
        self._read_sensors()
        self._last_obs = self._observation()
        return self._last_obs, self._info({}, unstable=False, cycle_stats=None)

    def step(self, action):
        action = self._validate_action(action, self.action_space)
        ctrl = self._ctrl_from_action(action)
        self.data.ctrl[self._act_ids] = ctrl
        stable, touched = self._physics()
        self._step_count += 1
        if not stable:
            return self._last_obs.copy(), 0.0, False, True, self._info({}, True, None)
        self._touched = touched
        self._collisions += touched
        self._read_sensors()
        # The penalty is paid once; stepping on after termination keeps `terminated` True.
        tipped = bool(self.data.xmat[self.sensors.torso_id, 8] < self.tip_over_cos)
        tipped = tipped and not self._tipped
        self._tipped = self._tipped or tipped
        terms = self._reward_terms(touched, tipped)
        cycle_stats = self._update_cycle_window(touched)
        self._prev_cog_x = float(self._cog[0])
        self._last_obs = self._observation()
        reward = float(sum(terms.values()))
        return self._last_obs, reward, self._tipped, False, self._info(terms, False, cycle_stats)

    def _ctrl_from_action(self, action: np.ndarray) -> np.ndarray:
        if self.action_mode == "joint":
            return self.action_map.to_joints(action)
        if self.action_mode == "gains" and self.controller.at_cycle_start:
            self.controller.set_gains(*action.tolist())
        targets = self.controller.step(self._controller_sensors()).reshape(-1)
        if self.action_mode == "residual":
            targets = targets + self._residual_gain * action
        return targets

    def _controller_sensors(self) -> AthenaSensors:
        return AthenaSensors(
            joint_angles=self._joints.reshape(6, 3),
            foot_forces=self._forces,
            torso_height=self._height,
        )

    def _physics(self) -> tuple[bool, bool]:
        """One control period of physics: (stable, torso touched the terrain)."""
        m, d = self.model, self.data
        t_expected = d.time + self.control_dt
        chunk = self.n_substeps // _CONTACT_CHECKS
        touched = False
        for _ in range(_CONTACT_CHECKS):
            mujoco.mj_step(m, d, nstep=chunk)
            touched = touched or d.sensordata[self._torso_contact_adr] > 0.0
        if abs(d.time - t_expected) > 1e-6:
            return False, bool(touched)
        return not d.warning.number[self._UNSTABLE_WARNINGS].any(), bool(touched)

    # --- measurements --------------------------------------------------------------------
    def _read_sensors(self) -> None:
        s = self.sensors
        self._joints = s.joint_positions()  # fancy indexing: already a copy
        self._forces = s.foot_forces()
        self._loaded = (self._forces * self._forces).sum(axis=1) > self._contact_force_sq
        self._height = float(self.data.sensordata[self._height_adr])
        self._gyro = s.gyro().copy()
        self._cog = s.cog().copy()
        feet_world = s.foot_positions()
        self._fasm_deg, self._fasm_edge = fasm_from_feet(
            feet_world, self._forces, self._cog, self._loaded
        )
        # Eqs. (32)-(33) in the torso frame (the paper's relative foot coordinates), weighted by
        # the vertical component of each foot's ground reaction.
        feet_torso = (feet_world - s.torso_position()) @ s.torso_rotation()
        normal = np.where(self._loaded, np.maximum(self._forces[:, 2], 0.0), 0.0)
        total = float(normal.sum())
        if total > 0:
            self._zmp = (normal @ feet_torso[:, :2]) / total
            self._zmp_margin = zmp_margin(feet_torso, normal)
        else:
            self._zmp, self._zmp_margin = np.full(2, np.nan), 0.0

    def _height_deviation(self) -> float:
        """Torso-height reading minus the standing reference, m (0 without a reading)."""
        return self._height - self.reference_height if self._height >= 0 else 0.0

    def torso_clearance(self) -> float:
        """True distance (m) from the torso box's bottom to the terrain below the torso centre
        (privileged: uses the terrain model and the true pose; for evaluation only)."""
        x, y, z = self.sensors.torso_position().tolist()
        ground = 0.0 if self.terrain_info is None else self.terrain_info.height_at(x, y)
        bottom = z - self._torso_half_height * float(self.data.xmat[self.sensors.torso_id, 8])
        return float(bottom - ground)

    # --- gait clock and per-cycle statistics ----------------------------------------------
    def _gait_cycle_index(self) -> int:
        """Index of the gait cycle the last step belonged to."""
        if self.action_mode == "joint":
            return max(0, self._step_count - 1) // self.ticks_per_cycle
        return max(0, self.controller.phase_index) // 2

    def _gait_phase(self) -> tuple[float, float, float]:
        if self.action_mode == "joint":
            k = self._step_count % self.ticks_per_cycle
            phase, start = k / self.ticks_per_cycle, k == 0
        else:
            phase, start = self.controller.cycle_phase, self.controller.at_cycle_start
        angle = 2 * math.pi * phase
        return math.sin(angle), math.cos(angle), float(start)

    def _update_cycle_window(self, touched: bool) -> dict | None:
        """Add this step to its cycle's window; on a new cycle return the finished one's stats."""
        cid = self._gait_cycle_index()
        stats = None
        if cid != self._cycle_id and self._window:
            stats = self._cycle_stats(self._cycle_id, self._window)
            m = self._episode_metrics
            m["cycle_height_rms"].append(stats["height_rms"])
            m["cycle_pitch_rate_rms"].append(stats["pitch_rate_rms"])
            m["cycle_roll_rate_rms"].append(stats["roll_rate_rms"])
            m["cycle_zmp_margin"].append(stats["zmp_margin_mean"])
            self._window = []
            self._window_x0 = self._prev_cog_x
        self._cycle_id = cid
        self._window.append(
            (
                self._height,
                float(self._gyro[1]),
                float(self._gyro[0]),
                self._zmp_margin,
                touched,
                float(self._cog[0]),
                self.controller.gains if self.action_mode != "joint" else None,
            )
        )
        return stats

    def _cycle_stats(self, index: int, window: list[tuple]) -> dict:
        h, pitch, roll, margin, touched, x, gains = zip(*window, strict=True)
        h, pitch, roll, margin = (np.asarray(v, dtype=float) for v in (h, pitch, roll, margin))
        return {
            "index": index,
            "steps": len(window),
            "height_rms": float(np.sqrt(np.mean(h * h))),
            "pitch_rate_rms": float(np.sqrt(np.mean(pitch * pitch))),
            "roll_rate_rms": float(np.sqrt(np.mean(roll * roll))),
            "zmp_margin_mean": float(margin.mean()),
            "zmp_margin_min": float(margin.min()),
            "torso_contact": bool(any(touched)),
            "distance": float(x[-1] - self._window_x0),
            "x_start": self._window_x0,
            "x_end": float(x[-1]),
            "gains": gains[0],
        }

    # --- observation, reward, info --------------------------------------------------------
    def _observation_pieces(self) -> dict[str, np.ndarray]:
        pieces = {
            "joint_pos": self._joints,
            "joint_vel": self.sensors.joint_velocities(),
            "foot_force": self._forces.reshape(-1),
            "foot_contact": self._loaded,
            "fasm_margin_deg": self._fasm_deg,
            "imu_gyro": self._gyro,
            "imu_accel": self.sensors.accelerometer(),
            "imu_quat": self.sensors.orientation(),
            "torso_height": self._height,
            "gait_phase": self._gait_phase(),
        }
        if self.action_mode == "gains":
            pieces["posture_gains"] = self.controller.gains
        return pieces

    def step_cost_bound(self) -> float:
        """The largest cost one step can carry (the bounded negative parts of every term but
        tip_over); the ``alive`` term pays it on every step the robot is up."""
        w = self.weights
        height = (HEIGHT_CLIP_M / 0.01) ** 2
        return (
            w["forward"] * SPEED_CLIP_M_S
            + w["steadiness_rate"] * RATE_CAP
            + w["steadiness_height"] * height
            + w["torso_collision"]
        )

    def _reward_terms(self, touched: bool, tipped: bool) -> dict[str, float]:
        w = self.weights
        speed = (self._cog[0] - self._prev_cog_x) / self.control_dt
        rates = float(self._gyro[0] ** 2 + self._gyro[1] ** 2)
        dz = min(abs(self._height_deviation()), HEIGHT_CLIP_M) / 0.01
        return {
            "forward": w["forward"] * min(max(speed, -SPEED_CLIP_M_S), SPEED_CLIP_M_S),
            "steadiness_rate": -w["steadiness_rate"] * min(rates, RATE_CAP),
            "steadiness_height": -w["steadiness_height"] * dz * dz,
            "torso_collision": -w["torso_collision"] if touched else 0.0,
            "alive": 0.0 if self._tipped else self.step_cost_bound(),
            "tip_over": -w["tip_over"] if tipped else 0.0,
        }

    def _made_progress(self) -> bool:
        """At least `MIN_PROGRESS` of the distance the gait's nominal speed (stride per phase)
        covers in the elapsed time: standing still or walking backwards is not a success."""
        speed = self.gait_config["stride"] / self.gait_config["phase_time"]
        walked = float(self._cog[0] - self._start_cog[0])
        return walked >= MIN_PROGRESS * speed * self._step_count * self.control_dt

    def _info(self, terms: dict[str, float], unstable: bool, cycle_stats: dict | None) -> dict:
        stance = tuple(leg for leg, on in zip(LEG_NAMES, self._loaded, strict=True) if on)
        edge = None
        if self._fasm_edge is not None:
            edge = (LEG_NAMES[self._fasm_edge[0]], LEG_NAMES[self._fasm_edge[1]])
        info = {f"reward_{name}": value for name, value in terms.items()}
        info.update(
            fasm_margin_deg=self._fasm_deg,
            fasm_edge=edge,
            stance_legs=stance,
            is_tipping=self._fasm_deg < self.tipping_threshold_deg,
            is_tipped_over=self._tipped,
            is_success=not self._tipped
            and not unstable
            and self._collisions == 0
            and self._made_progress(),
            sim_unstable=unstable,
            actuator_power_w=float(
                np.abs(self.sensors.actuator_forces() * self.sensors.joint_velocities()).sum()
            ),
            time=self._step_count * self.control_dt,
            cog=self._cog,  # a fresh copy every step
            distance=float(self._cog[0] - self._start_cog[0]),
            zmp=self._zmp.copy(),
            zmp_margin=self._zmp_margin,
            torso_contact=self._touched,
            torso_collisions=self._collisions,
            torso_height=self._height,
            torso_clearance=self.torso_clearance(),
            pitch_rate=float(self._gyro[1]),
            roll_rate=float(self._gyro[0]),
            posture_gains=self.controller.gains if self.action_mode != "joint" else None,
            gait_cycle=self._gait_cycle_index(),
            cycle_stats=cycle_stats,
            task=dict(self.task),
        )
        if cycle_stats is not None or self._step_count == 0:
            # A fresh copy whenever the lists change (and at reset): infos must not share data.
            info["episode_metrics"] = {k: list(v) for k, v in self._episode_metrics.items()}
        return info


def _gain_kwargs(gains: tuple[float, ...]) -> dict[str, float]:
    if len(gains) != 3:
        raise ValueError(f"gains must be (k_z, k_alpha, k_beta), got {gains!r}")
    return {"kz": gains[0], "k_alpha": gains[1], "k_beta": gains[2]}
