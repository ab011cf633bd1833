"""Closed-form tests of the 3-UPU kinematics (Li et al. 2018 §3-4) and parameters."""

import math

import numpy as np
import pytest

from hexapod_envs.robots.upu.kinematics import (
    check_limits,
    forward_kinematics,
    forward_kinematics_closed_form,
    hooke_angles,
    inside_limits,
    inverse_kinematics,
    inverse_kinematics_lower,
    is_reachable,
    limb_vectors,
    solve_forward_kinematics,
)
from hexapod_envs.robots.upu.params import (
    LEG_NAMES,
    LOWER_LEGS,
    UPPER_LEGS,
    UpuParams,
    leg_platform,
)

P = UpuParams()
MM = 1e-3


def test_paper_check_point_limb_lengths():
    """(80, 0, 443) mm, the apex of eq. (20): limb 1 = sqrt(115^2 + 443^2) (a closed-form check);
    limbs 2 and 3 from eq. (6) with Delta = 35 mm: sqrt(62.5^2 + 30.31^2 + 443^2)."""
    lengths = inverse_kinematics([0.080, 0.0, 0.443], P)
    assert lengths[0] / MM == pytest.approx(math.sqrt(115**2 + 443**2), abs=1e-9)
    assert lengths[0] / MM == pytest.approx(457.68, abs=0.01)
    expected_23 = math.sqrt((80 - 17.5) ** 2 + (math.sqrt(3) / 2 * 35) ** 2 + 443**2)
    assert lengths[1] / MM == pytest.approx(expected_23, abs=1e-9)
    assert lengths[2] / MM == pytest.approx(expected_23, abs=1e-9)
    assert expected_23 == pytest.approx(448.41, abs=0.01)


def test_limb_vectors_match_eq5():
    x, y, z = 0.03, -0.02, 0.4
    d = P.delta
    s = math.sqrt(3) / 2 * d
    expected = [[x + d, y, z], [x - d / 2, y - s, z], [x - d / 2, y + s, z]]
    np.testing.assert_allclose(limb_vectors([x, y, z], P), expected, atol=1e-15)


def test_initial_pose_is_paper_rounding_of_limb_min():
    lengths = inverse_kinematics(P.initial_position, P)
    np.testing.assert_allclose(lengths, math.hypot(0.035, 0.363))
    assert 0 < P.limb_min - lengths[0] < P.limit_tolerance
    assert is_reachable(P.initial_position, P)
    assert not is_reachable(P.initial_position, P, tol=0.0)


def test_lower_moving_is_point_reflection_and_matches_eq8():
    rng = np.random.default_rng(0)
    pts = rng.uniform([-0.2, -0.2, -0.45], [0.2, 0.2, -0.3], size=(50, 3))
    np.testing.assert_allclose(
        inverse_kinematics(pts, P, moving="lower"), inverse_kinematics_lower(pts, P), atol=1e-15
    )
    np.testing.assert_allclose(
        inverse_kinematics(pts, P, moving="lower"), inverse_kinematics(-pts, P), atol=1e-15
    )


def test_paper_eq21_apex_violates_limb_min():
    """Eq. (21) moves the lower platform through (-80, -283) mm in the upper frame; eq. (8) gives
    limb 1 = sqrt(115^2 + 283^2) = 305.5 mm < l_min = 365 mm, so that path is not reachable."""
    check = check_limits([-0.080, 0.0, -0.283], P, moving="lower")
    assert check.limb_lengths[0] / MM == pytest.approx(math.hypot(115, 283), abs=1e-9)
    assert not check.ok
    assert any("limb1 length" in r and "limb_min" in r for r in check.reasons)


@pytest.mark.parametrize(
    "position",
    [
        (0.0, 0.0, 0.4),
        (0.08, 0.0, 0.443),
        (0.16, 0.0, 0.363),
        (-0.1, 0.07, 0.38),
        (0.05, -0.1, 0.42),
    ],
)
def test_fk_ik_round_trip(position):
    lengths = inverse_kinematics(position, P)
    sol = solve_forward_kinematics(lengths, P)
    assert sol.converged and sol.residual < 1e-10
    np.testing.assert_allclose(sol.position, position, atol=1e-9)
    np.testing.assert_allclose(forward_kinematics_closed_form(lengths, P), position, atol=1e-12)


def test_fk_ik_round_trip_lower_moving():
    position = np.array([-0.12, 0.03, -0.39])
    lengths = inverse_kinematics(position, P, moving="lower")
    np.testing.assert_allclose(forward_kinematics(lengths, P, moving="lower"), position, atol=1e-9)
    np.testing.assert_allclose(
        forward_kinematics_closed_form(lengths, P, moving="lower"), position, atol=1e-12
    )


def test_ik_fk_round_trip_from_lengths():
    """Lengths of random reachable poses -> FK from the default guess -> the same lengths."""
    rng = np.random.default_rng(1)
    for _ in range(20):
        lengths = inverse_kinematics(rng.uniform([-0.15, -0.15, 0.37], [0.15, 0.15, 0.44]), P)
        q = forward_kinematics(lengths, P)
        np.testing.assert_allclose(inverse_kinematics(q, P), lengths, atol=1e-10)


def test_fk_reports_non_convergence():
    # Limb 1 far longer than limbs 2 and 3 can follow: no assembly exists.
    bad = [0.9, 0.1, 0.1]
    sol = solve_forward_kinematics(bad, P)
    assert not sol.converged
    with pytest.raises(ValueError, match="did not converge"):
        forward_kinematics(bad, P)
    with pytest.raises(ValueError, match="no assembly"):
        forward_kinematics_closed_form(bad, P)
    with pytest.raises(ValueError, match="lengths"):
        forward_kinematics([0.4, 0.4], P)


def test_hooke_angles_limb1_match_eqs_10_11():
    x, y, z = 0.05, 0.08, 0.4
    l1 = inverse_kinematics([x, y, z], P)[0]
    ang = hooke_angles([x, y, z], P)
    assert abs(ang.theta1[0]) == pytest.approx(math.asin(abs(y) / l1))
    assert abs(ang.theta2[0]) == pytest.approx(math.acos(z / math.sqrt(l1**2 - y**2)))


def test_hooke_angles_threefold_symmetry():
    """Rotating the platform offset by 120° permutes the limbs and keeps their angles."""
    p = np.array([0.06, 0.02, 0.41])
    c, s = math.cos(2 * math.pi / 3), math.sin(2 * math.pi / 3)
    rotated = np.array([c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]])
    a, b = hooke_angles(p, P), hooke_angles(rotated, P)
    # Limb order by azimuth 180°, 60°, -60°: +120° maps limb 1 -> 3, 2 -> 1, 3 -> 2.
    perm = [1, 2, 0]
    np.testing.assert_allclose(b.theta1, a.theta1[perm], atol=1e-12)
    np.testing.assert_allclose(b.theta2, a.theta2[perm], atol=1e-12)
    np.testing.assert_allclose(
        inverse_kinematics(rotated, P), inverse_kinematics(p, P)[perm], atol=1e-12
    )


@pytest.mark.parametrize(
    ("position", "fragment"),
    [
        ((0.0, 0.0, 0.47), "limb_max"),
        ((0.0, 0.0, 0.34), "limb_min"),
        ((0.3, 0.0, 0.3), "theta2"),
        ((0.0, 0.33, 0.3), "theta1"),
    ],
)
def test_points_outside_limits_are_rejected_with_reason(position, fragment):
    check = check_limits(position, P)
    assert not check.ok and not check
    assert any(fragment in r for r in check.reasons), check.reasons
    assert not is_reachable(position, P)
    assert not inside_limits(position, P)


def test_reachable_points_pass():
    for position in [(0.0, 0.0, 0.4), (0.08, 0.0, 0.443), (0.16, 0.0, 0.363)]:
        check = check_limits(position, P)
        assert check.ok and check.reasons == ()
    assert inside_limits(np.array([[0.0, 0.0, 0.4], [0.0, 0.0, 0.5]]), P).tolist() == [True, False]


def test_bad_inputs_raise():
    with pytest.raises(ValueError, match="moving"):
        inverse_kinematics([0, 0, 0.4], P, moving="middle")
    with pytest.raises(ValueError, match="shape"):
        inverse_kinematics([0, 0.4], P)
    with pytest.raises(ValueError, match="NaN"):
        check_limits([0, np.nan, 0.4], P)
    with pytest.raises(ValueError, match="one position"):
        check_limits(np.zeros((2, 3)), P)


def test_params_validation_and_derived_values():
    assert P.delta == pytest.approx(0.035)
    np.testing.assert_allclose(P.lower_hooke_points[1], [0.08, 0.08 * math.sqrt(3), 0.0])
    np.testing.assert_allclose(P.upper_hooke_points[0], [-0.125, 0.0, 0.0], atol=1e-15)
    assert P.upper_leg_length == pytest.approx(P.lower_leg_length + 0.363)
    assert P.total_mass == pytest.approx(P.upper_half_mass + P.lower_half_mass)
    with pytest.raises(ValueError, match="upper_radius != lower_radius"):
        UpuParams(upper_radius=0.16)
    with pytest.raises(ValueError, match="limb_min"):
        UpuParams(limb_min=0.5)
    with pytest.raises(ValueError, match="leg_mass"):
        UpuParams(leg_mass=-1.0)


def test_leg_names_and_layout():
    assert LEG_NAMES == UPPER_LEGS + LOWER_LEGS
    assert {leg_platform(leg) for leg in UPPER_LEGS} == {"upper"}
    assert {leg_platform(leg) for leg in LOWER_LEGS} == {"lower"}
    with pytest.raises(ValueError, match="valid legs"):
        leg_platform("LF")
    # Six feet on a regular hexagon alternating between the platforms (Fig. 8a).
    angles = sorted(
        (math.atan2(*P.foot_offset(leg)[::-1]) % (2 * math.pi), leg) for leg in LEG_NAMES
    )
    gaps = np.diff([a for a, _ in angles] + [angles[0][0] + 2 * math.pi])
    np.testing.assert_allclose(gaps, math.pi / 3, atol=1e-12)
    platforms = [leg_platform(leg) for _, leg in angles]
    assert all(a != b for a, b in zip(platforms, platforms[1:] + platforms[:1], strict=True))
    # Lower legs beside the lower Hooke joints A_i (same azimuth, farther out).
    for i, leg in enumerate(LOWER_LEGS):
        a = P.lower_hooke_points[i][:2]
        np.testing.assert_allclose(P.foot_offset(leg), a / np.linalg.norm(a) * 0.2, atol=1e-12)
