"""ATHENA's MuJoCo model: naming contract, agreement with the DH kinematics, standing."""

import math

import mujoco
import numpy as np
import pytest

from hexapod_envs.robots.athena import kinematics as kin
from hexapod_envs.robots.athena.model import FOOT_FORCE_SIGN, add_athena
from hexapod_envs.robots.athena.params import ATHENA, JOINT_NAMES, LEG_NAMES
from hexapod_envs.terrain.flat import add_flat
from hexapod_envs.terrain.irregular import PAPER_FRICTION


def _build(degree: bool = True, ground: bool = True, timestep: float = 0.002):
    spec = mujoco.MjSpec()
    spec.compiler.degree = degree
    spec.option.timestep = timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    if ground:  # the terrain collision convention (contype 0, conaffinity 1)
        add_flat(spec, friction=PAPER_FRICTION, size=5.0)
    handles = add_athena(spec)
    model = spec.compile()
    return model, mujoco.MjData(model), handles


def test_names_follow_the_contract():
    model, _, h = _build()
    for leg_idx, leg in enumerate(LEG_NAMES):
        for j, joint in enumerate(JOINT_NAMES):
            name = f"{leg}_{joint}"
            assert h.joint(leg, joint) == name == h.actuators[leg_idx][j]
            model.joint(name)
            model.actuator(name)
            model.sensor(f"{name}_pos")
            model.sensor(f"{name}_vel")
        model.body(f"{leg}_foot")
        model.site(f"{leg}_foot")
        model.sensor(f"{leg}_foot_force")
        assert model.body(f"{leg}_foot").jntnum[0] == 0  # welded: the force sensor sees it all
    model.body("torso")
    assert model.joint("root").type[0] == mujoco.mjtJoint.mjJNT_FREE
    for name in ("imu_gyro", "imu_accel", "imu_quat", "torso_height"):
        model.sensor(name)
    model.site("imu")
    model.geom(h.torso_geom)


def test_masses_limits_and_servos_follow_the_paper():
    model, _, _ = _build()
    assert model.body("torso").subtreemass[0] == pytest.approx(ATHENA.total_mass)
    np.testing.assert_allclose(model.body("LF_femur").inertia, ATHENA.femur.inertia)
    assert model.geom("LF_foot").size[0] == pytest.approx(0.02)
    assert model.geom("LF_foot").friction[0] == pytest.approx(0.9)
    for leg in LEG_NAMES:
        for joint in JOINT_NAMES:
            act = model.actuator(f"{leg}_{joint}")
            np.testing.assert_allclose(act.forcerange, [-1.89, 1.89])
            np.testing.assert_allclose(act.ctrlrange, ATHENA.joint_range(joint))
            np.testing.assert_allclose(
                model.joint(f"{leg}_{joint}").range, ATHENA.joint_range(joint)
            )


def test_joint_units_do_not_depend_on_the_compiler_angle_setting():
    deg, _, _ = _build(degree=True)
    rad, _, _ = _build(degree=False)
    np.testing.assert_allclose(deg.jnt_range, rad.jnt_range)
    np.testing.assert_allclose(deg.qpos0, rad.qpos0)


def test_default_configuration_is_the_standing_posture():
    model, data, _ = _build()
    mujoco.mj_forward(model, data)
    for leg in LEG_NAMES:
        for j, joint in enumerate(JOINT_NAMES):
            assert data.joint(f"{leg}_{joint}").qpos[0] == pytest.approx(ATHENA.standing_posture[j])
    assert data.sensor("torso_height").data[0] == pytest.approx(ATHENA.standing_torso_height)


def test_fk_matches_mujoco_foot_sites_for_random_poses():
    model, data, _ = _build(ground=False)
    rng = np.random.default_rng(3)
    lo, hi = ATHENA.joint_ranges[:, 0], ATHENA.joint_ranges[:, 1]
    for _ in range(20):
        q = rng.uniform(lo, hi, size=(6, 3))
        axis = rng.normal(size=3)
        angle = rng.uniform(-math.pi, math.pi)
        quat = np.concatenate(
            [[math.cos(angle / 2)], math.sin(angle / 2) * axis / np.linalg.norm(axis)]
        )
        data.joint("root").qpos[:] = np.concatenate([rng.uniform(-1, 1, 3), quat])
        for i, leg in enumerate(LEG_NAMES):
            for j, joint in enumerate(JOINT_NAMES):
                data.joint(f"{leg}_{joint}").qpos[0] = q[i, j]
        mujoco.mj_kinematics(model, data)
        rot = data.body("torso").xmat.reshape(3, 3)
        origin = data.body("torso").xpos
        feet = np.array([rot.T @ (data.site(f"{leg}_foot").xpos - origin) for leg in LEG_NAMES])
        np.testing.assert_allclose(feet, kin.forward_kinematics_all(q), atol=1e-6)


def test_robot_stands_still_for_two_seconds_and_sensors_read_right():
    model, data, h = _build()
    for leg in LEG_NAMES:
        for j, joint in enumerate(JOINT_NAMES):
            data.actuator(f"{leg}_{joint}").ctrl[0] = ATHENA.standing_posture[j]
    start_xy = data.body("torso").xpos[:2].copy()
    heights = []
    for _ in range(int(2.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
        heights.append(data.body("torso").xpos[2])
    heights = np.array(heights)
    # Settles within a few mm of the standing height (servo sag under load) and stays there.
    assert np.all(np.abs(heights[-500:] - ATHENA.standing_torso_height) < 0.004)
    assert np.ptp(heights[-500:]) < 1e-4
    assert np.linalg.norm(data.body("torso").xpos[:2] - start_xy) < 1e-3
    up = data.body("torso").xmat.reshape(3, 3)[:, 2]
    assert math.degrees(math.acos(min(1.0, up[2]))) < 0.2
    # Only the feet touch the ground.
    touching = {model.geom(data.contact[i].geom2).name for i in range(data.ncon)}
    touching |= {model.geom(data.contact[i].geom1).name for i in range(data.ncon)}
    assert touching == {"ground", *h.foot_geoms}
    # The rangefinder measures the torso centre's height.
    assert data.sensor("torso_height").data[0] == pytest.approx(
        data.body("torso").xpos[2], abs=1e-6
    )
    # Force sensor sign: ground reaction = FOOT_FORCE_SIGN * world-frame reading + foot weight.
    grf = []
    for leg in LEG_NAMES:
        rot = data.site(f"{leg}_foot").xmat.reshape(3, 3)
        reading_world = rot @ data.sensor(f"{leg}_foot_force").data
        grf.append(FOOT_FORCE_SIGN * reading_world + [0, 0, ATHENA.foot.mass * 9.81])
    grf = np.array(grf)
    assert np.all(grf[:, 2] > 2.0)  # every foot pushed up by the ground
    np.testing.assert_allclose(grf.sum(axis=0), [0, 0, ATHENA.total_mass * 9.81], atol=0.05)
    # Quaternion sensor is the torso orientation (level).
    np.testing.assert_allclose(np.abs(data.sensor("imu_quat").data), [1, 0, 0, 0], atol=1e-3)
