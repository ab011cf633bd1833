"""Settings checked by name at `gym.make`, and the train/test task distributions."""

import dataclasses
import math
import re

import gymnasium as gym
import mujoco
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from hexapod_envs.envs.cliff_walk import CLIFF_TEST, CLIFF_TRAIN, CliffTaskRanges
from hexapod_envs.envs.ditch_crossing import DITCH_TEST, DITCH_TRAIN
from hexapod_envs.envs.heavy_duty import HeavyDutySettings
from hexapod_envs.envs.irregular_terrain import TERRAIN_TEST, TERRAIN_TRAIN
from hexapod_envs.envs.physics import SOLVER_IDS
from hexapod_envs.envs.stewart_tilt import TILT_TEST, TILT_TRAIN

ENV_IDS = sorted(k for k in gym.registry if k.startswith("Hexapod"))
V0_IDS = [env_id for env_id in ENV_IDS if env_id.endswith("-v0")]
"""The -v0 envs, whose test ranges lie outside the training ranges; the -v1 benchmark's test
tasks are at least as hard instead (tests/hexapod_envs/test_benchmark_v1.py)."""


def _settings_class(env_id):
    module, name = gym.spec(env_id).entry_point.split(":")
    return getattr(__import__(module, fromlist=[name]), name).Settings


def _numeric_settings(env_id):
    return _settings_class(env_id).numeric_names()


def _unnamed(env_id, names, bad):
    """(setting, error or "accepted") for each setting whose bad value is not refused with an
    error that names it."""
    unnamed = []
    for name in names:
        try:
            gym.make(env_id, **{name: bad})
        except (ValueError, TypeError) as err:
            if not re.search(rf"(?<!\w){re.escape(name)}(?!\w)", str(err)):  # not a longer name
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
    signed = _settings_class(env_id).signed_names()
    names = [n for n in _numeric_settings(env_id) if n not in signed]
    assert not _unnamed(env_id, names, -1.0)
    assert len(signed) <= 4, signed  # positions and offsets only


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_unknown_and_renamed_keys_list_the_valid_ones(env_id):
    with pytest.raises(TypeError, match=r"unknown keyword argument\(s\) \['speed'\].*valid"):
        gym.make(env_id, speed=1.0)
    with pytest.raises(TypeError, match="progress_weight is now forward_weight"):
        gym.make(env_id, progress_weight=1.0)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_reward_scales_are_a_nested_record_given_flat_or_nested(env_id):
    env = gym.make(env_id).unwrapped
    reward = env.settings.reward
    assert dataclasses.is_dataclass(reward) and reward.tip_over_penalty > 0
    flat = gym.make(env_id, tip_over_penalty=7.0).unwrapped.settings.reward
    nested = gym.make(env_id, reward={"tip_over_penalty": 7.0}).unwrapped.settings.reward
    assert flat == nested == dataclasses.replace(reward, tip_over_penalty=7.0)
    with pytest.raises(ValueError, match="tip_over_penalty"):
        gym.make(env_id, reward={"tip_over_penalty": math.nan})
    with pytest.raises(TypeError, match="unknown reward scale"):
        gym.make(env_id, reward={"bonus": 1.0})


def test_one_vocabulary_across_envs():
    """The same name means the same thing in every env: a contact threshold is a fraction of
    the weight, ξ a setting of its own, the settle time the physics run before an episode,
    and the progress term is "forward"."""
    for env_id in ENV_IDS:
        env = gym.make(env_id).unwrapped
        s = env.settings
        assert 0 < s.contact_threshold < 0.1
        assert env.tipping_threshold_deg == s.tipping_threshold_deg
        assert s.settle_time == 0.5
        assert "forward_weight" in {f.name for f in dataclasses.fields(s.reward)}
    athena = gym.make("HexapodIrregularTerrain-v0").unwrapped
    assert athena.contact_force == pytest.approx(0.5)  # the paper robot's 0.5 N
    assert athena.gait_config["contact_threshold"] == pytest.approx(0.5)


def test_task_ranges_are_settings_a_user_can_widen():
    wide = CliffTaskRanges(
        cliff_x=(3.0, 6.0),
        edge_y=(-1.3, -0.7),
        drop=(1.0, 5.0),
        friction=(0.5, 1.5),
        payload_mass=(0.0, 0.0),
        payload_offset=0.0,
    )
    env = gym.make("HexapodCliffWalk-v0", task_distribution="train", train_ranges=wide)
    xs = [env.reset(seed=k)[1]["task"]["cliff_x"] for k in range(12)]
    assert max(xs) > CLIFF_TRAIN.cliff_x[1] and all(3.0 <= x <= 6.0 for x in xs)
    with pytest.raises(ValueError, match="drop"):
        dataclasses.replace(wide, drop=(2.0, 1.0))


@pytest.mark.parametrize("env_id", ["HexapodCliffWalk-v0", "HexapodStewartTilt-v0"])
def test_the_heavy_duty_payload_is_a_task_range(env_id):
    env = gym.make(
        env_id,
        task_distribution="test",
        test_ranges={"payload_mass": [100.0, 200.0], "payload_offset": 0.0},
    )
    tasks = [env.reset(seed=k)[1]["task"] for k in range(8)]
    assert all(100.0 <= t["payload_mass"] <= 200.0 for t in tasks)
    assert all(t["payload_offset_x"] == t["payload_offset_y"] == 0.0 for t in tasks)
    with pytest.raises(ValueError, match="payload_offset entries must be >= 0"):
        gym.make(env_id, train_ranges={"payload_offset": -0.1})


def test_task_ranges_take_a_mapping_as_a_yaml_config_gives_them():
    # the named ranges replace the default's (lists as tuples), the others stay
    env = gym.make(
        "HexapodIrregularTerrain-v0",
        task_distribution="train",
        train_ranges={"friction": [0.3, 0.4], "slope_deg": [[2.0, 3.0], [16.0, 17.0]]},
    )
    ranges = env.unwrapped.settings.train_ranges
    assert ranges == dataclasses.replace(
        TERRAIN_TRAIN, friction=(0.3, 0.4), slope_deg=((2.0, 3.0), (16.0, 17.0))
    )
    tasks = [env.reset(seed=k)[1]["task"] for k in range(6)]
    assert all(0.3 <= t["friction"] <= 0.4 for t in tasks)
    assert all(2.0 <= t["slope_deg"] <= 3.0 or 16.0 <= t["slope_deg"] <= 17.0 for t in tasks)
    one = gym.make("HexapodIrregularTerrain-v0", train_ranges={"slope_deg": [4.0, 5.0]})
    assert one.unwrapped.settings.train_ranges.slope_deg == ((4.0, 5.0),)  # one interval


@pytest.mark.parametrize(
    "ranges, error, words",
    [
        ({"frction": [0.3, 0.4]}, TypeError, ["frction", "valid", "friction"]),
        ({"friction": 0.5}, ValueError, ["train_ranges.friction", "(low, high) pair"]),
        ({"sides": [1.0, 2.0]}, ValueError, ["train_ranges.sides", "list of names"]),
        ({"sides": ["lft"]}, ValueError, ["train_ranges.sides", "'right', 'left'"]),
        ({"drop": [3.0, 1.0]}, ValueError, ["train_ranges", "drop", "low <= high"]),
    ],
)
def test_bad_task_ranges_are_named(ranges, error, words):
    with pytest.raises(error) as caught:
        gym.make("HexapodCliffWalk-v0", train_ranges=ranges)
    assert all(w in str(caught.value) for w in words), str(caught.value)


@pytest.mark.parametrize(
    "env_id, ranges, words",
    [
        ("HexapodCliffWalk-v0", {"friction": [-1.0, -0.5]}, ["friction", ">= 0"]),
        ("HexapodCliffWalk-v0", {"drop": [-1.0, 1.0]}, ["drop", "> 0"]),
        ("HexapodCliffWalk-v0", {"cliff_x": [0.0, 1.0]}, ["cliff_x", "> 2.471"]),
        ("HexapodStewartTilt-v0", {"rates_deg_s": [[0.0, 1.0]]}, ["rates_deg_s", "> 0"]),
        ("HexapodStewartTilt-v0", {"friction": [-1.0, 0.5]}, ["friction", ">= 0"]),
        ("HexapodIrregularTerrain-v0", {"servo_kp_scale": [[-2.0, -1.0]]}, ["servo_kp_scale"]),
        ("HexapodIrregularTerrain-v0", {"slope_deg": [[40.0, 50.0]]}, ["slope_deg", "<= 45"]),
        ("HexapodIrregularTerrain-v0", {"block_size": [0.0, 0.1]}, ["block_size", "> 0"]),
        ("HexapodDitchCrossing-v0", {"depth": [0.0, 0.1]}, ["depth", "> 0"]),
        ("HexapodDitchCrossing-v0", {"friction": [-1.0, 0.0]}, ["friction", "> 0"]),
        ("HexapodDitchCrossing-v0", {"start_x": [0.1, 0.2]}, ["start_x", ">= 0.240 m"]),
    ],
)
def test_task_ranges_outside_what_the_plain_setting_takes_are_refused_at_make(
    env_id, ranges, words
):
    """A range is refused where the plain setting of the same quantity is (negative friction,
    a cliff behind the robot, a ditch under it), at gym.make, not at a reset that draws it."""
    for where in ("train_ranges", "test_ranges"):
        with pytest.raises(ValueError) as caught:
            gym.make(env_id, **{where: ranges})
        assert all(w in str(caught.value) for w in [where, *words]), str(caught.value)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_task_ranges_cannot_be_none(env_id):
    with pytest.raises(ValueError, match="train_ranges must be a .*TaskRanges or a mapping"):
        gym.make(env_id, train_ranges=None)


def test_a_probability_range_outside_0_1_is_named():
    with pytest.raises(ValueError, match=r"case_probability must be in \[0, 1\]"):
        gym.make("HexapodStewartTilt-v0", train_ranges={"case_probability": 1.5})


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_a_recorded_settings_file_rebuilds_the_same_settings(env_id):
    import yaml

    from agents.run_files.configtools import dump_yaml
    from agents.run_files.env_settings import resolved_settings

    env = gym.make(env_id, task_distribution="train")
    record = yaml.safe_load(dump_yaml(resolved_settings(env)))  # env_settings.yaml's content
    assert isinstance(record["train_ranges"], dict)
    assert gym.make(env_id, **record).unwrapped.settings == env.unwrapped.settings
    # every setting is recorded, not only the ones that differ from a default that may change
    settings = env.unwrapped.settings
    assert set(record) == {f.name for f in dataclasses.fields(settings)}
    assert set(record["reward"]) == {f.name for f in dataclasses.fields(settings.reward)}


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_every_setting_is_checked_and_every_number_is_a_numeric_setting(env_id):
    """The bad-value tests above find the settings by their metadata (`number`, `choice`...):
    a field declared without it would be neither validated nor tested."""
    settings = _settings_class(env_id)
    numeric = set(settings.numeric_names())
    for klass in (settings, settings.reward_class):
        for f in dataclasses.fields(klass):
            if f.name == "reward":  # the nested section, checked field by field
                continue
            assert "check" in f.metadata, f"{klass.__name__}.{f.name} is not validated"
            default = f.default
            if isinstance(default, int | float) and not isinstance(default, bool):
                assert f.name in numeric, f"{klass.__name__}.{f.name} is not a numeric setting"


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
        ("HexapodDitchCrossing-v0", {"camera_name": "trak"}),
        ("HexapodCliffWalk-v0", {"camera_name": "side"}),
        ("HexapodCliffWalk-v0", {"control_dt": np.float32(0.02)}),  # not a divisor of the gait
    ],
)
def test_meaningless_values_are_named(env_id, kwargs):
    (name,) = kwargs
    with pytest.raises(ValueError, match=name):
        gym.make(env_id, **kwargs)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_physics_options_reach_every_model_the_env_builds(env_id):
    """integrator and solver land in model.opt, also after a reset that draws a new task (the
    block bed, a cliff, a ditch rebuild the model); a bad choice lists the valid ones."""
    env = gym.make(env_id, integrator="euler", solver="cg", task_distribution="train")
    for seed in range(2):
        env.reset(seed=seed)
        opt = env.unwrapped.model.opt
        assert opt.integrator == mujoco.mjtIntegrator.mjINT_EULER
        assert opt.solver == mujoco.mjtSolver.mjSOL_CG
    env.close()
    heavy_duty = issubclass(_settings_class(env_id), HeavyDutySettings)
    default = "pgs" if heavy_duty else "newton"  # the sweep's choice per robot
    assert gym.make(env_id).unwrapped.model.opt.solver == SOLVER_IDS[default]
    with pytest.raises(ValueError, match=r"solver must be one of \['cg', 'newton', 'pgs'\]"):
        gym.make(env_id, solver="lbfgs")


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
        ("block_size", [TERRAIN_TRAIN.block_size], [TERRAIN_TEST.block_size]),
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


@pytest.mark.parametrize("env_id", V0_IDS)
def test_train_resets_give_distinct_tasks_in_the_train_ranges(env_id):
    tasks = _tasks(env_id, "train", 20)
    distinct = {tuple(sorted(t.items())) for t in tasks}
    assert len(distinct) >= 10
    for key, train, _ in HELD_OUT[env_id]:
        assert all(_inside(t[key], train) for t in tasks), key


@pytest.mark.parametrize("env_id", V0_IDS)
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
    if env_id.startswith("HexapodStewartTilt"):  # the paper env's default scenario is "random"
        drawn = ("stance", "difficulty")  # and its difficulty rates the drawn tilt
        tasks = [{k: v for k, v in t.items() if "tilt" not in k and k not in drawn} for t in tasks]
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


@pytest.mark.parametrize("bad", ["yes", 1, 0.0])
def test_a_flag_setting_takes_a_bool_or_none_only(bad):
    with pytest.raises(ValueError, match=r"midphase must be one of \[False, None, True\]"):
        gym.make("HexapodCliffWalk-v0", midphase=bad)
