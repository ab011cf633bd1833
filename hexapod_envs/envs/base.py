"""The episode skeleton every hexapod env shares (`HexapodEnv`).

`HexapodEnv` owns `reset` and `step`: typed settings, seeding, task draws, building and
rebuilding the model, the settle phase, the step counter and time, action validation, physics
with instability detection, termination and truncation, ``reward = sum of the named terms`` and
the common `info` keys (`hexapod_envs.info_keys`). A concrete env supplies the hooks listed in
`HexapodEnv`'s docstring; docs/architecture.md explains the layering. Its parts live next to
it: `physics` (solver options, stepping), `observation` (the layout), `actions` (the joint
action map), `task` (the task description), `safety` (the safety figures and the benchmark's
rules on them) and `rendering`.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from itertools import compress
from types import MappingProxyType
from typing import Any, ClassVar, NamedTuple

import gymnasium as gym
import mujoco
import numpy as np
from gymnasium import spaces

from .. import info_keys as keys
from . import _compiled
from .difficulty import DifficultySpan, task_difficulty
from .observation import ObservationLayout, PieceGroup, Reader
from .physics import (
    UNSTABLE_WARNINGS,
    set_physics_options,
    step_sensing_last,
    step_without_sensors,
    substeps_for,
)
from .rendering import (
    check_camera,
    close_renderer,
    make_renderer,
    render_frame,
    set_visual_options,
)
from .safety import SafetyFigures
from .settings import RENDER_MODES, TASK_DISTRIBUTIONS, EnvSettings
from .task import TaskDescription

__all__ = ["HexapodEnv", "Measurement"]

_RK4 = int(mujoco.mjtIntegrator.mjINT_RK4)


class Measurement(NamedTuple):
    """What `_measure` returns each step, stored by the skeleton as ``_forces``, ``_loaded``,
    ``_fasm_deg``, ``_fasm_edge`` and ``_cog``. The arrays may be the sensors' buffers, which
    the next measurement overwrites."""

    forces: np.ndarray
    """(n_legs, 3) ground reaction on each foot, world frame [N]."""
    loaded: np.ndarray
    """(n_legs,) bool: the foot is loaded (in contact)."""
    fasm_deg: float
    """FASM over the loaded feet [deg]."""
    fasm_edge: tuple[int, int] | None
    """Its edge as leg indices, None without a support polygon."""
    cog: np.ndarray
    """(3,) the robot's centre of gravity, world frame [m]."""


class HexapodEnv(SafetyFigures, gym.Env):
    """The episode skeleton: `reset` and `step` live here; a concrete env supplies hooks.

    Construction (``gym.make(id, **kwargs)``): the keyword arguments build ``self.settings``, an
    instance of the env's `Settings` dataclass (checked by name, see
    `hexapod_envs.envs.settings`); then `_setup()` (robot, action space, first model through
    `_build_model`) and the observation layout from `_observation_pieces()`.

    `reset`: seed ``np_random``; draw the task (`paper_task` or `sample_task`, also
    ``info["task"]``); `_apply_task` (may rebuild the model); reset MuJoCo's data;
    `_set_initial_state` (start pose, reset noise); settle for ``settings.settle_time``;
    `_start_episode` (controller clocks, counters); `_measure`; first observation and info.

    `step`: validate the action (clear errors, clipped into the space); `_apply_action` (servo
    commands); physics for one control period with instability detection (`_run_physics`, a
    MuJoCo warning or a clock that did not advance truncates with ``info["sim_unstable"]``,
    reward 0 and the last good observation); `_measure`; tip-over (`_is_tipped_over`, the
    penalty paid once, termination sticky); success (`_is_success`); the named reward terms
    (`_reward_terms`, the reward is their sum); `_end_step`; observation and info (common keys
    here, `_extra_info` for the env's own).

    Hooks with a default here: `_apply_task`, `_set_initial_state`, `_start_episode`,
    `_run_physics`, `midphase_pays`, `_end_step`, `_is_tipped_over`, `_is_tipping`, `_extra_info`,
    `_reference_description`. Hooks every env defines: `_setup`, `_build_spec`, `_bind_model`,
    `_observation_pieces`, `_apply_action`, `_measure` (returns a `Measurement`, stored as
    ``_forces``, ``_loaded``, ``_fasm_deg``, ``_fasm_edge``, ``_cog``), `_is_success`,
    `_reward_terms`, `step_cost_bound`, `paper_task`, `sample_task`.
    """

    Settings: ClassVar[type[EnvSettings]] = EnvSettings
    """The env's settings dataclass."""

    metadata: ClassVar[dict[str, Any]] = {
        "render_modes": list(RENDER_MODES),
        "render_fps": 50,
    }

    evaluation_metrics: ClassVar[dict[str, Any]] = {
        keys.MAX_TILT_DEG: {
            "reduce": "last",
            "better": "lower",
            "description": "the episode's largest body tilt [deg]",
        },
        keys.TIPPING_SHARE: {
            "reduce": "last",
            "better": "lower",
            "description": "share of the episode with the stability criterion failing",
        },
    }
    """Per-episode metrics the evaluation reports (`agents.pipeline.episode`): the safety
    figures of the success rule; an env extends the mapping with its own."""

    ends_on_success: ClassVar[bool] = False
    """Whether a successful step terminates the episode (a crossing) or success is a running
    status (walking on, staying up)."""

    difficulty_spans: ClassVar[Mapping[str, DifficultySpan]] = {}
    """Task parameter -> where it is easy and hard: ``info["task"]["difficulty"]`` (0 easy,
    1 hard) is their weighted mean (`hexapod_envs.envs.difficulty`); none: no difficulty."""

    def task_difficulty_spans(self) -> Mapping[str, DifficultySpan]:
        """The spans that rate this env's tasks (an env whose hard parameters depend on a
        setting, such as the terrain, picks them here)."""
        return self.difficulty_spans

    stability_criterion: str = "FASM >= ξ"
    """The stability criterion in words, for reports."""

    def __init__(self, **kwargs: Any):
        self.settings = s = self.Settings.from_kwargs(type(self).__name__, kwargs)
        """Every setting of this env (the defaults and the keyword arguments given), frozen:
        ``gym.make(id, **vars(env.unwrapped.settings))`` rebuilds the same env."""
        self.control_dt = float(s.control_dt)
        self.physics_dt = float(s.physics_dt)
        self.n_substeps = substeps_for(self.control_dt, self.physics_dt)
        self.settle_steps = int(round(s.settle_time / self.control_dt))
        """Control periods of physics run in `reset` before the episode starts."""
        self.task_distribution = s.task_distribution
        self.sensor_noise = float(s.sensor_noise)
        """Relative std of the Gaussian noise added to the observed foot forces and IMU
        (`_add_sensor_noise`); 0 (default) observes the true values."""
        self.reset_noise_scale = float(s.reset_noise_scale)
        self.tipping_threshold_deg = float(s.tipping_threshold_deg)
        """The robot's tipping threshold ξ on the FASM [deg]: `info["is_tipping"]` below it."""
        self.tip_over_cos = math.cos(math.radians(s.tip_over_angle_deg))
        self._margin_steps_to_tip = (
            None
            if s.tip_over_margin_time is None
            else max(1, int(round(s.tip_over_margin_time / self.control_dt)))
        )
        self.task: dict[str, Any] = {}
        """The episode's task parameters (plain floats/ints/strings), also `info["task"]`."""
        self._needs_reset = True
        self.render_mode = s.render_mode
        self.metadata = {**self.metadata, "render_fps": int(round(1.0 / self.control_dt))}
        self._render_size = (int(s.width), int(s.height))
        self._camera_name = s.camera_name
        self._renderer = None
        self.model: mujoco.MjModel | None = None
        self.data: mujoco.MjData | None = None
        self._setup()
        check_camera(self.model, self._camera_name)
        self._action_low = np.asarray(self.action_space.low, dtype=np.float64)
        self._action_high = np.asarray(self.action_space.high, dtype=np.float64)
        self._action = np.empty_like(self._action_low)
        self.observation_layout = ObservationLayout(self._observation_pieces())
        self.observation_space = spaces.Box(
            -np.inf, np.inf, shape=(self.observation_layout.size,), dtype=np.float64
        )
        self._obs_buffer = np.zeros(self.observation_layout.size)

    # --- model ---------------------------------------------------------------------------
    def _build_model(self) -> None:
        """Build the MjSpec (`_build_spec`), compile it with the env's physics options and
        resolve the ids the env reads (`_bind_model`)."""
        spec = mujoco.MjSpec()
        spec.compiler.degree = False  # MjSpec defaults to degrees like MJCF; we use radians
        spec.modelname = type(self).__name__
        self._build_spec(spec)
        s = self.settings
        set_physics_options(
            spec,
            s.physics_dt,
            s.integrator,
            s.solver_iterations,
            s.solver_ls_iterations,
            s.solver_tolerance,
            s.solver,
            self.midphase_pays() if s.midphase is None else s.midphase,
        )
        set_visual_options(spec, self._render_size)
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        m = self.model
        self._sensors_every_step = bool(  # attributes of MuJoCo >= 3.3's sensor histories
            getattr(m, "nhistory", 0)
            or np.any(getattr(m, "sensor_interval", 0))
            or np.any(getattr(m, "sensor_delay", 0))
        )
        if self._renderer is not None:
            close_renderer(self._renderer)
            self._renderer = None
        self._bind_model()

    def __deepcopy__(self, memo: dict) -> HexapodEnv:
        """A deep copy (MuJoCo model and data, controllers, RNG) that observes itself: the
        observation readers close over ``self`` and `copy.deepcopy` shares functions, so the
        copy's layout is rebuilt from its own `_observation_pieces`. Look-ahead and
        common-random-number rollouts step such copies (`hexapod_envs.wrappers.GainsPerCycle`).
        The renderer (an OpenGL context, which cannot be copied) is not: the copy makes its own
        at its first `render()`."""
        cls = type(self)
        new = cls.__new__(cls)
        memo[id(self)] = new
        for key, value in self.__dict__.items():
            if key not in ("observation_layout", "_renderer"):
                new.__dict__[key] = copy.deepcopy(value, memo)
        new._renderer = None
        new.observation_layout = ObservationLayout(new._observation_pieces())
        return new

    @property
    def observation_structure(self) -> dict[str, slice]:
        """Name -> slice of every piece of the flat observation vector."""
        return dict(self.observation_layout.slices)

    @property
    def action_read_flags(self) -> dict[int, int]:
        """Action values the env reads only on some steps: action index -> index of the
        observation value that is 1.0 when the next action's value at that index is read and
        0.0 when it is ignored. Empty (every env's default): every value is read on every step.
        A learner can leave an ignored value out of its action's likelihood
        (`agents.read_actions`)."""
        return {}

    @property
    def inert_actions(self) -> tuple[int, ...]:
        """Action values the env as configured never reads: whatever they are, nothing changes
        (the ditch crossing's residuals with a residual range of 0). Empty (every env's
        default): every value acts. A learner can leave them out of its action's likelihood
        (`agents.read_actions`)."""
        return ()

    def _observation(self) -> np.ndarray:
        self.observation_layout.write(self._obs_buffer)
        if self.sensor_noise:
            self._add_sensor_noise(self._obs_buffer)
        return self._obs_buffer.copy()

    def _add_sensor_noise(self, obs: np.ndarray) -> None:
        """Add zero-mean Gaussian noise (from `np_random`) to the observed sensors, with
        std `sensor_noise` x: a sixth of the robot's weight for each foot-force component [N],
        1 rad/s for the gyro, g for the accelerometer, 1 for the quaternion components (then
        renormalised). The info, FASM and reward keep the true values."""
        o, rng, k = self.observation_layout.slices, self.np_random, self.sensor_noise
        weight = float(self.model.body_subtreemass[self.sensors.torso_id]) * 9.81
        for name, scale in (
            ("foot_force", weight / 6),
            ("imu_gyro", 1.0),
            ("imu_accel", 9.81),
            ("imu_quat", 1.0),
        ):
            sl = o[name]
            obs[sl] += rng.normal(0.0, k * scale, sl.stop - sl.start)
        q = obs[o["imu_quat"]]
        q /= max(float(np.linalg.norm(q)), 1e-9)

    # --- episode ---------------------------------------------------------------------------
    @property
    def time(self) -> float:
        """Episode time [s] (the settle phase is not counted)."""
        return self._step_count * self.control_dt

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """A new episode on a task drawn from ``task_distribution`` with ``np_random`` (seeded
        by `seed`). The hexapod envs take no reset `options` (None or empty): the task comes
        from the seed and the distribution, and a non-empty dict is refused rather than
        ignored."""
        if options:
            raise ValueError(
                f"{type(self).__name__}.reset takes no options, got {sorted(options, key=str)}; "
                "the task comes from the seed and task_distribution (make the env with "
                f"task_distribution= one of {list(TASK_DISTRIBUTIONS)})"
            )
        super().reset(seed=seed, options=options)
        self._needs_reset = False
        if self.task_distribution == "paper":
            self.task = self.paper_task()
        else:
            self.task = self.sample_task(self.np_random, self.task_distribution)
        self._apply_task(self.task)  # may draw the rest of a paper task (added to self.task)
        spans = self.task_difficulty_spans()
        if spans:
            self.task["difficulty"] = task_difficulty(self.task, spans)
        mujoco.mj_resetData(self.model, self.data)
        self._set_initial_state()
        mujoco.mj_forward(self.model, self.data)
        settled = True
        for _ in range(self.settle_steps):  # the robot settles onto its feet: not episode time
            settled = self._simulate() and settled
        self._step_count = 0
        self._tipped = False
        self._start_episode()
        self._forces, self._loaded, self._fasm_deg, self._fasm_edge, self._cog = self._measure()
        self._start_safety()
        self._start_cog_x = self._prev_cog_x = float(self._cog[0])
        self._success = self._is_success()
        self._new_success = False
        obs, info = self._observation(), self._info({}, unstable=not settled)
        # An unstable settle shows in info["sim_unstable"] now; MuJoCo's warning counts stay
        # until the next reset, so the first step truncates as unstable too.
        if self.render_mode == "human":
            self.render()
        return obs, info

    def step(self, action):
        action = self._validate_action(action)
        self._apply_action(action)
        stable = self._simulate()
        self._step_count += 1
        if not stable:
            # Keep training runs alive: end the episode with a flag and the last good observation
            # (the buffer it was copied from, which no caller holds); an episode that already
            # ended (stepped on after a tip-over or a crossing) stays terminated.
            info = self._info({}, unstable=True)
            return self._obs_buffer.copy(), 0.0, self._terminated, True, info
        self._forces, self._loaded, self._fasm_deg, self._fasm_edge, self._cog = self._measure()
        self._track_safety()
        # The penalty is paid once, on the step the robot tips over; stepping on after the
        # episode terminated keeps `terminated` True and never pays it again.
        tipped = not self._tipped and (self._is_tipped_over() or self._margin_lost())
        self._tipped = self._tipped or tipped
        # Likewise a success that ends the episode stays (and its bonus is paid once: on the
        # step `_new_success` is True).
        succeeded_before = self.ends_on_success and self._success
        self._success = not self._tipped and (
            succeeded_before or (self._is_success() and self._stayed_stable())
        )
        self._new_success = self._success and not succeeded_before
        terms = self._reward_terms(tipped)
        self._end_step()
        self._prev_cog_x = float(self._cog[0])
        obs = self._observation()
        reward = float(sum(terms.values()))
        if self.render_mode == "human":
            self.render()
        return obs, reward, self._terminated, False, self._info(terms, unstable=False)

    @property
    def _terminated(self) -> bool:
        """The episode has ended: a tip-over, or a success that ends it (`ends_on_success`)."""
        return self._tipped or (self.ends_on_success and self._success)

    def _info(self, terms: dict[str, float], unstable: bool) -> dict:
        """The common info keys (`hexapod_envs.info_keys`) plus the env's `_extra_info`, then
        the reward terms (``reward_<term>``)."""
        legs, edge = self.sensors.legs, self._fasm_edge
        info = {
            keys.FASM_MARGIN_DEG: self._fasm_deg,
            keys.FASM_EDGE: None if edge is None else (legs[edge[0]], legs[edge[1]]),
            keys.STANCE_LEGS: tuple(compress(legs, self._loaded.tolist())),
            keys.IS_TIPPING: self._tipping,
            keys.IS_TIPPED_OVER: self._tipped,
            keys.IS_SUCCESS: self._success and not unstable,
            keys.SIM_UNSTABLE: unstable,
            keys.TIME: self.time,
            keys.COG: self._cog.copy(),
            keys.DISTANCE: float(self._cog[0]) - self._start_cog_x,
            keys.TASK: dict(self.task),
            keys.TILT_DEG: self._tilt_deg,
            keys.MAX_TILT_DEG: self._max_tilt_deg,
            keys.TIPPING_TIME_S: self._tipping_steps * self.control_dt,
            keys.TIPPING_SHARE: self._tipping_share,
            **self._extra_info(unstable),
        }
        for name, value in terms.items():
            info[keys.REWARD_PREFIX + name] = value
        return info

    # --- hooks every env defines ----------------------------------------------------------
    def _setup(self) -> None:  # pragma: no cover - abstract
        """Robot, action space and mappings from ``self.settings``; then `_build_model()`."""
        raise NotImplementedError

    def _build_spec(self, spec: mujoco.MjSpec) -> None:  # pragma: no cover - abstract
        """Add the terrain and the robot to `spec`."""
        raise NotImplementedError

    def midphase_pays(self) -> bool:
        """Whether the collision midphase makes this env's physics faster (the default of the
        ``midphase`` setting): it pays where a body has many geoms, such as a terrain of
        hundreds of boxes, and costs where every body has few."""
        return True

    def _bind_model(self) -> None:  # pragma: no cover - abstract
        """Resolve the ids the env reads in the compiled model (sensors, actuators, qpos)."""
        raise NotImplementedError

    def _observation_pieces(self) -> dict[str, tuple[int, Reader] | PieceGroup]:  # pragma: no cover
        """Ordered name -> (size, reader) or `PieceGroup` of the observation (see
        `ObservationLayout`)."""
        raise NotImplementedError

    def _sensor_pieces(self) -> PieceGroup:
        """The observation's sensor pieces (`RobotSensors.OBSERVED`: encoders, measured foot
        forces and contacts, FASM, IMU) in one compiled write. The writer looks the sensors up
        at call time: a task may rebuild the model (and the sensors)."""
        return PieceGroup(
            self.sensors.observed_sizes(),
            lambda out: self.sensors.write_observation(
                out, self._forces, self._loaded, self._fasm_deg
            ),
        )

    def _apply_action(self, action: np.ndarray) -> None:  # pragma: no cover - abstract
        """Write the servo commands of a validated action into ``self.data``."""
        raise NotImplementedError

    def _measure(self) -> Measurement:  # pragma: no cover - abstract
        """Read the robot's sensors: return the skeleton's `Measurement` (and set the env's own
        measurements)."""
        raise NotImplementedError

    def _is_success(self) -> bool:  # pragma: no cover - abstract
        """The env's success rule for the episode so far (not called while tipped over)."""
        raise NotImplementedError

    def _reward_terms(self, tipped: bool) -> dict[str, float]:  # pragma: no cover - abstract
        """Named, bounded reward terms of the step; `tipped`: the robot tipped over now."""
        raise NotImplementedError

    def step_cost_bound(self) -> float:  # pragma: no cover - abstract
        """The largest cost one step can carry: the ``alive`` term pays it while the robot is
        up, so that tipping over early never returns more than staying up."""
        raise NotImplementedError

    # --- hooks with defaults ---------------------------------------------------------------
    def _apply_task(self, task: dict[str, Any]) -> None:
        """Set the episode's task (terrain, friction, payload...); rebuild the model if the
        task changes its geometry (`_build_model`)."""

    def _set_initial_state(self) -> None:
        """Write the start pose into the freshly reset data (qpos, ctrl, act); the seed-dependent
        reset noise is drawn here from `np_random`."""

    def _start_episode(self) -> None:
        """Reset the episode's own state after the settle phase (clocks, filters, counters)."""

    def _end_step(self) -> None:
        """Bookkeeping after the reward of a step (e.g. per-gait-cycle statistics)."""

    def _is_tipped_over(self) -> bool:
        """True when the body's up axis leans more than ``tip_over_angle_deg`` from vertical."""
        return self._tilt_cos_now < self.tip_over_cos  # read this step (`_read_posture`)

    def _is_tipping(self) -> bool:
        """The stability criterion fails: FASM below the robot's ξ."""
        return self._fasm_deg < self.tipping_threshold_deg

    def _extra_info(self, unstable: bool) -> dict[str, Any]:
        """The env's own info keys (documented in its module docstring)."""
        return {}

    def _reference_description(self) -> dict[str, Any]:
        return {}

    def paper_task(self) -> dict[str, Any]:
        """The task parameters of the paper's scenario (from the constructor's settings)."""
        return {}

    def sample_task(self, rng: np.random.Generator, distribution: str) -> dict[str, Any]:
        """Task parameters drawn from the `distribution` ("train" or "test") ranges."""
        return self.paper_task()

    # --- task description ------------------------------------------------------------------
    @property
    def task_description(self) -> TaskDescription:
        """The declared task description of the current episode (see `TaskDescription`)."""
        low, high = self._joint_limits()
        return TaskDescription(
            robot=self._robot_params(),
            action_mode=self.action_mode,
            control_dt=float(self.control_dt),
            joint_low=tuple(float(x) for x in low),
            joint_high=tuple(float(x) for x in high),
            tipping_threshold_deg=float(self.tipping_threshold_deg),
            stability_criterion=self.stability_criterion,
            course=MappingProxyType(dict(self.task)),
            reference=MappingProxyType(self._reference_description()),
            observation_structure=MappingProxyType(self.observation_structure),
        )

    def _robot_params(self) -> Any:
        return self.robot

    def _joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        return self.action_map.low, self.action_map.high

    # --- stepping ------------------------------------------------------------------------
    def _validate_action(self, action: Any) -> np.ndarray:
        """Check that an episode is running, the dtype is real, shape and finiteness (clear
        errors), then clip into the action space: the env's action buffer (float64), which the
        next step overwrites."""
        if self._needs_reset:
            raise RuntimeError(f"{type(self).__name__}: call reset() first, before step()")
        a = np.asarray(action)
        if a.dtype.kind not in "fiu":
            raise ValueError(
                f"action must be real numbers (float or int), got dtype {a.dtype}; "
                "complex, bool, string and object actions are refused"
            )
        if a.shape != self._action_low.shape:
            raise ValueError(
                f"action has shape {a.shape}; this env expects {self._action_low.shape}"
            )
        if a.dtype != np.float32:  # the action space's dtype; the others as float64 (compiled)
            a = a.astype(np.float64, copy=False)
        if not _compiled.clip_action(a, self._action_low, self._action_high, self._action):
            bad = np.flatnonzero(~np.isfinite(a)).tolist()
            raise ValueError(f"action contains NaN or inf at indices {bad}")
        return self._action

    _UNSTABLE_WARNINGS = UNSTABLE_WARNINGS
    """MuJoCo warnings that count as instability (`physics.UNSTABLE_WARNINGS`)."""

    def _simulate(self) -> bool:
        """Run the physics for one control period; False if the simulation went unstable.

        MuJoCo resets the state when it meets NaN/huge values and counts a warning; either sign
        (a warning or a clock that did not advance by one control period) means unstable.
        """
        t_expected = self.data.time + self.control_dt
        self._run_physics()
        return self._stayed_stable_to(t_expected)

    def _stayed_stable_to(self, t_expected: float) -> bool:
        """After a control period's physics: the clock reached `t_expected` [s] and MuJoCo
        counted no instability warning."""
        if abs(self.data.time - t_expected) > 1e-6:
            return False
        return not any(self.data.warning.number[self._UNSTABLE_WARNINGS].tolist())

    def _run_physics(self) -> None:
        """One control period of MuJoCo steps (an env may split it to sample contacts)."""
        self._step_sensing_last(self.n_substeps)

    def _step_sensing_last(self, nstep: int) -> None:
        """`nstep` MuJoCo steps, the sensors evaluated in the last one only (`step_sensing_last`),
        unless the model's sensors keep a history (delay, interval): those need every step."""
        if self._sensors_every_step:
            mujoco.mj_step(self.model, self.data, nstep=nstep)
        else:
            step_sensing_last(self.model, self.data, nstep)

    def _step_sensing_position(self, nstep: int) -> None:
        """`nstep` MuJoCo steps for a check within a control period (whose last step evaluates
        every sensor): without sensors, then the position-stage sensors alone (`mj_sensorPos`).

        Contact counts, frames and rangefinders then read what a full evaluation in the last
        step reads: the collisions and kinematics of that step's start. Encoders read the
        stepped qpos instead, so only the former may be read between evaluations. Under RK4,
        whose intermediate stages overwrite the contacts, and with sensors that keep a history,
        every sensor is evaluated in the last step instead (`_step_sensing_last`)."""
        if self._sensors_every_step or self.model.opt.integrator == _RK4:
            self._step_sensing_last(nstep)
        else:
            step_without_sensors(self.model, self.data, nstep)
            mujoco.mj_sensorPos(self.model, self.data)

    # --- rendering -----------------------------------------------------------------------
    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode= to make()")
            return None
        if self._renderer is None:
            self._renderer = make_renderer(
                self.model, self.data, self._camera_name, self._render_size
            )
        try:
            return render_frame(self._renderer, self.render_mode)
        except mujoco.FatalError as error:
            if "OpenGL" not in str(error):
                raise
            raise RuntimeError(
                f"rendering needs an OpenGL context, and MuJoCo found none ({error}). Without "
                "a display, set MUJOCO_GL=egl (or osmesa) in the environment before Python "
                "starts: MUJOCO_GL=egl python your_script.py"
            ) from error

    def close(self):
        if self._renderer is not None:
            close_renderer(self._renderer)
            self._renderer = None
