"""`OnlineGait`: the 3-3 gait built one platform step at a time (pure numpy)."""

import pytest

from hexapod_envs.robots.upu.gait_plan import Ditch, GaitSettings, plan_flat_walk
from hexapod_envs.robots.upu.online_gait import OnlineGait
from hexapod_envs.robots.upu.params import PLATFORM_LEGS, UpuParams

P, S = UpuParams(), GaitSettings()


def test_full_strides_are_the_flat_plan_exactly():
    plan = plan_flat_walk(P, 6, x_start=0.25, settings=S)
    gait = OnlineGait(P, S, 0.25)
    taken = [gait.advance(gait.stride_for(0.0)) for _ in plan.steps]
    assert taken == list(plan.steps)  # the same floats, not only close ones
    assert gait.x_upper == gait.x_lower == plan.steps[-1].end_x


def test_stride_for_maps_the_action_and_respects_the_room():
    gait = OnlineGait(P, S)
    full = gait.max_stride
    assert full == pytest.approx(0.16)  # eq. 17
    assert gait.stride_for(0.7) == gait.stride_for(0.0) == full
    assert gait.stride_for(-0.5) == pytest.approx(full / 2)
    assert gait.stride_for(-1.0) == gait.min_stride == S.grid
    gait.advance(0.05)  # the upper platform leads by 5 cm ...
    assert gait.moving == "lower"
    assert gait.stride_for(0.0) == pytest.approx(0.05)  # ... and the lower may not pass it
    gait.advance(gait.stride_for(-0.9))  # 1.6 cm
    assert gait.moving == "upper"
    assert gait.room == pytest.approx(full - (0.05 - 0.016))
    assert gait.stride_for(0.0) == pytest.approx(gait.room)  # the lead stays within eq. 17


def test_legs_land_at_the_ground_under_each_foot_and_keep_it_while_supporting():
    ditch = Ditch(start_x=0.6, width=0.35, depth=0.1)
    gait = OnlineGait(P, S, 0.0, ditch)
    step = gait.next_step(0.16)
    assert step.end_x == 0.16 and gait.steps == []  # next_step takes nothing
    while True:
        step = gait.advance(gait.stride_for(0.0))
        in_ditch = {
            leg: ditch.start_x < step.end_x + P.foot_offset(leg)[0] < ditch.end_x
            for leg in PLATFORM_LEGS[step.moving]
        }
        assert step.landing_extension == {
            leg: (0.1 if inside else 0.0) for leg, inside in in_ditch.items()
        }
        if any(in_ditch.values()):
            break
    following = gait.next_step(gait.stride_for(0.0))
    assert following.support_extension == step.landing_extension  # the landed legs stand


def test_plan_lists_the_decided_steps_and_the_pending_one():
    gait = OnlineGait(P, S)
    gait.advance(0.1)
    pending = gait.next_step(0.08)
    plan = gait.plan(pending)
    assert plan.ok and plan.strides == pytest.approx([0.1, 0.08])
    assert len(gait.plan().steps) == 1
