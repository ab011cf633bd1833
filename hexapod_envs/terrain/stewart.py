"""The 6-UPS Stewart platform of Zhang et al. 2024 §5.2 as a MuJoCo terrain piece.

The moving platform is a rigid plate whose tilt is driven by two stiff servos about its
centre (pitch about y, then roll about x, so R = Ry(pitch) Rx(roll) as in `stewart_kinematics`).
Driving the pose through joints, rather than a mocap body, gives the plate a real velocity, so
the feet's friction sees the platform move. The six actuator lengths that would produce the pose
are computed by `stewart_kinematics` (pure numpy) and reported by the env; the legs are drawn as
visual capsules only.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco

from .flat import add_flat, ground_geom_kwargs
from .stewart_kinematics import DEFAULT_PLATFORM, StewartPlatform

PLATFORM_JOINTS = ("platform_pitch", "platform_roll")


@dataclass(frozen=True)
class PlatformHandles:
    body: str
    joints: tuple[str, str]
    top_height: float
    """World height of the plate's top surface in the neutral pose [m]."""


def add_stewart_platform(
    spec: mujoco.MjSpec,
    platform: StewartPlatform = DEFAULT_PLATFORM,
    plate_half_size: tuple[float, float] = (4.0, 3.2),
    friction: float = 1.5,
    mass: float = 20000.0,
    servo_stiffness: float = 5.0e9,
) -> PlatformHandles:
    """Add the fixed base (on flat ground), the tilting plate and its two servos.

    `servo_stiffness` [N·m/rad] keeps the tilt error under ~0.01° with the 5 t robot on the
    plate; the servos are critically damped for the plate plus robot inertia.
    """
    if spec.compiler.degree:
        raise ValueError("set spec.compiler.degree = False: this builder gives angles in radians")
    add_flat(spec, friction=friction)
    spec.worldbody.add_geom(
        name="stewart_base",
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[platform.base_radius, 0.15, 0],
        pos=[0, 0, 0.15],
        contype=0,
        conaffinity=0,
        rgba=[0.4, 0.4, 0.45, 1],
    )
    h = platform.neutral_height
    body = spec.worldbody.add_body(name="platform", pos=[0, 0, h])
    inertia_scale = mass * (plate_half_size[0] ** 2 + plate_half_size[1] ** 2) / 3
    damping = 2.0 * (servo_stiffness * (inertia_scale + 5000.0 * 4.0)) ** 0.5
    for name, axis in zip(PLATFORM_JOINTS, ([0, 1, 0], [1, 0, 0]), strict=True):
        body.add_joint(
            name=name,
            type=mujoco.mjtJoint.mjJNT_HINGE,
            axis=axis,
            range=[-1.2, 1.2],
            damping=damping,
            armature=1.0e4,
        )
        # Integrated-velocity servo: ctrl is the tilt rate, integrated every physics substep
        # into the position target, so the plate moves smoothly between control instants
        # (a position target that jumps once per control period jerks the plate at 50 Hz and
        # biases the foot forces sampled at the control instants).
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_intvelocity(kp=servo_stiffness)
        act.actlimited = True
        act.actrange = [-1.2, 1.2]
    kw = ground_geom_kwargs(friction)
    body.add_geom(
        name="platform_plate",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[plate_half_size[0], plate_half_size[1], 0.1],
        pos=[0, 0, -0.1],
        mass=mass,
        **{**kw, "rgba": [0.55, 0.6, 0.65, 1.0]},
    )
    return PlatformHandles(body="platform", joints=PLATFORM_JOINTS, top_height=h)
