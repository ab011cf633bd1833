"""Tests of the 3-UPU "3-3" gait-planning math (Li et al. 2018 §5-7)."""

import math

import numpy as np
import pytest

from hexapod_envs.robots.upu.gait_plan import (
    PLAN_STATUSES,
    Ditch,
    GaitSettings,
    QuadraticPath,
    case_study_path,
    combined_cog,
    edge_clearance,
    foot_positions,
    margin_profile,
    max_stride,
    max_stride_diagonal,
    plan_ditch_crossing,
    plan_flat_walk,
    stance_margin,
    step_path,
    support_margin,
)
from hexapod_envs.robots.upu.kinematics import check_limits
from hexapod_envs.robots.upu.params import LEG_NAMES, PLATFORM_LEGS, UpuParams

P = UpuParams()
PAPER_DITCH = Ditch(start_x=0.6, width=0.35, depth=0.14)


@pytest.fixture(scope="module")
def ditch_plan():
    return plan_ditch_crossing(P, PAPER_DITCH)


def test_eq20_case_study_path():
    """z = -0.0125 x^2 + 2 x + 363 [mm] -> a = -12.5 1/m, b = 2, c = 0.363 m."""
    path = case_study_path(P)
    assert path.a == pytest.approx(-12.5)
    assert path.b == pytest.approx(2.0)
    assert path.c == pytest.approx(0.363)
    assert (path.x_start, path.x_end) == pytest.approx((0.0, 0.16))
    np.testing.assert_allclose(path.z([0.0, 0.08, 0.16]), [0.363, 0.443, 0.363])


def test_eq21_lower_platform_path_coefficients_and_infeasibility():
    """Eq. (21) through (-160, -363), (-80, -283), (0, -363) mm: z = -0.0125 x^2 - 2 x - 363.
    Its apex needs limb 1 = 305 mm < l_min, which is why the planner keeps the lower path flat."""
    path = QuadraticPath.through((-0.16, -0.363), (-0.08, -0.283), (0.0, -0.363))
    assert (path.a, path.b, path.c) == pytest.approx((-12.5, -2.0, -0.363))
    assert not check_limits([-0.08, 0.0, -0.283], P, moving="lower").ok


def test_quadratic_path_validation_and_flat_case():
    with pytest.raises(ValueError, match="distinct x"):
        QuadraticPath.through((0, 0), (0, 1), (1, 0))
    flat = step_path(-0.1, 0.0, -0.363, 0.0)
    np.testing.assert_allclose(flat.sample(5)[:, 1], -0.363)


def test_eq17_eq18_stride_limits():
    assert max_stride(P.support_inradius, P.leg_radius) == pytest.approx(0.160)
    assert max_stride_diagonal(P.support_inradius, P.leg_radius) == pytest.approx(0.080)
    with pytest.raises(ValueError, match="support_inradius"):
        max_stride(0.01, 0.02)


def test_eq13_combined_cog():
    g3 = combined_cog([0.16, 0.0, 0.5], [0.0, 0.0, 0.2], 3.0, 1.0)
    np.testing.assert_allclose(g3, [0.12, 0.0, 0.425])
    assert combined_cog([0.1, 0, 0], [0, 0, 0], 2.0, 2.0)[0] == pytest.approx(0.05)
    with pytest.raises(ValueError, match="masses"):
        combined_cog([0, 0, 0], [0, 0, 0], 0.0, 1.0)


def test_support_margin_closed_form_triangle():
    """Lower support triangle (vertices at 180°, ±60°, radius rho): inradius rho/2 at the
    centre; moving the CoG by t toward the front side leaves rho/2 - t; outside is negative."""
    feet = np.array([P.foot_offset(leg) for leg in PLATFORM_LEGS["lower"]])
    rho = P.leg_circle_radius
    assert support_margin(feet, [0.0, 0.0]) == pytest.approx(rho / 2)
    assert support_margin(feet, [0.03, 0.0]) == pytest.approx(rho / 2 - 0.03)
    assert support_margin(feet, [rho / 2 + 0.01, 0.0]) == pytest.approx(-0.01)
    with pytest.raises(ValueError, match="feet_xy"):
        support_margin(np.zeros((3, 3)), [0, 0])


def test_stage_margins_follow_eq13():
    """Upper moving by d over the lower triangle: margin = rho/2 - d m1/M; lower moving with the
    upper ahead by d: margin = rho/2 - d m2/M."""
    m1, m2, total = P.upper_half_mass, P.lower_half_mass, P.total_mass
    for d in (0.0, 0.08, 0.16):
        assert stance_margin(P, d, 0.0, "lower") == pytest.approx(0.1 - d * m1 / total)
        assert stance_margin(P, d, 0.0, "upper") == pytest.approx(0.1 - d * m2 / total)
    assert stance_margin(P, 0.16, 0.0, "all") > stance_margin(P, 0.16, 0.0, "lower")


def test_foot_positions_layout():
    feet = foot_positions(P, x_upper=0.1, x_lower=0.0)
    assert set(feet) == set(LEG_NAMES)
    np.testing.assert_allclose(feet["U1"], [0.3, 0.0], atol=1e-12)
    np.testing.assert_allclose(feet["L1"], [-0.2, 0.0], atol=1e-12)
    # Eq. (17): after the maximum stride the upper rear feet are 2 R_T from the lower front ones.
    feet = foot_positions(P, x_upper=0.16, x_lower=0.0)
    gap = np.linalg.norm(feet["U2"] - feet["L2"])
    assert gap == pytest.approx(2 * P.leg_radius)


def test_flat_walk_reproduces_paper_gait():
    plan = plan_flat_walk(P, n_cycles=3)
    assert plan.ok
    assert [s.moving for s in plan.steps] == ["upper", "lower"] * 3
    np.testing.assert_allclose(plan.strides, 0.16)
    assert plan.steps[0].lift == pytest.approx(0.08)
    path = plan.steps[0].path(P)
    assert (path.a, path.b, path.c) == pytest.approx((-12.5, 2.0, 0.363))
    assert plan.min_margin > 0  # Fig. 12: the margin stays positive
    for step in plan.steps:
        assert all(check_limits(q, P, moving=step.moving).ok for q in step.relative_poses(P))
    lengths = plan.steps[0].limb_lengths(P, n=3)
    np.testing.assert_allclose(lengths[1, 0], math.hypot(0.115, 0.443))  # apex, limb 1


def test_flat_walk_rejects_bad_stride():
    with pytest.raises(ValueError, match="stride"):
        plan_flat_walk(P, 1, stride=0.2)
    with pytest.raises(ValueError, match="n_cycles"):
        plan_flat_walk(P, 0)
    plan = plan_flat_walk(P, 1, settings=GaitSettings(min_margin=0.05))
    assert plan.status == "no_plan" and "margin" in plan.reason


def test_paper_ditch_is_crossed_with_positive_margin(ditch_plan):
    plan = ditch_plan
    assert plan.ok, plan.reason
    assert plan.status in PLAN_STATUSES
    assert plan.min_margin >= GaitSettings().min_margin > 0  # Fig. 14
    assert np.all(plan.strides > 0) and np.all(plan.strides <= 0.16 + 1e-9)
    assert np.any(plan.strides < 0.16 - 1e-9)  # steps shortened to fit the ditch
    moving = [s.moving for s in plan.steps]
    assert moving == ["upper", "lower"] * (len(moving) // 2)


def test_ditch_plan_feet_avoid_edges_and_extend_into_ditch(ditch_plan):
    settings = GaitSettings()
    band = P.foot_radius + settings.edge_clearance
    x_upper = x_lower = 0.0
    extension = dict.fromkeys(LEG_NAMES, 0.0)
    in_ditch = 0
    for step in ditch_plan.steps:
        # Continuity: the step starts where the previous one left the platforms.
        start = x_upper if step.moving == "upper" else x_lower
        support = x_lower if step.moving == "upper" else x_upper
        assert step.start_x == pytest.approx(start)
        assert step.support_x == pytest.approx(support)
        assert step.support_extension == pytest.approx(
            {leg: extension[leg] for leg in PLATFORM_LEGS[step.support]}
        )
        if step.moving == "upper":
            x_upper = step.end_x
        else:
            x_lower = step.end_x
        assert -1e-9 <= x_upper - x_lower <= 0.16 + 1e-9
        feet = foot_positions(P, x_upper, x_lower, PLATFORM_LEGS[step.moving])
        for leg, (x, _) in feet.items():
            assert min(abs(x - PAPER_DITCH.start_x), abs(x - PAPER_DITCH.end_x)) >= band - 1e-9
            expected = PAPER_DITCH.depth if PAPER_DITCH.start_x < x < PAPER_DITCH.end_x else 0.0
            assert step.landing_extension[leg] == pytest.approx(expected)
            in_ditch += expected > 0
            lo, hi = P.extension_range
            assert lo <= step.landing_extension[leg] <= hi
            assert lo <= step.swing_extension <= 0
        extension.update(step.landing_extension)
        for q in step.relative_poses(P):
            assert check_limits(q, P, moving=step.moving).ok
    assert in_ditch > 0  # legs extended into the ditch (§7)
    # Finish standing (platforms aligned) with every foot past the ditch, legs at nominal.
    assert x_upper == pytest.approx(x_lower)
    final = foot_positions(P, x_upper, x_lower)
    assert min(x for x, _ in final.values()) >= PAPER_DITCH.end_x + band - 1e-9
    assert all(v == 0.0 for v in extension.values())


def test_margin_profile_phases(ditch_plan):
    prof = margin_profile(ditch_plan, P, samples=5)
    n_steps = len(ditch_plan.steps)
    assert len(prof.margin) == n_steps * (5 + 3) == len(prof.phase) == len(prof.step)
    three_leg = np.array([ph != "six" for ph in prof.phase])
    assert prof.margin[three_leg].min() == pytest.approx(ditch_plan.min_margin)
    assert np.all(prof.margin[~three_leg] > prof.margin[three_leg].min())
    first = prof.margin[prof.step == 0]
    assert first[0] == first[1] and first[-2] == first[-3]  # legs move, platforms do not


def test_deep_ditch_reports_too_deep():
    plan = plan_ditch_crossing(P, Ditch(0.6, 0.35, 0.2))
    assert plan.status == "too_deep" and not plan.ok and plan.steps == ()
    assert "0.160" in plan.reason


def test_narrow_deep_ditch_is_stepped_over():
    ditch = Ditch(0.6, 0.05, 0.3)
    plan = plan_ditch_crossing(P, ditch)
    assert plan.ok and "stepping over" in plan.reason
    for step in plan.steps:
        assert all(v == 0.0 for v in step.landing_extension.values())


def test_too_wide_when_no_foot_fits_and_stride_too_short():
    settings = GaitSettings(edge_clearance=0.05)  # a foot needs 0.14 m of ditch bottom
    plan = plan_ditch_crossing(P, Ditch(0.6, 0.13, 0.1), settings=settings)
    assert plan.status == "too_wide"
    assert "step" in plan.reason


def test_ditch_validation():
    with pytest.raises(ValueError, match="width"):
        Ditch(0.6, 0.0, 0.1)
    with pytest.raises(ValueError, match="depth"):
        Ditch(0.6, 0.3, float("nan"))
    with pytest.raises(ValueError, match="before the ditch"):
        plan_ditch_crossing(P, Ditch(0.2, 0.3, 0.1))
    with pytest.raises(ValueError, match="grid"):
        GaitSettings(grid=0.0)


def test_lift_setting_overrides_paper_apex():
    plan = plan_flat_walk(P, 1, settings=GaitSettings(lift=0.05))
    assert plan.steps[0].lift == pytest.approx(0.05)
    assert plan.steps[1].lift == 0.0  # the lower platform cannot rise (see module doc)
    assert plan.steps[1].swing_extension == pytest.approx(-0.08)
    with pytest.raises(ValueError, match="lift"):
        GaitSettings(lift=-0.01)


def test_statuses_when_the_step_over_search_fails():
    """Deep ditches wider than the 3-3 gait can step over (~75 mm with the hexagonal foot
    pattern) are "too_deep"; shallow ones too narrow for a foot and too wide to step over are
    "too_wide"; a reachable flat bottom is crossable at any width."""
    deep = plan_ditch_crossing(P, Ditch(0.6, 0.08, 0.3))
    assert deep.status == "too_deep" and "too wide to step over" in deep.reason
    narrow = plan_ditch_crossing(P, Ditch(0.6, 0.08, 0.05))
    assert narrow.status == "too_wide" and "too narrow" in narrow.reason
    assert plan_ditch_crossing(P, Ditch(0.6, 0.07, 0.3)).ok  # stepped over
    wide = plan_ditch_crossing(P, Ditch(0.6, 1.0, 0.14))
    assert wide.ok and "standing in the ditch" in wide.reason


def test_transfer_margin_minimum_is_at_an_end():
    """The planner evaluates the margin at the ends of a transfer only: the CoG moves on a line
    and the margin is concave along it. Dense sampling agrees."""
    from hexapod_envs.robots.upu.gait_plan import _transfer_margin

    for moving, x0, x1 in (("upper", 0.0, 0.16), ("upper", 0.04, 0.12), ("lower", -0.16, 0.0)):
        dense = min(
            stance_margin(P, *((x, 0.0) if moving == "upper" else (0.0, x)), support=support)
            for x in np.linspace(x0, x1, 201)
            for support in ["lower" if moving == "upper" else "upper"]
        )
        assert _transfer_margin(P, moving, x0, x1) == pytest.approx(dense, abs=1e-12)


def test_feasible_lift_matches_brute_force():
    from hexapod_envs.robots.upu.gait_plan import _feasible_lift
    from hexapod_envs.robots.upu.kinematics import inside_limits

    settings = GaitSettings()
    for x0, x1 in ((0.0, 0.16), (0.1, 0.16), (0.0, 0.05)):
        lift = _feasible_lift(P, settings, "upper", x0, x1)
        brute = None
        for candidate in np.linspace(0.08, 0.0, 81):
            pts = step_path(x0, x1, P.initial_height, float(candidate)).sample(21)
            poses = np.column_stack([pts[:, 0], np.zeros(21), pts[:, 1]])
            if np.all(inside_limits(poses, P)):
                brute = float(candidate)
                break
        assert lift == pytest.approx(brute)


def _fifo_search(crossing):
    """The planner's search one state at a time with a FIFO queue (its definition)."""
    from collections import deque

    from hexapod_envs.robots.upu.gait_plan import _relative_moves

    moves = _relative_moves(crossing.params, crossing.settings, crossing.n_d)
    ok_upper = crossing.footholds_ok(crossing.upper_offsets)
    ok_lower = crossing.footholds_ok(crossing.lower_offsets)
    start = (0, 0, "upper")
    parent, queue = {start: None}, deque([start])
    while queue:
        i, j, mover = state = queue.popleft()
        if mover == "upper":
            nexts = [(i, j1, "lower") for (j0, j1) in moves.upper if j0 == j and ok_upper[i + j1]]
        else:
            nexts = [
                (i + j - j1, j1, "upper")
                for (j0, j1) in moves.lower
                if j0 == j and i + j - j1 < crossing.n_x and ok_lower[i + j - j1]
            ]
        for nxt in nexts:
            if nxt in parent:
                continue
            parent[nxt] = state
            if nxt[1] == 0 and nxt[0] >= crossing.n_goal:
                chain = [nxt]
                while parent[chain[-1]] is not None:
                    chain.append(parent[chain[-1]])
                return chain[::-1]
            queue.append(nxt)
    return None


@pytest.mark.parametrize("seed", range(4))
def test_compiled_search_finds_the_plan_a_fifo_search_finds(seed):
    """The compiled search returns the chain of states of the planner's definition (first
    discovery, longest step first) on random ditches and grids."""
    from hexapod_envs.robots.upu.gait_plan import _Crossing, _fewest_steps

    rng = np.random.default_rng(seed)
    params = UpuParams()
    for _ in range(6):
        ditch = Ditch(rng.uniform(0.35, 0.9), rng.uniform(0.02, 0.6), rng.uniform(0.01, 0.2))
        settings = GaitSettings(grid=float(rng.choice([0.005, 0.01])))
        crossing = _Crossing(params, ditch, 0.0, settings)
        if not (crossing.can_stand or crossing.can_step_over):
            continue
        assert _fewest_steps(crossing) == _fifo_search(crossing), ditch


def test_edge_clearance_is_the_distance_to_the_nearer_edge_where_feet_may_stand():
    # A ditch from 1.0 to 1.3 m: feet before, near the near edge, in the middle, past it.
    feet = [0.9, 0.99, 1.15, 1.32]
    clear = edge_clearance(feet, 1.0, 1.3, band=0.04, can_stand=True)
    np.testing.assert_allclose(clear, [0.1, 0.01, 0.15, 0.02], atol=1e-12)


def test_edge_clearance_is_negative_over_a_ditch_too_deep_to_stand_in():
    feet = [0.9, 0.99, 1.15, 1.32, 1.4]
    clear = edge_clearance(feet, 1.0, 1.3, band=0.04, can_stand=False)
    # Within the band before the ditch, over it, or within the band past it: negative.
    np.testing.assert_allclose(clear, [0.1, -0.01, -0.15, -0.02, 0.1], atol=1e-12)
    # A foot just at the band counts as clear, as the planner's footholds_ok has it.
    assert edge_clearance([0.96], 1.0, 1.3, band=0.04, can_stand=False)[0] > 0
