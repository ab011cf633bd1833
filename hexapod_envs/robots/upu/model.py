"""MuJoCo model of the 3-UPU hexapod walking robot, generated from `UpuParams` with MjSpec.

Structure (names follow the package's model-building contract where it applies):

- ``torso``: the lower platform, with the free joint ``root`` and the IMU site ``imu``
  (sensors ``imu_gyro``, ``imu_accel``, ``imu_quat``). Its frame is the paper's O-xyz: origin
  at the centre of the lower Hooke joints, x forward, z up.
- ``upper``: the upper platform, a child of the torso joined by three slide joints ``upper_x``,
  ``upper_y``, ``upper_z`` (unactuated), so that it can only translate relative to the lower
  platform, which is exactly the motion the 3-UPU mechanism allows (paper §2). Its origin O' is
  at the centre of the upper Hooke joints; slide positions are measured from
  (0, 0, initial_height).
- The limbs ``limb1..3``: spatial tendons from the Hooke-joint sites ``hooke_A<i>`` (torso) to
  ``hooke_B<i>`` (upper), each driven by a position actuator of the same name whose control is
  the limb length [m], ctrlrange = [limb_min, limb_max]; the tendons also have end stops at
  those limits. The servo is PD by default: under the upper half's weight the platform settles
  up to ~3 mm (mostly horizontally) from the IK pose, as the closed-form compliance predicts;
  `UpuParams.limb_integral_gain` > 0 switches to MuJoCo 4's PID actuator. Sensors
  ``limb<i>_length`` (tendon length). The Hooke-joint angle limits are not enforced by the
  model (the slide joints replace the joints); planners check them with
  `kinematics.check_limits`.
- Per leg ``U1 U2 U3`` (upper) and ``L1 L2 L3`` (lower): body ``<leg>_leg`` with the slide
  joint ``<leg>_extend`` along -z (extension [m], + = longer leg, range
  [-leg_retract, leg_extend]), a position actuator ``<leg>_extend``, a joint sensor
  ``<leg>_extend_pos``; the foot body ``<leg>_foot`` (no joint; origin at the sole) with the site
  ``<leg>_foot`` carrying a 3-D ``force`` sensor ``<leg>_foot_force`` and a ``touch`` sensor
  ``<leg>_foot_touch`` (the paper's per-leg pressure switch: normal contact force [N]). The
  force sensor reads the force the leg exerts on the foot, in the site frame (parallel to its
  platform's frame); for a foot at rest the ground reaction force on it is
  -R_site @ sensor - foot_mass * g with g = (0, 0, -9.81) m/s^2 (world frame), checked by
  tests/hexapod_envs/robots/upu/test_upu_model.py.

Command modes (`add_upu(..., command=...)`): ``"position"`` (default): each actuator's ctrl is
its target (limb length or leg extension [m]). ``"interpolated"``: the servo target is the
actuator's activation (act, clamped to the same ranges) and ctrl is its rate [m/s], limited to
`UpuParams.limb_speed_limit` / `leg_speed_limit`: an executor that wants target T at the end of
a control period of length dt sets ctrl = (T - act) / dt, and MuJoCo moves the target linearly
within the period (a first-order hold, as servo drives interpolate set-points). A controller
running at a few tens of Hz then drives the robot as smoothly as one that sets every physics
step, with no per-step Python work; stepping a position target at 20 Hz instead jerks the
5e5 N/m limb servos into their force limit and makes the feet slip.

Collisions: robot geoms have contype 1 / conaffinity 0 and terrain geoms contype 0 /
conaffinity 1, so the robot touches only the terrain, never itself (the upper legs pass beside
the lower platform). The stiff limb servos want a timestep of at most `RECOMMENDED_TIMESTEP`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from ..sensor_spec import add_foot_force_sensor, add_imu_sensors
from .kinematics import inverse_kinematics
from .params import (
    LEG_NAMES,
    LIMB_NAMES,
    LOWER_LEGS,
    UPPER_LEGS,
    UpuParams,
    leg_platform,
)

RECOMMENDED_TIMESTEP = 0.002
"""[s] Largest timestep tested with the stiff limb servos (5e5 N/m, explicit in MuJoCo) and the
implicitfast integrator (which treats the servo damping implicitly)."""

UPPER_JOINTS: tuple[str, str, str] = ("upper_x", "upper_y", "upper_z")
_ROBOT_COLLISION = {"contype": 1, "conaffinity": 0}
_NO_COLLISION = {"contype": 0, "conaffinity": 0}
_PLATE_THICKNESS = 0.02
_SLIDE_RANGE_XY = 0.35
_SLIDE_RANGE_Z = (-0.12, 0.12)


@dataclass(frozen=True)
class UpuHandles:
    """Names created by `add_upu`, for named accessors in envs and tests."""

    legs: tuple[str, ...] = LEG_NAMES
    upper_legs: tuple[str, ...] = UPPER_LEGS
    lower_legs: tuple[str, ...] = LOWER_LEGS
    limbs: tuple[str, ...] = LIMB_NAMES
    """Tendon names = limb actuator names; ctrl is the limb length [m]."""
    limb_length_sensors: tuple[str, ...] = tuple(f"{n}_length" for n in LIMB_NAMES)
    upper_body: str = "upper"
    upper_joints: tuple[str, str, str] = UPPER_JOINTS
    torso: str = "torso"
    root_joint: str = "root"
    imu_site: str = "imu"
    imu_sensors: tuple[str, str, str] = ("imu_gyro", "imu_accel", "imu_quat")

    def leg_joint(self, leg: str) -> str:
        """Slide joint (= actuator) name of `leg`'s length servo."""
        leg_platform(leg)
        return f"{leg}_extend"

    def foot(self, leg: str) -> str:
        """Foot body name = foot site name."""
        leg_platform(leg)
        return f"{leg}_foot"

    @property
    def leg_joints(self) -> tuple[str, ...]:
        return tuple(self.leg_joint(leg) for leg in self.legs)

    @property
    def leg_actuators(self) -> tuple[str, ...]:
        return self.leg_joints

    @property
    def leg_pos_sensors(self) -> tuple[str, ...]:
        return tuple(f"{j}_pos" for j in self.leg_joints)

    @property
    def foot_bodies(self) -> tuple[str, ...]:
        return tuple(self.foot(leg) for leg in self.legs)

    @property
    def foot_force_sensors(self) -> tuple[str, ...]:
        return tuple(f"{f}_force" for f in self.foot_bodies)

    @property
    def foot_touch_sensors(self) -> tuple[str, ...]:
        return tuple(f"{f}_touch" for f in self.foot_bodies)

    @property
    def actuators(self) -> tuple[str, ...]:
        """Every actuator `add_upu` creates, in creation order (limbs, then legs)."""
        return self.limbs + self.leg_actuators


def _disc_inertia(mass: float, radius: float, height: float) -> list[float]:
    side = mass * (3 * radius**2 + height**2) / 12
    return [side, side, mass * radius**2 / 2]


def _add_plate(body, name: str, hub_radius: float, arm_ends, rgba) -> None:
    """A hub disc plus one box arm per end point, as the platform's (massless) shape."""
    body.add_geom(
        name=name,
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[hub_radius, _PLATE_THICKNESS / 2, 0],
        pos=[0, 0, -_PLATE_THICKNESS / 2],
        density=0,
        rgba=rgba,
        **_ROBOT_COLLISION,
    )
    for k, (x, y) in enumerate(arm_ends):
        length = math.hypot(x, y)
        angle = math.atan2(y, x)
        body.add_geom(
            name=f"{name}_arm{k + 1}",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[length / 2, 0.022, _PLATE_THICKNESS / 2],
            pos=[x / 2, y / 2, -_PLATE_THICKNESS / 2],
            quat=[math.cos(angle / 2), 0, 0, math.sin(angle / 2)],
            density=0,
            rgba=rgba,
            **_ROBOT_COLLISION,
        )


COMMAND_MODES: tuple[str, ...] = ("position", "interpolated")


def _interpolate_commands(act, speed_limit: float) -> None:
    """Turn a position servo into one whose target is its activation, moved at rate ctrl."""
    act.dyntype = mujoco.mjtDyn.mjDYN_INTEGRATOR
    act.actlimited = mujoco.mjtLimited.mjLIMITED_TRUE
    act.actrange = list(act.ctrlrange)
    act.ctrlrange = [-speed_limit, speed_limit]


def _set_limb_servo(act, p: UpuParams) -> None:
    """PD length servo, or with `limb_integral_gain` > 0 MuJoCo's PID actuator (position input,
    integral clamped at `limb_integral_limit`), which needs MuJoCo >= 4."""
    if p.limb_integral_gain == 0:
        act.set_to_position(kp=p.limb_stiffness, kv=p.limb_damping)
        return
    if not hasattr(mujoco, "mjtCtrlInput"):
        raise ValueError(
            "UpuParams.limb_integral_gain > 0 needs MuJoCo's PID actuator (MuJoCo >= 4, "
            f"found {mujoco.__version__}); set limb_integral_gain=0 for a PD servo"
        )
    act.set_to_pid(
        kp=p.limb_stiffness,
        kv=p.limb_damping,
        ki=p.limb_integral_gain,
        imax=p.limb_integral_limit,
        ctrlspec=int(mujoco.mjtCtrlInput.mjINPUT_POS),
    )


def _add_leg(
    spec: mujoco.MjSpec, platform_body, leg: str, p: UpuParams, interpolated: bool
) -> None:
    x, y = p.foot_offset(leg)
    length = p.leg_length(leg)
    leg_body = platform_body.add_body(name=f"{leg}_leg", pos=[x, y, 0.0])
    joint = f"{leg}_extend"
    leg_body.add_joint(
        name=joint,
        type=mujoco.mjtJoint.mjJNT_SLIDE,
        axis=[0, 0, -1],
        range=list(p.extension_range),
        limited=mujoco.mjtLimited.mjLIMITED_TRUE,
        damping=20.0,
        armature=0.05,
    )
    rod_radius = 0.75 * p.leg_radius
    leg_body.add_geom(
        name=f"{leg}_rod",
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        fromto=[0, 0, 0.04, 0, 0, -length + p.foot_radius],
        size=[rod_radius, 0, 0],
        mass=p.leg_mass,
        rgba=[0.35, 0.35, 0.4, 1] if leg_platform(leg) == "upper" else [0.5, 0.45, 0.35, 1],
        **_ROBOT_COLLISION,
    )
    foot = leg_body.add_body(name=f"{leg}_foot", pos=[0, 0, -length])
    foot.add_geom(
        name=f"{leg}_foot",
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=[p.foot_radius, 0, 0],
        pos=[0, 0, p.foot_radius],
        mass=p.foot_mass,
        friction=[p.friction, 0.005, 0.0001],
        condim=3,
        rgba=[0.1, 0.1, 0.1, 1],
        **_ROBOT_COLLISION,
    )
    # Sphere site enclosing the foot geom: frame for the force sensor, volume for the touch one.
    foot.add_site(
        name=f"{leg}_foot",
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        pos=[0, 0, p.foot_radius],
        size=[1.15 * p.foot_radius, 0, 0],
        rgba=[0.9, 0.2, 0.2, 0.0],
    )
    act = spec.add_actuator(name=joint, target=joint, trntype=mujoco.mjtTrn.mjTRN_JOINT)
    act.set_to_position(kp=p.leg_stiffness, kv=p.leg_damping)
    act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    act.ctrlrange = list(p.extension_range)
    act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
    act.forcerange = [-p.leg_force_limit, p.leg_force_limit]
    if interpolated:
        _interpolate_commands(act, p.leg_speed_limit)
    site = mujoco.mjtObj.mjOBJ_SITE
    spec.add_sensor(
        name=f"{joint}_pos",
        type=mujoco.mjtSensor.mjSENS_JOINTPOS,
        objtype=mujoco.mjtObj.mjOBJ_JOINT,
        objname=joint,
    )
    add_foot_force_sensor(spec, leg)
    spec.add_sensor(
        name=f"{leg}_foot_touch",
        type=mujoco.mjtSensor.mjSENS_TOUCH,
        objtype=site,
        objname=f"{leg}_foot",
    )


def add_upu(
    spec: mujoco.MjSpec,
    params: UpuParams | None = None,
    pos: tuple[float, float, float] | None = None,
    command: str = "position",
) -> UpuHandles:
    """Add the 3-UPU hexapod to `spec`; return the names it created.

    Args:
        spec: the model being built (terrain is added separately).
        params: robot parameters (default: the paper's, `UpuParams()`).
        pos: world position of the torso origin (lower Hooke-joint centre) [m]. Default:
            standing with all six nominal-length legs on flat ground at z = 0, 1 mm above it.
        command: "position" (ctrl = target) or "interpolated" (act = target, ctrl = its rate;
            see the module docstring). The interpolated mode needs the PD limb servo.

    The lower platform (the torso), the upper platform on its slides, the three limbs between
    them, the six legs (upper platform's first), then the IMU: the order fixes the compiled
    model's indices.
    """
    p = params or UpuParams()
    interpolated = _is_interpolated(command, p)
    torso = _add_lower_platform(spec, p, _torso_position(pos, p))
    upper = _add_upper_platform(torso, p)
    _add_limbs(spec, p, interpolated)
    for leg in UPPER_LEGS:
        _add_leg(spec, upper, leg, p, interpolated)
    for leg in LOWER_LEGS:
        _add_leg(spec, torso, leg, p, interpolated)
    add_imu_sensors(spec)
    return UpuHandles()


def _is_interpolated(command: str, p: UpuParams) -> bool:
    """Whether `command` is the interpolated mode; ValueError for an unknown mode, or for the
    interpolated one with an integrating limb servo (both use the actuator activation)."""
    if command not in COMMAND_MODES:
        raise ValueError(f"command must be one of {COMMAND_MODES}, got {command!r}")
    interpolated = command == "interpolated"
    if interpolated and p.limb_integral_gain > 0:
        raise ValueError(
            'command="interpolated" drives the servo target through the actuator activation, '
            "which MuJoCo's PID actuator uses for its integral: set limb_integral_gain=0"
        )
    return interpolated


def _torso_position(pos: tuple[float, float, float] | None, p: UpuParams) -> list[float]:
    """`pos` as three finite floats [m] (ValueError otherwise); None: standing on flat ground
    at z = 0 with nominal-length legs, 1 mm above it."""
    if pos is None:
        pos = (0.0, 0.0, p.lower_leg_length + 0.001)
    pos = [float(v) for v in pos]
    if len(pos) != 3 or not all(math.isfinite(v) for v in pos):
        raise ValueError(f"pos must be three finite coordinates [m], got {pos}")
    return pos


def _set_plate_inertia(body: mujoco.MjsBody, mass: float, radius: float) -> None:
    """A platform's mass [kg] as a 4 cm disc of `radius` [m] centred half a plate below the
    body's origin."""
    body.explicitinertial = True
    body.mass = mass
    body.ipos = [0, 0, -_PLATE_THICKNESS / 2]
    body.inertia = _disc_inertia(mass, radius, 0.04)


def _add_lower_platform(spec: mujoco.MjSpec, p: UpuParams, pos: list[float]) -> mujoco.MjsBody:
    """The torso: the free-floating lower platform at `pos` with its plate, the ``imu`` site,
    the ``track`` camera and the limbs' lower Hooke-joint sites ``hooke_A<i>``."""
    torso = spec.worldbody.add_body(name="torso", pos=pos)
    torso.add_freejoint(name="root")
    _set_plate_inertia(torso, p.lower_platform_mass, p.lower_radius)
    lower_arms = [p.foot_offset(leg) for leg in LOWER_LEGS]
    _add_plate(torso, "lower_plate", 0.1, lower_arms, [0.75, 0.55, 0.2, 1])
    torso.add_site(name="imu", pos=[0, 0, 0], size=[0.01, 0, 0])
    torso.add_camera(
        name="track",
        mode=mujoco.mjtCamLight.mjCAMLIGHT_TRACKCOM,
        pos=[-0.9, 1.3, 0.9],
        xyaxes=[-0.82, -0.57, 0, 0.3, -0.43, 0.85],
    )
    for i, point in enumerate(p.lower_hooke_points):
        torso.add_site(name=f"hooke_A{i + 1}", pos=point.tolist(), size=[0.012, 0, 0])
    return torso


def _add_upper_platform(torso: mujoco.MjsBody, p: UpuParams) -> mujoco.MjsBody:
    """The upper platform on three damped slides (x, y, z) relative to the torso, which only
    translate it (the limbs hold it parallel), with its plate and the upper Hooke-joint sites
    ``hooke_B<i>``."""
    upper = torso.add_body(name="upper", pos=p.initial_position.tolist())
    _set_plate_inertia(upper, p.upper_platform_mass, p.upper_radius)
    for name, axis in zip(UPPER_JOINTS, np.eye(3), strict=True):
        lo, hi = (-_SLIDE_RANGE_XY, _SLIDE_RANGE_XY) if name != "upper_z" else _SLIDE_RANGE_Z
        upper.add_joint(
            name=name,
            type=mujoco.mjtJoint.mjJNT_SLIDE,
            axis=axis.tolist(),
            range=[lo, hi],
            limited=mujoco.mjtLimited.mjLIMITED_TRUE,
            damping=p.upper_slide_damping,
            armature=0.01,
        )
    upper_arms = [p.foot_offset(leg) for leg in UPPER_LEGS]
    upper_arms += [tuple(b[:2]) for b in p.upper_hooke_points]
    _add_plate(upper, "upper_plate", 0.07, upper_arms, [0.3, 0.5, 0.75, 1])
    for i, point in enumerate(p.upper_hooke_points):
        upper.add_site(name=f"hooke_B{i + 1}", pos=point.tolist(), size=[0.012, 0, 0])
    return upper


def _add_limbs(spec: mujoco.MjSpec, p: UpuParams, interpolated: bool) -> None:
    """The three UPU limbs: a tendon between ``hooke_A<i>`` and ``hooke_B<i>`` within the limb
    length range, its servo (limited in stroke and force; `interpolated`: rate-limited
    commands) and a ``<limb>_length`` sensor."""
    for i, limb in enumerate(LIMB_NAMES):
        tendon = spec.add_tendon(name=limb)
        tendon.wrap_site(f"hooke_A{i + 1}")
        tendon.wrap_site(f"hooke_B{i + 1}")
        tendon.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        tendon.range = [p.limb_min, p.limb_max]
        tendon.width = 0.012
        tendon.rgba = [0.8, 0.8, 0.85, 1]
        act = spec.add_actuator(name=limb, target=limb, trntype=mujoco.mjtTrn.mjTRN_TENDON)
        _set_limb_servo(act, p)
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        act.ctrlrange = [p.limb_min, p.limb_max]
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        act.forcerange = [-p.limb_force_limit, p.limb_force_limit]
        if interpolated:
            _interpolate_commands(act, p.limb_speed_limit)
        spec.add_sensor(
            name=f"{limb}_length",
            type=mujoco.mjtSensor.mjSENS_TENDONPOS,
            objtype=mujoco.mjtObj.mjOBJ_TENDON,
            objname=limb,
        )


def upper_slide_offset(position, params: UpuParams) -> np.ndarray:
    """Slide-joint values (upper_x, upper_y, upper_z) [m] that put the upper centre at
    `position` (lower frame) [m]."""
    return np.asarray(position, dtype=float) - params.initial_position


def limb_controls(position, params: UpuParams, moving: str = "upper") -> dict[str, float]:
    """Limb-actuator controls [m] (inverse kinematics, clipped to the ctrlrange) that drive the
    `moving` platform to `position` (see `kinematics`)."""
    lengths = np.clip(
        inverse_kinematics(position, params, moving), params.limb_min, params.limb_max
    )
    return {name: float(v) for name, v in zip(LIMB_NAMES, lengths, strict=True)}


def standing_controls(params: UpuParams | None = None) -> dict[str, float]:
    """Actuator name -> control for the initial stance: upper platform at the initial position,
    every leg at its nominal length (extension 0)."""
    p = params or UpuParams()
    ctrl = limb_controls(p.initial_position, p)
    ctrl.update({f"{leg}_extend": 0.0 for leg in LEG_NAMES})
    return ctrl
