"""The heavy-duty robot's servo armature: `HeavyDutyParams.joint_armature` reaches each joint of
the model, the envs' ``joint_armature`` setting reaches the robot, and the physics sweep's
``armature`` reaches the envs it makes (experiments/physics_settings/heavy_duty_armature_probe.py
builds on it)."""

import gymnasium as gym
import mujoco
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from experiments.physics_settings.physics_settings import PhysicsSetting, make_env
from hexapod_envs.robots.heavy_duty import HeavyDutyParams
from hexapod_envs.robots.heavy_duty.model import add_heavy_duty


def _armature_by_joint(model: mujoco.MjModel, handles) -> list[np.ndarray]:
    """Per paper joint (x, leg length, swing): its armature on the six legs."""
    return [
        model.dof_armature[
            [model.jnt_dofadr[model.joint(handles.joints[leg][k]).id] for leg in handles.legs]
        ]
        for k in range(3)
    ]


def test_joint_armature_sets_each_joint_of_every_leg():
    spec = mujoco.MjSpec()
    spec.compiler.degree = False
    handles = add_heavy_duty(spec, HeavyDutyParams(joint_armature=(1.0, 2.0, 3.0)))
    model = spec.compile()
    for armature, value in zip(_armature_by_joint(model, handles), (1.0, 2.0, 3.0), strict=True):
        np.testing.assert_array_equal(armature, value)
    kinds = (mujoco.mjtJoint.mjJNT_SLIDE, mujoco.mjtJoint.mjJNT_SLIDE, mujoco.mjtJoint.mjJNT_HINGE)
    for k, kind in enumerate(kinds):
        assert all(model.joint(handles.joints[leg][k]).type == kind for leg in handles.legs)


@pytest.mark.parametrize("env_id", ["HexapodCliffWalk-v0", "HexapodStewartTilt-v0"])
def test_armature_setting_reaches_the_robot(env_id):
    default = gym.make(env_id).unwrapped
    assert default.robot.joint_armature == HeavyDutyParams().joint_armature
    assert default.physics_dt == 0.002
    env = gym.make(env_id, joint_armature=(20.0, 20.0, 50.0), physics_dt=0.001)
    env.reset(seed=0)
    base = env.unwrapped
    assert base.robot.joint_armature == (20.0, 20.0, 50.0)
    assert base.model.opt.timestep == 0.001
    for armature, value in zip(
        _armature_by_joint(base.model, base.handles), (20, 20, 50), strict=True
    ):
        np.testing.assert_array_equal(armature, value)
    with pytest.raises(ValueError, match="joint_armature must have 3 entries"):
        gym.make(env_id, joint_armature=(1.0, 2.0))


def test_physics_sweep_armature_reaches_heavy_duty_envs_only():
    setting = PhysicsSetting(factor=0.5, armature=(40.0, 60.0, 80.0))
    env = make_env("HexapodCliffWalk-v0", setting)
    base = env.unwrapped
    assert base.physics_dt == pytest.approx(0.001)
    for armature, value in zip(
        _armature_by_joint(base.model, base.handles), (40, 60, 80), strict=True
    ):
        np.testing.assert_array_equal(armature, value)
    assert "armature 40/60/80" in setting.label
    with pytest.raises(ValueError, match="heavy-duty envs"):
        make_env("HexapodDitchCrossing-v0", setting)
