"""HexapodIrregularTerrain-v0 / -v1: ATHENA walks a tripod gait across a ramp or a bed of blocks.

## Description
Coelho et al. 2024 §5: the 0.7 kg-body hexapod ATHENA walks forward (+x) with the tripod gait
of eqs. (19)-(23) (t_g = 1 s per phase, control at 20 Hz) over

| terrain | what | robot starts |
|---|---|---|
| ``"ramp"`` | 10° slope along +x (`ramp_slope_deg`), 4.5 m run, flat top | on the slope (1) |
| ``"blocks"`` | test bed: grid of `block_size` blocks 0.04-0.13 m high | on the bed (2) |
| ``"flat"`` | plain ground | on the ground |

(1) body parallel to the slope, `ramp_start_x` = -0.4 m behind the slope's foot; a positive
`ramp_start_x` starts it on the flat approach instead. (2) dropped onto the blocks under its feet.

Servos and gait. The paper's joints are servos with a 1.89 N·m stall torque. Ours are
proportional position servos with that torque limit, a stiffness ``servo_kp`` and viscous damping
``servo_damping``. The default stiffness, 6.8 N·m/rad, reaches the stall torque at 0.28 rad (15.9°)
of position error, a hobby servo's proportional band; a stance leg carrying a third to a half of
the robot's weight sags by a few millimetres. The paper's own simple-control results (median torso
height 0.068 m on the ramp against 0.104 m standing) show that its simulated servos sagged too
(6.8 N·m/rad is calibrated to that sag: 0.0681 m over seeds 0-3 at the 2 ms step of the
calibration, 0.0676 m at the 2.5 ms default; 8 N·m/rad gives 0.089 m): because every phase
starts from the *measured* feet (eq. 12 on the encoders) the sag accumulates and the torso
slowly sinks unless the height correction k_z δz brings it back. The phase start uses the
measured heights but the commanded horizontal positions (``gait_start_from=
"measured_height"``, see `hexapod_envs.robots.athena.gait.START_FROM`): with measured x, y too
the stance legs' lag makes the footholds wander ~4 mm per cycle until the legs reach their limits.
`reports/athena_gain_sweep.md` shows how the ramp results depend on ``servo_kp`` and this rule.
Landing legs that found no ground are extended until they touch only in phases that use the
ground plane (k_α or k_β > 0; ``gait_ground_search``, see
`hexapod_envs.robots.athena.gait.GROUND_SEARCH`), so that all gains 0 is the paper's
non-adaptive "simple control".

## Observation Space

| Observation piece | size | unit |
|---|---|---|
| joint_pos | 18 | encoder angles θ2 (TC), θ3 (CTr), θ4 (FTi) per leg (LF LM LR RF RM RR) [rad] |
| joint_vel | 18 | [rad/s] |
| foot_force | 18 | ground reaction on each foot, world frame [N] (3-D foot force sensors) |
| foot_contact | 6 | 1 when the foot force exceeds ``contact_threshold`` x weight (0.5 N) |
| fasm_margin_deg | 1 | FASM from the measured foot forces [deg] (0 without a support polygon) |
| imu_gyro | 3 | torso angular velocity, torso frame: roll rate, pitch rate, yaw rate [rad/s] |
| imu_accel | 3 | accelerometer [m/s²] |
| imu_quat | 4 | torso orientation (w, x, y, z) |
| torso_height | 1 | infrared torso-height reading along the torso's -z [m] (-1: nothing below) |
| gait_phase | 3 | sin, cos of 2π x the gait-cycle phase; 1 if the next step starts a gait cycle |
| posture_gains | 3 | ("gains" mode only) (k_z, k_α, k_β) in effect this cycle |
| height_offset | 1 | (``gains_height_offset_m`` > 0) the height reference's offset this cycle [m] |
| terrain_scan | 15 | (``terrain_scan=True``) torso height above the terrain at 5 x 3 points [m] |
| foot_scan | 108 | (``foot_scan=True``) each foot's height above the terrain at 6 x 3 points [m] |

``terrain_scan=True`` adds what the robot's sensors cannot give: the true terrain around and
ahead of the torso, at `SCAN_X` (0.15 m behind to 0.25 m ahead along the torso's heading) x
`SCAN_Y` (the feet's lateral span) - the privileged height samples that legged-robot RL
commonly feeds a policy on rough ground (for a learner or a teacher policy; the paper's robot
has no such sensor). ``foot_scan=True`` samples the terrain around each foot instead, finely
enough to place it relative to a block's edge: per leg (LF LM LR RF RM RR) the height of the
foot sphere's centre above the terrain at `FOOT_SCAN_X` (3 cm behind to 12 cm ahead, where the
next steps land) x `FOOT_SCAN_Y`, 3 cm apart - the per-foot height samples of perceptive legged
locomotion.

## Action Space
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
  (the action passed to `step` when the current observation's ``gait_phase[2]`` turns 1; while
  the gait waits there for its stance feet to touch, the flag stays 1 and those actions are
  ignored too; `gains_due` tells) and held for the cycle's two phases; the actions of the other
  steps are ignored. Gains start at ``reference_gains``. With ``gains_height_offset_m`` > 0 a
  fourth value in [-1, 1] moves the height control's torso-height reference by that value x
  ``gains_height_offset_m`` for the cycle (0: the standing height, as the paper): a body-height
  knob read with the gains.
  `hexapod_envs.wrappers.GainsPerCycle` turns this into one env step per gait cycle.

## Rewards

| Reward term (info key) | meaning |
|---|---|
| reward_forward | forward_weight x torso CoG speed along +x, clipped to ±0.1 m/s [m/s] |
| reward_steadiness_rate | -rate_weight x min(pitch_rate_factor x pitch rate² + roll rate², 4) |
| reward_steadiness_height | -height_weight x (min(|torso height - standing|, 0.1 m) / 0.01 m)² |
| reward_torso_collision | -collision_penalty when the torso touched the terrain during the step |
| reward_alive | the largest cost of a step (the bounds above), paid while the robot is up |
| reward_tip_over | -tip_over_penalty on the step the robot tips over (episode ends) |

Every term is bounded and the alive term makes an upright step's reward >= 0, so an episode that
ends by tipping over returns less than staying up, however unsteadily the robot walks.

## Starting State
The robot stands in its standing posture (joints perturbed by up to ``reset_noise_scale`` of
their half range) and settles for ``settle_time``. The block heights are drawn from the
episode's ``np_random`` at every reset (one bed per seed); ``block_layout_seed=<int>`` fixes one
bed for all episodes. Task distributions (``task_distribution=``): "paper" (default) is the
terrain above; "train" / "test" draw the slope, the block bed's highest block and block size,
friction and servo stiffness at every reset from the ``train_ranges`` / ``test_ranges``
settings (defaults `TERRAIN_TRAIN` / `TERRAIN_TEST`; held out: slopes 8.5-11.5 deg, taller and
smaller blocks, lower friction, stiffness farther from nominal). ``info["task"]`` holds the
values and their ``difficulty``. ``sensor_noise`` adds Gaussian noise to the observed foot
forces and IMU.

## Episode End
Terminated when the torso's up axis leans more than ``tip_over_angle_deg`` from vertical (-v0:
60°, -v1: 45°); truncated at 1200 steps (60 s).

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
``gains``), absent on the other steps (a key that is sometimes None and sometimes a dict breaks
Gymnasium's vector envs' info batching). The seed's box plots are made from these.
``actuator_power_w`` (sum of |torque x joint speed|, W) and ``episode_metrics`` (at reset and
whenever a cycle finishes: the lists so far of this episode's per-cycle height, pitch-rate and
roll-rate RMS and mean ZMP margin) feed the evaluation pipeline (`evaluation_metrics`).

## Arguments
`IrregularTerrainSettings` (``gym.make(id, **kwargs)``).

## Version History
- v1: the block bed (``terrain="blocks"``), termination at a 45° tilt, success only with the
  tilt within 25° and at most 30 % of the episode below ξ; beds from easy to hard in training
  and from the harder half in test (`hexapod_envs.benchmark`, docs/benchmark.md); the
  calibrated robot model (`CALIBRATED_MODEL`), and the terrain's friction as the contact's
  (``robot_friction=0``).
- v0: the 10° ramp by default; the robot model before the joint calibration (the papers'
  reproduction passes `CALIBRATED_MODEL`).
"""

from __future__ import annotations

import dataclasses
import math
from types import MappingProxyType

import mujoco
import numpy as np
from gymnasium import spaces

from ..robots.athena.gait import (
    GROUND_SEARCH,
    START_FROM,
    AthenaPostureController,
)
from ..robots.athena.kinematics import standing_foot_positions
from ..robots.athena.model import DELAY_MIN_TIMESTEP, add_athena
from ..robots.athena.params import ATHENA, LEG_NAMES
from ..terrain.flat import add_flat
from ..terrain.irregular import PAPER_FRICTION, add_blocks, add_ramp
from . import _compiled
from .actions import JointActionMap
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

TERRAINS = ("ramp", "blocks", "flat")
ACTION_MODES = ("residual", "joint", "gains")
DEFAULT_SWING_HEIGHT = {"ramp": 0.16, "flat": 0.16, "blocks": 0.32}
"""h of eqs. (20)-(21) per terrain [m]; the swing apex is h/4 (4 cm, and 8 cm to clear the
blocks' steps of up to 9 cm from one block to the next). The paper gives no value."""

RAMP_TOP_LENGTH = 2.0
"""Flat top after the slope [m], long enough that a 1200-step episode ends on it."""

CALIBRATED_MODEL: MappingProxyType = MappingProxyType(
    {"contact_solref": (0.01, 1.0), "servo_armature": 0.001}
)
"""Settings of the robot model calibrated jointly against the paper's ramp and block-bed results
(posture against simple control: torso height, roll and pitch rates, torso contacts; the choice
and its measurements: docs/reproduction.md): robot-terrain contacts with a 10 ms time constant
instead of MuJoCo's 20 ms (the paper's simulator has rigid contacts; on soft ones the tall robot
rocks on its stance tripod) and 0.001 kg·m² of servo rotor inertia. ``HexapodIrregularTerrain-v1``
and the papers' reproduction use it; the ``-v0`` defaults keep the model that the shipped agents
were trained on."""


@dataclasses.dataclass(frozen=True)
class TerrainTaskRanges(TaskRanges):
    """Ranges of one task distribution (uniform draws; a tuple of ranges: one chosen at random).

    Held-out test ranges (`TERRAIN_TEST`): slopes interleaved with training (8.5-11.5 deg, which
    holds the paper's 10 deg, against 5-8.5 and 11.5-15), taller blocks and smaller blocks than
    in training (extrapolated), lower friction, servo stiffness farther from nominal.

    Block sizes lie around the calibrated 0.25 m default (training 0.25-0.35 m, test 0.2-0.25 m).
    """

    slope_deg: tuple[tuple[float, float], ...] = bounded(high=45.0)
    block_height_max: tuple[float, float] = bounded(strict=True)
    """Highest block [m] (blocks are drawn 0.04 m up to it)."""
    block_size: tuple[float, float] = bounded(strict=True)
    """Block edge length [m] (square blocks)."""
    friction: tuple[float, float] = bounded()
    servo_kp_scale: tuple[tuple[float, float], ...] = bounded(strict=True)
    """Servo stiffness as a multiple of `servo_kp`."""


TERRAIN_TRAIN = TerrainTaskRanges(
    slope_deg=((5.0, 8.5), (11.5, 15.0)),
    block_height_max=(0.08, 0.12),
    block_size=(0.25, 0.35),
    friction=(0.7, 1.1),
    servo_kp_scale=((0.85, 1.15),),
)
TERRAIN_TEST = TerrainTaskRanges(
    slope_deg=((8.5, 11.5),),
    block_height_max=(0.12, 0.15),
    block_size=(0.20, 0.25),
    friction=(0.5, 0.7),
    servo_kp_scale=((0.7, 0.85), (1.15, 1.3)),
)


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

SCAN_X = (-0.15, -0.05, 0.05, 0.15, 0.25)
"""Terrain-scan rows: distance ahead of the torso centre along its heading [m]."""
SCAN_Y = (-0.15, 0.0, 0.15)
"""Terrain-scan columns: distance to the left of the torso centre [m] (the feet stand at about
±0.15 m)."""

FOOT_SCAN_X = (-0.03, 0.0, 0.03, 0.06, 0.09, 0.12)
"""Foot-scan rows: distance ahead of each foot along the torso's heading [m] (a stride is
0.06 m; the blocks are 0.2-0.25 m wide)."""
FOOT_SCAN_Y = (-0.03, 0.0, 0.03)
"""Foot-scan columns: distance to the left of each foot [m]."""

_CONTACT_CHECKS = 5
"""Torso-terrain contact is looked for this many times per control period (every 10 ms)."""

CONTACT_FORCE_N = 0.5
"""Ground reaction above which ATHENA's foot counts as loaded [N] (the default
``contact_threshold`` is this share of the robot's 21 N weight, about 2.4 %)."""


@dataclasses.dataclass(frozen=True)
class IrregularTerrainRewardScales(RewardScales):
    """Weights of HexapodIrregularTerrain-v0's reward terms (see the module docstring)."""

    forward_weight: float = number(10.0)
    rate_weight: float = number(0.5)
    pitch_rate_factor: float = number(1.0)
    """Weight of pitch rate² against roll rate² in the steadiness-rate term (1: alike). Any
    weighted sum ranks gains by a trade-off between the two rates; a larger factor moves its
    optimum towards gains that lower both (see configs/irregular_terrain_gains.yaml)."""
    height_weight: float = number(0.02)
    collision_penalty: float = number(1.0)
    tip_over_penalty: float = number(50.0)


@dataclasses.dataclass(frozen=True)
class IrregularTerrainSettings(EnvSettings):
    """Settings of HexapodIrregularTerrain-v0 (ATHENA; see the module docstring)."""

    reward_class = IrregularTerrainRewardScales
    control_dt: float = number(0.05, strict=True)
    physics_dt: float = number(0.0025, strict=True)
    """MuJoCo timestep [s]: 2.5 ms, the coarsest step at which every ATHENA physics fidelity row
    holds (the ramp's pitch- and roll-rate RMS within 5 % of their 2 ms values, the simple
    control's sag, the block-bed rate changes and contacts; experiments/physics_settings); 1.3x
    the simulated seconds per wall second of ``physics_dt=0.002``. Not converged in one row:
    posture control's ramp roll-rate RMS is 12 % lower at 0.625 ms (0.0391 against
    0.0445 rad/s)."""
    contact_threshold: float = number(CONTACT_FORCE_N / (ATHENA.total_mass * 9.81), high=1.0)
    """A foot is loaded above this fraction of the weight (default: 0.5 N)."""
    tipping_threshold_deg: float = number(10.0, high=90.0)
    tip_over_angle_deg: float = number(60.0, strict=True, high=90.0)
    camera_name: str | None = option("track", kind=str)
    """The camera that follows the robot (None: the free camera of the heavy-duty envs, from
    which the 0.3 m robot is a few pixels)."""
    terrain: str = choice("ramp", TERRAINS)
    action_mode: str = choice("residual", ACTION_MODES)
    residual_scale: float = number(0.25)
    reference_gains: tuple[float, float, float] = numbers((0.0, 0.0, 0.0), size=3, high=1.0)
    """(k_z, k_α, k_β) of the reference gait's posture control (all 0: simple control)."""
    gains_height_offset_m: float = number(0.0, high=0.05)
    """"gains" mode: when > 0, a fourth action in [-1, 1] raises (or lowers) the torso-height
    reference of the height control (δz of eq. 27) by that action x this many metres, read with
    the gains at each cycle start [m] (0: the three gains alone)."""
    stride: float = number(0.06, strict=True)
    """Stride of the tripod gait [m]."""
    swing_height: float | None = number(None, strict=True, optional=True)
    """h of eqs. (20)-(21) [m] (None: per terrain, `DEFAULT_SWING_HEIGHT`)."""
    phase_time: float = number(1.0, strict=True)
    """t_g, duration of one gait phase [s]."""
    gait_start_from: str = choice("measured_height", START_FROM)
    gait_ground_search: str = choice("auto", GROUND_SEARCH)
    terrain_scan: bool = choice(False, (False, True))
    """Add the privileged ``terrain_scan`` observation piece (see the module docstring)."""
    foot_scan: bool = choice(False, (False, True))
    """Add the privileged ``foot_scan`` observation piece (see the module docstring)."""
    servo_kp: float = number(6.8, strict=True)
    """Servo stiffness [N·m/rad] (calibrated to the paper's simple-control ramp sag, 0.068 m)."""
    servo_damping: float = number(0.2, strict=True)
    """Servo viscous damping [N·m·s/rad]."""
    servo_torque_limit: float | None = number(None, strict=True, optional=True)
    """Servo torque limit [N·m] (None: the paper's stall torque, 1.89 N·m)."""
    servo_armature: float | None = number(None, optional=True)
    """Reflected rotor inertia of each servo [kg·m²] (None: `AthenaParams.servo_armature`)."""
    servo_delay: float = number(0.0)
    """Control latency [s]: each servo acts on the target sent this long ago (0: none)."""
    robot_friction: float | None = number(None, optional=True)
    """Friction of the robot's feet and links [-] (None: the paper's 0.9). MuJoCo takes the
    larger of the two geoms' friction, so a contact's friction is max(this, ``friction``)."""
    contact_solref: tuple[float, float] | None = numbers(None, size=2, optional=True)
    """MuJoCo solref (time constant [s], damping ratio) of the robot-terrain contacts (None:
    MuJoCo's (0.02, 1)): the contacts' softness."""
    contact_solimp: tuple[float, float, float, float, float] | None = numbers(
        None, size=5, optional=True
    )
    """MuJoCo solimp of the robot-terrain contacts (None: MuJoCo's (0.9, 0.95, 0.001, 0.5, 2))."""
    friction: float = number(PAPER_FRICTION)
    ramp_slope_deg: float = number(10.0, high=45.0)
    ramp_start_x: float = number(-0.4, low=None)
    """x of the slope's foot [m]: <= -0.3 starts on the slope, >= 0.3 on the flat approach."""
    ramp_length: float = number(4.5, strict=True)
    block_height_range: tuple[float, float] = numbers((0.04, 0.13), size=2, ordered=True)
    """Block heights are drawn uniformly from this range [m]."""
    block_size: tuple[float, float] = numbers((0.25, 0.25), size=2)
    """Block edge lengths (x, y) [m] (the paper gives only the heights; calibrated against the
    paper's block-bed rows, docs/reproduction.md)."""
    block_region: tuple[tuple[float, float], tuple[float, float]] = numbers(
        ((-0.4, 3.0), (-0.5, 0.5)), size=2, low=None, ordered=True
    )
    """((x0, x1), (y0, y1)) covered by blocks [m]."""
    block_layout_seed: int | None = number(None, integer=True, optional=True)
    """Fixes one block bed for all episodes (None: a new bed from every episode's seed)."""
    train_ranges: TerrainTaskRanges = option(TERRAIN_TRAIN, kind=TerrainTaskRanges, optional=False)
    test_ranges: TerrainTaskRanges = option(TERRAIN_TEST, kind=TerrainTaskRanges, optional=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.terrain == "ramp" and -0.3 < self.ramp_start_x < 0.3:
            raise ValueError(
                f"ramp_start_x={self.ramp_start_x} m puts the foot of the slope under the robot; "
                "use <= -0.3 (start on the slope) or >= 0.3 (start on the flat approach)"
            )


class IrregularTerrainEnv(HexapodEnv):
    """ATHENA on a ramp, a block test bed or flat ground; see the module docstring."""

    evaluation_metrics = {
        **HexapodEnv.evaluation_metrics,
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
            "description": "smallest true clearance below the torso centre [m]",
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

    Settings = IrregularTerrainSettings

    def _setup(self) -> None:
        s = self.settings
        self._scan_offsets = _offsets(SCAN_X, SCAN_Y)
        self._foot_scan_offsets = _offsets(FOOT_SCAN_X, FOOT_SCAN_Y)
        if self.n_substeps % _CONTACT_CHECKS:
            raise ValueError(
                f"control_dt / physics_dt = {self.n_substeps} substeps must be a multiple of "
                f"{_CONTACT_CHECKS} (torso contact is checked {_CONTACT_CHECKS} times per step)"
            )
        if s.servo_delay > 0 and s.physics_dt < DELAY_MIN_TIMESTEP:
            raise ValueError(
                f"servo_delay > 0 needs physics_dt >= {DELAY_MIN_TIMESTEP} s (the servos' target "
                f"history covers the delay at that step or longer), got {s.physics_dt}"
            )
        self.terrain = s.terrain
        self.action_mode = s.action_mode
        self._gains_read_for = -1
        """Phase index of the cycle start at which the gains were last read ("gains" mode)."""
        self.residual_scale = float(s.residual_scale)
        self.robot = dataclasses.replace(ATHENA, **_servo_and_contact(s))
        self.contact_force = s.contact_threshold * self.robot.total_mass * 9.81
        """Ground reaction above which a foot counts as loaded [N]."""
        self.gait_config = {
            "stride": float(s.stride),
            "swing_height": float(
                DEFAULT_SWING_HEIGHT[s.terrain] if s.swing_height is None else s.swing_height
            ),
            "phase_time": float(s.phase_time),
            "control_dt": float(s.control_dt),
            "contact_threshold": float(self.contact_force),
            "start_from": s.gait_start_from,
            "ground_search": s.gait_ground_search,
        }
        """Keyword arguments of `AthenaPostureController` that match this env (policies use it)."""
        self.reference_gains = tuple(float(g) for g in s.reference_gains)
        # Validates the gait numbers (and the gains) with clear errors before anything is built.
        self.controller = AthenaPostureController(
            self.robot, **self.gait_config, **_gain_kwargs(self.reference_gains)
        )
        self.ticks_per_cycle = self.controller.ticks_per_cycle
        self.friction = float(s.friction)
        self.ramp = {
            "slope_deg": float(s.ramp_slope_deg),
            "start_x": float(s.ramp_start_x),
            "length": float(s.ramp_length),
        }
        self.blocks = {
            "height_range": tuple(s.block_height_range),
            "block_size": tuple(s.block_size),
            "region": tuple(tuple(r) for r in s.block_region),
        }
        self.block_layout_seed = s.block_layout_seed
        self.task_ranges = {"train": s.train_ranges, "test": s.test_ranges}
        r = s.reward
        self.weights = {
            "forward": r.forward_weight,
            "steadiness_rate": r.rate_weight,
            "steadiness_height": r.height_weight,
            "torso_collision": r.collision_penalty,
            "tip_over": r.tip_over_penalty,
        }
        self._pitch_rate_factor = float(r.pitch_rate_factor)
        self.stability_criterion = f"FASM >= {self.tipping_threshold_deg:g} deg"
        self.reference_height = self.robot.standing_torso_height
        self.action_map = JointActionMap(np.tile(self.robot.joint_ranges, (6, 1)))
        self._residual_gain = self.residual_scale * self.action_map.half
        self.height_offset_range = float(s.gains_height_offset_m)
        """Metres of torso-height reference per unit of the gains mode's fourth action."""
        if self.height_offset_range and s.action_mode != "gains":
            raise ValueError(
                "gains_height_offset_m adds an action of the 'gains' action mode; got "
                f"action_mode={s.action_mode!r} (set gains_height_offset_m=0 or "
                "action_mode='gains')"
            )
        if s.action_mode == "gains":  # (k_z, k_α, k_β) in [0, 1], the offset in [-1, 1]
            low = [0.0, 0.0, 0.0] + ([-1.0] if self.height_offset_range else [])
            self.action_space = spaces.Box(
                np.array(low, np.float32), np.ones(len(low), np.float32), dtype=np.float32
            )
        else:
            self.action_space = spaces.Box(-1.0, 1.0, shape=(18,), dtype=np.float32)
        self._contact_force_sq = self.contact_force**2
        self._built_task = self.paper_task()
        self._terrain_rng = np.random.default_rng(s.block_layout_seed or 0)
        self._build_model()

    # --- model ---------------------------------------------------------------------------
    def midphase_pays(self) -> bool:
        """On the block bed (hundreds of boxes: without the midphase raw `mj_step` runs at
        0.81x), not on the ramp or flat ground (1.13x without; benchmarks/README.md, "Latest
        figures")."""
        return self.terrain == "blocks"

    def _build_spec(self, spec: mujoco.MjSpec) -> None:
        """Terrain (blocks drawn from `_terrain_rng`) and the robot at its start pose."""
        pos, quat = self._add_terrain(spec, self._terrain_rng)
        self.handles = add_athena(spec, pos=pos, quat=quat, params=self.robot)

    def _bind_model(self) -> None:
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
        u, v = np.meshgrid(np.linspace(-1.0, 1.0, 5), np.linspace(-1.0, 1.0, 5))
        half = np.asarray(self.robot.body.size, dtype=np.float64)[:, None] / 2
        # points of the torso's bottom face in the torso frame, (3, 25) [m]
        self._footprint = np.stack([u.ravel(), v.ravel(), np.full(u.size, -1.0)]) * half

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
        residual scale, the terrain kind and the ramp geometry."""
        return {
            "gait_config": dict(self.gait_config),
            "reference_gains": self.reference_gains,
            "ticks_per_cycle": self.ticks_per_cycle,
            "residual_scale": self.residual_scale,
            "terrain": self.terrain,
            "ramp": dict(self.ramp),
        }

    # --- task distribution -----------------------------------------------------------------
    def paper_task(self) -> dict:
        s = self.settings
        return {
            "terrain": self.terrain,
            "slope_deg": float(s.ramp_slope_deg),
            "block_height_max": float(s.block_height_range[1]),
            "block_size": float(s.block_size[0]),
            "friction": float(s.friction),
            "servo_kp": float(s.servo_kp),
        }

    def task_difficulty_spans(self) -> dict[str, DifficultySpan]:
        """What makes a terrain task hard: on the blocks tall and small blocks, on the ramp a
        steep slope; on both a slippery ground and soft servos (down to 70 % of the nominal
        stiffness; stiffer servos rate as nominal: they hold the posture at least as well)."""
        kp = self.settings.servo_kp
        spans = {
            "friction": DifficultySpan(easy=1.1, hard=0.5),
            "servo_kp": DifficultySpan(easy=kp, hard=0.7 * kp),
        }
        if self.terrain == "blocks":
            spans["block_height_max"] = DifficultySpan(easy=0.06, hard=0.15, weight=2.0)
            spans["block_size"] = DifficultySpan(easy=0.35, hard=0.20)
        elif self.terrain == "ramp":
            spans["slope_deg"] = DifficultySpan(easy=5.0, hard=15.0, weight=2.0)
        return spans

    def sample_task(self, rng: np.random.Generator, distribution: str) -> dict:
        r = self.task_ranges[distribution]
        return {
            "terrain": self.terrain,
            "slope_deg": _uniform_in(rng, r.slope_deg),
            "block_height_max": float(rng.uniform(*r.block_height_max)),
            "block_size": float(rng.uniform(*r.block_size)),
            "friction": float(rng.uniform(*r.friction)),
            "servo_kp": float(self.settings.servo_kp) * _uniform_in(rng, r.servo_kp_scale),
        }

    def _apply_task(self, task: dict) -> None:
        """Set the terrain and servo parameters of `task` and rebuild the model if they changed;
        the block bed is drawn anew from the episode's `np_random` at every reset, unless
        `block_layout_seed` fixes it."""
        low = self.blocks["height_range"][0]
        if task["block_height_max"] < low:  # the bed's lowest block bounds its highest
            task["block_height_max"] = low  # what the bed has, in info["task"] and its rating
        changed = task != self._built_task
        if changed:
            self._built_task = dict(task)
            self.ramp["slope_deg"] = task["slope_deg"]
            self.blocks["height_range"] = (low, task["block_height_max"])
            self.blocks["block_size"] = (task["block_size"], task["block_size"])
            self.friction = task["friction"]
            self.robot = dataclasses.replace(self.robot, servo_kp=task["servo_kp"])
        if self.terrain == "blocks" and self.block_layout_seed is None:
            self._terrain_rng = self.np_random  # a new test bed per episode, from its seed
            self._build_model()
        elif changed:
            self._terrain_rng = np.random.default_rng(self.block_layout_seed or 0)
            self._build_model()

    def _set_initial_state(self) -> None:
        standing = np.tile(self.robot.standing_posture, 6)
        noise = self.reset_noise_scale * self.action_map.half
        joints = standing + self.np_random.uniform(-noise, noise)
        low, high = self.action_map.low, self.action_map.high
        self.data.qpos[self._joint_qpos] = np.clip(joints, low, high)
        self.data.ctrl[self._act_ids] = standing
        if self.robot.servo_delay > 0:  # the delayed servos start from the standing targets too
            for i, target in zip(self._act_ids, standing, strict=True):
                n = self.model.actuator_history[i, 0]
                mujoco.mj_initCtrlHistory(self.model, self.data, i, None, np.full((n, 1), target))

    def _start_episode(self) -> None:
        self.controller.reset()
        self.controller.set_gains(*self.reference_gains)
        self.controller.reference_height = self.reference_height
        self._gains_read_for = -1
        self._collisions = 0
        self._touched_in_physics = False
        self._cycle_id = 0
        self._finished_cycle: dict | None = None
        self._window: list[tuple] = []
        self._window_x0 = float(self.sensors.cog()[0])
        self._episode_metrics = {
            "cycle_height_rms": [],
            "cycle_pitch_rate_rms": [],
            "cycle_roll_rate_rms": [],
            "cycle_zmp_margin": [],
        }

    @property
    def gains_due(self) -> bool:
        """True when the next `step` reads its action as the posture gains: in the "gains" mode,
        the first step of each gait cycle (the other steps' actions are ignored, also those of
        the steps on which the gait waits at the cycle start for its stance feet to touch). See
        `hexapod_envs.wrappers.GainsPerCycle`, which makes one env step of each gait cycle."""
        c = self.controller
        return (
            self.action_mode == "gains"
            and c.at_cycle_start
            and c.next_phase_index != self._gains_read_for
        )

    def _apply_action(self, action: np.ndarray) -> None:
        """The servo targets: the mapped action ("joint"), or the posture controller's targets
        (plus the scaled action in "residual" mode, one compiled call)."""
        ctrl = self.data.ctrl
        if self.action_mode == "joint":
            ctrl[self._act_ids] = self.action_map.to_joints(action)
            return
        if self.gains_due:
            self.controller.set_gains(*action[:3].tolist())
            if self.height_offset_range:
                offset = float(action[3]) * self.height_offset_range
                self.controller.reference_height = self.reference_height + offset
            self._gains_read_for = self.controller.next_phase_index
        targets = self.controller.step_readings(
            self._joints.reshape(6, 3), self._forces, self._height
        )
        if self.action_mode == "residual":
            _compiled.offset_targets(targets, self._residual_gain, action, ctrl, self._act_ids)
        else:
            ctrl[self._act_ids] = targets.reshape(-1)

    def _run_physics(self) -> None:
        """One control period of physics, looking for torso-terrain contact every 10 ms.

        The `torso_contact` sensor is a position-stage sensor: it counts the torso geom's
        entries in `data.contact`, the contacts of the last physics step's collision pass. The
        first checks evaluate the position-stage sensors alone (`_step_sensing_position`, about
        1 µs); the period's last step evaluates every sensor for the step's measurements. The
        counts are the ones a full evaluation gives, without its dynamics pass for the
        foot-force sensors and the accelerometer (about 4 µs per check); under RK4 every check
        evaluates every sensor (see `_step_sensing_position`).
        """
        chunk = self.n_substeps // _CONTACT_CHECKS
        sensordata, adr = self.data.sensordata, self._torso_contact_adr
        touched = False
        for _ in range(_CONTACT_CHECKS - 1):
            self._step_sensing_position(chunk)
            touched = touched or sensordata[adr] > 0.0
        self._step_sensing_last(chunk)
        touched = touched or sensordata[adr] > 0.0
        self._touched_in_physics = bool(touched)

    # --- measurements --------------------------------------------------------------------
    def _measure(self) -> Measurement:
        self._touched = self._touched_in_physics
        self._collisions += self._touched
        s = self.sensors
        self._joints = s.joint_positions()  # fancy indexing: already a copy
        reading = s.support(self._contact_force_sq)
        self._power = reading.power
        self._height = float(self.data.sensordata[self._height_adr])
        self._gyro = s.gyro().copy()
        self._zmp, self._zmp_margin = s.torso_frame_zmp(reading.forces, reading.loaded)
        return Measurement(
            reading.forces, reading.loaded, reading.fasm_deg, reading.fasm_edge, reading.cog
        )

    def _height_deviation(self) -> float:
        """Torso-height reading minus the standing reference, m (0 without a reading)."""
        return self._height - self.reference_height if self._height >= 0 else 0.0

    def _height_offset(self) -> float:
        """The height control's torso-height reference minus the standing height [m]."""
        return self.controller.reference_height - self.reference_height

    def torso_clearance(self) -> float:
        """True distance (m) from the torso box's bottom to the terrain below the torso centre
        (privileged: uses the terrain model and the true pose; for evaluation only)."""
        x, y, z = self.sensors.torso_position().tolist()
        ground = 0.0 if self.terrain_info is None else self.terrain_info.height_at(x, y)
        bottom = z - self._torso_half_height * self.sensors.tilt_cos()
        return float(bottom - ground)

    def torso_footprint_clearance(self) -> float:
        """Smallest true distance (m) from the torso box's bottom face to the terrain, over a
        5 x 5 grid of points spanning that face (privileged, like `torso_clearance`; negative
        when the face dips into a block). A block under an edge of the torso shows here, not
        below its centre: on 6 held-out block beds all 928 torso-contact steps fell in gait
        cycles whose footprint clearance dropped below 1 cm, 819 of them in cycles whose
        clearance below the centre stayed at 4 cm or more."""
        pos, rot = self.sensors.torso_position(), self.sensors.torso_rotation()
        points = pos[:, None] + rot @ self._footprint
        return float(np.min(points[2] - self._ground(points[0], points[1])))

    def _ground(self, x: np.ndarray, y: np.ndarray) -> np.ndarray | float:
        """True terrain height [m] at world points (0 on flat ground, which has no model)."""
        return 0.0 if self.terrain_info is None else self.terrain_info.surface_height(x, y)

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

    def _end_step(self) -> None:
        """Add this step to its cycle's window; on a new cycle keep the finished one's stats
        (``info["cycle_stats"]``)."""
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
                self._touched,
                float(self._cog[0]),
                self.controller.gains if self.action_mode != "joint" else None,
            )
        )
        self._finished_cycle = stats

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
    def _observation_pieces(self) -> dict:
        # Readers look the sensors up at call time: a task may rebuild the model (and sensors).
        pieces = {
            "sensors": self._sensor_pieces(),
            "torso_height": (1, lambda: self._height),
            "gait_phase": (3, self._gait_phase),
        }
        if self.action_mode == "gains":
            pieces["posture_gains"] = (3, lambda: self.controller.gains)
        if self.height_offset_range:
            pieces["height_offset"] = (1, self._height_offset)
        if self.settings.terrain_scan:
            pieces["terrain_scan"] = (len(SCAN_X) * len(SCAN_Y), self.terrain_scan)
        if self.settings.foot_scan:
            size = len(LEG_NAMES) * len(FOOT_SCAN_X) * len(FOOT_SCAN_Y)
            pieces["foot_scan"] = (size, self.foot_scan)
        return pieces

    def terrain_scan(self) -> np.ndarray:
        """(15,) torso centre height above the terrain at the scan points [m], rows `SCAN_X`
        ahead along the torso's heading, columns `SCAN_Y` to its left (privileged: the terrain
        model and the true pose)."""
        x, y, z = self.sensors.torso_position().tolist()
        return z - self._ground_around(x, y, self._scan_offsets)

    def foot_scan(self) -> np.ndarray:
        """(6 x 18,) each foot's height above the terrain at the foot-scan points [m]: per leg,
        rows `FOOT_SCAN_X` ahead of the foot along the torso's heading, columns `FOOT_SCAN_Y`
        to its left (privileged, like `terrain_scan`). The height is the foot sphere's centre's,
        so a foot standing on the ground reads its radius (0.02 m) at its own point."""
        feet = self.sensors.foot_positions()
        points = len(self._foot_scan_offsets[0])
        ground = self._ground_around(feet[:, :1], feet[:, 1:2], self._foot_scan_offsets)
        heights = feet[:, 2:3] - ground  # (6, 1) on flat ground, which has no model
        return np.broadcast_to(heights, (len(feet), points)).reshape(-1)

    def _ground_around(self, x, y, offsets: tuple[np.ndarray, np.ndarray]):
        """True terrain height [m] at `offsets` (ahead, left) [m] from the world points (x, y),
        ahead along the torso's heading: (n,) offsets around a point, (k, n) around k points
        given as (k, 1) columns (a float 0 on flat ground)."""
        rot = self.sensors.torso_rotation()
        heading = math.atan2(float(rot[1, 0]), float(rot[0, 0]))
        c, s = math.cos(heading), math.sin(heading)
        ahead, left = offsets
        return self._ground(x + c * ahead - s * left, y + s * ahead + c * left)

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

    def _reward_terms(self, tipped: bool) -> dict[str, float]:
        w = self.weights
        speed = (self._cog[0] - self._prev_cog_x) / self.control_dt
        rates = float(self._gyro[0] ** 2 + self._pitch_rate_factor * self._gyro[1] ** 2)
        dz = min(abs(self._height_deviation()), HEIGHT_CLIP_M) / 0.01
        return {
            "forward": w["forward"] * min(max(speed, -SPEED_CLIP_M_S), SPEED_CLIP_M_S),
            "steadiness_rate": -w["steadiness_rate"] * min(rates, RATE_CAP),
            "steadiness_height": -w["steadiness_height"] * dz * dz,
            "torso_collision": -w["torso_collision"] if self._touched else 0.0,
            "alive": 0.0 if self._tipped else self.step_cost_bound(),
            "tip_over": -w["tip_over"] if tipped else 0.0,
        }

    def _is_success(self) -> bool:
        """No torso contact so far, and at least `MIN_PROGRESS` of the distance the gait's
        nominal speed (stride per phase) covers in the elapsed time: standing still or walking
        backwards is not a success."""
        if self._collisions:
            return False
        speed = self.gait_config["stride"] / self.gait_config["phase_time"]
        walked = float(self._cog[0] - self._start_cog_x)
        return walked >= MIN_PROGRESS * speed * self._step_count * self.control_dt

    def _extra_info(self, unstable: bool) -> dict:
        stats = None if unstable else self._finished_cycle
        info = {
            "actuator_power_w": self._power,
            "zmp": self._zmp.copy(),
            "zmp_margin": self._zmp_margin,
            "torso_contact": self._touched,
            "torso_collisions": self._collisions,
            "torso_height": self._height,
            "torso_clearance": self.torso_clearance(),
            "pitch_rate": float(self._gyro[1]),
            "roll_rate": float(self._gyro[0]),
            "posture_gains": self.controller.gains if self.action_mode != "joint" else None,
            "gait_cycle": self._gait_cycle_index(),
        }
        if stats is not None:
            info["cycle_stats"] = stats
        if stats is not None or self._step_count == 0:
            # A fresh copy whenever the lists change (and at reset): infos must not share data.
            info["episode_metrics"] = {k: list(v) for k, v in self._episode_metrics.items()}
        return info


def _offsets(ahead: tuple[float, ...], left: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
    """The (ahead, left) offsets [m] of a scan grid, rows `ahead`, columns `left`, flattened."""
    rows, columns = np.meshgrid(ahead, left, indexing="ij")
    return rows.reshape(-1), columns.reshape(-1)


def _gain_kwargs(gains: tuple[float, ...]) -> dict[str, float]:
    if len(gains) != 3:
        raise ValueError(f"gains must be (k_z, k_alpha, k_beta), got {gains!r}")
    return {"kz": gains[0], "k_alpha": gains[1], "k_beta": gains[2]}


def _servo_and_contact(s: IrregularTerrainSettings) -> dict:
    """The `AthenaParams` fields that `s` sets: the servo stiffness and damping always, the
    torque limit, armature, latency, friction and contact softness where `s` gives them."""
    fields = {
        "servo_kp": s.servo_kp,
        "servo_damping": s.servo_damping,
        "stall_torque": s.servo_torque_limit,
        "servo_armature": s.servo_armature,
        "servo_delay": s.servo_delay,
        "friction": s.robot_friction,
        "contact_solref": s.contact_solref,
        "contact_solimp": s.contact_solimp,
    }
    return {k: v for k, v in fields.items() if v is not None}
