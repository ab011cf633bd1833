"""Common part of the envs that use the 5 t heavy-duty hexapod of Zhang et al. 2024.

Action modes:
- ``"joint"``: 18 joint position targets, each normalised to [-1, 1] over its range
  (J_x, J_z, J_theta per leg, legs in LEG_NAMES order).
- ``"residual"``: 18 offsets in [-1, 1] added to the reference tripod gait's targets, scaled by
  ``residual_scale`` times each joint's half range and low-pass filtered with time constant
  ``residual_filter_tau`` [s]; a zero action walks the paper's gait.

``is_success``: not tipped over and, in walking scenarios, at least ``min_progress`` of the
distance the reference gait covers in the elapsed walking time.
"""

from __future__ import annotations

import mujoco
import numpy as np
from gymnasium import spaces

from ..robots.heavy_duty import LEG_NAMES, HeavyDutyParams
from ..robots.heavy_duty.gait import TripodGait, TripodGaitParams
from ..robots.heavy_duty.model import add_heavy_duty
from ..stability import fasm_from_feet
from .base import HexapodEnv, JointActionMap, check_choice
from .sensors import RobotSensors

XI_F_DEG = 20.0
"""Tipping threshold ξ_f of Zhang et al. 2024 §3 [deg]."""

EFFORT_CAP = 20.0
"""Bound of the effort term's power ratio |power| / (weight x gait speed) [-]: the reference gait
peaks near 20, random actions reach 150. Bounded costs let the alive term make every upright
step's reward >= 0, so that tipping over early never pays more than staying up."""

ACTION_MODES = ("joint", "residual")


class HeavyDutyEnv(HexapodEnv):
    """Base for the heavy-duty hexapod scenarios: robot, sensors, FASM, action modes, rewards."""

    walks: bool = True
    """Walking scenarios follow the reference tripod gait and observe its phase."""

    tipping_threshold_deg: float = XI_F_DEG
    """ξ_f [deg]: FASM below it means the robot is tipping (the paper's judgment threshold)."""
    stability_criterion = f"FASM >= ξ_f = {XI_F_DEG:g} deg (the paper's tipping judgment)"

    def __init__(
        self,
        *,
        action_mode: str = "residual",
        residual_scale: float = 0.25,
        residual_filter_tau: float = 0.1,
        min_progress: float = 0.5,
        control_dt: float = 0.02,
        physics_dt: float = 0.001,
        gait: TripodGaitParams | None = None,
        forward_weight: float = 1.0,
        stability_weight: float = 1.0,
        tip_over_penalty: float = 100.0,
        effort_weight: float = 0.05,
        contact_threshold: float = 0.02,
        tip_over_angle_deg: float = 20.0,
        reset_noise_scale: float = 0.01,
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
        check_choice("action_mode", action_mode, ACTION_MODES)
        self.action_mode = action_mode
        self.residual_scale = residual_scale
        self.robot = HeavyDutyParams()
        self.gait = TripodGait(self.robot, gait)
        self.weights = {
            "forward": forward_weight,
            "stability": stability_weight,
            "tip_over": tip_over_penalty,
            "effort": effort_weight,
        }
        self.contact_threshold = contact_threshold
        self.tip_over_cos = float(np.cos(np.radians(tip_over_angle_deg)))
        self.reset_noise_scale = reset_noise_scale
        # Physics run in reset() so the episode starts with the robot resting on its feet [s].
        self.settle_time = 0.5
        self.weight_n = self.robot.total_mass * 9.81
        self._contact_force_sq = (contact_threshold * self.weight_n) ** 2
        self.action_map = JointActionMap(np.tile(self.robot.joint_ranges, (6, 1)))
        self.action_space = spaces.Box(-1.0, 1.0, shape=(18,), dtype=np.float32)
        self._residual_gain = residual_scale * self.action_map.half
        if residual_filter_tau < 0:
            raise ValueError(f"residual_filter_tau must be >= 0 s, got {residual_filter_tau}")
        # First-order low-pass on the residual (a servo command filter): a step-to-step
        # jittering residual would otherwise hammer 5 t through 4e6 N/m servos.
        self._filter_alpha = control_dt / (residual_filter_tau + control_dt)
        self.min_progress = min_progress
        steps_per_cycle = self.gait.gait.period / control_dt
        if abs(steps_per_cycle - round(steps_per_cycle)) > 1e-9:
            raise ValueError("gait period must be a whole number of control periods")
        self._steps_per_cycle = int(round(steps_per_cycle))
        self._reference_table = np.array(
            [
                self.gait.joints_at_phase(k / self._steps_per_cycle).reshape(-1)
                for k in range(self._steps_per_cycle)
            ]
        )
        self._stand_steps = int(round(self.gait.gait.stand_time / control_dt))
        self._build()
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
                **({"gait_phase": 3} if self.walks else {}),
                **self._extra_observation_sizes(),
            }
        )

    # --- model ---------------------------------------------------------------------------
    def _add_terrain(self, spec: mujoco.MjSpec) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    def _robot_start_height(self) -> float:
        return self.robot.stand_height + 0.005

    def _build(self) -> None:
        spec = mujoco.MjSpec()
        spec.compiler.degree = False  # MjSpec defaults to degrees like MJCF; we use radians
        spec.modelname = type(self).__name__
        self._add_terrain(spec)
        self.handles = add_heavy_duty(spec, self.robot, pos=(0.0, 0.0, self._robot_start_height()))
        self._compile(spec)
        actuators = tuple(j for leg in LEG_NAMES for j in self.handles.joints[leg])
        self.sensors = RobotSensors(self.model, self.data, LEG_NAMES, actuators)
        self._act_ids = np.array([self.model.actuator(a).id for a in actuators])
        # qpos of each joint in actuator order, to start the robot in the commanded pose.
        self._joint_qpos = np.array(
            [self.model.jnt_qposadr[self.model.actuator_trnid[i, 0]] for i in self._act_ids]
        )
        self._gears = self.model.actuator_gear[self._act_ids, 0].copy()

    def _extra_observation_sizes(self) -> dict[str, int]:
        return {}

    # --- time and reference gait ------------------------------------------------------------
    @property
    def time(self) -> float:
        return self._step_count * self.control_dt

    def _gait_step(self) -> int:
        """Index into the reference table (the gait clock is frozen while standing)."""
        return max(0, self._step_count - self._stand_steps) % self._steps_per_cycle

    def reference_joints(self) -> np.ndarray:
        """(18,) reference tripod-gait joint targets at the current time."""
        return self._reference_table[self._gait_step()]

    def _ctrl_from_action(self, action: np.ndarray) -> np.ndarray:
        """Joint targets; MuJoCo clamps them to the servo ranges (ctrlrange)."""
        if self.action_mode == "joint":
            return self.action_map.to_joints(action)
        self._residual += self._filter_alpha * (self._residual_gain * action - self._residual)
        return self.reference_joints() + self._residual

    # --- reset / step --------------------------------------------------------------------
    def _initial_joints(self) -> np.ndarray:
        return self._reference_table[0]

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed, options=options)
        self._apply_task(self.task)
        mujoco.mj_resetData(self.model, self.data)
        self._step_count = 0
        self._residual = np.zeros(self.action_space.shape)
        self._on_reset()
        # The initial joint state is perturbed; the servo targets are not, and the settling
        # below lets the perturbation decay into a seed-dependent resting state.
        targets = self._initial_joints()
        noise = self.reset_noise_scale * self.action_map.half
        joints = targets + self.np_random.uniform(-noise, noise)
        joints = np.clip(joints, self.action_map.low, self.action_map.high)
        self.data.qpos[self._joint_qpos] = joints / self._gears
        self.data.ctrl[self._act_ids] = targets
        mujoco.mj_forward(self.model, self.data)
        # Let the robot settle onto its feet before the episode starts (not part of the episode).
        for _ in range(int(round(self.settle_time / self.control_dt))):
            self._simulate()
        self._tipped = False
        self._power = 0.0
        self._start_cog = self.sensors.cog().copy()
        self._prev_cog_x = float(self._start_cog[0])
        self._update_stability()
        self._last_obs = self._observation()
        return self._last_obs, self._info({}, unstable=False)

    def _on_reset(self) -> None:
        """Hook for scenario state (terrain randomisation, platform pose)."""

    def _reference_description(self) -> dict:
        """The reference: tripod gait parameters, its table of joint targets per control step
        of a cycle, steps per cycle and standing steps, residual scale and filter."""
        return {
            "gait": self.gait.gait,
            "reference_table": self._reference_table.copy(),
            "steps_per_cycle": self._steps_per_cycle,
            "stand_steps": self._stand_steps,
            "residual_scale": self.residual_scale,
            "residual_filter_alpha": self._filter_alpha,
            "walks": self.walks,
        }

    # --- task distribution -----------------------------------------------------------------
    PAYLOAD_RANGES = {"train": ((0.0, 500.0), 0.15), "test": ((500.0, 800.0), 0.25)}
    """Payload on the body per distribution: (mass range [kg], max CoG offset in x and y [m]).
    The test payload is heavier (extrapolated) and may sit farther off centre."""

    NO_PAYLOAD = {"payload_mass": 0.0, "payload_offset_x": 0.0, "payload_offset_y": 0.0}
    """The paper's scenarios carry no payload (task keys as `_sample_payload`'s)."""

    def _sample_payload(self, rng: np.random.Generator, distribution: str) -> dict:
        (m_lo, m_hi), off = self.PAYLOAD_RANGES[distribution]
        return {
            "payload_mass": float(rng.uniform(m_lo, m_hi)),
            "payload_offset_x": float(rng.uniform(-off, off)),
            "payload_offset_y": float(rng.uniform(-off, off)),
        }

    def _apply_task(self, task: dict) -> None:
        """Rebuild the model when the task changes it, then place the payload (a point mass
        added to the body at its CoG offset; the body's inertia is kept)."""
        if self._rebuild_needed(task):
            self._build()
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

    def _rebuild_needed(self, task: dict) -> bool:
        """Whether the task changes the terrain geometry (the model is then rebuilt)."""
        return False

    def step(self, action):
        action = self._validate_action(action, self.action_space)
        ctrl = self._ctrl_from_action(action)
        self._before_physics()
        self.data.ctrl[self._act_ids] = ctrl
        stable = self._simulate()
        self._step_count += 1
        if not stable:
            # Keep training runs alive: end the episode with a flag, return the last good obs.
            return self._last_obs.copy(), 0.0, False, True, self._info({}, unstable=True)
        self._update_stability()
        # The penalty is paid once, on the step the robot tips over; stepping on after the
        # episode terminated keeps `terminated` True and never pays it again.
        tipped = self._is_tipped_over() and not self._tipped
        self._tipped = self._tipped or tipped
        self._power = float(
            np.abs(self.sensors.actuator_forces() * self.sensors.joint_velocities()).sum()
        )
        cog_x = float(self.sensors.cog()[0])
        terms = self._reward_terms(tipped, cog_x)
        self._prev_cog_x = cog_x
        self._last_obs = self._observation()
        reward = float(sum(terms.values()))
        return self._last_obs, reward, self._tipped, False, self._info(terms, unstable=False)

    def _before_physics(self) -> None:
        """Hook run before each control period's physics (e.g. driving a platform)."""

    # --- stability -----------------------------------------------------------------------
    def _update_stability(self) -> None:
        forces = self.sensors.foot_forces()
        self._forces = forces
        self._loaded = (forces * forces).sum(axis=1) > self._contact_force_sq
        self._fasm_deg, self._fasm_edge = fasm_from_feet(
            self.sensors.foot_positions(), forces, self.sensors.cog(), self._loaded
        )

    def _is_tipped_over(self) -> bool:
        """True when the body up axis leans more than `tip_over_angle_deg` from vertical."""
        return bool(self.data.xmat[self.sensors.torso_id, 8] < self.tip_over_cos)

    # --- observation, reward, info ----------------------------------------------------------
    def _observation_pieces(self) -> dict[str, np.ndarray]:
        phase = self._gait_step() / self._steps_per_cycle
        walking = float(self._step_count >= self._stand_steps)
        return {
            "joint_pos": self.sensors.joint_positions(),
            "joint_vel": self.sensors.joint_velocities(),
            "foot_force": self._forces.reshape(-1),
            "foot_contact": self._loaded,
            "fasm_margin_deg": self._fasm_deg,
            "imu_gyro": self.sensors.gyro(),
            "imu_accel": self.sensors.accelerometer(),
            "imu_quat": self.sensors.orientation(),
            "gait_phase": (np.sin(2 * np.pi * phase), np.cos(2 * np.pi * phase), walking),
            **self._extra_observation_pieces(),
        }

    def _extra_observation_pieces(self) -> dict[str, np.ndarray]:
        return {}

    def step_cost_bound(self) -> float:
        """The largest cost one step can carry (the sum of the bounded negative parts of the
        forward, stability and effort terms); the ``alive`` term pays it on every step the robot
        is up, as Gymnasium's MuJoCo envs pay a healthy reward."""
        w = self.weights
        forward = w["forward"] if self.walks else 0.0
        stability = w["stability"] * self.tipping_threshold_deg / 45.0
        return forward + stability + w["effort"] * EFFORT_CAP

    def _reward_terms(self, tipped: bool, cog_x: float) -> dict[str, float]:
        """Named reward terms, each bounded; the progress term only in walking scenarios."""
        w = self.weights
        v_ref = self.gait.gait.body_speed
        margin = min(max(self._fasm_deg, -self.tipping_threshold_deg), 45.0)
        terms = {}
        if self.walks:
            # Progress up to the reference gait's speed: faster is not rewarded, so a policy
            # cannot trade stability for a scramble (PPO did, at 1 m/s with FASM ~ 0).
            speed = (cog_x - self._prev_cog_x) / self.control_dt
            terms["forward"] = w["forward"] * min(max(speed / v_ref, -1.0), 1.0)
        terms["stability"] = w["stability"] * margin / 45.0
        terms["alive"] = 0.0 if self._tipped else self.step_cost_bound()
        terms["tip_over"] = -w["tip_over"] if tipped else 0.0
        ratio = self._power / (self.weight_n * v_ref)
        terms["effort"] = -w["effort"] * min(ratio, EFFORT_CAP)
        return terms

    def _info(self, terms: dict[str, float], unstable: bool) -> dict:
        stance = tuple(leg for leg, on in zip(LEG_NAMES, self._loaded, strict=True) if on)
        edge = None
        if self._fasm_edge is not None:
            edge = (LEG_NAMES[self._fasm_edge[0]], LEG_NAMES[self._fasm_edge[1]])
        cog = self.sensors.cog()
        info = {f"reward_{name}": value for name, value in terms.items()}
        info.update(
            fasm_margin_deg=self._fasm_deg,
            fasm_edge=edge,
            stance_legs=stance,
            is_tipping=self._fasm_deg < self.tipping_threshold_deg,
            is_tipped_over=self._tipped,
            is_success=not self._tipped and not unstable and self._made_progress(cog),
            actuator_power_w=self._power,
            sim_unstable=unstable,
            time=self.time,
            cog=cog.copy(),
            distance=float(cog[0] - self._start_cog[0]),
            task=dict(self.task),
        )
        info.update(self._extra_info())
        return info

    def _extra_info(self) -> dict:
        return {}

    def _made_progress(self, cog: np.ndarray) -> bool:
        """Walking envs: at least `min_progress` of the reference gait's distance so far."""
        if not self.walks:
            return True
        walked = max(0.0, self.time - self.gait.gait.stand_time)
        return cog[0] - self._start_cog[0] >= self.min_progress * self.gait.gait.body_speed * walked
