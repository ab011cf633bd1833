"""Where each candidate stride lands the moving feet (`StrideClearance`), against hand-computed
cases. The robot's constants: upper feet at x = +0.2, -0.1, -0.1 m from its centre, lower feet
at -0.2, +0.1, +0.1 m, band 0.04 m, reach 0.16 m, strides 0.005-0.16 m."""

import numpy as np
import pytest

from hexapod_envs.robots.upu.gait_plan import GaitSettings
from hexapod_envs.robots.upu.params import UpuParams
from hexapod_envs.robots.upu.stride_clearance import StrideClearance

GEOMETRY = StrideClearance.of(UpuParams(), GaitSettings())


def ahead(near_u, far_u, lead=0.0, depth=0.1):
    """``ditch_ahead`` with the upper platform `lead` [m] ahead of the lower."""
    return np.array([near_u, far_u, near_u + lead, far_u + lead, depth])


def test_the_constants_are_the_robots():
    assert GEOMETRY.feet_x["upper"].tolist() == pytest.approx([0.2, -0.1, -0.1])
    assert GEOMETRY.feet_x["lower"].tolist() == pytest.approx([-0.2, 0.1, 0.1])
    assert (GEOMETRY.band, GEOMETRY.reach) == pytest.approx((0.04, 0.16))
    assert (GEOMETRY.max_stride, GEOMETRY.grid) == pytest.approx((0.16, 0.005))


def test_the_front_foot_sets_the_clearance_before_the_ditch():
    # Full stride: front foot at 0.36, 0.14 before the near edge; half: 0.28, 0.22 before it.
    strides, clear = GEOMETRY.candidates(ahead(0.5, 0.8), True, [0.0, -0.5])
    np.testing.assert_allclose(strides, [0.16, 0.08])
    np.testing.assert_allclose(clear, [0.14, 0.22])


def test_a_foot_on_an_edge_has_clearance_0():
    _, clear = GEOMETRY.candidates(ahead(0.36, 0.7), True, [0.0])
    np.testing.assert_allclose(clear, [0.0], atol=1e-12)


def test_a_foot_inside_counts_negative_only_where_the_ditch_is_too_deep_to_stand_in():
    # Front foot at 0.36 in a ditch from 0.3 to 0.6: 0.06 from the near edge.
    _, shallow = GEOMETRY.candidates(ahead(0.3, 0.6, depth=0.1), True, [0.0])
    _, deep = GEOMETRY.candidates(ahead(0.3, 0.6, depth=0.2), True, [0.0])
    np.testing.assert_allclose(shallow, [0.06])
    np.testing.assert_allclose(deep, [-0.06])


def test_the_room_the_other_platform_leaves_caps_the_stride():
    # Upper 0.1 ahead of the lower: the upper may go 0.06 further, the lower 0.1.
    upper, _ = GEOMETRY.candidates(ahead(1.0, 1.3, lead=0.1), True, [0.0, -0.8])
    lower, clear = GEOMETRY.candidates(ahead(1.0, 1.3, lead=0.1), False, [0.0])
    np.testing.assert_allclose(upper, [0.06, 0.032])
    np.testing.assert_allclose(lower, [0.1])
    # The lower's front feet (+0.1) land at 0.2 from its centre, 1.1 - 0.2 = 0.9 before the edge.
    np.testing.assert_allclose(clear, [0.9])


def test_without_values_every_stride_on_the_grid_from_the_longest_down():
    strides, clear = GEOMETRY.candidates(ahead(0.5, 0.8), True)
    assert strides.size == 32 and strides[0] == pytest.approx(0.16)
    assert strides[-1] == pytest.approx(0.005)
    np.testing.assert_allclose(clear, 0.5 - (strides + 0.2))
