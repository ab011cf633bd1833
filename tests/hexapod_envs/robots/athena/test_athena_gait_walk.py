"""Closed loop in MuJoCo: ATHENA walks with the Coelho et al. 2024 gait, and the posture gains act
in the
right direction on the 10 degree ramp (direction checks, not the paper's figures)."""

import math

import mujoco
import numpy as np
import pytest

from hexapod_envs.envs.physics import set_physics_options
from hexapod_envs.robots.athena.gait import AthenaPostureController, AthenaSensors
from hexapod_envs.robots.athena.model import add_athena
from hexapod_envs.robots.athena.params import ATHENA, JOINT_NAMES, LEG_NAMES
from hexapod_envs.terrain.flat import add_flat
from hexapod_envs.terrain.irregular import PAPER_FRICTION, add_ramp

DT, CONTROL_DT = 0.002, 0.05


def _walk(ctrl, duration, ramp_start=None):
    spec = mujoco.MjSpec()
    set_physics_options(spec, DT)
    if ramp_start is None:
        add_flat(spec, friction=PAPER_FRICTION, size=5.0)
    else:
        add_ramp(spec, start_x=ramp_start)
    add_athena(spec)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)  # valid sensor readings before the first control tick
    pos_ids = [[model.sensor(f"{leg}_{j}_pos").adr[0] for j in JOINT_NAMES] for leg in LEG_NAMES]
    force_ids = [model.sensor(f"{leg}_foot_force").adr[0] for leg in LEG_NAMES]
    height_id = model.sensor("torso_height").adr[0]
    torso_geom = model.geom("torso").id
    log, torso_contact = [], False
    for _ in range(round(duration / CONTROL_DT)):
        s = data.sensordata
        sensors = AthenaSensors(
            joint_angles=s[np.array(pos_ids)],
            foot_forces=np.array([s[a : a + 3] for a in force_ids]),
            torso_height=float(s[height_id]),
        )
        data.ctrl[:] = ctrl.step(sensors).reshape(-1)  # actuators were added leg by leg
        for _ in range(round(CONTROL_DT / DT)):
            mujoco.mj_step(model, data)
            geoms = data.contact.geom[: data.ncon]
            torso_contact |= bool(np.any(geoms == torso_geom))
        rot = data.body("torso").xmat.reshape(3, 3)
        nose_up = math.degrees(math.asin(rot[2, 0]))
        roll = math.degrees(math.atan2(rot[2, 1], rot[2, 2]))
        log.append((*data.body("torso").xpos, float(s[height_id]), nose_up, roll))
    return np.array(log), torso_contact


def test_simple_control_walks_straight_on_flat_ground():
    stride = 0.06
    ctrl = AthenaPostureController(stride=stride)
    log, torso_contact = _walk(ctrl, duration=6.0)
    expected = stride / 2 + 5 * stride  # six phases, the first one a half step
    assert log[-1, 0] == pytest.approx(expected, rel=0.15)
    assert abs(log[-1, 1]) < 0.02
    assert np.all(np.abs(log[:, 4:6]) < 3.0)  # pitch and roll within 3 degrees
    assert np.all(np.abs(log[:, 3] - ATHENA.standing_torso_height) < 0.01)
    assert not torso_contact


def test_posture_gains_align_the_torso_with_the_ramp_and_hold_its_height():
    def climb(gains, ground_search="auto"):
        kz, ka, kb = gains
        ctrl = AthenaPostureController(kz=kz, k_alpha=ka, k_beta=kb, ground_search=ground_search)
        log, _ = _walk(ctrl, duration=20.0, ramp_start=0.3)
        return log[-80:], ctrl.last_estimate  # the last 4 s: all feet on the slope

    simple, _ = climb((0.0, 0.0, 0.0))
    # Simple control with ground search: legs that land early on the slope ahead push the nose
    # less far up than the slope, so the torso lags behind the ground's inclination.
    lagging, lagging_est = climb((0.0, 0.0, 0.0), ground_search="always")
    posture, posture_est = climb((0.8, 0.6, 0.0))
    for log in (simple, lagging, posture):
        assert np.all(log[:, 0] > 0.6)  # rear feet past 0.3 m: all on the slope
    # The non-adaptive gait's legs keep their lengths, so on a uniform slope the torso follows it.
    assert simple[:, 4].mean() == pytest.approx(10.0, abs=1.5)
    # k_alpha pitches the nose up towards the 10 degree slope; the residual estimate shrinks.
    assert posture[:, 4].mean() > lagging[:, 4].mean() + 1.5
    assert posture[:, 4].mean() == pytest.approx(10.0, abs=1.5)
    assert abs(posture_est.delta_pitch) < abs(lagging_est.delta_pitch)
    # k_z brings the torso-height reading closer to the standing reference.
    ref = ATHENA.standing_torso_height
    assert abs(np.median(posture[:, 3]) - ref) < abs(np.median(simple[:, 3]) - ref)
