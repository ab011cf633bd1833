"""Foot-force distribution QP with the FASM stability cone (Zhang et al. 2024 §4.3, eqs. 16-24)."""

import math
import re

import numpy as np
import pytest
import qpsolvers

from agents.tipping.force_distribution import (
    GRAVITY,
    SOLVERS,
    ForceDistributionConfig,
    ForceDistributor,
    desired_wrench,
    stability_cone,
    tipping_force_matrices,
)
from hexapod_envs.robots.heavy_duty import HeavyDutyParams, standing_feet
from hexapod_envs.stability import fasm, support_polygon

PARAMS = HeavyDutyParams()
FEET = standing_feet(PARAMS)
MASS = PARAMS.total_mass  # 5 t
INERTIA = np.diag([3.0e3, 8.5e3, 1.0e4])
COG = np.zeros(3)
WEIGHT = MASS * GRAVITY
REL = 1e-6  # constraint tolerance relative to the weight


def feet_of(*legs):
    return np.array([FEET[leg] for leg in legs])


def gravity_pitched(deg: float) -> np.ndarray:
    """Gravity in the body frame when the body is pitched nose-up by ``deg`` (tips backward)."""
    a = math.radians(deg)
    return GRAVITY * np.array([math.sin(a), 0.0, -math.cos(a)])


def check_constraints(result, feet, config, normal=(0.0, 0.0, 1.0)):
    """Independent check of every constraint on the returned forces."""
    x = result.forces
    n = np.asarray(normal)
    t1 = np.array([1.0, 0.0, 0.0]) - n[0] * n
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    normal_force = x @ n
    assert np.all(normal_force >= config.min_normal_force - REL * WEIGHT)
    for t in (t1, t2):
        assert np.all(np.abs(x @ t) <= config.friction * normal_force + REL * WEIGHT)
    for name, slack in result.slack.items():
        assert slack.min() >= -REL * WEIGHT, name
    if config.stability_cone:
        edges = np.column_stack([support_polygon(feet), np.roll(support_polygon(feet), -1)])
        v = tipping_force_matrices(feet, COG, edges)
        for v_i in v:
            f_star = -v_i @ x.ravel()
            assert np.all(result.cone.faces @ f_star <= REL * WEIGHT)


def test_desired_wrench_closed_forms():
    b = desired_wrench(MASS, INERTIA, [0.0, 0.0, -GRAVITY])
    np.testing.assert_allclose(b, [0, 0, WEIGHT, 0, 0, 0])
    accel, omega, omega_dot = np.array([0.5, -0.2, 1.0]), np.array([0.1, 0.3, -0.2]), np.ones(3)
    b = desired_wrench(MASS, INERTIA, [0.0, 0.0, -GRAVITY], accel, omega, omega_dot)
    np.testing.assert_allclose(b[:3], MASS * (accel + [0.0, 0.0, GRAVITY]))
    np.testing.assert_allclose(b[3:], INERTIA @ omega_dot + np.cross(omega, INERTIA @ omega))
    with pytest.raises(ValueError, match="inertia"):
        desired_wrench(MASS, np.eye(2), [0.0, 0.0, -GRAVITY])
    with pytest.raises(ValueError, match=re.escape("omega must be a (3,) vector, got shape (2,)")):
        desired_wrench(MASS, INERTIA, [0.0, 0.0, -GRAVITY], omega=[0.1, 0.3])


@pytest.mark.parametrize("solver", SOLVERS)
def test_four_feet_carry_the_robot(solver):
    feet = feet_of("LF", "LR", "RF", "RR")
    config = ForceDistributionConfig(solver=solver)
    b = desired_wrench(MASS, INERTIA, [0.0, 0.0, -GRAVITY])
    result = ForceDistributor(4, config).solve(feet, COG, b)
    assert result.status == "optimal" and result.ok
    # Symmetric stance: a quarter of 5 t on each foot, no tangential force; the regulariser κ
    # costs a relative wrench error of about κ/k.
    np.testing.assert_allclose(result.forces[:, 2], WEIGHT / 4, rtol=1e-3)
    np.testing.assert_allclose(result.forces[:, :2], 0.0, atol=REL * WEIGHT)
    assert np.linalg.norm(result.wrench_residual) < 1e-3 * WEIGHT
    assert result.max_violation <= REL * WEIGHT
    check_constraints(result, feet, config)
    assert set(result.slack) == {"normal", "friction", "stability"}
    assert result.slack["friction"].shape == (4, 4) and result.slack["stability"].shape == (4, 4)


@pytest.mark.parametrize(
    ("legs", "pitch_deg"),
    [
        (("LF", "LR", "RM"), 0.0),
        (("LF", "LR", "RM"), 15.0),
        (("LF", "LR", "RM", "RR"), 20.0),
        (("LM", "RF", "RR", "LR"), -12.0),
        (("LF", "LR", "RF", "RR"), 30.0),
    ],
)
def test_constraints_hold_and_planned_forces_are_stable(legs, pitch_deg):
    feet = feet_of(*legs)
    config = ForceDistributionConfig()
    b = desired_wrench(MASS, INERTIA, gravity_pitched(pitch_deg))
    result = ForceDistributor(len(legs), config).solve(feet, COG, b)
    assert result.status == "optimal"
    check_constraints(result, feet, config)
    # Tipping forces inside the cone point inside the support polygon: FASM of the planned
    # support wrench is positive.
    x = result.forces
    planned = fasm(feet, COG, -x.sum(axis=0), -np.cross(feet - COG, x).sum(axis=0))
    assert planned.margin_deg > 5.0


def test_without_cone_the_desired_wrench_is_tracked():
    feet = feet_of("LF", "LR", "RM", "RR")
    b = desired_wrench(MASS, INERTIA, gravity_pitched(20.0), omega=[0.0, 0.2, 0.0])
    config = ForceDistributionConfig(stability_cone=False)
    result = ForceDistributor(4, config).solve(feet, COG, b)
    assert result.status == "optimal" and "stability" not in result.slack
    assert np.linalg.norm(result.wrench_residual) < 1e-3 * np.linalg.norm(b)
    check_constraints(result, feet, config)


def test_cone_trades_wrench_error_for_stability():
    # Pitched 20° nose-up the gravity wrench leaves FASM at 13°; the cone only admits support
    # wrenches whose tipping forces point into the base circle, so the QP gives up wrench
    # accuracy for a stabilising wrench (the paper's design, §4.3).
    feet = feet_of("LF", "LR", "RM", "RR")
    b = desired_wrench(MASS, INERTIA, gravity_pitched(20.0))
    gravity_only = fasm(feet, COG, MASS * gravity_pitched(20.0)).margin_deg
    result = ForceDistributor(4).solve(feet, COG, b)
    x = result.forces
    planned = fasm(feet, COG, -x.sum(axis=0), -np.cross(feet - COG, x).sum(axis=0)).margin_deg
    assert gravity_only == pytest.approx(13.0, abs=0.1)
    assert planned > gravity_only + 10.0
    assert np.linalg.norm(result.wrench_residual) > 0.1 * np.linalg.norm(b)


def test_min_normal_force_becomes_active():
    # Level tripod without the cone: LF-LR-RM carries the weight; f_min = 8 kN exceeds what
    # exact wrench tracking would give the lightest foot.
    feet = feet_of("LF", "LR", "RM")
    b = desired_wrench(MASS, INERTIA, [0.0, 0.0, -GRAVITY])
    free = ForceDistributor(3, ForceDistributionConfig(stability_cone=False, min_normal_force=0.0))
    lightest = free.solve(feet, COG, b).forces[:, 2].min()
    config = ForceDistributionConfig(stability_cone=False, min_normal_force=lightest + 3000.0)
    result = ForceDistributor(3, config).solve(feet, COG, b)
    assert result.status == "optimal"
    assert result.slack["normal"].min() == pytest.approx(0.0, abs=REL * WEIGHT)
    check_constraints(result, feet, config)


def test_tipping_force_matrices_check_the_moment_rows():
    feet = feet_of("LF", "LR", "RM")
    with pytest.raises(ValueError, match=re.escape("moment_rows must have shape (3, 9) for 3")):
        tipping_force_matrices(feet, COG, [[0, 1], [1, 2], [2, 0]], np.zeros((3, 8)))


def test_tipping_force_matrices_match_fasm():
    rng = np.random.default_rng(11)
    feet = feet_of("LF", "LR", "RM", "RR") + rng.normal(scale=0.05, size=(4, 3))
    cog = np.array([0.2, -0.1, 0.05])
    x = rng.normal(scale=2000.0, size=(4, 3)) + [0.0, 0.0, 12000.0]
    ref = fasm(feet, cog, -x.sum(axis=0), -np.cross(feet - cog, x).sum(axis=0))
    v = tipping_force_matrices(feet, cog, ref.edges)
    for (i0, i1), v_i, angle in zip(ref.edges, v, ref.angles_deg, strict=True):
        f_star = -v_i @ x.ravel()
        a = (feet[i1] - feet[i0]) / np.linalg.norm(feet[i1] - feet[i0])
        w = feet[i1] - cog
        l_hat = (w - (w @ a) * a) / np.linalg.norm(w - (w @ a) * a)
        assert f_star @ a == pytest.approx(0.0, abs=1e-9 * np.abs(x).max())
        mine = math.degrees(math.atan2(np.cross(l_hat, f_star) @ a, f_star @ l_hat))
        assert mine == pytest.approx(angle, abs=1e-9)


def test_cone_geometry_symmetric_case_is_the_printed_s_m():
    feet = feet_of("LF", "LR", "RF", "RR")
    cone = stability_cone(feet, COG, [0.0, 0.0, 1.0], cone_ratio=0.5)
    np.testing.assert_allclose(cone.centroid, [0.0, 0.0, -1.75], atol=1e-12)
    assert cone.d_min == pytest.approx(1.9)  # centroid to the side edges y = ±1.9
    tan_alpha = 0.5 * 1.9 / 1.75
    np.testing.assert_allclose(cone.tan_alpha, tan_alpha)
    s_m = np.array([[1.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, -1.0], [tan_alpha / math.sqrt(2.0)] * 4])
    np.testing.assert_allclose(cone.faces, s_m.T, atol=1e-12)


def test_cone_geometry_oblique_case():
    feet = feet_of("LF", "LR", "RM")  # centroid (0, 0.633) is off the CoG's vertical
    cone = stability_cone(feet, COG, [0.0, 0.0, 1.0], cone_ratio=0.5)
    np.testing.assert_allclose(cone.centroid, [0.0, 1.9 / 3.0, -1.75], atol=1e-12)
    assert cone.d_min == pytest.approx(1.9 - 1.9 / 3.0)  # to the LF-LR edge
    for t in cone.base_points:
        assert np.linalg.norm(t - cone.centroid) == pytest.approx(cone.radius)
        assert t[2] == pytest.approx(-1.75)
        assert not cone.contains(t - COG)  # the circle lies outside the inscribed pyramid
    assert cone.contains(cone.centroid - COG)
    # Seen from the CoG the tilted base circle spans different angles to each side (eq. 22).
    assert cone.tan_alpha[1] != pytest.approx(cone.tan_alpha[3])


@pytest.mark.parametrize("solver", SOLVERS)
def test_infeasible_problem_returns_status(solver):
    # CoG 10 m ahead of the feet: no upward, friction-bounded forces put a tipping force inside
    # the (almost horizontal) cone.
    feet = feet_of("LF", "LR", "RF", "RR")
    b = desired_wrench(MASS, INERTIA, [0.0, 0.0, -GRAVITY])
    distributor = ForceDistributor(4, ForceDistributionConfig(solver=solver))
    result = distributor.solve(feet, np.array([10.0, 0.0, 0.0]), b)
    assert result.status == "infeasible" and not result.ok
    assert np.isnan(result.forces).all() and result.forces.shape == (4, 3)
    assert "relaxation" in result.message
    free = ForceDistributor(4, ForceDistributionConfig(solver=solver, stability_cone=False))
    assert free.solve(feet, np.array([10.0, 0.0, 0.0]), b).status == "optimal"


@pytest.mark.parametrize(
    ("legs", "pitch_deg", "cone"),
    [
        (("LF", "LR", "RF", "RR"), 0.0, True),
        (("LF", "LR", "RM"), 15.0, True),
        (("LF", "LR", "RM", "RR"), 20.0, True),
        (("LF", "LR", "RM", "RR"), 20.0, False),
    ],
)
def test_daqp_and_quadprog_agree(legs, pitch_deg, cone):
    feet = feet_of(*legs)
    b = desired_wrench(MASS, INERTIA, gravity_pitched(pitch_deg))
    results = [
        ForceDistributor(len(legs), ForceDistributionConfig(solver=s, stability_cone=cone)).solve(
            feet, COG, b
        )
        for s in SOLVERS
    ]
    assert all(r.status == "optimal" for r in results)
    np.testing.assert_allclose(results[0].forces, results[1].forces, atol=REL * WEIGHT)


def test_degenerate_geometry_does_not_raise():
    feet = np.array([[2.4, 1.9, -1.75], [0.0, 1.9, -1.75], [-2.4, 1.9, -1.75]])  # collinear
    b = desired_wrench(MASS, INERTIA, [0.0, 0.0, -GRAVITY])
    result = ForceDistributor(3).solve(feet, COG, b)
    assert result.status == "solver_error" and "degenerate" in result.message
    with pytest.raises(ValueError, match="shape"):
        ForceDistributor(3).solve(feet[:2], COG, b)


def test_build_refuses_bad_input_with_the_reason():
    feet = feet_of("LF", "LR", "RM", "RR")
    b = desired_wrench(MASS, INERTIA, [0.0, 0.0, -GRAVITY])
    build = ForceDistributor(4).build
    for bad in (feet.copy(), COG.copy(), b.copy()):
        bad.flat[1] = np.nan
        args = [bad if x.shape == bad.shape else x for x in (feet, COG, b)]
        with pytest.raises(ValueError, match="must be finite"):
            build(*args)
    huge = feet.copy()
    huge[:2, 0] = 1e308  # finite entries whose sum overflows
    with pytest.raises(ValueError, match="too large"):
        build(huge, COG, b)
    upright = feet.copy()
    upright[:, :2] = 0.0  # one vertical line: no plane z = ax + by + c
    with pytest.raises(ValueError, match="collinear|coincident"):
        build(upright, COG, b)
    # With the normal given, the same feet are collinear seen along it: no support polygon.
    upright[:, 2] = np.arange(4.0)
    with pytest.raises(ValueError, match="collinear"):
        build(upright, COG, b, normal=np.array([1.0, 0.0, 0.0]))


def test_config_validation_names_choices():
    with pytest.raises(ValueError, match="valid solvers"):
        ForceDistributionConfig(solver="osqp")
    with pytest.raises(ValueError, match="lambda"):
        ForceDistributionConfig(cone_ratio=1.0)
    with pytest.raises(ValueError, match="at least 3"):
        ForceDistributor(2)


def _random_case(rng):
    """A random stance (3-6 feet, perturbed standing footholds), CoG, wrench and options."""
    k = int(rng.integers(3, 7))
    legs = list(rng.permutation(list(FEET))[:k])
    feet = feet_of(*legs) + rng.normal(scale=0.15, size=(k, 3))
    cog = rng.normal(scale=0.3, size=3)
    pitch, roll = rng.normal(scale=12.0, size=2)
    b = desired_wrench(
        MASS,
        INERTIA,
        gravity_pitched(pitch) + [0.0, GRAVITY * math.sin(math.radians(roll)), 0.0],
        accel_body=rng.normal(scale=0.5, size=3),
        omega=rng.normal(scale=0.2, size=3),
        omega_dot=rng.normal(scale=0.5, size=3),
    )
    normal = None if rng.random() < 0.3 else rng.normal(scale=0.15, size=3) + [0.0, 0.0, 1.0]
    config = ForceDistributionConfig(
        cone_ratio=float(rng.choice([0.5, 0.65, 0.8, 0.95])),
        stability_cone=bool(rng.random() < 0.85),
        solver=str(rng.choice(SOLVERS)),
    )
    return k, feet, cog, b, normal, config


def test_build_is_bit_identical_to_the_original_assembly():
    """The speed-up of the assembly (issue 14) changes no bit of U, f, G, h, A, the cone or the
    forces: 200 random stances against the verbatim original in reference_force_distribution.

    The compiled products call scipy's BLAS where the original called numpy's; the test skips
    itself where those two differ in the last bit (not on the machines this was built on).
    """
    from helpers.blas_bits import REASON, numba_blas_matches_numpy
    from helpers.reference_force_distribution import reference_build

    if not numba_blas_matches_numpy():
        pytest.skip(REASON)
    rng = np.random.default_rng(14)
    distributors = {}
    compared = errors = 0
    for _ in range(200):
        k, feet, cog, b, normal, config = _random_case(rng)
        # Reuse distributors across cases, as the controller does (the G buffers persist).
        distributor = distributors.setdefault((k, config), ForceDistributor(k, config))
        try:
            old = reference_build(distributor, feet, cog, b, normal)
        except ValueError as error:
            with pytest.raises(ValueError, match=re.escape(str(error)[:20])):
                distributor.build(feet, cog, b, normal)
            errors += 1
            continue
        new = distributor.build(feet, cog, b, normal)
        for name in ("U", "f", "G", "h", "A", "b", "edges", "normal"):
            old_v, new_v = getattr(old, name), getattr(new, name)
            assert old_v.shape == new_v.shape and old_v.tobytes() == new_v.tobytes(), name
        assert (old.scale, old.blocks) == (new.scale, new.blocks)
        if config.stability_cone:
            for name in ("apex", "centroid", "base_points", "tan_alpha", "faces"):
                assert getattr(old.cone, name).tobytes() == getattr(new.cone, name).tobytes()
            assert (old.cone.d_min, old.cone.radius) == (new.cone.d_min, new.cone.radius)
        else:
            assert new.cone is None
        # The forces as before: qpsolvers on the old problem (solve_qp calls daqp directly).
        x_old = qpsolvers.solve_qp(old.U, old.f, old.G, old.h, solver=config.solver)
        new_x = distributor.solve_qp(new)
        assert (x_old is not None) == (new_x.status != "infeasible")
        if new_x.ok:
            assert (x_old * old.scale).reshape(k, 3).tobytes() == new_x.forces.tobytes()
        compared += 1
    assert compared >= 150 and errors < 50
