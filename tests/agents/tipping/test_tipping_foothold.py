"""Reachable region and foothold selection of the adjustment leg (Zhang et al. 2024 §4.2, eqs.
10-14)."""

import math

import numpy as np
import pytest

from agents.tipping.foothold import (
    AXIS_ANGLE_THRESHOLD_DEG,
    reachable_region,
    select_foothold,
    terrain_plane,
)
from agents.tipping.judgment import select_adjustment_leg
from hexapod_envs.robots.heavy_duty import (
    TRIPODS,
    HeavyDutyParams,
    joints_for_foot,
    standing_feet,
    within_limits,
)
from hexapod_envs.stability import Plane

PARAMS = HeavyDutyParams()
FEET = standing_feet(PARAMS)
HEIGHT = PARAMS.stand_height  # flat ground 1.75 m below the hips
FLAT = Plane.from_coefficients(0.0, 0.0, -HEIGHT)
TRIPOD_1, TRIPOD_2 = TRIPODS


def stance(names):
    return {name: FEET[name] for name in names}


def swing_extreme(l1: float, theta: float, height: float) -> float:
    """Lateral foot offset [m] from the hip on flat ground `height` below at swing angle theta.

    Eq. (1) with J_x = 0: P_z = L1 sin θ - d cos θ = -height fixes d, then P_y follows.
    """
    d = (height + l1 * math.sin(theta)) / math.cos(theta)
    return l1 * math.cos(theta) + d * math.sin(theta)


def test_terrain_plane_of_standing_feet_is_flat():
    plane = terrain_plane(stance(TRIPOD_1))
    np.testing.assert_allclose(plane.normal, [0.0, 0.0, 1.0], atol=1e-12)
    assert plane.height_at(1.0, -2.0) == pytest.approx(-HEIGHT)


@pytest.mark.parametrize("leg", ["LM", "RR"])
@pytest.mark.parametrize("rho", [0.8, 1.0])
def test_paper_model_flat_ground_closed_form(leg, rho):
    region = reachable_region(leg, FLAT, PARAMS, rho=rho, model="paper")
    hip = PARAMS.hip_offsets[leg]
    pts = region.points
    np.testing.assert_allclose(pts["H"], hip + [0.0, 0.0, -HEIGHT], atol=1e-12)
    assert region.hip_height == pytest.approx(HEIGHT)
    np.testing.assert_allclose(region.lateral, [0.0, -1.0, 0.0], atol=1e-12)
    # The L_max circle would reach sqrt(L_max² - h²) = 1.48 m, i.e. 40° at B_i > 0.35 rad, so
    # the swing clamp sets ‖HR‖ = ‖HL‖ = h tan(θ_max), then scaled by ρ.
    reach = rho * HEIGHT * math.tan(0.35)
    np.testing.assert_allclose(pts["R"], pts["H"] + [0.0, -reach, 0.0], atol=1e-12)
    np.testing.assert_allclose(pts["L"], pts["H"] + [0.0, reach, 0.0], atol=1e-12)
    front, rear = rho * 5.0 * 0.1, rho * 5.0 * -0.1  # ρ K_x J_x on flat ground
    np.testing.assert_allclose(pts["A"], pts["L"] + [front, 0, 0], atol=1e-12)
    np.testing.assert_allclose(pts["B"], pts["L"] + [rear, 0, 0], atol=1e-12)
    np.testing.assert_allclose(pts["C"], pts["R"] + [rear, 0, 0], atol=1e-12)
    np.testing.assert_allclose(pts["D"], pts["R"] + [front, 0, 0], atol=1e-12)


def test_paper_model_without_swing_clamp_uses_eq_10():
    wide = HeavyDutyParams(j_theta_range=(-1.2, 1.2))
    region = reachable_region("RR", FLAT, wide, rho=0.9, model="paper")
    # Flat ground: β = 90°, eq. (10) gives ‖HR‖ = sqrt(L_max² - ‖B_iH‖²).
    reach = 0.9 * math.sqrt(wide.max_leg_length**2 - HEIGHT**2)
    assert region.points["R"][1] - region.points["H"][1] == pytest.approx(-reach)
    assert region.points["L"][1] - region.points["H"][1] == pytest.approx(reach)


@pytest.mark.parametrize("leg", ["LF", "LM", "RM", "RR"])
def test_kinematic_model_flat_ground_closed_form(leg):
    rho = 0.9
    region = reachable_region(leg, FLAT, PARAMS, rho=rho)
    l1 = PARAMS.signed_l1(leg)
    lo, hi = PARAMS.j_theta_range
    # Exact extremes at the swing limits (leg length stays inside 1.2-2.2 m there).
    outer = [swing_extreme(l1, lo, HEIGHT), swing_extreme(l1, hi, HEIGHT)]
    s_lo, s_hi = sorted(-y for y in outer)  # s runs along r̂_HR = -y
    assert abs(max(outer, key=abs)) == pytest.approx(1.3308, abs=1e-4)
    # H (straight under the hip) is out of swing range, so ρ shrinks about the midpoint.
    assert not within_limits(joints_for_foot(leg, region.points["H"], PARAMS), PARAMS)
    mid = 0.5 * (s_lo + s_hi)
    h_point = region.points["H"]
    expect_r = h_point + [0.0, -(mid + rho * (s_hi - mid)), 0.0]
    expect_l = h_point + [0.0, -(mid + rho * (s_lo - mid)), 0.0]
    np.testing.assert_allclose(region.points["R"], expect_r, atol=1e-9)
    np.testing.assert_allclose(region.points["L"], expect_l, atol=1e-9)
    # Every corner is reachable by the leg's inverse kinematics.
    for name in "ABCDLR":
        joints = joints_for_foot(leg, region.points[name], PARAMS)
        assert within_limits(joints, PARAMS), name


def test_region_on_tilted_plane_stays_in_leg_plane():
    plane = Plane.from_coefficients(0.15, -0.25, -1.7)
    for model in ("kinematic", "paper"):
        region = reachable_region("RF", plane, PARAMS, model=model)
        u = region.lateral
        assert u @ [1.0, 0.0, 0.0] == pytest.approx(0.0, abs=1e-12)
        assert u @ plane.normal == pytest.approx(0.0, abs=1e-12)
        y_on_plane = np.array([0.0, 1.0, 0.0]) - plane.normal[1] * plane.normal
        assert u @ y_on_plane < 0.0  # opposite to the projected body y
        for name, p in region.points.items():
            assert plane.distance(p) == pytest.approx(0.0, abs=1e-9), name
        assert region.points["R"][0] == pytest.approx(PARAMS.hip_x)
        assert region.points["L"][0] == pytest.approx(PARAMS.hip_x)


def test_no_reachable_ground_is_a_status():
    deep = Plane.from_coefficients(0.0, 0.0, -3.0)  # ‖B_iH‖ = 3 m > L_max = 2.29 m
    for model in ("kinematic", "paper"):
        feet = {name: FEET[name] + [0.0, 0.0, -1.25] for name in TRIPOD_1}
        choice = select_foothold("RR", feet, ("LR", "RM"), PARAMS, model=model)
        assert choice.status == "no_reachable_ground"
        assert choice.foothold is None and choice.point is None
        assert "L_max" in choice.reason
        assert reachable_region("RR", deep, PARAMS, model=model).status == "no_reachable_ground"


def test_ground_at_exactly_l_max_makes_h_the_target():
    # Paper model: ‖B_iH‖ = L_max -> H is the target location.
    drop = PARAMS.max_leg_length - HEIGHT
    feet = {name: FEET[name] + [0.0, 0.0, -drop] for name in TRIPOD_1}
    choice = select_foothold("RR", feet, ("LR", "RM"), PARAMS, model="paper")
    assert choice.status == "ok" and choice.point == "H"
    np.testing.assert_allclose(
        choice.foothold, PARAMS.hip_offsets["RR"] + [0.0, 0.0, -PARAMS.max_leg_length]
    )
    assert "L_max" in choice.reason


# §5.2 of the paper: (stance, tipping edge, adjustment leg, paper's foothold [m], tolerance [m]).
# The forward case of the first tripod prints x = -2490 for the right front leg, impossible for a
# front leg (its hip is at x = +2.4); the sign is read as a typo. The paper's front/rear footholds
# sit at x = ±2.39-2.49, ours at the hip's x = ±2.4 (its hips' x positions are not given).
PAPER_CASES = [
    (TRIPOD_1, ("LR", "RM"), "RR", (-2.390, -1.908, -1.741)),  # climbing, tips backward
    (TRIPOD_1, ("RM", "LF"), "RF", (2.490, -1.908, -1.741)),  # descending, tips forward
    (TRIPOD_1, ("LF", "LR"), "LM", (0.0, 1.894, -1.783)),  # side slope
    (TRIPOD_2, ("RR", "LM"), "LR", (-2.390, 1.908, -1.741)),
    (TRIPOD_2, ("LM", "RF"), "LF", (2.490, 1.913, -1.728)),
    (TRIPOD_2, ("RF", "RR"), "RM", (0.0, -1.894, -1.782)),
]


@pytest.mark.parametrize(("stance_legs", "edge", "leg", "paper_foothold"), PAPER_CASES)
def test_paper_cases_with_paper_model(stance_legs, edge, leg, paper_foothold):
    assert select_adjustment_leg(stance_legs, edge) == leg
    choice = select_foothold(leg, stance(stance_legs), edge, PARAMS, rho=1.0, model="paper")
    # All six of the paper's footholds are R or L points (level with the hip).
    assert choice.point in ("R", "L")
    assert choice.axis_angle_deg < AXIS_ANGLE_THRESHOLD_DEG
    # Lateral reach h tan(0.35) = 0.639 m vs the paper's 0.644-0.663 m; x and z differ by the
    # paper's hip x (2.39 / 2.49) and its tilted fitted plane (z -1.728 to -1.783).
    np.testing.assert_allclose(choice.foothold[1], paper_foothold[1], atol=0.025)
    np.testing.assert_allclose(choice.foothold, paper_foothold, atol=0.095)
    assert choice.within_joint_limits


@pytest.mark.parametrize(("stance_legs", "edge", "leg", "paper_foothold"), PAPER_CASES)
def test_paper_cases_with_kinematic_model(stance_legs, edge, leg, paper_foothold):
    choice = select_foothold(leg, stance(stance_legs), edge, PARAMS)
    assert choice.status == "ok" and choice.within_joint_limits
    assert choice.point in ("R", "L")
    hip = PARAMS.hip_offsets[leg]
    assert choice.foothold[0] == pytest.approx(hip[0])
    # Our leg reaches farther sideways than the paper's model allows (L1 offset): the foothold
    # lies outside the paper's, on the same side.
    assert np.sign(choice.foothold[1]) == np.sign(paper_foothold[1])
    assert abs(choice.foothold[1]) > abs(paper_foothold[1]) + 0.5
    assert choice.distances[choice.point] > 0.5


def test_side_case_paper_model_lands_on_the_axis():
    # The paper's explanation of the weak side recovery (margin only 21.5°): the lateral reach
    # barely passes the tipping edge. The paper model puts L 0.011 m inside the LF-LR line.
    choice = select_foothold("LM", stance(TRIPOD_1), ("LF", "LR"), PARAMS, rho=1.0, model="paper")
    assert abs(choice.distances["L"]) < 0.02
    assert choice.status == "no_outside_foothold"
    kinematic = select_foothold("LM", stance(TRIPOD_1), ("LF", "LR"), PARAMS)
    assert kinematic.status == "ok" and kinematic.distances["L"] > 0.6


def test_backward_case_farthest_corner_when_threshold_is_zero():
    choice = select_foothold("RR", stance(TRIPOD_1), ("LR", "RM"), PARAMS, angle_threshold_deg=0.0)
    assert choice.point == "C"  # rear-right corner: farthest from the LR-RM axis
    assert choice.distances["C"] == max(choice.distances.values())


def test_h_on_axis_prefers_right_side_eq_14():
    # Build a stance whose tipping axis LR -> RM passes through H of leg RR at 45° to the
    # region's segments (farthest-point branch); the paper model's region is symmetric about H.
    h_xy = PARAMS.hip_offsets["RR"][:2]
    d = np.array([1.0, -1.0]) / math.sqrt(2.0)
    feet = {
        "LR": np.array([*(h_xy - 2.0 * d), -HEIGHT]),
        "RM": np.array([*(h_xy + 2.0 * d), -HEIGHT]),
        "LF": np.array([2.4, 1.9, -HEIGHT]),
    }
    choice = select_foothold("RR", feet, ("RM", "LR"), PARAMS, model="paper")
    assert choice.tipping_edge == ("LR", "RM")
    assert choice.axis_angle_deg == pytest.approx(45.0)
    dist = choice.distances
    for a, b in (("B", "D"), ("A", "C"), ("L", "R")):
        assert abs(dist[a]) == pytest.approx(abs(dist[b]))
    # Eq. (14): Θ = (P'_i->X × P'_i->P'_j)·z_C > 0 means X is right of the axis.
    p_i, p_j = feet["LR"], feet["RM"]
    theta = np.cross(choice.foothold - p_i, p_j - p_i)[2]
    assert theta > 0.0
    assert choice.point == "C"


def test_bad_inputs_raise():
    feet = stance(TRIPOD_1)
    with pytest.raises(ValueError, match="valid legs"):
        select_foothold("XX", feet, ("LR", "RM"), PARAMS)
    with pytest.raises(ValueError, match="among the stance"):
        select_foothold("LF", feet, ("LR", "RM"), PARAMS)
    with pytest.raises(ValueError, match="rho"):
        select_foothold("RR", feet, ("LR", "RM"), PARAMS, rho=1.5)
    with pytest.raises(ValueError, match="valid models"):
        select_foothold("RR", feet, ("LR", "RM"), PARAMS, model="exact")
    with pytest.raises(ValueError, match="stance legs"):
        select_foothold("RR", feet, ("LR", "RR"), PARAMS)
