"""Inverse kinematics of Zhang et al. 2024's 6-UPS Stewart platform (§5.2)."""

import math

import numpy as np
import pytest

from hexapod_envs.terrain.stewart_kinematics import (
    DEFAULT_PLATFORM,
    StewartPlatform,
    actuator_lengths,
    axis_angle_matrix,
    check_pose,
    max_tilt,
    rpy_matrix,
)

P = DEFAULT_PLATFORM
# Horizontal distance between a base joint and its platform joint in the neutral pose: the two
# are 40° apart in angle (base at ±10°, platform at ±50°) on radii 5.5 m and 3.5 m.
HORIZONTAL_SQ = 5.5**2 + 3.5**2 - 2.0 * 5.5 * 3.5 * math.cos(math.radians(40.0))


def test_layout_radii_and_pairs():
    np.testing.assert_allclose(np.linalg.norm(P.base_joints, axis=1), 5.5)
    np.testing.assert_allclose(np.linalg.norm(P.platform_joints, axis=1), 3.5)
    base_deg = np.degrees(np.arctan2(P.base_joints[:, 1], P.base_joints[:, 0])) % 360
    np.testing.assert_allclose(base_deg, [350, 10, 110, 130, 230, 250], atol=1e-9)
    top_deg = np.degrees(np.arctan2(P.platform_joints[:, 1], P.platform_joints[:, 0])) % 360
    np.testing.assert_allclose(top_deg, [310, 50, 70, 170, 190, 290], atol=1e-9)


def test_neutral_pose_symmetric_lengths():
    lengths = actuator_lengths(P.neutral_position, (0.0, 0.0, 0.0))
    expected = math.sqrt(P.neutral_height**2 + HORIZONTAL_SQ)
    np.testing.assert_allclose(lengths, expected, rtol=1e-12)
    assert 9.0 < expected < 14.0


@pytest.mark.parametrize("height", [8.6, 10.0, 12.0, 13.4])
def test_pure_vertical_translation_closed_form(height):
    lengths = actuator_lengths([0.0, 0.0, height], (0.0, 0.0, 0.0))
    np.testing.assert_allclose(lengths, math.sqrt(height**2 + HORIZONTAL_SQ), rtol=1e-12)


def test_yaw_splits_the_legs_into_two_groups():
    yaw = math.radians(7.0)
    lengths = actuator_lengths(P.neutral_position, (0.0, 0.0, yaw))
    h2 = P.neutral_height**2
    even = math.sqrt(h2 + 5.5**2 + 3.5**2 - 2 * 5.5 * 3.5 * math.cos(math.radians(-40.0) + yaw))
    odd = math.sqrt(h2 + 5.5**2 + 3.5**2 - 2 * 5.5 * 3.5 * math.cos(math.radians(40.0) + yaw))
    np.testing.assert_allclose(lengths[0::2], even, rtol=1e-12)
    np.testing.assert_allclose(lengths[1::2], odd, rtol=1e-12)


def test_tilt_lengths_match_joint_geometry():
    rpy = (0.2, -0.3, 0.1)
    position = np.array([0.3, -0.2, 11.2])
    rot = rpy_matrix(rpy)
    expected = np.linalg.norm(position + P.platform_joints @ rot.T - P.base_joints, axis=1)
    np.testing.assert_allclose(actuator_lengths(position, rpy), expected, rtol=1e-12)


def test_rpy_matrix_conventions():
    for axis, rpy in ((0, (0.4, 0.0, 0.0)), (1, (0.0, 0.4, 0.0)), (2, (0.0, 0.0, 0.4))):
        np.testing.assert_allclose(rpy_matrix(rpy), axis_angle_matrix(np.eye(3)[axis], 0.4))
    rot = rpy_matrix((0.3, -0.5, 1.1))
    np.testing.assert_allclose(rot @ rot.T, np.eye(3), atol=1e-12)
    expected = axis_angle_matrix([0, 0, 1], 1.1) @ axis_angle_matrix([0, 1, 0], -0.5)
    np.testing.assert_allclose(rot, expected @ axis_angle_matrix([1, 0, 0], 0.3), atol=1e-12)


def test_check_pose_accepts_and_rejects():
    lengths = check_pose(P.neutral_position, (0.1, 0.1, 0.0))
    assert np.all((lengths >= 9.0) & (lengths <= 14.0))
    with pytest.raises(ValueError, match=r"actuator 1 at 15\.\d+ m, outside its range \[9, 14\]"):
        check_pose([0.0, 0.0, 14.6], (0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="actuator [1-6] at 8"):
        check_pose([0.0, 0.0, 7.6], (0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="actuator"):
        check_pose(P.neutral_position, (0.0, math.radians(60.0), 0.0))


@pytest.mark.parametrize("axis", ["x", "y", (-1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (1.0, 1.0, 0.0)])
def test_max_tilt_is_the_reachability_boundary(axis):
    angle = max_tilt(axis)
    vec = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0)}.get(axis, axis)
    pos = P.neutral_position
    assert math.radians(40.0) < angle < math.radians(60.0)
    for a in np.linspace(0.0, angle, 25):
        assert P.in_range(pos, axis_angle_matrix(vec, a))
    assert not P.in_range(pos, axis_angle_matrix(vec, angle + 1e-5))


def test_max_tilt_mirror_symmetry_about_x():
    # The layout is symmetric under y -> -y, so tilting about +x and -x reaches equally far.
    assert max_tilt("x") == pytest.approx(max_tilt((-1.0, 0.0, 0.0)), abs=1e-6)


def test_bad_geometry_and_axis():
    with pytest.raises(ValueError, match="outside"):
        StewartPlatform(neutral_height=5.0)
    with pytest.raises(ValueError, match="valid names"):
        P.max_tilt("diagonal")
    with pytest.raises(ValueError, match="length_range"):
        StewartPlatform(length_range=(14.0, 9.0))
