"""Tests of the limit-boundary workspace search (Li et al. 2018 §4.2, Fig. 9)."""

import math

import numpy as np
import pytest

from hexapod_envs.robots.upu.kinematics import LIMIT_NAMES, check_limits, inside_limits
from hexapod_envs.robots.upu.params import UpuParams
from hexapod_envs.robots.upu.workspace import search_workspace

P = UpuParams()


@pytest.fixture(scope="module")
def ws():
    return search_workspace(P, step=0.01)


def test_workspace_contains_gait_points_and_fits_search_box(ws):
    assert not ws.touches_search_box
    inside = {tuple(np.round(p, 3)) for p in ws.points}
    for point in [(0.0, 0.0, 0.4), (0.08, 0.0, 0.44), (0.16, 0.0, 0.37)]:
        assert point in inside


def test_workspace_z_extent_on_axis_is_closed_form(ws):
    """On the z axis every limb is sqrt(Delta^2 + z^2): z spans [sqrt(lmin^2 - D^2),
    sqrt(lmax^2 - D^2)] = [363.3, 463.7] mm."""
    on_axis = ws.points[(np.abs(ws.points[:, 0]) < 1e-9) & (np.abs(ws.points[:, 1]) < 1e-9)]
    z_lo = math.sqrt(P.limb_min**2 - P.delta**2)
    z_hi = math.sqrt(P.limb_max**2 - P.delta**2)
    assert on_axis[:, 2].min() == pytest.approx(z_lo, abs=0.01)
    assert on_axis[:, 2].max() == pytest.approx(z_hi, abs=0.01)
    assert on_axis[:, 2].min() >= z_lo and on_axis[:, 2].max() <= z_hi


def test_every_accepted_point_passes_check_limits(ws):
    rng = np.random.default_rng(0)
    pts = ws.points[rng.choice(len(ws.points), size=200, replace=False)]
    assert all(check_limits(p, P, tol=0.0).ok for p in pts)


def test_boundary_points_are_labelled_by_paper_surfaces(ws):
    assert len(ws.boundary_points) > 0
    assert set(ws.boundary_limit) <= set(LIMIT_NAMES)
    # Top surface: limb_max; bottom: limb_min; sides: Hooke-joint limits (paper §7).
    top = ws.boundary_points[:, 2] > 0.455
    assert set(ws.boundary_limit[top]) == {"limb_max"}
    labels = set(ws.boundary_limit)
    assert {"limb_min", "limb_max"} <= labels
    assert labels & {"hooke_theta1", "hooke_theta2"}


def test_lower_moving_workspace_is_point_reflection():
    rng = np.random.default_rng(2)
    pts = rng.uniform([-0.3, -0.3, 0.25], [0.3, 0.3, 0.47], size=(2000, 3))
    up = inside_limits(pts, P, tol=0.0)
    assert 0 < up.sum() < len(pts)
    np.testing.assert_array_equal(inside_limits(-pts, P, moving="lower", tol=0.0), up)
    a = search_workspace(P, z_range=(0.2, 0.48), step=0.02)
    b = search_workspace(P, z_range=(-0.48, -0.2), step=0.02, moving="lower")
    np.testing.assert_allclose(b.extent()["z"], [-a.extent()["z"][1], -a.extent()["z"][0]])
    assert b.volume == pytest.approx(a.volume, rel=1e-3)


def test_bad_search_box_raises():
    with pytest.raises(ValueError, match="x_range"):
        search_workspace(P, x_range=(0.1, -0.1))
    with pytest.raises(ValueError, match="step"):
        search_workspace(P, step=0.0)
    with pytest.raises(ValueError, match="too large"):
        search_workspace(P, step=0.0005)
