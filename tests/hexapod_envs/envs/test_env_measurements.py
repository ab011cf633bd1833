"""The compiled per-step measurements (hexapod_envs.envs._compiled, hexapod_envs._compiled, the
UPU robot's hexapod_envs.robots.upu._compiled) against their numpy forms."""

import gymnasium as gym
import numpy as np
import pytest
from helpers.blas_bits import REASON, numba_blas_matches_numpy

import hexapod_envs  # noqa: F401
from hexapod_envs._compiled import numpy_sum
from hexapod_envs.envs._compiled import (
    clip_action,
    filtered_residual_targets,
    offset_targets,
)
from hexapod_envs.stability import fasm_from_feet, zmp_margin
from hexapod_envs.stability._geometry import hull_2d, signed_distance_2d

needs_same_blas = pytest.mark.skipif(not numba_blas_matches_numpy(), reason=REASON)


@pytest.mark.parametrize("n", [0, 1, 7, 8, 9, 15, 16, 17, 18, 31, 64, 127, 128])
def test_numpy_sum_is_numpys_pairwise_order(n):
    """Bit for bit, including lengths where a plain left-to-right loop differs."""
    rng = np.random.default_rng(n)
    plain_differs = 0
    for _ in range(200):
        a = np.abs(rng.normal(size=n)) * 10 ** rng.uniform(-3, 3, n)
        assert numpy_sum(a) == a.sum()
        plain = 0.0
        for value in a.tolist():
            plain += value
        plain_differs += plain != a.sum()
    if n >= 16:  # the check above could not tell the orders apart otherwise
        assert plain_differs > 0
    with pytest.raises(ValueError, match="at most 128"):
        numpy_sum(np.ones(129))


def _seeded_env(env_id: str, seed: int, **kwargs):
    """(env, its unwrapped env) reset and with its action space seeded by `seed`."""
    env = gym.make(env_id, **kwargs)
    env.reset(seed=seed)
    env.action_space.seed(seed)
    return env, env.unwrapped


def _same(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.tobytes() == b.tobytes()


@needs_same_blas
@pytest.mark.parametrize(
    "env_id, kwargs",
    [
        ("HexapodCliffWalk-v0", {}),
        ("HexapodStewartTilt-v0", {}),
        ("HexapodIrregularTerrain-v0", {"terrain": "blocks"}),
    ],
)
def test_support_reading_is_the_sensor_accessors_to_the_bit(env_id, kwargs):
    """RobotSensors.support = foot_forces, the contact test, cog, fasm_from_feet and Σ|F v|
    (numpy's pairwise sum), along a random-action episode."""
    env, base = _seeded_env(env_id, 3, **kwargs)
    s = base.sensors
    threshold = base._contact_force_sq
    polygons = 0
    for _ in range(60):
        env.step(env.action_space.sample())
        reading = s.support(threshold)
        forces = s.foot_forces()
        assert _same(reading.forces, forces)
        loaded = (forces * forces).sum(axis=1) > threshold
        assert _same(reading.loaded, loaded) and _same(reading.cog, s.cog())
        margin, edge = fasm_from_feet(s.foot_positions(), forces, s.cog(), loaded)
        assert (reading.fasm_deg, reading.fasm_edge) == (margin, edge)
        polygons += edge is not None
        assert reading.power == np.abs(s.actuator_forces() * s.joint_velocities()).sum()
    assert polygons > 0
    env.close()


def _former_static_margin(soles: np.ndarray, cog: np.ndarray) -> float:
    """The ditch env's former static margin: tripods as their triangle, else the hull."""
    if len(soles) < 3:
        return 0.0
    xs, ys = soles[:, 0].tolist(), soles[:, 1].tolist()
    px, py = float(cog[0]), float(cog[1])
    if len(xs) == 3:
        area2 = (xs[1] - xs[0]) * (ys[2] - ys[0]) - (ys[1] - ys[0]) * (xs[2] - xs[0])
        if area2 != 0.0:
            return signed_distance_2d(xs, ys, [0, 1, 2] if area2 > 0 else [0, 2, 1], px, py)
    try:
        hull = hull_2d(xs, ys)
    except ValueError:  # collinear: no polygon
        return 0.0
    return signed_distance_2d(xs, ys, hull, px, py)


@needs_same_blas
def test_ditch_measurements_are_their_numpy_form_to_the_bit():
    """HexapodDitchCrossing-v0's compiled measurements against the former expressions: forces =
    foot weight - s Rᵀ, the touch switches, the soles' FASM, Σ|F v| and the static margin."""
    env, base = _seeded_env("HexapodDitchCrossing-v0", 1)
    d = base.data
    polygons = 0
    for _ in range(60):
        env.step(env.action_space.sample())
        rot = d.xmat[base._torso].reshape(3, 3)
        forces = base._foot_weight - d.sensordata[base._force_idx] @ rot.T
        assert _same(base._forces, forces)
        loaded = d.sensordata[base._touch] > base.contact_force
        assert _same(base._loaded, loaded)
        cog = d.subtree_com[base._torso]
        margin, edge = fasm_from_feet(d.xpos[base._foot_body], forces, cog, loaded)
        assert (base._fasm_deg, base._fasm_edge) == (margin, edge)
        polygons += edge is not None
        act = base._act
        assert base._power == np.abs(d.actuator_force[act] * d.actuator_velocity[act]).sum()
        soles = d.xpos[base._foot_body][loaded]
        assert base._static_margin == _former_static_margin(soles, cog)
    assert polygons > 0
    env.close()


@needs_same_blas
def test_torso_frame_zmp_is_its_numpy_form_to_the_bit():
    """ATHENA's ZMP and margin (RobotSensors.torso_frame_zmp) against the env's former numpy
    expressions, along random-action episodes on a block bed (loaded feet tilted and lifted)."""
    env, base = _seeded_env("HexapodIrregularTerrain-v0", 1, terrain="blocks")
    s = base.sensors
    margins = 0
    for _ in range(200):
        _, _, terminated, truncated, info = env.step(0.3 * env.action_space.sample())
        feet = (s.foot_positions() - s.torso_position()) @ s.torso_rotation()
        normal = np.where(base._loaded, np.maximum(base._forces[:, 2], 0.0), 0.0)
        total = float(normal.sum())
        if total > 0:
            assert _same(info["zmp"], (normal @ feet[:, :2]) / total)
            assert info["zmp_margin"] == zmp_margin(feet, normal)
            margins += info["zmp_margin"] != 0.0
        else:
            assert np.isnan(info["zmp"]).all() and info["zmp_margin"] == 0.0
        if terminated or truncated:
            env.reset()
    assert margins > 0
    env.close()


@pytest.mark.parametrize(
    "env_id, kwargs",
    [
        ("HexapodCliffWalk-v0", {}),
        ("HexapodStewartTilt-v0", {"action_mode": "joint"}),
        ("HexapodIrregularTerrain-v0", {"terrain": "blocks"}),
    ],
)
def test_sensor_pieces_of_the_observation_are_the_sensor_accessors(env_id, kwargs):
    """RobotSensors.write_observation (one compiled call) = the pieces read one by one."""
    env, base = _seeded_env(env_id, 2, **kwargs)
    s = base.sensors
    assert tuple(base.observation_structure)[: len(s.OBSERVED)] == s.OBSERVED
    for _ in range(40):
        obs, *_ = env.step(env.action_space.sample())
        piece = base.observation_layout.unpack(obs)
        expected = {
            "joint_pos": s.joint_positions(),
            "joint_vel": s.joint_velocities(),
            "foot_force": base._forces.reshape(-1),
            "foot_contact": base._loaded.astype(float),
            "fasm_margin_deg": np.array([base._fasm_deg]),
            "imu_gyro": s.gyro(),
            "imu_accel": s.accelerometer(),
            "imu_quat": s.orientation(),
        }
        for name, value in expected.items():
            assert _same(piece[name], value), name
    env.close()


@pytest.mark.parametrize("dtype", [np.float32, np.float64, np.int64])
def test_clip_action_is_numpys_clip_and_stops_at_non_finite_values(dtype):
    rng = np.random.default_rng(0)
    low, high = -np.ones(18), np.linspace(0.5, 2.0, 18)
    out = np.empty(18)
    for _ in range(20):
        action = (3 * rng.normal(size=18)).astype(dtype)
        assert clip_action(action, low, high, out)
        expected = np.minimum(np.maximum(action.astype(np.float64), low), high)
        assert _same(out, expected)
    if dtype is not np.int64:  # signed zeros at zero bounds (the gains mode's [0, 1])
        zeros = np.array([0.0, -0.0])
        for low, high in ((zeros, zeros + 1), (zeros - 1, zeros), (zeros[::-1], zeros[::-1])):
            for action in (np.array([-0.0, 0.0]), np.array([0.0, -0.0])):
                action = action.astype(dtype)
                out = np.empty(2)
                assert clip_action(action, low, high, out)
                expected = np.minimum(np.maximum(action.astype(np.float64), low), high)
                assert _same(out, expected), (action, low, high)
        low, high, out = -np.ones(18), np.ones(18), np.empty(18)
        for bad in (np.nan, np.inf, -np.inf):
            action = np.zeros(18, dtype=dtype)
            action[7] = bad
            assert not clip_action(action, low, high, out)


def test_filtered_residual_targets_is_the_numpy_filter_to_the_bit():
    rng = np.random.default_rng(1)
    gain, reference = rng.uniform(0.01, 0.2, 18), rng.normal(size=18)
    actuators = rng.permutation(20)[:18]
    alpha = 0.2 / 1.2
    residual, numpy_residual = np.zeros(18), np.zeros(18)
    ctrl = np.zeros(20)
    for _ in range(30):
        action = rng.uniform(-1, 1, 18)
        filtered_residual_targets(action, gain, alpha, residual, reference, ctrl, actuators)
        numpy_residual += alpha * (gain * action - numpy_residual)
        assert _same(residual, numpy_residual)
        assert _same(ctrl[actuators], reference + numpy_residual)


def test_offset_targets_is_the_numpy_sum_to_the_bit():
    rng = np.random.default_rng(2)
    actuators = rng.permutation(24)[:18]
    ctrl = np.zeros(24)
    for _ in range(30):
        targets, gain, action = (
            rng.normal(size=(6, 3)),
            rng.uniform(0, 0.3, 18),
            rng.uniform(-1, 1, 18),
        )
        offset_targets(targets, gain, action, ctrl, actuators)
        assert _same(ctrl[actuators], targets.reshape(-1) + gain * action)


@needs_same_blas
def test_stewart_actuator_lengths_are_the_platforms_to_the_bit():
    """The tilt env's compiled actuator lengths are StewartPlatform.actuator_lengths' numbers
    for random poses about every axis, level and yawed ones among them."""
    from hexapod_envs.terrain._compiled import stewart_actuator_lengths
    from hexapod_envs.terrain.stewart_kinematics import DEFAULT_PLATFORM as platform

    rng = np.random.default_rng(4)
    centre = platform.neutral_position
    for k in range(500):
        rpy = rng.uniform(-0.8, 0.8, 3) * (1.0, 1.0, k % 2)
        if k % 50 == 0:
            rpy[:] = 0.0
        expected = platform.actuator_lengths(centre, rpy)
        got = stewart_actuator_lengths(
            platform.base_joints, platform.platform_joints, centre, *rpy.tolist()
        )
        assert got.tobytes() == expected.tobytes(), rpy


def test_torso_up_is_the_rotations_third_column_and_a_copy_reads_its_own_data():
    """`RobotSensors.torso_up` is a view bound once: it follows the data step by step, and a
    deep copy of the env reads the copy's data, not the original's."""
    import copy

    env, base = _seeded_env("HexapodStewartTilt-v0", 4, task_distribution="train")
    twin = copy.deepcopy(base)
    for _ in range(20):
        action = env.action_space.sample()
        base.step(action)
        twin.step(-action)
        for e in (base, twin):
            assert _same(e.sensors.torso_up(), e.data.xmat[e.sensors.torso_id].reshape(3, 3)[:, 2])
    assert not _same(twin.sensors.torso_up(), base.sensors.torso_up())
