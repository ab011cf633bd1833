"""Heavy-duty hexapod leg kinematics (Zhang et al. 2024 eqs. 1-2) and standing geometry."""

import numpy as np
import pytest

from hexapod_envs.robots.heavy_duty import (
    LEG_NAMES,
    HeavyDutyParams,
    foot_in_body,
    foot_in_coxa,
    joints_for_foot,
    joints_from_coxa,
    standing_feet,
    within_limits,
)

P = HeavyDutyParams()


def test_forward_kinematics_matches_eq1_closed_form():
    j = np.array([0.04, 0.2, 0.1])
    l1 = 0.65
    d = P.k_z * 0.2 + P.l2
    expected = [5 * 0.04, l1 * np.cos(0.1) + d * np.sin(0.1), l1 * np.sin(0.1) - d * np.cos(0.1)]
    np.testing.assert_allclose(foot_in_coxa(j, l1, P), expected)


@pytest.mark.parametrize("leg", LEG_NAMES)
def test_inverse_then_forward_round_trip(leg):
    rng = np.random.default_rng(0)
    r = P.joint_ranges
    joints = rng.uniform(r[:, 0], r[:, 1], size=(200, 3))
    feet = foot_in_body(leg, joints, P)
    np.testing.assert_allclose(joints_for_foot(leg, feet, P), joints, atol=1e-12)


def test_unreachable_point_is_a_clear_error():
    with pytest.raises(ValueError, match="L1"):
        joints_from_coxa(np.array([0.0, 0.1, 0.1]), 0.65, P)


def test_standing_feet_match_the_paper_footholds():
    feet = standing_feet(P)
    for leg, foot in feet.items():
        assert abs(abs(foot[0]) - (2.4 if leg[1] != "M" else 0.0)) < 1e-12
        assert foot[1] == pytest.approx(1.9 if leg[0] == "L" else -1.9)
        assert foot[2] == pytest.approx(-1.75)
        assert within_limits(joints_for_foot(leg, foot, P), P)


def test_masses_from_the_paper():
    assert P.total_mass == pytest.approx(5000.0)
