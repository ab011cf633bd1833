"""Common part of the envs that use the 5 t heavy-duty hexapod of Zhang et al. 2024.

Action modes:
- ``"joint"``: 18 joint position targets, each normalised to [-1, 1] over its range
  (J_x, J_z, J_theta per leg, legs in LEG_NAMES order).
- ``"residual"``: 18 offsets in [-1, 1] added to the reference tripod gait's targets, scaled by
  ``residual_scale`` times each joint's half range and low-pass filtered with time constant
  ``residual_filter_tau`` [s]; a zero action walks the paper's gait. With ``clock_action=True``
  (walking scenarios) a 19th value sets how far the reference gait's clock advances after this
  step, 1 + min(a, 0) control steps: 0 keeps the paper's pace, -1 holds the gait where it is
  (every leg's target stays from the next step on; the ``gait_phase`` observation follows the
  clock). With ``clock_action="stop"`` the 19th value is a one-way stop instead: the first
  walking step it is at its lower bound (-1) stops the gait's clock for the rest of the episode
  (the walking flag of ``gait_phase`` then reads 0); any value above walks at the paper's pace.
  A stop is one decision per episode, where a hold through the rate needs -1 at every step.

``is_success``: not tipped over and, in walking scenarios, at least ``min_progress`` of the
distance the reference gait covers in the elapsed walking time.
``info["behind_pace"]`` (walking scenarios): past the standing phase (also after a stop), the
CoG is short of that distance.
"""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
from gymnasium import spaces

from ..robots.heavy_duty import LEG_NAMES, HeavyDutyParams
from ..robots.heavy_duty.gait import TripodGait, TripodGaitParams
from ..robots.heavy_duty.model import add_heavy_duty
from . import _compiled
from .actions import JointActionMap
from .base import HexapodEnv, Measurement
from .sensors import RobotSensors
from .settings import (
    SOLVERS,
    EnvSettings,
    RewardScales,
    TaskRanges,
    bounded,
    choice,
    number,
    numbers,
    option,
)

XI_F_DEG = 20.0
"""Tipping threshold ξ_f of Zhang et al. 2024 §3 [deg]."""

EFFORT_CAP = 20.0
"""Bound of the effort term's power ratio |power| / (weight x gait speed) [-]: the reference gait
peaks near 20, random actions reach 150. Bounded costs let the alive term make every upright
step's reward >= 0, so that tipping over early never pays more than staying up."""

ACTION_MODES = ("joint", "residual")
CLOCK_ACTIONS = (False, True, "stop")
"""``clock_action`` values: none, the gait clock's rate, a one-way stop."""


@dataclasses.dataclass(frozen=True)
class HeavyDutyRewardScales(RewardScales):
    """Weights of the heavy-duty envs' reward terms (see the env docstrings)."""

    forward_weight: float = number(1.0)
    forward_cap: float = number(1.0, strict=True)
    """The forward term counts speed up to this multiple of the reference gait's speed (1:
    faster is not rewarded, so a policy cannot trade stability for a scramble)."""
    stability_weight: float = number(1.0)
    tip_over_penalty: float = number(100.0)
    effort_weight: float = number(0.05)


@dataclasses.dataclass(frozen=True, kw_only=True)
class HeavyDutyTaskRanges(TaskRanges):
    """What every heavy-duty scenario's task ranges hold: the payload on the body, a point mass
    at an offset from the body's CoG (the scenarios' range dataclasses extend this one)."""

    payload_mass: tuple[float, float] = bounded()
    """Payload mass range [kg] (uniform)."""
    payload_offset: float = bounded()
    """Largest offset of the payload from the body's CoG in x and in y [m] (uniform in ±)."""


TRAIN_PAYLOAD = {"payload_mass": (0.0, 500.0), "payload_offset": 0.15}
"""The training payload: up to 500 kg (a tenth of the robot), up to 0.15 m off centre."""
TEST_PAYLOAD = {"payload_mass": (500.0, 800.0), "payload_offset": 0.25}
"""The held-out payload: heavier (extrapolated) and farther off centre."""


@dataclasses.dataclass(frozen=True)
class HeavyDutySettings(EnvSettings):
    """Settings of the heavy-duty hexapod envs (the scenario envs extend them)."""

    reward_class = HeavyDutyRewardScales
    physics_dt: float = number(0.002, strict=True)
    """MuJoCo timestep [s]. 2 ms with the servo armature below: the paper scenarios' fidelity
    rows of the former 1 ms model hold at about 1.8x its speed, while on the held-out test
    cliffs the reference gait tips on 2 of 20 instead of 0 (benchmarks/README.md, "The servo
    armature and the 2 ms step"); the former physics is ``physics_dt=0.001,
    joint_armature=(20.0, 20.0, 50.0)``."""
    joint_armature: tuple[float, float, float] = numbers(HeavyDutyParams().joint_armature, size=3)
    """Servo rotor inertia reflected to the joints (x [kg], leg length [kg], swing [kg·m²]):
    `HeavyDutyParams.joint_armature`."""
    tipping_threshold_deg: float = number(XI_F_DEG, high=90.0)
    """ξ_f [deg]: FASM below it means the robot is tipping (the paper's judgment threshold)."""
    solver: str = choice("pgs", SOLVERS)
    """MuJoCo's constraint solver. Projected Gauss-Seidel: 1.24x Newton's speed on this robot
    with every physics fidelity row holding (experiments/physics_settings)."""
    action_mode: str = choice("residual", ACTION_MODES)
    residual_scale: float = number(0.25)
    """Residual action 1 = this fraction of each joint's half range."""
    residual_filter_tau: float = number(0.1)
    """Time constant of the residual's first-order low-pass filter [s] (0: none)."""
    min_progress: float = number(0.5)
    """Share of the reference gait's distance a successful walking episode covers."""
    gait: TripodGaitParams | None = option(None, kind=TripodGaitParams)
    """The reference tripod gait (None: the paper's)."""
    clock_action: bool | str = choice(False, CLOCK_ACTIONS)
    """Residual mode of a walking scenario: add the reference gait's clock as a 19th action,
    its rate (True) or a one-way stop ("stop"; see the module docstring). The reference's pace
    is the one thing per-step joint residuals cannot change: slowing or holding the whole gait
    would take a residual that tracks the moving reference."""


class HeavyDutyEnv(HexapodEnv):
    """Base for the heavy-duty hexapod scenarios: robot, sensors, FASM, action modes, rewards."""

    Settings = HeavyDutySettings

    walks: bool = True
    """Walking scenarios follow the reference tripod gait and observe its phase."""

    def _setup(self) -> None:
        s = self.settings
        self.stability_criterion = (
            f"FASM >= ξ_f = {self.tipping_threshold_deg:g} deg (the paper's tipping judgment)"
        )
        self.action_mode = s.action_mode
        self.residual_scale = s.residual_scale
        self.robot = HeavyDutyParams(joint_armature=s.joint_armature)
        self.gait = TripodGait(self.robot, s.gait)
        self.weights = {
            "forward": s.reward.forward_weight,
            "stability": s.reward.stability_weight,
            "tip_over": s.reward.tip_over_penalty,
            "effort": s.reward.effort_weight,
        }
        self._forward_cap = s.reward.forward_cap
        self.weight_n = self.robot.total_mass * 9.81
        self._contact_force_sq = (s.contact_threshold * self.weight_n) ** 2
        self.action_map = JointActionMap(np.tile(self.robot.joint_ranges, (6, 1)))
        if s.clock_action and (s.action_mode != "residual" or not self.walks):
            raise ValueError(
                f"clock_action={s.clock_action!r} adds the reference gait's clock to the residual "
                f"action of a walking scenario; got action_mode={s.action_mode!r} on "
                f"{type(self).__name__} (walks: {self.walks})"
            )
        self.clock_action = s.clock_action
        self.action_space = spaces.Box(
            -1.0, 1.0, shape=(19 if s.clock_action else 18,), dtype=np.float32
        )
        self._residual_gain = s.residual_scale * self.action_map.half
        # First-order low-pass on the residual (a servo command filter): a step-to-step
        # jittering residual would otherwise hammer 5 t through 4e6 N/m servos.
        self._filter_alpha = self.control_dt / (s.residual_filter_tau + self.control_dt)
        self.min_progress = s.min_progress
        steps_per_cycle = self.gait.gait.period / self.control_dt
        if abs(steps_per_cycle - round(steps_per_cycle)) > 1e-9:
            raise ValueError(
                f"the gait period ({self.gait.gait.period:g} s, settings.gait) must be a whole "
                f"number of control periods: control_dt={self.control_dt!r} s gives "
                f"{steps_per_cycle:.9g} per cycle"
            )
        self._steps_per_cycle = int(round(steps_per_cycle))
        self._reference_table = np.array(
            [
                self.gait.joints_at_phase(k / self._steps_per_cycle).reshape(-1)
                for k in range(self._steps_per_cycle)
            ]
        )
        self._stand_steps = int(round(self.gait.gait.stand_time / self.control_dt))
        phases = [2 * np.pi * (k / self._steps_per_cycle) for k in range(self._steps_per_cycle)]
        self._phase_table = np.array(
            [[(np.sin(a), np.cos(a), walking) for a in phases] for walking in (0.0, 1.0)]
        )
        """The gait_phase observation [standing / walking, control step of the cycle]."""
        self._phase_table.flags.writeable = False
        self._build_model()

    # --- model ---------------------------------------------------------------------------
    def _add_terrain(self, spec) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    def _robot_start_height(self) -> float:
        return self.robot.stand_height + 0.005

    def midphase_pays(self) -> bool:
        """No: every body of the robot and its terrain has few geoms; without the midphase raw
        `mj_step` runs 1.05x as fast on the cliff walk (benchmarks/README.md, "Latest
        figures")."""
        return False

    def _build_spec(self, spec) -> None:
        self._add_terrain(spec)
        self.handles = add_heavy_duty(spec, self.robot, pos=(0.0, 0.0, self._robot_start_height()))

    def _bind_model(self) -> None:
        actuators = tuple(j for leg in LEG_NAMES for j in self.handles.joints[leg])
        self.sensors = RobotSensors(self.model, self.data, LEG_NAMES, actuators)
        self._act_ids = np.array([self.model.actuator(a).id for a in actuators])
        # qpos of each joint in actuator order, to start the robot in the commanded pose.
        self._joint_qpos = np.array(
            [self.model.jnt_qposadr[self.model.actuator_trnid[i, 0]] for i in self._act_ids]
        )
        self._gears = self.model.actuator_gear[self._act_ids, 0].copy()

    # --- time and reference gait ------------------------------------------------------------
    def _gait_step(self) -> int:
        """Index into the reference table (the gait clock is frozen while standing)."""
        if self.clock_action:
            return int(self._clock) % self._steps_per_cycle
        return max(0, self._step_count - self._stand_steps) % self._steps_per_cycle

    def reference_joints(self) -> np.ndarray:
        """(18,) reference tripod-gait joint targets at the gait clock's current step."""
        return self._reference_table[self._gait_step()]

    # --- episode hooks ---------------------------------------------------------------------
    def _initial_joints(self) -> np.ndarray:
        return self._reference_table[0]

    def _set_initial_state(self) -> None:
        # The initial joint state is perturbed; the servo targets are not, and the settling
        # lets the perturbation decay into a seed-dependent resting state.
        targets = self._initial_joints()
        noise = self.reset_noise_scale * self.action_map.half
        joints = targets + self.np_random.uniform(-noise, noise)
        joints = np.clip(joints, self.action_map.low, self.action_map.high)
        self.data.qpos[self._joint_qpos] = joints / self._gears
        self.data.ctrl[self._act_ids] = targets

    def _start_episode(self) -> None:
        self._residual = np.zeros(18)
        self._clock = 0.0
        """With `clock_action`: reference-gait control steps walked so far (fractional)."""
        self._stopped = False
        """With ``clock_action="stop"``: the gait was stopped for the rest of the episode."""

    def _apply_action(self, action: np.ndarray) -> None:
        """Joint targets from the action (MuJoCo clamps them to the servo ranges, ctrlrange):
        the mapped action, or the reference gait plus the filtered residual (one compiled
        call); with `clock_action`, then the gait clock's advance for the next step."""
        self._before_physics()
        if self.action_mode == "joint":
            self.data.ctrl[self._act_ids] = self.action_map.to_joints(action)
            return
        _compiled.filtered_residual_targets(
            action[:18],
            self._residual_gain,
            self._filter_alpha,
            self._residual,
            self.reference_joints(),
            self.data.ctrl,
            self._act_ids,
        )
        if self.clock_action and self._step_count >= self._stand_steps:
            if self.clock_action == "stop":
                self._stopped = self._stopped or bool(action[18] <= -1.0)
                self._clock += 0.0 if self._stopped else 1.0
            else:
                self._clock += 1.0 + min(float(action[18]), 0.0)

    def _before_physics(self) -> None:
        """Hook run before each control period's physics (e.g. driving a platform)."""

    def _reference_description(self) -> dict:
        """The reference: tripod gait parameters, its table of joint targets per control step
        of a cycle, steps per cycle and standing steps, residual scale and filter, and whether
        the action ends with the gait clock's rate or stop (`clock_action`)."""
        return {
            "gait": self.gait.gait,
            "reference_table": self._reference_table.copy(),
            "steps_per_cycle": self._steps_per_cycle,
            "stand_steps": self._stand_steps,
            "residual_scale": self.residual_scale,
            "residual_filter_alpha": self._filter_alpha,
            "walks": self.walks,
            "clock_action": self.clock_action,
        }

    # --- task distribution -----------------------------------------------------------------
    NO_PAYLOAD = {"payload_mass": 0.0, "payload_offset_x": 0.0, "payload_offset_y": 0.0}
    """The paper's scenarios carry no payload (task keys as `_sample_payload`'s)."""

    @staticmethod
    def _sample_payload(rng: np.random.Generator, ranges: HeavyDutyTaskRanges) -> dict:
        off = ranges.payload_offset
        return {
            "payload_mass": float(rng.uniform(*ranges.payload_mass)),
            "payload_offset_x": float(rng.uniform(-off, off)),
            "payload_offset_y": float(rng.uniform(-off, off)),
        }

    def _apply_task(self, task: dict) -> None:
        """Rebuild the model when the task changes it, then place the payload (a point mass
        added to the body at its CoG offset; the body's inertia is kept)."""
        if self._set_terrain(task):
            self._build_model()
        m = self.model
        torso = self.sensors.torso_id
        if not hasattr(self, "_torso_mass0"):
            self._torso_mass0 = float(m.body_mass[torso])
            self._torso_ipos0 = m.body_ipos[torso].copy()
        mass = task.get("payload_mass", 0.0)
        offset = np.array([task.get("payload_offset_x", 0.0), task.get("payload_offset_y", 0.0)])
        total = self._torso_mass0 + mass
        m.body_mass[torso] = total
        m.body_ipos[torso] = self._torso_ipos0
        m.body_ipos[torso, :2] = (self._torso_mass0 * self._torso_ipos0[:2] + mass * offset) / total
        mujoco.mj_setConst(m, self.data)

    def _set_terrain(self, task: dict) -> bool:
        """Take the task's terrain (geometry, friction); True if it changed (the model is then
        rebuilt)."""
        return False

    # --- measurements ----------------------------------------------------------------------
    def _measure(self) -> Measurement:
        reading = self.sensors.support(self._contact_force_sq)
        self._power = reading.power
        return Measurement(
            reading.forces, reading.loaded, reading.fasm_deg, reading.fasm_edge, reading.cog
        )

    # --- observation, reward, info ----------------------------------------------------------
    def _observation_pieces(self) -> dict:
        # Readers look the sensors up at call time: a task may rebuild the model (and sensors).
        pieces = {"sensors": self._sensor_pieces()}
        if self.walks:
            pieces["gait_phase"] = (3, self._gait_phase)
        return pieces

    def _gait_phase(self) -> np.ndarray:
        """sin, cos of the gait clock's phase, and 1 once walking (until a stop)."""
        walking = self._step_count >= self._stand_steps and not self._stopped
        return self._phase_table[int(walking), self._gait_step()]

    def step_cost_bound(self) -> float:
        """The largest cost one step can carry (the sum of the bounded negative parts of the
        forward, stability and effort terms); the ``alive`` term pays it on every step the robot
        is up, as Gymnasium's MuJoCo envs pay a healthy reward."""
        w = self.weights
        forward = w["forward"] if self.walks else 0.0
        stability = w["stability"] * self.tipping_threshold_deg / 45.0
        return forward + stability + w["effort"] * EFFORT_CAP

    def _reward_terms(self, tipped: bool) -> dict[str, float]:
        """Named reward terms, each bounded; the forward term only in walking scenarios."""
        w = self.weights
        v_ref = self.gait.gait.body_speed
        margin = min(max(self._fasm_deg, -self.tipping_threshold_deg), 45.0)
        terms = {}
        if self.walks:
            # Progress up to `forward_cap` x the reference gait's speed (default 1: faster is
            # not rewarded, so a policy cannot trade stability for a scramble; PPO did, at 1 m/s
            # with FASM ~ 0).
            speed = (float(self._cog[0]) - self._prev_cog_x) / self.control_dt
            terms["forward"] = w["forward"] * min(max(speed / v_ref, -1.0), self._forward_cap)
        terms["stability"] = w["stability"] * margin / 45.0
        terms["alive"] = 0.0 if self._tipped else self.step_cost_bound()
        terms["tip_over"] = -w["tip_over"] if tipped else 0.0
        ratio = self._power / (self.weight_n * v_ref)
        terms["effort"] = -w["effort"] * min(ratio, EFFORT_CAP)
        return terms

    def _extra_info(self, unstable: bool) -> dict:
        info = {"actuator_power_w": self._power}
        if self.walks:  # while standing the pace asks for nothing
            info["behind_pace"] = self.time > self.gait.gait.stand_time and not self._on_pace()
        return info

    def _is_success(self) -> bool:
        """Walking envs: at least `min_progress` of the reference gait's distance so far."""
        return not self.walks or self._on_pace()

    def _on_pace(self) -> bool:
        """Whether the CoG has advanced at least `min_progress` of the reference gait's distance
        in the walking time so far (``info["behind_pace"]`` is its negation past the standing
        phase)."""
        walked = max(0.0, self.time - self.gait.gait.stand_time)
        progress = float(self._cog[0]) - self._start_cog_x
        return progress >= self.min_progress * self.gait.gait.body_speed * walked
