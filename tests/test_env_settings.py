"""Settings checked by name at `gym.make`, and the train/test task distributions."""

import inspect
import math
import numbers

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from hexapod_envs.envs.base import _settings_signature
from hexapod_envs.envs.cliff_walk import CLIFF_TEST, CLIFF_TRAIN
from hexapod_envs.envs.ditch_crossing import DITCH_TEST, DITCH_TRAIN
from hexapod_envs.envs.irregular_terrain import TERRAIN_TEST, TERRAIN_TRAIN
from hexapod_envs.envs.stewart_tilt import TILT_TEST, TILT_TRAIN

ENV_IDS = sorted(k for k in gym.registry if k.startswith("Hexapod"))


def _is_numeric(p: inspect.Parameter) -> bool:
    """Numeric by default value (a real number or a tuple of them) or by its float/int type."""
    d = p.default
    if isinstance(d, tuple):
        flat = [x for v in d for x in (v if isinstance(v, tuple) else (v,))]
        return bool(flat) and all(isinstance(x, numbers.Real) for x in flat)
    if isinstance(d, numbers.Real) and not isinstance(d, bool):
        return True
    ann = str(p.annotation)
    return d is None and (ann in ("float | None", "int | None") or ann.startswith("tuple["))


def _numeric_settings(env_id):
    cls = gym.spec(env_id).entry_point
    module, name = cls.split(":")
    klass = getattr(__import__(module, fromlist=[name]), name)
    return [n for n, p in _settings_signature(klass).items() if _is_numeric(p)]


def _unnamed(env_id, names, bad):
    """(setting, error or "accepted") for each setting whose bad value is not refused with an
    error that names it."""
    unnamed = []
    for name in names:
        try:
            gym.make(env_id, **{name: bad})
        except (ValueError, TypeError) as err:
            if name not in str(err):
                unnamed.append((name, str(err)))
        else:
            unnamed.append((name, "accepted"))
    return unnamed


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("bad", [math.nan, "abc", math.inf, True])
def test_every_numeric_setting_names_itself_when_bad(env_id, bad):
    names = _numeric_settings(env_id)
    assert len(names) >= 10
    assert not _unnamed(env_id, names, bad)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_negative_values_are_named_where_meaningless(env_id):
    from hexapod_envs.envs.base import SIGNED_SETTINGS

    names = [n for n in _numeric_settings(env_id) if n not in SIGNED_SETTINGS]
    assert not _unnamed(env_id, names, -1.0)


@pytest.mark.parametrize(
    "env_id, kwargs",
    [
        ("HexapodCliffWalk-v0", {"friction": -1.0}),
        ("HexapodCliffWalk-v0", {"reset_noise_scale": -1.0}),
        ("HexapodCliffWalk-v0", {"forward_weight": -1.0}),
        ("HexapodStewartTilt-v0", {"platform_friction": -0.5}),
        ("HexapodIrregularTerrain-v0", {"block_height_range": (0.04, math.nan)}),
        ("HexapodDitchCrossing-v0", {"ditch_width_range": (0.3, math.inf)}),
        ("HexapodDitchCrossing-v0", {"task_distribution": "easy"}),
    ],
)
def test_meaningless_values_are_named(env_id, kwargs):
    (name,) = kwargs
    with pytest.raises(ValueError, match=name):
        gym.make(env_id, **kwargs)


# --- task distributions ---------------------------------------------------------------------
def _inside(x, ranges):
    return any(lo <= x <= hi for lo, hi in ranges)


HELD_OUT = {
    # env id -> (task key, train ranges, test ranges); every test task must lie in the test
    # ranges and outside the training ones for these keys.
    "HexapodCliffWalk-v0": [
        ("cliff_x", [CLIFF_TRAIN.cliff_x], [CLIFF_TEST.cliff_x]),
        ("cliff_drop", [CLIFF_TRAIN.drop], [CLIFF_TEST.drop]),
        ("friction", [CLIFF_TRAIN.friction], [CLIFF_TEST.friction]),
        ("payload_mass", [(0.0, 500.0)], [(500.0, 800.0)]),
    ],
    "HexapodStewartTilt-v0": [
        ("tilt_rate_deg", TILT_TRAIN.rates_deg_s, TILT_TEST.rates_deg_s),
        ("platform_friction", [TILT_TRAIN.friction], [TILT_TEST.friction]),
    ],
    "HexapodIrregularTerrain-v0": [
        ("slope_deg", TERRAIN_TRAIN.slope_deg, TERRAIN_TEST.slope_deg),
        ("block_height_max", [TERRAIN_TRAIN.block_height_max], [TERRAIN_TEST.block_height_max]),
        ("friction", [TERRAIN_TRAIN.friction], [TERRAIN_TEST.friction]),
    ],
    "HexapodDitchCrossing-v0": [
        ("ditch_width", [DITCH_TRAIN.width], [DITCH_TEST.width]),
        ("ditch_depth", [DITCH_TRAIN.depth], [DITCH_TEST.depth]),
        ("friction", [DITCH_TRAIN.friction], [DITCH_TEST.friction]),
    ],
}


def _tasks(env_id, distribution, n, seed0=0):
    env = gym.make(env_id, task_distribution=distribution).unwrapped
    tasks = [env.reset(seed=seed0 + k)[1]["task"] for k in range(n)]
    env.close()
    return tasks


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_train_resets_give_distinct_tasks_in_the_train_ranges(env_id):
    tasks = _tasks(env_id, "train", 20)
    distinct = {tuple(sorted(t.items())) for t in tasks}
    assert len(distinct) >= 10
    for key, train, _ in HELD_OUT[env_id]:
        assert all(_inside(t[key], train) for t in tasks), key


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_test_tasks_lie_in_the_held_out_ranges(env_id):
    tasks = _tasks(env_id, "test", 8, seed0=100)
    for key, train, test in HELD_OUT[env_id]:
        for t in tasks:
            assert _inside(t[key], test), (key, t[key])
            lo_hi = [(lo, hi) for lo, hi in train]
            assert not any(lo < t[key] < hi for lo, hi in lo_hi), (key, t[key])


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_paper_distribution_is_one_task(env_id):
    tasks = _tasks(env_id, "paper", 3)
    if env_id == "HexapodStewartTilt-v0":  # the paper env's default scenario is "random"
        tasks = [{k: v for k, v in t.items() if "tilt" not in k and k != "stance"} for t in tasks]
    assert tasks[0] == tasks[1] == tasks[2]


def test_sampled_task_changes_the_physics():
    env = gym.make("HexapodCliffWalk-v0", task_distribution="train").unwrapped
    _, info = env.reset(seed=5)
    torso = env.sensors.torso_id
    assert env.model.body_mass[torso] > env._torso_mass0 + 1.0  # the payload is on board
    assert env.cliff["drop"] == pytest.approx(info["task"]["cliff_drop"])
    obs, *_ = env.step(np.zeros(18))
    assert np.all(np.isfinite(obs))


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_sensor_noise_perturbs_forces_and_imu_only(env_id):
    clean = gym.make(env_id).unwrapped
    noisy = gym.make(env_id, sensor_noise=0.05).unwrapped
    o_clean, i_clean = clean.reset(seed=4)
    o_noisy, i_noisy = noisy.reset(seed=4)
    s = clean.observation_structure
    for name in ("foot_force", "imu_gyro", "imu_accel"):
        assert not np.allclose(o_clean[s[name]], o_noisy[s[name]]), name
    np.testing.assert_array_equal(o_clean[s["joint_pos"]], o_noisy[s["joint_pos"]])
    assert i_clean["fasm_margin_deg"] == i_noisy["fasm_margin_deg"]
    assert np.linalg.norm(o_noisy[s["imu_quat"]]) == pytest.approx(1.0)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_settings_are_one_frozen_record_that_rebuilds_the_env(env_id):
    import dataclasses

    env = gym.make(env_id, task_distribution="train", reset_noise_scale=0.002).unwrapped
    settings = env.settings
    assert settings.task_distribution == "train" and settings.reset_noise_scale == 0.002
    with pytest.raises(dataclasses.FrozenInstanceError):
        settings.reset_noise_scale = 0.1
    fields = {f.name: getattr(settings, f.name) for f in dataclasses.fields(settings)}
    again = gym.make(env_id, **fields).unwrapped
    o1, i1 = env.reset(seed=9)
    o2, i2 = again.reset(seed=9)
    np.testing.assert_array_equal(o1, o2)
    assert i1["task"] == i2["task"]
