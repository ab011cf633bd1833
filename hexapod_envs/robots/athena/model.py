"""MuJoCo model of ATHENA (Coelho et al. 2024, Table 2 simplified model), generated with
`mujoco.MjSpec`.

Body tree per leg L in `LEG_NAMES` (frames follow the DH chain of `kinematics`):

    torso --L_TC (hinge, z)--> L_coxa --L_CTr (hinge, -y)--> L_femur --L_FTi (hinge, -y)-->
    L_tibia --(welded)--> L_foot

Each link frame has x along the link, so the link boxes and Table 2's inertias (converted as
explained in `params`) sit on the link's x axis. MuJoCo joint angles are exactly the DH angles
theta_2, theta_3, theta_4 of `kinematics`; the FTi joint has `ref = -pi/2`, so `qpos0` (what
`mj_resetData` gives) is the paper's standing posture (0, 0, -pi/2) on every leg.

Sensors: IMU site `imu` at the torso centre with `imu_gyro`, `imu_accel`, `imu_quat`; the
infrared torso-height sensor is a rangefinder `torso_height` on site `torso_height` at the torso
centre looking along the torso's -z (it ignores the torso's own geom, reads the distance to the
first geom below, -1 if none; in the standing posture on flat ground it reads
`AthenaParams.standing_torso_height` = 0.104 m); `torso_contact` counts the torso box's contacts
(for evaluation, the real robot has no such sensor). Per leg: `L_<joint>_pos` / `L_<joint>_vel`
(joint encoders), `L_foot_force` (3-D force sensor on site `L_foot`). MuJoCo's force sensor
reads, in the site frame, the force that the foot body receives from its parent (the tibia); for a
foot at rest that is minus the ground reaction force (plus the foot's 0.087 N weight), so
rotate it to the world frame and multiply by `FOOT_FORCE_SIGN` (-1) to get the ground reaction
(`tests/hexapod_envs/robots/athena/test_athena_model.py` checks this on a standing robot).

Collisions: robot geoms have contype 1 / conaffinity 0 and terrain geoms contype 0 /
conaffinity 1 (the convention of `hexapod_envs.terrain`), so the robot touches the terrain and
never itself. MuJoCo combines the friction of two geoms by taking the larger one: build the
terrain with friction 0.9 (the paper's value) to get exactly 0.9.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from ..sensor_spec import add_foot_force_sensor, add_imu_sensors
from .params import ATHENA, JOINT_NAMES, LEG_NAMES, AthenaParams

_COLLIDE_GROUND = 1  # contype bit that terrain geoms accept (their conaffinity)
_TORSO_RGBA = [0.2, 0.45, 0.75, 1.0]
_LINK_RGBA = [0.35, 0.35, 0.4, 1.0]
_FOOT_RGBA = [0.1, 0.1, 0.1, 1.0]

_SOLMIX_DOMINANT = 1e6
"""solmix of the robot's geoms when `AthenaParams.contact_solref` / `contact_solimp` are set:
MuJoCo averages a contact's solref and solimp over its two geoms weighted by solmix, so against
the terrain's default weight 1 the robot's values count 1e6 : 1 (within 1e-6 of them)."""
DELAY_MIN_TIMESTEP = 0.0005
"""Smallest physics step [s] for which a servo's target history covers `AthenaParams.servo_delay`
(the history keeps delay / this + 2 samples)."""

FOOT_FORCE_SIGN = -1.0
"""Multiply the `L_foot_force` reading (rotated from the site to the world frame) by this to get
the ground reaction force acting on the foot, up to the foot's own weight and inertia (0.087 N).
Measured in `tests/hexapod_envs/robots/athena/test_athena_model.py`."""


@dataclass(frozen=True)
class AthenaHandles:
    """Names created by `add_athena`, for named accessors in the envs.

    All per-leg tuples are in `legs` order; per-joint tuples in `joint_names` order.
    """

    legs: tuple[str, ...]
    joint_names: tuple[str, ...]
    joints: tuple[tuple[str, ...], ...]
    """MuJoCo joint names per leg, e.g. ("LF_TC", "LF_CTr", "LF_FTi"); actuators share them."""
    joint_pos_sensors: tuple[tuple[str, ...], ...]
    joint_vel_sensors: tuple[tuple[str, ...], ...]
    foot_bodies: tuple[str, ...]
    foot_sites: tuple[str, ...]
    foot_geoms: tuple[str, ...]
    foot_force_sensors: tuple[str, ...]
    torso: str = "torso"
    torso_geom: str = "torso"
    root_joint: str = "root"
    imu_site: str = "imu"
    imu_gyro: str = "imu_gyro"
    imu_accel: str = "imu_accel"
    imu_quat: str = "imu_quat"
    torso_height_site: str = "torso_height"
    torso_height_sensor: str = "torso_height"
    torso_contact_sensor: str = "torso_contact"
    """Contact sensor (evaluation only): number of contacts the torso geom has."""

    @property
    def actuators(self) -> tuple[tuple[str, ...], ...]:
        """Position-servo actuator names per leg (same as the joint names)."""
        return self.joints

    def joint(self, leg: str, joint: str) -> str:
        """MuJoCo name of `joint` (TC, CTr, FTi) of `leg`."""
        return self.joints[_index(leg, self.legs)][_index(joint, self.joint_names)]


def add_athena(
    spec: mujoco.MjSpec,
    pos: tuple[float, float, float] | None = None,
    quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0),
    params: AthenaParams = ATHENA,
) -> AthenaHandles:
    """Add ATHENA to `spec` with its torso centre at `pos` (world, m) and orientation `quat`.

    The default `pos` is (0, 0, standing torso height): in the default configuration (standing
    posture) the feet then just touch a ground plane at z = 0. Joint ranges are converted to the
    spec's angle unit (`spec.compiler.degree`) as it is at the time of this call. Returns the
    created names.
    """
    if pos is None:
        pos = (0.0, 0.0, params.standing_torso_height)
    if len(pos) != 3 or len(quat) != 4:
        raise ValueError(f"pos must have 3 and quat 4 numbers, got pos={pos}, quat={quat}")

    torso = spec.worldbody.add_body(name="torso", pos=list(pos), quat=list(quat))
    torso.add_freejoint(name="root")
    _set_inertial(torso, params.body.mass, params.body.inertia, [0.0, 0.0, 0.0])
    torso.add_geom(
        name="torso",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[s / 2 for s in params.body.size],
        rgba=_TORSO_RGBA,
        **_collision_kwargs(params),
    )
    torso.add_site(name="imu", pos=[0, 0, 0], size=[0.01, 0, 0])
    # Rangefinders look along their site's +z: rotate by pi about x so +z points down.
    torso.add_site(name="torso_height", pos=[0, 0, 0], quat=[0, 1, 0, 0], size=[0.005, 0, 0])
    torso.add_camera(
        name="track",
        mode=mujoco.mjtCamLight.mjCAMLIGHT_TRACKCOM,
        pos=[-0.7, 0.5, 0.4],
        xyaxes=[-0.58, -0.81, 0, 0.3, -0.22, 0.93],
    )

    joints, pos_sensors, vel_sensors = [], [], []
    for leg in LEG_NAMES:
        names = tuple(f"{leg}_{j}" for j in JOINT_NAMES)
        joints.append(names)
        _add_leg(spec, torso, leg, names, params)
        pos_sensors.append(tuple(f"{n}_pos" for n in names))
        vel_sensors.append(tuple(f"{n}_vel" for n in names))

    add_imu_sensors(spec)
    spec.add_sensor(
        name="torso_height",
        type=mujoco.mjtSensor.mjSENS_RANGEFINDER,
        objtype=mujoco.mjtObj.mjOBJ_SITE,
        objname="torso_height",
        intprm=[1 << int(mujoco.mjtRayDataField.mjRAYDATA_DIST), 0, 0],  # output: distance only
    )
    # Evaluation only (the real robot has no such sensor): number of contacts of the torso box.
    spec.add_sensor(
        name="torso_contact",
        type=mujoco.mjtSensor.mjSENS_CONTACT,
        objtype=mujoco.mjtObj.mjOBJ_GEOM,
        objname="torso",
        intprm=[1 << int(mujoco.mjtConDataField.mjCONDATA_FOUND), 1, 1],  # found; mindist; 1
    )
    return AthenaHandles(
        legs=LEG_NAMES,
        joint_names=JOINT_NAMES,
        joints=tuple(joints),
        joint_pos_sensors=tuple(pos_sensors),
        joint_vel_sensors=tuple(vel_sensors),
        foot_bodies=tuple(f"{leg}_foot" for leg in LEG_NAMES),
        foot_sites=tuple(f"{leg}_foot" for leg in LEG_NAMES),
        foot_geoms=tuple(f"{leg}_foot" for leg in LEG_NAMES),
        foot_force_sensors=tuple(f"{leg}_foot_force" for leg in LEG_NAMES),
    )


def _add_leg(
    spec: mujoco.MjSpec,
    torso: mujoco.MjsBody,
    leg: str,
    names: tuple[str, ...],
    p: AthenaParams,
) -> None:
    """Coxa, femur, tibia and foot of one leg, with joints, servos and sensors."""
    theta1 = p.mounting_angle(leg)
    coxa = torso.add_body(
        name=f"{leg}_coxa",
        pos=p.hip_position(leg).tolist(),
        quat=[math.cos(theta1 / 2), 0.0, 0.0, math.sin(theta1 / 2)],
    )
    _add_link(coxa, p.coxa.size, p.coxa.mass, p.coxa.inertia, p, geom_length=p.l2)
    _add_joint(coxa, names[0], [0, 0, 1], p, 0)

    femur = coxa.add_body(name=f"{leg}_femur", pos=[p.l2, 0, 0])
    _add_link(femur, p.femur.size, p.femur.mass, p.femur.inertia, p, geom_length=p.l3)
    _add_joint(femur, names[1], [0, -1, 0], p, 1)

    # The tibia frame is built in the standing pose (theta_4 = -pi/2: x pointing down), which
    # the joint's ref declares as the angle of this configuration.
    tibia = femur.add_body(
        name=f"{leg}_tibia",
        pos=[p.l3, 0, 0],
        quat=_quat_about([0, -1, 0], p.standing_posture[2]),
    )
    # The collision box stops at the foot sphere so that only the sphere touches flat ground.
    _add_link(
        tibia, p.tibia.size, p.tibia.mass, p.tibia.inertia, p, geom_length=p.l4 - p.foot.radius
    )
    _add_joint(tibia, names[2], [0, -1, 0], p, 2)

    foot = tibia.add_body(name=f"{leg}_foot", pos=[p.l4, 0, 0])
    _set_inertial(foot, p.foot.mass, p.foot.inertia, [0.0, 0.0, 0.0])
    foot.add_geom(
        name=f"{leg}_foot",
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=[p.foot.radius, 0, 0],
        rgba=_FOOT_RGBA,
        **_collision_kwargs(p),
    )
    foot.add_site(name=f"{leg}_foot", pos=[0, 0, 0], size=[0.006, 0, 0])
    add_foot_force_sensor(spec, leg)

    for k, name in enumerate(names):
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_position(kp=p.servo_kp)
        act.forcelimited = True
        act.forcerange = [-p.stall_torque, p.stall_torque]
        act.ctrllimited = True
        act.ctrlrange = list(p.joint_range(JOINT_NAMES[k]))
        if p.servo_delay > 0:
            act.delay = p.servo_delay
            act.nsample = math.ceil(p.servo_delay / DELAY_MIN_TIMESTEP) + 2
        spec.add_sensor(
            name=f"{name}_pos",
            type=mujoco.mjtSensor.mjSENS_JOINTPOS,
            objtype=mujoco.mjtObj.mjOBJ_JOINT,
            objname=name,
        )
        spec.add_sensor(
            name=f"{name}_vel",
            type=mujoco.mjtSensor.mjSENS_JOINTVEL,
            objtype=mujoco.mjtObj.mjOBJ_JOINT,
            objname=name,
        )


def _add_link(
    body: mujoco.MjsBody,
    size: tuple[float, float, float],
    mass: float,
    inertia: np.ndarray,
    p: AthenaParams,
    geom_length: float,
) -> None:
    """Table 2 inertia of a uniform box along x from the joint, plus its collision box."""
    length, width, height = size
    _set_inertial(body, mass, inertia, [length / 2, 0.0, 0.0])
    body.add_geom(
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[geom_length / 2, width / 2, height / 2],
        pos=[geom_length / 2, 0, 0],
        rgba=_LINK_RGBA,
        **_collision_kwargs(p),
    )


def _add_joint(body: mujoco.MjsBody, name: str, axis: list[float], p: AthenaParams, k: int):
    # The spec's compiler reads joint ranges and ref in degrees unless `compiler.degree` is off
    # (the MJCF default, shared by every piece of the model), so convert; ctrlrange is not
    # converted by MuJoCo and stays in rad.
    unit = 180.0 / math.pi if body.compiler.degree else 1.0
    joint = JOINT_NAMES[k]
    body.add_joint(
        name=name,
        type=mujoco.mjtJoint.mjJNT_HINGE,
        axis=axis,
        range=[unit * v for v in p.joint_range(joint)],
        limited=mujoco.mjtLimited.mjLIMITED_TRUE,
        ref=unit * p.standing_posture[k],
        damping=p.servo_damping,
        armature=p.servo_armature,
    )


def _set_inertial(body: mujoco.MjsBody, mass: float, inertia: np.ndarray, ipos: list[float]):
    body.explicitinertial = True
    body.mass = mass
    body.ipos = ipos
    body.inertia = list(np.asarray(inertia, dtype=float))


def _collision_kwargs(p: AthenaParams) -> dict:
    kwargs = {
        "contype": _COLLIDE_GROUND,
        "conaffinity": 0,
        "condim": 3,
        "friction": [p.friction, 0.005, 0.0001],
        "density": 0.0,
    }
    if p.contact_solref is not None or p.contact_solimp is not None:
        kwargs["solmix"] = _SOLMIX_DOMINANT
    if p.contact_solref is not None:
        kwargs["solref"] = list(p.contact_solref)
    if p.contact_solimp is not None:
        kwargs["solimp"] = list(p.contact_solimp)
    return kwargs


def _quat_about(axis: list[float], angle: float) -> list[float]:
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    return [math.cos(angle / 2), *(math.sin(angle / 2) * a)]


def _index(name: str, valid: tuple[str, ...]) -> int:
    if name not in valid:
        raise ValueError(f"unknown name {name!r}; valid: {', '.join(valid)}")
    return valid.index(name)
