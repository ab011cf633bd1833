"""Least-squares ground plane z = a x + b y + c (Zhang et al. 2024 §4.2)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hexapod_envs.stability import Plane, fit_plane

A, B, C = 0.2, -0.35, -1.75  # a 11 deg / 19 deg slope, 1.75 m below the body


def on_plane(xy: np.ndarray) -> np.ndarray:
    return np.column_stack([xy, A * xy[:, 0] + B * xy[:, 1] + C])


@pytest.mark.parametrize("k", [3, 4, 6, 40])
def test_recovers_a_known_plane_exactly(k):
    rng = np.random.default_rng(k)
    plane = fit_plane(on_plane(rng.uniform(-3.0, 3.0, size=(k, 2))))
    assert (plane.a, plane.b, plane.c) == pytest.approx((A, B, C), abs=1e-12)
    expected_normal = np.array([-A, -B, 1.0]) / math.sqrt(A * A + B * B + 1.0)
    np.testing.assert_allclose(plane.normal, expected_normal, atol=1e-12)
    assert plane.height_at(1.0, 2.0) == pytest.approx(A + 2 * B + C)


def test_far_from_the_origin_is_still_exact():
    xy = np.array([[1000.0, 2000.0], [1003.0, 2000.0], [1000.0, 2004.0], [1002.0, 2003.0]])
    plane = fit_plane(on_plane(xy))
    assert (plane.a, plane.b, plane.c) == pytest.approx((A, B, C), abs=1e-8)


@pytest.mark.parametrize("k", [6, 200])
def test_noisy_points_give_the_ordinary_least_squares_solution(k):
    rng = np.random.default_rng(7)
    pts = on_plane(rng.uniform(-2.5, 2.5, size=(k, 2)))
    pts[:, 2] += rng.normal(scale=0.01, size=k)
    plane = fit_plane(pts)
    design = np.column_stack([pts[:, :2], np.ones(k)])
    coeffs, *_ = np.linalg.lstsq(design, pts[:, 2], rcond=None)
    assert (plane.a, plane.b, plane.c) == pytest.approx(tuple(coeffs), abs=1e-10)
    # And close to the true plane (noise 1 cm over a 5 m patch).
    tolerance = 0.02 if k == 6 else 0.005
    assert (plane.a, plane.b, plane.c) == pytest.approx((A, B, C), abs=tolerance)


def test_distance_projection_and_inclination():
    plane = Plane.from_coefficients(A, B, C)
    p = np.array([0.5, -1.0, 2.0])
    foot = np.array([0.5, -1.0, plane.height_at(0.5, -1.0)])
    # Signed distance along the unit normal = vertical gap times cos(inclination).
    vertical_gap = p[2] - foot[2]
    assert plane.distance(p) == pytest.approx(vertical_gap * plane.normal[2])
    projected = plane.project(p)
    assert plane.distance(projected) == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(np.cross(p - projected, plane.normal), 0.0, atol=1e-12)
    assert plane.distance(p - 2 * plane.distance(p) * plane.normal) == pytest.approx(
        -plane.distance(p)
    )
    batch = np.vstack([p, foot, projected])
    np.testing.assert_allclose(plane.distance(batch), [plane.distance(p), 0.0, 0.0], atol=1e-12)
    assert plane.project(batch).shape == (3, 3)
    assert plane.inclination_rad == pytest.approx(math.atan(math.hypot(A, B)))


def test_point_lies_on_the_plane_and_plane_is_frozen():
    rng = np.random.default_rng(1)
    plane = fit_plane(on_plane(rng.normal(size=(5, 2))))
    assert plane.distance(plane.point) == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(AttributeError):
        plane.a = 0.0  # type: ignore[misc]


@pytest.mark.parametrize(
    ("points", "message"),
    [
        ([[0, 0, 0], [1, 1, 1]], "at least 3"),
        ([[0, 0, 0], [1, 1, 1], [2, 2, 5]], "collinear"),  # vertical plane
        ([[1, 1, 0], [1, 1, 1], [1, 1, 2], [1, 1, 3]], "collinear"),  # all above one point
        ([[0, 0, 0], [1, 0, 0], [0, 1, np.nan]], "NaN"),
        ([[0, 0], [1, 0], [0, 1]], "shape"),
    ],
)
def test_fit_plane_errors(points, message):
    with pytest.raises(ValueError, match=message):
        fit_plane(points)


def test_plane_normal_is_fit_planes_normal_or_none_where_it_raises():
    from hexapod_envs.stability import plane_normal

    rng = np.random.default_rng(5)
    for k in (3, 4, 6):
        pts = rng.normal(size=(k, 3))
        assert np.array_equal(plane_normal(pts), fit_plane(pts).normal)
    collinear = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 0.2], [2.0, 2.0, 0.1]])
    with pytest.raises(ValueError):
        fit_plane(collinear)
    assert plane_normal(collinear) is None
    assert plane_normal(np.array([[0.0, 0.0, np.nan], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])) is None
