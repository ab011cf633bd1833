"""Timed commands of the 3-UPU 3-3 gait (gait_schedule): phases, ramps, gates, limits."""

import math

import numpy as np
import pytest

from hexapod_envs.robots.upu.gait_plan import (
    Ditch,
    GaitPlan,
    plan_ditch_crossing,
    plan_flat_past,
    plan_flat_walk,
)
from hexapod_envs.robots.upu.gait_schedule import (
    COMMAND_NAMES,
    PHASES,
    GaitSchedule,
    GaitTiming,
    quintic,
    raise_to_limb_min,
    standing_command,
    walking_height,
)
from hexapod_envs.robots.upu.kinematics import forward_kinematics, inverse_kinematics
from hexapod_envs.robots.upu.params import LEG_NAMES, PLATFORM_LEGS, UpuParams

P = UpuParams()
DT = 0.1
LEG_COL = {leg: 3 + i for i, leg in enumerate(LEG_NAMES)}


@pytest.fixture(scope="module")
def flat():
    plan = plan_flat_walk(P, n_cycles=2)
    return plan, GaitSchedule(plan, P, DT)


@pytest.fixture(scope="module")
def ditch():
    plan = plan_ditch_crossing(P, Ditch(0.6, 0.35, 0.14))
    return plan, GaitSchedule(plan, P, DT)


def test_quintic_is_rest_to_rest():
    a = np.linspace(0, 1, 1001)
    q = quintic(a)
    assert q[0] == 0 and q[-1] == pytest.approx(1)
    assert quintic(0.5) == pytest.approx(0.5)
    v = np.gradient(q, a)
    acc = np.gradient(v, a)
    assert abs(v[0]) < 1e-5 and abs(v[-1]) < 1e-5
    assert abs(acc[1]) < 0.1 and abs(acc[-2]) < 0.1  # zero acceleration at both ends
    assert np.all(np.diff(q) >= 0)
    assert quintic(-1.0) == 0 and quintic(2.0) == 1


def test_timing_validation_and_durations():
    t = GaitTiming()
    assert t.step_duration == pytest.approx(sum(t.durations))
    assert len(t.durations) == len(PHASES)
    with pytest.raises(ValueError, match="transfer"):
        GaitTiming(transfer=0.0)
    with pytest.raises(ValueError, match="unload_retract"):
        GaitTiming(unload_retract=-0.001)
    with pytest.raises(ValueError, match="control_dt"):
        GaitSchedule(plan_flat_walk(P, 1), P, 0.0)


def test_rows_per_step_and_phase_bookkeeping(flat):
    plan, sched = flat
    per_step = sum(sched.phase_ticks)
    assert sched.phase_ticks == tuple(round(d / DT) for d in GaitTiming().durations)
    assert sched.n_ticks == per_step * len(plan.steps)
    assert sched.duration == pytest.approx(sched.n_ticks * DT)
    assert sched.phase(0) == (0, "unload")
    assert sched.phase(per_step) == (1, "unload")
    assert sched.phase(sched.n_ticks) == (len(plan.steps) - 1, "done")
    transfer = sum(sched.phase_ticks[: PHASES.index("transfer")])
    assert sched.phase(transfer) == (0, "transfer")
    assert sched.support(transfer) == "lower"  # upper moves first, on the lower tripod
    assert sched.support(per_step + transfer) == "upper"
    assert sched.support(per_step - 1) == "all"  # 'loaded': six legs


def test_walking_height_closed_form():
    h = walking_height(P)
    assert h == pytest.approx(math.sqrt(P.limb_min**2 - 0.75 * P.delta**2))
    assert 0 < h - P.initial_height < 1e-3  # within the paper's rounding (1 mm tolerance)
    x = np.linspace(0.0, 0.16, 161)
    poses = np.column_stack([x, np.zeros_like(x), np.full_like(x, h)])
    assert inverse_kinematics(poses, P).min() == pytest.approx(P.limb_min)
    assert walking_height(UpuParams(initial_height=0.40)) == 0.40  # already high enough


def test_standing_command_levels_all_six_feet():
    stand = standing_command(P)
    assert stand[:3].min() >= P.limb_min
    z = forward_kinematics(stand[:3], P)[2]
    assert z == pytest.approx(walking_height(P))
    # Upper legs longer by exactly the rise: upper soles at the lower soles' height.
    np.testing.assert_allclose(stand[3:6], z - P.initial_height)
    np.testing.assert_allclose(stand[6:], 0.0)


def test_first_and_last_rows_stand(flat):
    _, sched = flat
    stand = standing_command(P)
    np.testing.assert_allclose(sched.command(0)[:3], stand[:3])  # limbs still
    np.testing.assert_allclose(sched.command(-5), sched.command(0))  # clamped before start
    np.testing.assert_allclose(sched.command(10**6), sched.commands[-1])  # holds after end
    last = sched.commands[-1]
    np.testing.assert_allclose(last[:3], stand[:3], atol=1e-12)  # platforms aligned again
    # Level again: upper minus lower extension = the rise of the standing pose.
    np.testing.assert_allclose(last[3:6] - last[6:], stand[3] - stand[6], atol=1e-12)


def test_commands_respect_ranges_and_servo_speed_limits(ditch):
    _, sched = ditch
    c = sched.commands
    assert c.shape[1] == len(COMMAND_NAMES) == 9
    assert np.all(c[:, :3] >= P.limb_min - 1e-12) and np.all(c[:, :3] <= P.limb_max + 1e-12)
    lo, hi = P.extension_range
    assert np.all(c[:, 3:] >= lo - 1e-12) and np.all(c[:, 3:] <= hi + 1e-12)
    rate = np.abs(np.diff(c, axis=0)) / DT
    assert rate[:, :3].max() <= P.limb_speed_limit
    assert rate[:, 3:].max() <= P.leg_speed_limit


def test_phases_move_only_what_they_should(ditch):
    plan, sched = ditch
    names = [PHASES[i] for i in sched.phase_index]
    for k in range(1, sched.n_ticks):
        delta = np.abs(sched.commands[k] - sched.commands[k - 1])
        step = plan.steps[sched.step_index[k]]
        moving_cols = [LEG_COL[leg] for leg in PLATFORM_LEGS[step.moving]]
        support_cols = [LEG_COL[leg] for leg in PLATFORM_LEGS[step.support]]
        assert delta[support_cols].max() == 0  # the supporting legs never move
        if names[k] in ("unloaded", "settle", "loaded"):
            assert delta.max() == 0
        elif names[k] == "transfer":
            assert delta[moving_cols].max() == 0
        else:  # unload, lift, land: legs only
            assert delta[:3].max() == 0


def test_step_commands_follow_the_plan(ditch):
    plan, sched = ditch
    per_step = sum(sched.phase_ticks)
    end_transfer = sum(sched.phase_ticks[: PHASES.index("transfer") + 1]) - 1
    end_lift = sum(sched.phase_ticks[: PHASES.index("lift") + 1]) - 1
    for k, step in enumerate(plan.steps):
        row_lift = sched.commands[k * per_step + end_lift]
        row_end = sched.commands[(k + 1) * per_step - 1]
        for leg in PLATFORM_LEGS[step.moving]:
            assert row_lift[LEG_COL[leg]] == pytest.approx(step.swing_extension)
            # The planned extension (ditch depth or 0), upper legs + the walking height offset.
            offset = walking_height(P) - P.initial_height if step.moving == "upper" else 0.0
            expected = min(step.landing_extension[leg] + offset, P.leg_extend)
            assert row_end[LEG_COL[leg]] == pytest.approx(expected, abs=1e-12)
        # The limbs place the moving platform at the planned end, relative to the support.
        limbs = sched.commands[k * per_step + end_transfer, :3]
        rel = forward_kinematics(limbs, P, moving=step.moving)
        assert rel[0] == pytest.approx(step.end_x - step.support_x, abs=1e-9)
        assert abs(rel[1]) < 1e-9
        assert abs(rel[2]) == pytest.approx(walking_height(P), abs=1e-9)


def test_gates_one_off_and_one_down_per_step(ditch):
    plan, sched = ditch
    offs = [c for c in sched.checkpoints if c.state == "off"]
    downs = [c for c in sched.checkpoints if c.state == "down"]
    assert len(offs) == len(plan.steps) and len(downs) == len(plan.steps) - 1
    for c in sched.checkpoints:
        assert c.legs == PLATFORM_LEGS[plan.steps[c.step].moving]
        assert sched.gate(c.tick) is c
        expected = "transfer" if c.state == "off" else "unload"
        assert sched.phase(c.tick)[1] == expected  # the gate opens the next phase
    assert sched.gate(1) is None


def test_raise_to_limb_min_keeps_x_and_lifts_at_most_the_paper_shortfall():
    x = np.linspace(0.0, 0.16, 65)  # the gait's relative positions (upper ahead of lower)
    poses = np.column_stack([x, np.zeros_like(x), np.full_like(x, P.initial_height)])
    raised = raise_to_limb_min(poses, P, "upper")
    np.testing.assert_array_equal(raised[:, :2], poses[:, :2])
    assert np.all(inverse_kinematics(raised, P).min(axis=-1) >= P.limb_min - 1e-12)
    assert np.all(raised[:, 2] >= poses[:, 2])
    assert (raised[:, 2] - poses[:, 2]).max() < 1e-3  # < the 1 mm limit tolerance
    lower = raise_to_limb_min(-poses, P, "lower")
    np.testing.assert_allclose(lower, -raised)  # eq. (8) at -p is eq. (6) at p
    high = poses + [0, 0, 0.05]
    np.testing.assert_array_equal(raise_to_limb_min(high, P, "upper"), high)  # already long
    # Closed form at x = Delta/2 (limbs 2, 3 shortest): z = sqrt(l_min^2 - 3/4 Delta^2).
    z = raise_to_limb_min([[P.delta / 2, 0.0, 0.3]], P, "upper")[0, 2]
    assert z == pytest.approx(math.sqrt(P.limb_min**2 - 0.75 * P.delta**2))
    # Behind the lower centre by Delta limb 1 is vertical: z = l_min (2 mm above 363 mm).
    z = raise_to_limb_min([[-P.delta, 0.0, P.initial_height]], P, "upper")[0, 2]
    assert z == pytest.approx(P.limb_min)


def test_no_plan_means_standing_still():
    plan = GaitPlan("too_deep", "bottom out of reach")
    sched = GaitSchedule(plan, P, DT)
    assert sched.n_ticks == 1 and sched.checkpoints == ()
    np.testing.assert_allclose(sched.command(0), standing_command(P))
    np.testing.assert_allclose(sched.command(500), standing_command(P))
    assert sched.phase(0) == (-1, "stand") and sched.support(0) == "all"


def test_flat_past_reaches_the_finish_line():
    plan = plan_flat_past(P, goal_x=0.95)
    assert plan.ok and np.allclose(plan.strides, 0.16)
    final = plan.steps[-1].end_x
    rear = final - P.leg_circle_radius
    assert rear - P.foot_radius > 0.95
    assert rear - 0.16 - P.foot_radius <= 0.95 + 0.02  # one cycle fewer would not do
    with pytest.raises(ValueError, match="behind"):
        plan_flat_past(P, goal_x=-0.5)
