"""Tipping judgment and Table II adjustment-leg selection (Zhang et al. 2024 §3, §4.1)."""

import numpy as np
import pytest

from agents.tipping.judgment import (
    ADJUSTMENT_LEG,
    CCW_LEG_ORDER,
    XI_F_DEG,
    ccw_edge,
    effective_support_legs,
    is_tipping,
    judge,
    select_adjustment_leg,
    tipping_edge,
)
from hexapod_envs.robots.heavy_duty import TRIPODS, HeavyDutyParams, standing_feet

TRIPOD_1, TRIPOD_2 = TRIPODS
TABLE_II = [
    (TRIPOD_1, ("LF", "LR"), "LM"),
    (TRIPOD_1, ("LR", "RM"), "RR"),
    (TRIPOD_1, ("RM", "LF"), "RF"),
    (TRIPOD_2, ("LM", "RF"), "LF"),
    (TRIPOD_2, ("RF", "RR"), "RM"),
    (TRIPOD_2, ("RR", "LM"), "LR"),
]
FEET = standing_feet(HeavyDutyParams())


@pytest.mark.parametrize("reverse", [False, True])
@pytest.mark.parametrize(("stance", "edge", "leg"), TABLE_II)
def test_table_ii_all_edges_both_orders(stance, edge, leg, reverse):
    edge = edge[::-1] if reverse else edge
    assert select_adjustment_leg(stance, edge) == leg
    assert select_adjustment_leg(stance[::-1], edge) == leg


def test_table_ii_is_the_swing_leg_between_the_edge_legs():
    # Geometric reading of Table II: going round the body, the adjustment leg sits between the
    # two edge legs, on the far side of the tipping edge, and is a swing leg.
    ring = list(CCW_LEG_ORDER)
    for pair, leg in ADJUSTMENT_LEG.items():
        stance = next(t for t in TRIPODS if pair <= set(t))
        assert leg not in stance
        i = ring.index(leg)
        assert {ring[i - 1], ring[(i + 1) % 6]} == set(pair)


def test_threshold_is_strict():
    assert XI_F_DEG == 20.0
    assert is_tipping(19.99)
    assert not is_tipping(20.0)
    assert is_tipping(5.0, threshold_deg=10.0) and not is_tipping(15.0, threshold_deg=10.0)


def test_effective_support_legs_are_the_two_largest_vertical_forces():
    forces = {"LF": 9000.0, "LR": 21000.0, "RM": 18000.0, "LM": 50000.0}  # LM is swinging
    assert effective_support_legs(forces, TRIPOD_1) == ("LR", "RM")


def test_effective_support_legs_rejects_missing_and_unknown_legs():
    with pytest.raises(ValueError, match="no entry for stance leg"):
        effective_support_legs({"LF": 1.0, "LR": 2.0}, TRIPOD_1)
    with pytest.raises(ValueError, match="valid legs"):
        effective_support_legs({"XX": 1.0}, ("XX", "LF"))


@pytest.mark.parametrize(("stance", "edge", "leg"), TABLE_II)
def test_tipping_edge_is_counter_clockwise(stance, edge, leg):
    forces = {name: 1000.0 for name in stance}
    for name in edge:
        forces[name] = 20000.0
    by_names = tipping_edge(forces, stance)
    by_geometry = tipping_edge(forces, stance, {name: FEET[name] for name in stance})
    assert by_names == by_geometry
    # Counter-clockwise seen from above: the third foot lies to the left of i -> j.
    p, q = FEET[by_names[0]], FEET[by_names[1]]
    (third,) = set(stance) - set(edge)
    r = FEET[third]
    assert np.cross(q - p, r - p)[2] > 0.0
    assert select_adjustment_leg(stance, by_names) == leg


def test_ccw_edge_geometry_overrides_name_order():
    # Feet mirrored left-right: geometry decides, not the nominal order round the body.
    stance = TRIPOD_1
    mirrored = {name: FEET[name] * np.array([1.0, -1.0, 1.0]) for name in stance}
    assert ccw_edge("LR", "RM", stance) == ("LR", "RM")
    assert ccw_edge("LR", "RM", stance, mirrored) == ("RM", "LR")


def test_select_adjustment_leg_errors_name_valid_choices():
    with pytest.raises(ValueError, match="valid edges"):
        select_adjustment_leg(TRIPOD_1, ("LF", "LM"))
    with pytest.raises(ValueError, match="not one of"):
        select_adjustment_leg(("LF", "LM", "LR"), ("LF", "LR"))
    with pytest.raises(ValueError, match="valid legs"):
        select_adjustment_leg(TRIPOD_1, ("LF", "front"))


def test_judge_backward_tipping_of_paper_case():
    # §5.2, climbing: stance {1, 3, 5}, legs 3 and 5 carry the most, leg 6 is put down.
    forces = {"LF": 4000.0, "LR": 24000.0, "RM": 21000.0}
    verdict = judge(19.2, forces, TRIPOD_1)
    assert verdict.tipping
    assert verdict.support_legs == ("LR", "RM")
    assert verdict.edge == ("LR", "RM")
    assert verdict.adjustment_leg == "RR"
    calm = judge(31.4, forces, TRIPOD_1)
    assert not calm.tipping and calm.adjustment_leg == "RR"


def test_judge_without_tripod_gives_no_adjustment_leg():
    forces = {name: 10000.0 + i for i, name in enumerate(CCW_LEG_ORDER)}
    verdict = judge(10.0, forces, CCW_LEG_ORDER)
    assert verdict.tipping and verdict.adjustment_leg is None
