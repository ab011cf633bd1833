"""MuJoCo model of the heavy-duty hexapod, generated from `HeavyDutyParams` with `mujoco.MjSpec`.

Each leg is modelled in foot space: a hinge about x (the swing joint J_theta), a slide along x that
moves the foot by P_x = K_x J_x (the horizontal joint through its pantograph), and a slide along the
leg that sets the length d = K_z J_z + L2 (the vertical joint). The position servos act in the
paper's joint units: their gear is 1/K, so `ctrl` is J and the actuator length sensor reads J.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from ..sensor_spec import add_foot_force_sensor, add_imu_sensors
from .params import JOINT_NAMES, LEG_NAMES, HeavyDutyParams

_COLLIDE_GROUND = 1  # contype/conaffinity bit shared with terrain geoms
_MASS_SPLIT = {"hip": 0.40, "carriage": 0.30, "shank": 0.28, "foot": 0.02}


@dataclass(frozen=True)
class HeavyDutyHandles:
    """Names created by `add_heavy_duty`, for the env's named accessors."""

    legs: tuple[str, ...]
    joints: dict[str, tuple[str, ...]]
    """Per leg: MuJoCo joint names in the paper's order (horizontal, vertical, swing)."""
    gears: tuple[float, float, float]
    """Actuator gear per joint: J = gear * qpos."""
    torso: str = "torso"
    root_joint: str = "root"


def _box_inertia(mass: float, size: tuple[float, float, float]) -> list[float]:
    lx, ly, lz = size
    return [mass * (ly**2 + lz**2) / 12, mass * (lx**2 + lz**2) / 12, mass * (lx**2 + ly**2) / 12]


def add_heavy_duty(
    spec: mujoco.MjSpec,
    params: HeavyDutyParams | None = None,
    pos: tuple[float, float, float] = (0.0, 0.0, 1.87),
    joints: dict[str, np.ndarray] | None = None,
) -> HeavyDutyHandles:
    """Add the robot to `spec` with its torso at `pos` (world, m).

    `joints` optionally gives the initial [J_x, J_z, J_theta] per leg (default: standing pose).
    The torso, then per leg its bodies, its three servos and its foot force sensor, then the
    IMU: the order fixes the compiled model's indices.
    """
    if spec.compiler.degree:
        raise ValueError("set spec.compiler.degree = False: this builder gives angles in radians")
    p = params or HeavyDutyParams()
    gears = (1.0 / p.k_x, 1.0 / p.k_z, 1.0)
    torso = _add_torso(spec, p, pos)
    leg_joints: dict[str, tuple[str, ...]] = {}
    for leg in LEG_NAMES:
        names = tuple(f"{leg}_{j}" for j in JOINT_NAMES)
        leg_joints[leg] = names
        _add_leg(torso, p, leg, names)
        _add_servos(spec, p, names, gears)
        add_foot_force_sensor(spec, leg)
    add_imu_sensors(spec)
    return HeavyDutyHandles(legs=LEG_NAMES, joints=leg_joints, gears=gears)


def _add_torso(
    spec: mujoco.MjSpec, p: HeavyDutyParams, pos: tuple[float, float, float]
) -> mujoco.MjsBody:
    """The free-floating torso box at `pos` [m] with the ``imu`` and ``cog`` sites and the
    ``track`` camera; returns its body."""
    torso = spec.worldbody.add_body(name="torso", pos=list(pos))
    torso.add_freejoint(name="root")
    torso.add_geom(
        name="torso",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[s / 2 for s in p.body_size],
        mass=p.body_mass,
        rgba=[0.75, 0.55, 0.2, 1],
        contype=_COLLIDE_GROUND,
        conaffinity=0,
    )
    torso.add_site(name="imu", pos=[0, 0, 0])
    torso.add_site(name="cog", pos=[0, 0, 0], size=[0.05, 0, 0])
    # Camera that follows the body from behind-left, looking forward-down.
    torso.add_camera(
        name="track",
        mode=mujoco.mjtCamLight.mjCAMLIGHT_TRACKCOM,
        pos=[-9.0, 7.0, 4.5],
        xyaxes=[-0.6, -0.8, 0, 0.33, -0.25, 0.91],
    )
    return torso


def _add_joint(
    body: mujoco.MjsBody,
    p: HeavyDutyParams,
    name: str,
    kind: mujoco.mjtJoint,
    axis: list[float],
    limits: list[float],
    index: int,
) -> None:
    """A joint of a leg with the damping and armature of the paper's joint `index` (0: the
    horizontal, 1: the vertical, 2: the swing joint); `limits` in MuJoCo units (m or rad)."""
    body.add_joint(
        name=name,
        type=kind,
        axis=axis,
        range=limits,
        damping=p.foot_damping[index],
        armature=p.joint_armature[index],
    )


def _link_geom(
    body: mujoco.MjsBody, kind: mujoco.mjtGeom, mass: float, rgba: list[float], **shape
) -> None:
    """A visual link of a leg: it carries `mass` [kg] and collides with nothing."""
    body.add_geom(type=kind, **shape, mass=mass, contype=0, conaffinity=0, rgba=rgba)


def _add_leg(torso: mujoco.MjsBody, p: HeavyDutyParams, leg: str, names: tuple[str, ...]) -> None:
    """The leg's chain in foot space: the hip swings about x (J_theta), the carriage slides
    along x (the horizontal joint), the shank slides down the leg (the vertical joint) and the
    foot, fixed to the shank, carries the sole's sphere and the ``{leg}_foot`` site.
    `names`: the joints in `JOINT_NAMES` order."""
    l1 = p.signed_l1(leg)
    m = p.leg_mass
    hip = torso.add_body(name=f"{leg}_hip", pos=p.hip_offsets[leg].tolist())
    _add_joint(hip, p, names[2], mujoco.mjtJoint.mjJNT_HINGE, [1, 0, 0], list(p.j_theta_range), 2)
    _link_geom(
        hip,
        mujoco.mjtGeom.mjGEOM_BOX,
        m * _MASS_SPLIT["hip"],
        [0.3, 0.3, 0.35, 1],
        size=[0.25, abs(l1) / 2, 0.2],
        pos=[0, l1 / 2, 0],
    )
    carriage = hip.add_body(name=f"{leg}_carriage", pos=[0, l1, 0])
    x_range = [p.k_x * p.j_x_range[0], p.k_x * p.j_x_range[1]]
    _add_joint(carriage, p, names[0], mujoco.mjtJoint.mjJNT_SLIDE, [1, 0, 0], x_range, 0)
    _link_geom(
        carriage,
        mujoco.mjtGeom.mjGEOM_CAPSULE,
        m * _MASS_SPLIT["carriage"],
        [0.3, 0.3, 0.35, 1],
        fromto=[0, 0, 0.15, 0, 0, -p.l2],
        size=[0.1, 0, 0],
    )
    shank = carriage.add_body(name=f"{leg}_shank", pos=[0, 0, -p.l2])
    z_range = [p.k_z * p.j_z_range[0], p.k_z * p.j_z_range[1]]
    _add_joint(shank, p, names[1], mujoco.mjtJoint.mjJNT_SLIDE, [0, 0, -1], z_range, 1)
    _link_geom(
        shank,
        mujoco.mjtGeom.mjGEOM_CAPSULE,
        m * _MASS_SPLIT["shank"],
        [0.45, 0.45, 0.5, 1],
        fromto=[0, 0, 0.7, 0, 0, p.foot_radius],
        size=[0.08, 0, 0],
    )
    foot = shank.add_body(name=f"{leg}_foot", pos=[0, 0, 0])
    foot.add_geom(
        name=f"{leg}_foot",
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=[p.foot_radius, 0, 0],
        pos=[0, 0, p.foot_radius],
        mass=m * _MASS_SPLIT["foot"],
        contype=_COLLIDE_GROUND,
        conaffinity=0,
        friction=[p.friction, 0.005, 0.0001],
        condim=3,
        rgba=[0.15, 0.15, 0.15, 1],
    )
    # The shank's origin is the sole: the kinematic foot point and the paper's foothold.
    foot.add_site(name=f"{leg}_foot", pos=[0, 0, 0], size=[0.04, 0, 0])


def _add_servos(
    spec: mujoco.MjSpec, p: HeavyDutyParams, names: tuple[str, ...], gears: tuple[float, ...]
) -> None:
    """A position servo per joint in the paper's joint units (gear 1/K, so ``ctrl`` is J),
    with its stiffness, force limit and control range, and an ``{joint}_pos`` sensor that
    reads J."""
    for joint, gear, k, f_max in zip(names, gears, p.foot_stiffness, p.force_limit, strict=True):
        # A position servo in actuator units: joint-space stiffness = gear^2 * kp.
        act = spec.add_actuator(
            name=joint,
            target=joint,
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
            gear=[gear, 0, 0, 0, 0, 0],
        )
        kp = k / gear**2
        act.set_to_position(kp=kp)
        act.forcelimited = True
        act.forcerange = [-f_max / gear, f_max / gear]
        act.ctrlrange = list(p.joint_ranges[JOINT_NAMES.index(joint.split("_")[1])])
        act.ctrllimited = True
        spec.add_sensor(
            name=f"{joint}_pos",
            type=mujoco.mjtSensor.mjSENS_ACTUATORPOS,
            objtype=mujoco.mjtObj.mjOBJ_ACTUATOR,
            objname=joint,
        )
