"""Coelho et al. 2024's irregular terrain pieces (ramp, block test bed), checked with MuJoCo ray
casts."""

import math

import mujoco
import numpy as np
import pytest

from hexapod_envs.envs.physics import set_physics_options
from hexapod_envs.robots.athena.model import add_athena
from hexapod_envs.robots.athena.params import ATHENA
from hexapod_envs.terrain.irregular import add_blocks, add_ramp


def _ray_height(model, data, x, y, top=2.0):
    """Height of the first geom hit by a vertical ray from (x, y, top) downwards."""
    geomid = np.zeros(1, dtype=np.int32)
    dist = mujoco.mj_ray(
        model, data, np.array([x, y, top]), np.array([0, 0, -1.0]), None, 1, -1, geomid
    )
    assert dist >= 0, f"nothing below ({x}, {y})"
    return top - dist


def _compiled(spec):
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def test_ramp_surface_has_the_requested_slope_and_a_flat_approach():
    spec = mujoco.MjSpec()
    ramp = add_ramp(spec, slope_deg=10.0, start_x=0.5, length=1.5, top_length=0.5)
    model, data = _compiled(spec)
    for x in (-0.3, 0.0, 0.4, 0.6, 1.0, 1.9, 2.1, 2.4):
        assert _ray_height(model, data, x, 0.1) == pytest.approx(
            ramp.surface_height(x, 0.1), abs=1e-9
        )
    assert ramp.surface_height(0.0) == 0.0  # robot starts on flat ground at the origin
    slope = math.atan2(_ray_height(model, data, 1.5, 0) - _ray_height(model, data, 0.7, 0), 0.8)
    assert math.degrees(slope) == pytest.approx(10.0, abs=1e-9)
    assert ramp.top_height == pytest.approx(1.5 * math.tan(math.radians(10)))
    assert _ray_height(model, data, 2.2, 0.0) == pytest.approx(ramp.top_height, abs=1e-9)
    for name in ramp.geom_names:
        assert model.geom(name).friction[0] == pytest.approx(0.9)


def test_same_generator_state_gives_the_same_blocks():
    def heights(seed):
        return add_blocks(mujoco.MjSpec(), np.random.default_rng(seed)).heights

    np.testing.assert_array_equal(heights(7), heights(7))
    assert not np.array_equal(heights(7), heights(8))
    h = heights(7)
    assert h.min() >= 0.04 and h.max() <= 0.13


def test_blocks_tile_the_region_at_the_sampled_heights():
    spec = mujoco.MjSpec()
    field = add_blocks(
        spec, np.random.default_rng(0), block_size=(0.15, 0.1), region=((0.4, 1.0), (-0.3, 0.3))
    )
    assert field.heights.shape == (4, 6)
    model, data = _compiled(spec)
    rng = np.random.default_rng(1)
    for x, y in rng.uniform([0.41, -0.29], [0.99, 0.29], size=(40, 2)):
        assert _ray_height(model, data, x, y) == pytest.approx(field.surface_height(x, y), abs=1e-9)
    assert field.surface_height(0.0, 0.0) == 0.0
    assert _ray_height(model, data, 0.0, 0.0) == pytest.approx(0.0, abs=1e-9)


def test_scalar_height_at_matches_surface_height_on_and_off_the_pieces():
    ramp = add_ramp(mujoco.MjSpec(), start_x=-0.4, length=3.0, top_length=1.0, width=1.0)
    field = add_blocks(mujoco.MjSpec(), np.random.default_rng(3), region=((0.0, 1.0), (-0.5, 0.5)))
    rng = np.random.default_rng(2)
    for x, y in rng.uniform([-1.0, -0.8], [4.0, 0.8], size=(300, 2)):
        assert ramp.height_at(x, y) == pytest.approx(float(ramp.surface_height(x, y)), abs=1e-15)
        assert field.height_at(x, y) == float(field.surface_height(x, y))
    assert ramp.height_at(3.3, 0.0) == pytest.approx(ramp.top_height)
    assert ramp.height_at(3.3, 0.6) == 0.0 and field.height_at(1.2, 0.0) == 0.0


def test_bad_terrain_arguments_raise_clear_errors():
    spec = mujoco.MjSpec()
    with pytest.raises(ValueError, match="slope_deg"):
        add_ramp(spec, slope_deg=0)
    with pytest.raises(ValueError, match="length"):
        add_ramp(spec, length=-1)
    with pytest.raises(ValueError, match="Generator"):
        add_blocks(spec, 3)
    with pytest.raises(ValueError, match="height_range"):
        add_blocks(spec, np.random.default_rng(0), height_range=(0.2, 0.1))
    with pytest.raises(ValueError, match="region"):
        add_blocks(spec, np.random.default_rng(0), region=((1.0, 0.0), (0.0, 1.0)))


def test_standing_robot_does_not_slide_on_the_ten_degree_ramp():
    # Friction 0.9 >> tan(10 deg): the standing robot placed on the slope stays put. MuJoCo's
    # soft contacts let a loaded foot creep slowly (about 5 mm/s here with the default
    # pyramidal cone and impratio 1); the elliptic cone with impratio 10 brings that to
    # about 0.25 mm/s, so envs on slopes should use these options.
    spec = mujoco.MjSpec()
    set_physics_options(spec, 0.002)
    ramp = add_ramp(spec, start_x=-1.0, length=2.0)
    slope = ramp.slope
    x0 = 0.0
    up = np.array([-math.sin(slope), 0, math.cos(slope)])
    pos = np.array([x0, 0, ramp.surface_height(x0)]) + up * (ATHENA.standing_torso_height + 0.002)
    add_athena(spec, pos=tuple(pos), quat=(math.cos(-slope / 2), 0, math.sin(-slope / 2), 0))
    model, data = _compiled(spec)
    data.ctrl[:] = np.tile(ATHENA.standing_posture, 6)
    mujoco.mj_step(model, data, nstep=250)
    start = data.body("torso").xpos.copy()
    mujoco.mj_step(model, data, nstep=500)
    assert np.linalg.norm(data.body("torso").xpos - start) < 1e-3
    assert data.sensor("torso_height").data[0] == pytest.approx(
        ATHENA.standing_torso_height, abs=0.005
    )
