"""The compiled control periods (`hexapod_envs.vector.compiled_steps`) step a world exactly as
the env's own `_simulate` does through the Python binding, and leave its flags as they were."""

from __future__ import annotations

import gymnasium as gym
import mujoco
import numpy as np
import pytest

import hexapod_envs  # noqa: F401  (registers the ids)
from hexapod_envs.envs.physics import SENSORS_OFF
from hexapod_envs.vector.compiled_steps import (
    _disableflags_offset,
    compiled_steps_available,
    run_control_periods,
)

pytestmark = pytest.mark.skipif(
    not compiled_steps_available(), reason="libmujoco's mj_step not reachable through ctypes"
)

FIELDS = ("time", "qpos", "qvel", "act", "qacc_warmstart", "ctrl", "sensordata", "xpos", "cfrc_ext")


def test_the_flags_offset_points_at_the_models_disableflags():
    import ctypes

    offset = _disableflags_offset()
    model = mujoco.MjModel.from_xml_string("<mujoco/>")
    for flags in (0, 5, int(mujoco.mjtDisableBit.mjDSBL_MIDPHASE) | SENSORS_OFF):
        model.opt.disableflags = flags
        assert ctypes.c_int32.from_address(model._address + offset).value == flags


@pytest.mark.parametrize("env_id", ["HexapodCliffWalk-v1", "HexapodDitchCrossing-v1"])
def test_compiled_periods_equal_the_envs_own_physics(env_id):
    """Two copies of one env, each a whole control period in its own share, against a third
    stepped by its own `_simulate`."""
    worlds = [gym.make(env_id).unwrapped for _ in range(3)]
    for env in worlds:
        env.reset(seed=3)
    *compiled, reference = worlds
    rng = np.random.default_rng(0)
    own = reference.model.opt.disableflags
    flags = np.array([[own | SENSORS_OFF, own]] * 2, np.int32)
    nsteps = np.array([reference.n_substeps] * 2)
    done = np.zeros(2, np.int8)
    for step in range(40):
        action = rng.uniform(-1, 1, reference.action_space.shape).astype(np.float32)
        for env in worlds:
            env._apply_action(env._validate_action(action))
        models = np.array([env.model._address for env in compiled])  # a reset may rebuild
        datas = np.array([env.data._address for env in compiled])
        done[:] = 0
        run_control_periods(models, datas, flags, nsteps, done, 0, 1)  # one share ...
        assert done.tolist() == [1, 0]
        run_control_periods(models, datas, flags, nsteps, done, 1, 2)  # ... then the next
        assert done.tolist() == [1, 1]
        assert reference._simulate()
        for env in compiled:
            assert env.model.opt.disableflags == own  # the model's own flags are left
            for field in FIELDS:
                got, expected = getattr(env.data, field), getattr(reference.data, field)
                assert np.array_equal(got, expected), (step, field)


def test_a_control_period_of_one_step_evaluates_the_sensors():
    env = gym.make("HexapodStewartTilt-v1").unwrapped
    env.reset(seed=0)
    before = env.data.sensordata.copy()
    args = [np.array([env.model._address]), np.array([env.data._address])]
    own = env.model.opt.disableflags
    flags = np.array([[own | SENSORS_OFF, own]], np.int32)
    run_control_periods(*args, flags, np.array([1]), np.zeros(1, np.int8), 0, 1)
    assert not np.array_equal(env.data.sensordata, before)
