"""The compiled per-step measurements (hexapod_envs.envs._compiled) against their numpy forms."""

import contextlib

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from hexapod_envs.envs._compiled import numpy_sum
from hexapod_envs.stability import fasm_from_feet, static_stability_margin


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


@pytest.mark.parametrize(
    "env_id, kwargs",
    [
        ("HexapodCliffWalk-v0", {}),
        ("HexapodStewartTilt-v0", {}),
        ("HexapodIrregularTerrain-v0", {"terrain": "blocks"}),
    ],
)
def test_support_reading_matches_the_sensor_accessors(env_id, kwargs):
    """RobotSensors.support = foot_forces, the contact test, cog, fasm_from_feet and Σ|F v|,
    along a random-action episode (forces to the last bits of the BLAS products)."""
    env = gym.make(env_id, **kwargs)
    env.reset(seed=3)
    env.action_space.seed(3)
    base = env.unwrapped
    s = base.sensors
    threshold = base._contact_force_sq
    polygons = 0
    for _ in range(60):
        env.step(env.action_space.sample())
        reading = s.support(threshold)
        forces = s.foot_forces()
        np.testing.assert_allclose(reading.forces, forces, rtol=1e-12, atol=1e-9)
        loaded = (forces * forces).sum(axis=1) > threshold
        assert reading.loaded.tolist() == loaded.tolist()
        assert reading.cog.tobytes() == s.cog().tobytes()
        margin, edge = fasm_from_feet(s.foot_positions(), forces, s.cog(), loaded)
        assert reading.fasm_deg == pytest.approx(margin, abs=1e-9) and reading.fasm_edge == edge
        polygons += edge is not None
        power = np.abs(s.actuator_forces() * s.joint_velocities()).sum()
        assert reading.power == pytest.approx(power, rel=1e-12)
    assert polygons > 0
    env.close()


def test_ditch_measurements_match_their_numpy_form():
    """HexapodDitchCrossing-v0's compiled measurements against the numpy expressions: forces =
    foot weight - s Rᵀ, the touch switches, the soles' FASM and Σ|F v|."""
    env = gym.make("HexapodDitchCrossing-v0")
    env.reset(seed=1)
    env.action_space.seed(1)
    base = env.unwrapped
    d = base.data
    polygons = 0
    for _ in range(60):
        env.step(env.action_space.sample())
        rot = d.xmat[base._torso].reshape(3, 3)
        forces = base._foot_weight - d.sensordata[base._force_idx] @ rot.T
        np.testing.assert_allclose(base._forces, forces, rtol=1e-12, atol=1e-9)
        loaded = d.sensordata[base._touch] > base.contact_force
        assert base._loaded.tolist() == loaded.tolist()
        cog = d.subtree_com[base._torso]
        margin, edge = fasm_from_feet(d.xpos[base._foot_body], forces, cog, loaded)
        assert base._fasm_deg == pytest.approx(margin, abs=1e-9) and base._fasm_edge == edge
        polygons += edge is not None
        act = base._act
        power = np.abs(d.actuator_force[act] * d.actuator_velocity[act]).sum()
        assert base._power == pytest.approx(power, rel=1e-12)
        soles = d.xpos[base._foot_body][loaded]
        static = 0.0
        with contextlib.suppress(ValueError):  # fewer than 3 loaded soles, or collinear
            static = static_stability_margin(soles, cog, gravity=(0.0, 0.0, -9.81))
        assert base._static_margin == pytest.approx(static, abs=1e-12)
    assert polygons > 0
    env.close()
