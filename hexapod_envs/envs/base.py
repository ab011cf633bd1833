"""Shared machinery of every hexapod env: model building, fixed control timing, stepping with
instability detection, observations from named pieces, reward from named terms, rendering.

Subclasses provide the model (`_build_spec`), the action mapping (`_ctrl_from_action`), the
observation pieces (`_observation_pieces`), the reward terms and the termination rule.
"""

from __future__ import annotations

import dataclasses
import inspect
import math
import numbers
import re
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any, ClassVar

import gymnasium as gym
import mujoco
import numpy as np
from gymnasium import spaces

DEFAULT_CAMERA = {"distance": 14.0, "elevation": -20.0, "azimuth": 135.0, "trackbodyid": 1}


def check_kwargs(cls: type, kwargs: Mapping[str, Any]) -> None:
    """Raise a TypeError naming unknown keyword arguments and listing the valid ones."""
    valid: set[str] = set()
    for klass in cls.__mro__:
        init = klass.__dict__.get("__init__")
        if init is None:
            continue
        params = inspect.signature(init).parameters.values()
        valid |= {p.name for p in params if p.kind is p.KEYWORD_ONLY}
        if not any(p.kind is p.VAR_KEYWORD for p in params):
            break
    unknown = sorted(set(kwargs) - set(valid))
    if unknown:
        raise TypeError(
            f"{cls.__name__} got unknown keyword argument(s) {unknown}; valid: {sorted(valid)}"
        )


TASK_DISTRIBUTIONS = ("paper", "train", "test")
"""``task_distribution`` values: the paper's scenario (plus small reset noise), or task and
physical parameters sampled at every reset from the env's training or held-out test ranges."""

SIGNED_SETTINGS = frozenset(
    {
        "cliff_x",
        "cliff_edge_y",
        "ramp_start_x",
        "block_region",
        "ditch_start_x",
        "ditch_start_x_range",
    }
)
"""Numeric settings for which a negative value is meaningful (positions, signed offsets)."""


def _settings_signature(cls: type) -> dict[str, inspect.Parameter]:
    """Keyword-only parameters of `cls.__init__` and of the bases it forwards **kwargs to."""
    params: dict[str, inspect.Parameter] = {}
    for klass in cls.__mro__:
        init = klass.__dict__.get("__init__")
        if init is None:
            continue
        sig = inspect.signature(init).parameters.values()
        for p in sig:
            if p.kind is p.KEYWORD_ONLY:
                params.setdefault(p.name, p)
        if not any(p.kind is p.VAR_KEYWORD for p in sig):
            break
    return params


def _numbers_in(value: Any):
    if isinstance(value, (tuple, list)):
        for v in value:
            yield from _numbers_in(v)
    else:
        yield value


def check_settings(cls: type, kwargs: Mapping[str, Any]) -> None:
    """Check every numeric setting passed to `cls` by name: a real number (not a string, bool
    or complex), finite, and >= 0 unless the setting is signed (`SIGNED_SETTINGS`). Numeric
    settings are those whose annotation is int/float or a tuple of them. Raises ValueError
    naming the setting, so a bad value never reaches the physics (NaN gains, inf drops)."""
    params = _settings_signature(cls)
    for name, value in kwargs.items():
        p = params.get(name)
        if p is None or value is None:
            continue
        ann = str(p.annotation)
        if not re.match(r"^(int|float|tuple\[[\w\[\], .]*\])( \| None)?$", ann):
            continue
        if ann.startswith("tuple") and not isinstance(value, (tuple, list)):
            raise ValueError(f"{name} must be a tuple of numbers, got {value!r}")
        for x in _numbers_in(value):
            if isinstance(x, bool) or not isinstance(x, numbers.Real):
                kind = type(x).__name__
                raise ValueError(f"{name} must be a real number, got {value!r} ({kind})")
            if not math.isfinite(float(x)):
                raise ValueError(f"{name} must be finite, got {value!r}")
            if name not in SIGNED_SETTINGS and x < 0:
                raise ValueError(f"{name} must be >= 0, got {value!r}")
    if "task_distribution" in kwargs:
        check_choice("task_distribution", kwargs["task_distribution"], TASK_DISTRIBUTIONS)


_SETTINGS_CLASSES: dict[type, type] = {}


def settings_class(cls: type) -> type:
    """A frozen dataclass with one field per keyword setting of `cls` (its name, annotation and
    default), built once per env class: ``env.unwrapped.settings`` is an instance of it."""
    if cls not in _SETTINGS_CLASSES:
        fields = [
            (name, p.annotation, dataclasses.field(default=p.default))
            for name, p in _settings_signature(cls).items()
        ]
        _SETTINGS_CLASSES[cls] = dataclasses.make_dataclass(
            f"{cls.__name__}Settings", fields, frozen=True
        )
    return _SETTINGS_CLASSES[cls]


def check_choice(name: str, value: Any, choices) -> None:
    """Raise a ValueError naming `name`, the bad value and the valid choices."""
    if value not in choices:
        raise ValueError(f"{name} must be one of {sorted(choices)}, got {value!r}")


class JointActionMap:
    """Maps normalised actions in [-1, 1] to joint targets in the robot's units and back."""

    def __init__(self, ranges: np.ndarray):
        ranges = np.asarray(ranges, dtype=float)
        self.low, self.high = ranges[:, 0], ranges[:, 1]
        self.center = (self.low + self.high) / 2
        self.half = (self.high - self.low) / 2

    def to_joints(self, action: np.ndarray) -> np.ndarray:
        return self.center + self.half * np.asarray(action)

    def to_action(self, joints: np.ndarray) -> np.ndarray:
        return np.clip((np.asarray(joints).reshape(-1) - self.center) / self.half, -1.0, 1.0)


def substeps_for(control_dt: float, physics_dt: float) -> int:
    """Physics steps per control step; the ratio must be a whole number."""
    if control_dt <= 0 or physics_dt <= 0:
        raise ValueError(f"control_dt and physics_dt must be > 0, got {control_dt}, {physics_dt}")
    n = round(control_dt / physics_dt)
    if n < 1 or abs(n * physics_dt - control_dt) > 1e-9 * max(1.0, control_dt):
        raise ValueError(
            f"control_dt={control_dt} s is not a whole multiple of physics_dt={physics_dt} s"
        )
    return n


class ObservationLayout:
    """An ordered list of named pieces laid out in one flat vector (name -> slice)."""

    def __init__(self, sizes: Mapping[str, int]):
        self.slices: dict[str, slice] = {}
        start = 0
        for name, size in sizes.items():
            self.slices[name] = slice(start, start + size)
            start += size
        self.size = start

    def pack(self, pieces: Mapping[str, np.ndarray], out: np.ndarray) -> np.ndarray:
        for name, sl in self.slices.items():
            out[sl] = pieces[name]
        return out

    def unpack(self, observation: np.ndarray) -> dict[str, np.ndarray]:
        return {name: observation[..., sl] for name, sl in self.slices.items()}


def set_physics_options(spec: mujoco.MjSpec, timestep: float) -> None:
    """The solver options every env uses: `timestep` [s], implicit-fast integration, and
    elliptic friction cones with a high impedance ratio (the default pyramidal cone lets a
    loaded foot creep down a slope at several cm/s, far below its friction limit)."""
    spec.option.timestep = timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = 10.0


@dataclasses.dataclass(frozen=True)
class TaskDescription:
    """What a controller may know about the env's task, declared by the env (instead of reading
    its attributes): robot, action mapping, timing, stability criterion, the episode's course
    and the reference gait. Per-step information comes through the observation."""

    robot: Any
    """The robot's parameters (frozen dataclass of its `params` module)."""
    action_mode: str
    control_dt: float
    """Control period [s]."""
    joint_low: tuple[float, ...]
    """Joint (command) target at action -1, per action entry, robot units ("joint" mode)."""
    joint_high: tuple[float, ...]
    """Joint (command) target at action +1."""
    tipping_threshold_deg: float
    stability_criterion: str
    course: Mapping[str, Any]
    """The episode's task parameters (`info["task"]`, read-only)."""
    reference: Mapping[str, Any]
    """Env-specific reference gait and timing (see the env's `_reference_description`)."""


class HexapodEnv(gym.Env):
    """Base class; see the module docstring. Keyword arguments are checked by name."""

    metadata: ClassVar[dict[str, Any]] = {
        "render_modes": ["human", "rgb_array", "depth_array"],
        "render_fps": 50,
    }

    def __new__(cls, *args: Any, **kwargs: Any):
        check_kwargs(cls, kwargs)
        check_settings(cls, kwargs)
        env = super().__new__(cls)
        env.settings = settings_class(cls)(**kwargs)
        """Every setting of this env (the defaults and the keyword arguments given), frozen:
        ``gym.make(id, **vars(env.unwrapped.settings))`` rebuilds the same env."""
        return env

    def __init__(
        self,
        *,
        control_dt: float,
        physics_dt: float,
        render_mode: str | None = None,
        width: int = 640,
        height: int = 480,
        camera_name: str | None = None,
        task_distribution: str = "paper",
        sensor_noise: float = 0.0,
    ):
        check_choice("task_distribution", task_distribution, TASK_DISTRIBUTIONS)
        self.sensor_noise = float(sensor_noise)
        """Relative std of the Gaussian noise added to the observed foot forces and IMU
        (`_add_sensor_noise`); 0 (default) observes the true values."""
        self.task_distribution = task_distribution
        self.task: dict[str, Any] = {}
        """The episode's task parameters (plain floats/ints/strings), also `info["task"]`."""
        self._needs_reset = True
        if render_mode is not None:
            check_choice("render_mode", render_mode, self.metadata["render_modes"])
        self.control_dt = control_dt
        self.physics_dt = physics_dt
        self.n_substeps = substeps_for(control_dt, physics_dt)
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "render_fps": int(round(1.0 / control_dt))}
        self._render_size = (width, height)
        self._camera_name = camera_name
        self._renderer = None
        self.model: mujoco.MjModel | None = None
        self.data: mujoco.MjData | None = None

    # --- model ---------------------------------------------------------------------------
    def _compile(self, spec: mujoco.MjSpec) -> None:
        """Compile `spec` with the env's physics timestep and (re)create data."""
        set_physics_options(spec, self.physics_dt)
        spec.visual.headlight.ambient = [0.35, 0.35, 0.35]
        spec.visual.headlight.diffuse = [0.65, 0.65, 0.65]
        spec.worldbody.add_light(
            name="sun", pos=[0, 0, 30], dir=[0.3, 0.2, -1.0], diffuse=[0.5, 0.5, 0.5]
        )
        spec.visual.global_.offwidth = max(self._render_size[0], 640)
        spec.visual.global_.offheight = max(self._render_size[1], 480)
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def _set_observation_layout(self, sizes: Mapping[str, int]) -> None:
        self.observation_layout = ObservationLayout(sizes)
        self.observation_space = spaces.Box(
            -np.inf, np.inf, shape=(self.observation_layout.size,), dtype=np.float64
        )
        self._obs_buffer = np.zeros(self.observation_layout.size)

    @property
    def observation_structure(self) -> dict[str, slice]:
        """Name -> slice of every piece of the flat observation vector."""
        return dict(self.observation_layout.slices)

    def _observation(self) -> np.ndarray:
        self.observation_layout.pack(self._observation_pieces(), self._obs_buffer)
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
    tipping_threshold_deg: float = 20.0
    """The robot's tipping threshold ξ on the FASM [deg]: `info["is_tipping"]` below it."""
    stability_criterion: str = "FASM >= 20 deg"
    """The stability criterion in words, for reports."""

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Seed `np_random` and draw the episode's task (`sample_task`); subclasses extend it."""
        super().reset(seed=seed, options=options)
        self._needs_reset = False
        if self.task_distribution == "paper":
            self.task = self.paper_task()
        else:
            self.task = self.sample_task(self.np_random, self.task_distribution)
        return None

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
        )

    def _robot_params(self) -> Any:
        return self.robot

    def _joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        return self.action_map.low, self.action_map.high

    def _reference_description(self) -> dict[str, Any]:
        return {}

    def paper_task(self) -> dict[str, Any]:
        """The task parameters of the paper's scenario (from the constructor's settings)."""
        return {}

    def sample_task(self, rng: np.random.Generator, distribution: str) -> dict[str, Any]:
        """Task parameters drawn from the `distribution` ("train" or "test") ranges."""
        return self.paper_task()

    # --- stepping ------------------------------------------------------------------------
    def _validate_action(self, action: Any, space: spaces.Box) -> np.ndarray:
        """Check that an episode is running, the dtype is real, shape and finiteness (clear
        errors), then clip into the action space."""
        if self._needs_reset:
            raise RuntimeError(f"{type(self).__name__}: call reset() first, before step()")
        a = np.asarray(action)
        if a.dtype.kind not in "fiu":
            raise ValueError(
                f"action must be real numbers (float or int), got dtype {a.dtype}; "
                "complex, bool, string and object actions are refused"
            )
        a = a.astype(np.float64, copy=False)
        if a.shape != space.shape:
            raise ValueError(f"action has shape {a.shape}; this env expects {space.shape}")
        if not math.isfinite(a.sum()):  # one reduction instead of an element-wise test
            bad = np.flatnonzero(~np.isfinite(a)).tolist()
            if bad:
                raise ValueError(f"action contains NaN or inf at indices {bad}")
        return np.clip(a, space.low, space.high)

    _UNSTABLE_WARNINGS = [
        int(mujoco.mjtWarning.mjWARN_BADQACC),
        int(mujoco.mjtWarning.mjWARN_BADQVEL),
        int(mujoco.mjtWarning.mjWARN_BADQPOS),
        int(mujoco.mjtWarning.mjWARN_BADCTRL),
    ]
    """MuJoCo warnings that count as instability (`info["sim_unstable"]`, truncation)."""

    def _simulate(self, ctrl: np.ndarray | None = None) -> bool:
        """Run the physics for one control period; False if the simulation went unstable.

        MuJoCo resets the state when it meets NaN/huge values and counts a warning; either sign
        (a warning or a clock that did not advance by one control period) means unstable.
        """
        if ctrl is not None:
            self.data.ctrl[:] = ctrl
        t_expected = self.data.time + self.control_dt
        mujoco.mj_step(self.model, self.data, nstep=self.n_substeps)
        if abs(self.data.time - t_expected) > 1e-6:
            return False
        return not self.data.warning.number[self._UNSTABLE_WARNINGS].any()

    def _observation_pieces(self) -> dict[str, np.ndarray]:  # pragma: no cover - abstract
        raise NotImplementedError

    # --- rendering -----------------------------------------------------------------------
    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode= to make()")
            return None
        if self._renderer is None:
            from gymnasium.envs.mujoco.mujoco_rendering import MujocoRenderer

            cam_id = None
            if self._camera_name is not None:
                cam_id = self.model.camera(self._camera_name).id
            self._renderer = MujocoRenderer(
                self.model,
                self.data,
                default_cam_config=None if cam_id is not None else DEFAULT_CAMERA,
                width=self._render_size[0],
                height=self._render_size[1],
                camera_id=cam_id,
            )
        return self._renderer.render(self.render_mode)

    def close(self):
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
