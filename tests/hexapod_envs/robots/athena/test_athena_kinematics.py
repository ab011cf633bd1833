"""ATHENA parameters and DH kinematics (Coelho et al. 2024, Section 3.2): closed-form checks, no
MuJoCo."""

import math

import numpy as np
import pytest
from helpers.blas_bits import REASON, numba_blas_matches_numpy

from hexapod_envs.robots.athena import kinematics as kin
from hexapod_envs.robots.athena.params import (
    ATHENA,
    JOINT_NAMES,
    LEG_FROM_PAPER_NUMBER,
    LEG_NAMES,
    PAPER_LEG_NUMBER,
    TRIPODS,
)

needs_same_blas = pytest.mark.skipif(not numba_blas_matches_numpy(), reason=REASON)


def _random_angles(rng, n):
    lo, hi = ATHENA.joint_ranges[:, 0], ATHENA.joint_ranges[:, 1]
    return rng.uniform(lo, hi, size=(n, 3))


def test_table2_inertias_are_those_of_the_listed_boxes():
    # The reading of the table's inertia unit (1e-3 kg m^2) rests on this check.
    for link in (ATHENA.body, ATHENA.coxa, ATHENA.femur, ATHENA.tibia):
        lx, ly, lz = link.size
        box = link.mass / 12 * np.array([ly**2 + lz**2, lx**2 + lz**2, lx**2 + ly**2])
        np.testing.assert_allclose(link.inertia, box, rtol=0.04)
    sphere = 0.4 * ATHENA.foot.mass * ATHENA.foot.radius**2
    np.testing.assert_allclose(ATHENA.foot.inertia, sphere, rtol=0.01)


def test_total_mass_and_standing_height():
    assert ATHENA.total_mass == pytest.approx(0.7 + 6 * (0.081 + 0.136 + 0.0134 + 0.0089))
    assert ATHENA.standing_torso_height == pytest.approx(0.084 + 0.020)


def test_joint_ranges_keep_the_papers_ranges_about_the_standing_posture():
    np.testing.assert_allclose(ATHENA.joint_range("TC"), (-0.612, 0.612))
    np.testing.assert_allclose(ATHENA.joint_range("CTr"), (-1.484, 1.484))
    np.testing.assert_allclose(
        ATHENA.joint_range("FTi"), (-math.pi / 2 - 1.484, -math.pi / 2 + 1.484)
    )
    assert np.all(kin.within_limits(kin.standing_joint_angles()))


def test_mounting_angles_are_eq13_rotated_into_our_frame():
    a = math.atan(ATHENA.hip_offset_x / ATHENA.hip_offset_y)  # eq. (13)'s atan(l0/w)
    paper = {1: 0.0, 2: a, 3: math.pi - a, 4: math.pi, 5: math.pi + a, 6: -a}
    for n, theta_paper in paper.items():
        ours = ATHENA.mounting_angle(LEG_FROM_PAPER_NUMBER[n])
        assert math.isclose(math.cos(ours), math.cos(theta_paper - math.pi / 2), abs_tol=1e-12)
        assert math.isclose(math.sin(ours), math.sin(theta_paper - math.pi / 2), abs_tol=1e-12)


def test_paper_numbering_runs_counter_clockwise_from_the_right_middle_leg():
    assert LEG_FROM_PAPER_NUMBER[1] == "RM"
    azimuths = [ATHENA.mounting_angle(LEG_FROM_PAPER_NUMBER[n]) for n in range(1, 7)]
    steps = np.mod(np.diff(azimuths + azimuths[:1]), 2 * math.pi)
    assert np.all(steps > 0) and math.isclose(steps.sum(), 2 * math.pi)  # one CCW turn
    # Paper tripods {1, 3, 5} and {2, 4, 6} are the project's tripods.
    assert {PAPER_LEG_NUMBER[leg] for leg in TRIPODS[0]} == {1, 3, 5}
    assert {PAPER_LEG_NUMBER[leg] for leg in TRIPODS[1]} == {2, 4, 6}


def test_dh_chain_equals_eq12_closed_form():
    rng = np.random.default_rng(0)
    for q in _random_angles(rng, 50):
        for leg in LEG_NAMES:
            np.testing.assert_allclose(
                kin.forward_kinematics(leg, q), kin.foot_position_closed_form(leg, q), atol=1e-12
            )


def test_dh_foot_frame_matches_eq11_rotation():
    q = np.array([0.3, -0.4, -1.2])
    leg = "RF"
    t = kin.leg_frames(leg, q)[-1]
    t12 = ATHENA.mounting_angle(leg) + q[0]
    t34 = q[1] + q[2]
    expected = np.array(
        [
            [math.cos(t12) * math.cos(t34), -math.cos(t12) * math.sin(t34), math.sin(t12)],
            [math.sin(t12) * math.cos(t34), -math.sin(t12) * math.sin(t34), -math.cos(t12)],
            [math.sin(t34), math.cos(t34), 0.0],
        ]
    )
    np.testing.assert_allclose(t[:3, :3], expected, atol=1e-12)


def test_standing_feet_are_below_and_outward_of_the_hips():
    feet = kin.standing_foot_positions()
    for i, leg in enumerate(LEG_NAMES):
        hip = ATHENA.hip_position(leg)
        t1 = ATHENA.mounting_angle(leg)
        reach = ATHENA.l2 + ATHENA.l3
        expected = hip + np.array([reach * math.cos(t1), reach * math.sin(t1), -ATHENA.l4])
        np.testing.assert_allclose(feet[i], expected, atol=1e-12)
    # Left feet at y > 0, right at y < 0, front at x > 0 (our frame: x fwd, y left).
    assert np.all(feet[:3, 1] > 0) and np.all(feet[3:, 1] < 0)
    assert feet[0, 0] > 0 and feet[2, 0] < 0


def test_ik_inverts_fk_over_the_joint_ranges():
    rng = np.random.default_rng(1)
    for q in _random_angles(rng, 300):
        for leg in LEG_NAMES:
            p = kin.forward_kinematics(leg, q)
            q_ik = kin.inverse_kinematics(leg, p)
            np.testing.assert_allclose(q_ik, q, atol=1e-9)
            np.testing.assert_allclose(kin.forward_kinematics(leg, q_ik), p, atol=1e-12)


def test_whole_robot_ik_round_trip():
    rng = np.random.default_rng(2)
    q = _random_angles(rng, 6)
    np.testing.assert_allclose(
        kin.inverse_kinematics_all(kin.forward_kinematics_all(q)), q, atol=1e-9
    )


def test_ik_rejects_unreachable_points_and_clamps_on_request():
    hip = ATHENA.hip_position("LM")
    far = hip + np.array([0.0, 0.5, -0.1])
    with pytest.raises(ValueError, match="out of reach"):
        kin.inverse_kinematics("LM", far)
    assert not kin.is_reachable("LM", far)
    q = kin.inverse_kinematics("LM", far, clamp=True)
    assert np.all(kin.within_limits(q))
    # Clamped pose: the femur points from the CTr joint at the target (the leg-plane angle of
    # eq. 16), the knee stretched as far as its range allows, the foot near the full reach.
    dxy, dz = np.hypot(*(far - hip)[:2]), (far - hip)[2]
    assert q[1] == pytest.approx(math.atan2(dz, dxy - ATHENA.l2), abs=5e-4)
    assert q[2] == pytest.approx(ATHENA.joint_range("FTi")[1])
    p = kin.forward_kinematics("LM", q)
    assert np.linalg.norm(p - far) == pytest.approx(
        np.linalg.norm(far - hip) - ATHENA.l2 - ATHENA.l3 - ATHENA.l4, abs=0.02
    )
    # A foot swung beyond the TC range is rejected, and clamped to the range limit.
    behind = hip + 0.15 * np.array([-math.sin(1.0), math.cos(1.0), 0.0]) - [0, 0, 0.08]
    with pytest.raises(ValueError, match="TC"):
        kin.inverse_kinematics("LM", behind)
    assert kin.inverse_kinematics("LM", behind, clamp=True)[0] == pytest.approx(0.612)


def test_bad_inputs_raise_clear_errors():
    with pytest.raises(ValueError, match="valid: LF, LM, LR, RF, RM, RR"):
        kin.forward_kinematics("XX", np.zeros(3))
    with pytest.raises(ValueError, match="shape"):
        kin.forward_kinematics("LF", np.zeros(2))
    with pytest.raises(ValueError, match=r"\(6, 3\)"):
        kin.forward_kinematics_all(np.zeros((5, 3)))
    with pytest.raises(ValueError, match="joint"):
        ATHENA.joint_range("knee")
    assert JOINT_NAMES == ("TC", "CTr", "FTi")


def test_compiled_hypot_is_cpythons():
    """cpython_hypot = math.hypot to the bit (libm's hypot is not): normal, subnormal and
    mixed magnitudes, zeros of both signs, inf and nan."""
    from hexapod_envs.stability._compiled import cpython_hypot

    rng = np.random.default_rng(5)
    n = 20000
    xs = rng.normal(size=n) * 10 ** rng.uniform(-4, 2, n)
    ys = rng.normal(size=n) * 10 ** rng.uniform(-4, 2, n)
    tiny = rng.uniform(-2.2e-308, 2.2e-308, size=(2, 4000)) * rng.choice([1.0, 1e-6], (2, 4000))
    pairs = list(zip(xs.tolist(), ys.tolist(), strict=True))
    pairs += list(zip(tiny[0].tolist(), tiny[1].tolist(), strict=True))
    pairs += [(0.0, 0.0), (-0.0, 3.0), (5e-324, 1e-320), (7.5922331158553e-311, -3.1409296e-316)]
    pairs += [(1e300, 1e300), (1.7976931348623157e308, 1.0), (3.0, -4.0), (1e-310, 1.0)]
    for x, y in pairs:
        assert cpython_hypot(x, y) == math.hypot(x, y), (x, y)
    assert cpython_hypot(math.inf, math.nan) == math.inf == math.hypot(math.inf, math.nan)
    assert math.isnan(cpython_hypot(math.nan, 1.0)) and math.isnan(math.hypot(math.nan, 1.0))


def test_compiled_six_leg_ik_is_leg_ik_solve():
    """solve_legs gives LegIK.solve's angles to the bit, the clamped poses included, and flags
    exactly the points LegIK.solve reports a problem for (out of reach, behind the hip, out of
    range)."""
    from hexapod_envs.robots.athena._compiled import solve_legs

    iks = [kin.leg_ik(leg) for leg in LEG_NAMES]
    constants = np.array([ik.packed_constants for ik in iks])
    rng = np.random.default_rng(7)
    standing = kin.forward_kinematics_all(np.tile(ATHENA.standing_posture, (6, 1)))
    flagged = solved = unreachable = 0
    for _ in range(400):
        feet = standing + rng.normal(scale=rng.choice([0.01, 0.05, 0.2]), size=(6, 3))
        angles, ok = solve_legs(constants, feet)
        for i, ik in enumerate(iks):
            t2, t3, t4, problem = ik.solve(*feet[i].tolist())
            assert ok[i] == (problem is None)
            assert angles[i].tobytes() == np.array([t2, t3, t4]).tobytes()
            solved += problem is None
            flagged += problem is not None
            unreachable += problem is not None and "out of reach" in problem
    assert solved > 1000 and flagged > 100 and unreachable > 50


def test_compiled_tick_is_the_controllers_numpy_tick():
    """tick_legs writes the Bezier swing and straight stance feet of the former numpy tick
    (``weights @ control points``, ``start + u delta``) to the bit, and solves them as
    solve_legs does; u covers the ticks of several phase lengths and random fractions."""
    from hexapod_envs.robots.athena._compiled import solve_legs, tick_legs

    constants = np.array([kin.leg_ik(leg).packed_constants for leg in LEG_NAMES])
    standing = kin.forward_kinematics_all(np.tile(ATHENA.standing_posture, (6, 1)))
    rng = np.random.default_rng(3)
    fractions = [k / n for n in (10, 20, 40) for k in range(1, n + 1)] + list(rng.uniform(size=200))
    for k, u in enumerate(fractions):
        swing, stance = (np.array([0, 2, 4]), np.array([1, 3, 5]))[:: 1 if k % 2 else -1]
        points = standing[swing, None, :] + rng.normal(scale=0.03, size=(3, 4, 3))
        start = standing[stance] + rng.normal(scale=0.01, size=(3, 3))
        delta = rng.normal(scale=0.03, size=(3, 3))
        command = standing.copy()
        angles, solved = tick_legs(constants, command, u, swing, points, stance, start, delta)
        v = 1.0 - u
        expected = standing.copy()
        expected[swing] = np.array([v**3, 3 * v * v * u, 3 * v * u * u, u**3]) @ points
        expected[stance] = start + u * delta
        assert command.tobytes() == expected.tobytes()
        ref_angles, ref_solved = solve_legs(constants, expected)
        assert angles.tobytes() == ref_angles.tobytes() and (solved == ref_solved).all()


@needs_same_blas
def test_compiled_phase_plan_is_the_controllers_geometry():
    """phase_plan gives swing_control_points' control points and stance_end_point's end
    points (as deltas from the start) to the bit, for random start feet, strides, heights,
    height corrections and posture rotations."""
    from hexapod_envs.robots.athena._compiled import phase_plan
    from hexapod_envs.robots.athena.gait import (
        posture_rotation,
        stance_end_point,
        swing_control_points,
    )

    standing = kin.forward_kinematics_all(np.tile(ATHENA.standing_posture, (6, 1)))
    rng = np.random.default_rng(5)
    for k in range(300):
        swing, stance = (np.array([0, 2, 4]), np.array([1, 3, 5]))[:: 1 if k % 2 else -1]
        start = standing + rng.normal(scale=0.02, size=(6, 3))
        stride, height, correction = (
            rng.uniform(0.01, 0.1),
            rng.uniform(0.05, 0.2),
            rng.normal(0, 0.01),
        )
        rotation = posture_rotation(*rng.normal(scale=0.1, size=2))
        points, stance_start, delta = phase_plan(
            start, swing, stance, stride, height, correction, rotation
        )
        expected = np.array(
            [swing_control_points(start[i], stride, height, correction) for i in swing]
        )
        assert points.tobytes() == expected.tobytes()
        assert stance_start.tobytes() == start[stance].tobytes()
        ends = np.array([stance_end_point(start[i], stride, correction, rotation) for i in stance])
        assert delta.tobytes() == (ends - start[stance]).tobytes()


def test_compiled_closed_form_is_foot_position_closed_form():
    """feet_closed_form (all six legs, one compiled call) gives eq. (12)'s Python numbers to the
    bit, over the joint ranges and beyond."""
    rng = np.random.default_rng(11)
    for _ in range(300):
        q = rng.uniform(-2.5, 2.5, size=(6, 3))
        expected = [kin.foot_position_closed_form(leg, q[i]) for i, leg in enumerate(LEG_NAMES)]
        assert kin.feet_closed_form(q).tobytes() == np.array(expected).tobytes()
    with pytest.raises(ValueError, match=r"shape \(6, 3\)"):
        kin.feet_closed_form(np.zeros((5, 3)))


def test_compiled_plane_triples_are_the_controllers_comprehension():
    """plane_triples lists the triples of contact legs with a usable triangle in
    itertools.combinations order, each area `triangle_area_xy`'s to the bit, for random feet
    (some near-collinear triples among them) and every contact pattern."""
    import itertools

    from hexapod_envs.robots.athena._compiled import plane_triples
    from hexapod_envs.robots.athena.gait import triangle_area_xy

    rng = np.random.default_rng(5)
    standing = kin.forward_kinematics_all(np.tile(ATHENA.standing_posture, (6, 1)))
    rejected = 0
    for k in range(300):
        feet = standing + rng.normal(scale=0.02, size=(6, 3))
        if k % 3 == 0:  # legs 0, 2, 4 on one line in x-y (up to 1 mm)
            feet[[2, 4], 1] = feet[0, 1] + rng.normal(scale=0.001, size=2)
        contact = rng.uniform(size=6) < 0.7
        legs = [int(i) for i in np.flatnonzero(contact)]
        areas = {t: triangle_area_xy(feet[list(t)]) for t in itertools.combinations(legs, 3)}
        expected = [t for t, area in areas.items() if area > 1e-4]
        rejected += len(areas) - len(expected)
        triples, got = plane_triples(feet, contact, 1e-4)
        assert [tuple(t) for t in triples.tolist()] == expected
        assert got.tobytes() == np.array([areas[t] for t in expected], dtype=float).tobytes()
    assert rejected > 10
