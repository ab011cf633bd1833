"""Tests of the ditch terrain (Li et al. 2018 §7): surface heights by ray casts and argument
checks."""

import mujoco
import numpy as np
import pytest

from hexapod_envs.terrain.ditch import DITCH_GEOMS, add_ditch, ditch_ground_height


def surface_height(model, data, x, y=0.0):
    geomid = np.zeros(1, dtype=np.int32)
    dist = mujoco.mj_ray(
        model, data, np.array([x, y, 1.0]), np.array([0, 0, -1.0]), None, 1, -1, geomid
    )
    return 1.0 - dist


def test_ditch_surface_heights_and_edges():
    spec = mujoco.MjSpec()
    add_ditch(spec, start_x=0.6, width=0.35, depth=0.14, friction=0.8)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    for x in [-3.0, 0.0, 0.59, 0.61, 0.775, 0.94, 0.96, 3.0]:
        expected = ditch_ground_height(x, 0.6, 0.35, 0.14)
        assert surface_height(model, data, x, y=0.3) == pytest.approx(expected, abs=1e-9)
    assert ditch_ground_height(0.7, 0.6, 0.35, 0.14) == -0.14
    for name in DITCH_GEOMS:
        geom = model.geom(name)
        assert geom.friction[0] == pytest.approx(0.8)
        assert geom.contype == 0 and geom.conaffinity == 1


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"width": 0.0}, "width"),
        ({"depth": -0.1}, "depth"),
        ({"start_x": float("inf")}, "start_x"),
        ({"length": 0.3}, "length"),
    ],
)
def test_bad_ditch_arguments_raise(kwargs, fragment):
    with pytest.raises(ValueError, match=fragment):
        add_ditch(mujoco.MjSpec(), **kwargs)
