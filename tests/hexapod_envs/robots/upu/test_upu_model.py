"""Short MuJoCo checks of the 3-UPU model: names, standing on six legs, limb-length control."""

import mujoco
import numpy as np
import pytest

from hexapod_envs.robots.upu.kinematics import forward_kinematics, limb_vectors
from hexapod_envs.robots.upu.model import (
    RECOMMENDED_TIMESTEP,
    add_upu,
    limb_controls,
    standing_controls,
    upper_slide_offset,
)
from hexapod_envs.robots.upu.params import LEG_NAMES, UpuParams
from hexapod_envs.terrain.flat import add_flat

P = UpuParams()
G = 9.81


def build(params=P):
    spec = mujoco.MjSpec()
    spec.option.timestep = RECOMMENDED_TIMESTEP
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    add_flat(spec, friction=params.friction)
    handles = add_upu(spec, params)
    model = spec.compile()
    data = mujoco.MjData(model)
    return model, data, handles


def set_ctrl(data, ctrl):
    for name, value in ctrl.items():
        data.actuator(name).ctrl = value


def step(model, data, seconds):
    for _ in range(round(seconds / model.opt.timestep)):
        mujoco.mj_step(model, data)


def upper_in_torso(data):
    rot = data.body("torso").xmat.reshape(3, 3)
    return rot.T @ (data.body("upper").xpos - data.body("torso").xpos)


@pytest.fixture(scope="module")
def standing():
    model, data, handles = build()
    set_ctrl(data, standing_controls(P))
    step(model, data, 1.5)
    return model, data, handles


def test_contract_names_exist():
    model, _, h = build()
    assert model.body("torso").id == 1
    assert model.jnt_type[model.joint("root").id] == mujoco.mjtJoint.mjJNT_FREE
    assert model.site("imu").bodyid == model.body("torso").id
    for name in h.imu_sensors + h.limb_length_sensors:
        model.sensor(name)
    for leg in LEG_NAMES:
        joint = model.joint(f"{leg}_extend")
        assert joint.type == mujoco.mjtJoint.mjJNT_SLIDE
        model.actuator(f"{leg}_extend")
        model.sensor(f"{leg}_extend_pos")
        model.sensor(f"{leg}_foot_force")
        model.sensor(f"{leg}_foot_touch")
        foot = model.body(f"{leg}_foot")
        assert foot.jntnum == 0  # welded to the leg: the force sensor sees the whole contact
        assert model.site(f"{leg}_foot").bodyid == foot.id
    platform_of = {leg: int(model.body(f"{leg}_leg").parentid[0]) for leg in LEG_NAMES}
    assert {platform_of[leg] for leg in h.upper_legs} == {model.body("upper").id}
    assert {platform_of[leg] for leg in h.lower_legs} == {model.body("torso").id}
    # The upper platform can only translate relative to the lower one.
    upper = model.body("upper")
    assert upper.parentid == model.body("torso").id
    types = model.jnt_type[upper.jntadr[0] : upper.jntadr[0] + upper.jntnum[0]]
    assert list(types) == [mujoco.mjtJoint.mjJNT_SLIDE] * 3
    for limb in h.limbs:
        np.testing.assert_allclose(model.actuator(limb).ctrlrange, [P.limb_min, P.limb_max])
        assert model.actuator(limb).trntype == mujoco.mjtTrn.mjTRN_TENDON
    assert set(h.actuators) == {model.actuator(i).name for i in range(model.nu)}
    assert sum(model.body_mass) == pytest.approx(P.total_mass)


def test_stands_still_on_six_legs(standing):
    model, data, h = standing
    torso = data.body("torso")
    z_axis = torso.xmat.reshape(3, 3)[:, 2]
    assert z_axis[2] > 0.9999
    assert torso.xpos[2] == pytest.approx(P.lower_leg_length, abs=0.003)
    assert np.abs(torso.xpos[:2]).max() < 1e-3
    assert np.abs(data.qvel).max() < 1e-3
    touch = np.array([data.sensor(s).data[0] for s in h.foot_touch_sensors])
    assert touch.min() > 2.0  # every foot carries load
    assert touch.sum() == pytest.approx(P.total_mass * G, rel=0.01)
    np.testing.assert_allclose(upper_in_torso(data), [0, 0, 0.3633], atol=5e-4)


def test_foot_force_sensor_sign_convention(standing):
    """Ground reaction on a resting foot = -R_site @ sensor - m_foot g (see model docstring)."""
    model, data, h = standing
    for leg in LEG_NAMES:
        rot = data.site(f"{leg}_foot").xmat.reshape(3, 3)
        grf = -rot @ data.sensor(f"{leg}_foot_force").data - np.array([0, 0, -P.foot_mass * G])
        touch = data.sensor(f"{leg}_foot_touch").data[0]
        np.testing.assert_allclose(grf, [0, 0, touch], atol=0.05 + 0.01 * touch)


def move_upper_through_targets(params, targets):
    """Stand, lift the upper legs, then ramp the limb lengths from IK to each target (1 s ramp,
    as a gait would command) and let it settle; yield (target, reached, model, data, handles)."""
    model, data, h = build(params)
    set_ctrl(data, standing_controls(params))
    step(model, data, 0.5)
    set_ctrl(data, {f"{leg}_extend": -params.leg_retract for leg in h.upper_legs})
    step(model, data, 0.4)
    current = upper_in_torso(data)
    for target in targets:
        target = np.array(target)
        ramp = round(1.0 / model.opt.timestep)
        for k in range(ramp):
            set_ctrl(data, limb_controls(current + (target - current) * (k + 1) / ramp, params))
            mujoco.mj_step(model, data)
        step(model, data, 0.6)
        mujoco.mj_forward(model, data)
        yield target, upper_in_torso(data), model, data, h
        current = target


TARGETS = [(0.08, 0.0, 0.443), (0.12, 0.05, 0.40), (-0.1, -0.05, 0.38)]


def test_limb_lengths_from_ik_move_upper_platform_to_pose():
    """PD limb servos: the platform reaches the IK pose within a few mm; the remaining offset
    is the elastic sag under the upper half's weight, (kp sum n_i n_i^T)^-1 m_1 g (n_i: limb
    directions), which the nearly parallel limbs make mostly horizontal."""
    for target, reached, _, data, h in move_upper_through_targets(P, TARGETS):
        assert np.linalg.norm(reached - target) < 4e-3, (target, reached)
        v = limb_vectors(target, P)
        n = v / np.linalg.norm(v, axis=1, keepdims=True)
        sag = np.linalg.solve(P.limb_stiffness * n.T @ n, [0, 0, -P.upper_half_mass * G])
        np.testing.assert_allclose(reached - target, sag, atol=2.5e-4)
        # Slide joints and the forward kinematics of the measured limb lengths agree.
        slides = np.array([data.joint(j).qpos[0] for j in h.upper_joints])
        np.testing.assert_allclose(slides, upper_slide_offset(reached, P), atol=1e-6)
        lengths = [data.sensor(s).data[0] for s in h.limb_length_sensors]
        np.testing.assert_allclose(forward_kinematics(lengths, P), reached, atol=1e-6)
        assert data.body("torso").xmat.reshape(3, 3)[2, 2] > 0.999  # still upright


@pytest.mark.skipif(not hasattr(mujoco, "mjtCtrlInput"), reason="PID actuator needs MuJoCo 4")
def test_pid_limb_servo_removes_the_sag():
    # The PID gains were tuned on the lightly damped mechanism; see UpuParams.limb_integral_gain.
    params = UpuParams(limb_integral_gain=2.0e6, upper_slide_damping=5.0)
    for target, reached, model, _, _ in move_upper_through_targets(params, TARGETS):
        assert model.actuator("limb1").dyntype == mujoco.mjtDyn.mjDYN_PID
        assert np.linalg.norm(reached - target) < 1e-3, (target, reached)


def test_leg_extension_raises_torso():
    model, data, h = build()
    set_ctrl(data, standing_controls(P))
    step(model, data, 0.5)
    z0 = data.body("torso").xpos[2]
    set_ctrl(data, {f"{leg}_extend": 0.05 for leg in LEG_NAMES})
    step(model, data, 1.0)
    assert data.body("torso").xpos[2] - z0 == pytest.approx(0.05, abs=0.002)
    assert data.sensor("L1_extend_pos").data[0] == pytest.approx(0.05, abs=0.002)


def test_bad_pos_raises():
    with pytest.raises(ValueError, match="pos"):
        add_upu(mujoco.MjSpec(), pos=(0.0, float("nan"), 0.3))
