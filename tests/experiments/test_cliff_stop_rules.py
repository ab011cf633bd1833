"""experiments/cliff_stop/stop_rules.py: holding the reference gait once the FASM falls below
ξ_f does on the cliff what the analytical controller does, from memory or from the sensors."""

import pytest

from experiments.cliff_stop import stop_rules


@pytest.mark.parametrize("policy", ["hold", "sensed_hold"])
def test_a_hold_at_the_edge_succeeds_and_fails_where_the_controller_does(policy):
    """Training task 1000: the edge 1.3 m ahead, far enough to stop at it; task 1004: 0.15 m
    ahead, where stopping leaves the robot short of the distance the rule asks for."""
    seeds = range(1000, 1005, 4)
    controller = stop_rules.run("analytical", "train", seeds)
    hold = stop_rules.run(policy, "train", seeds)
    assert [r["success"] for r in controller] == [r["success"] for r in hold] == [True, False]
    assert not any(r["tipped_over"] for r in controller + hold)
    for c, h in zip(controller, hold, strict=True):
        assert h["distance_m"] == pytest.approx(c["distance_m"], abs=0.1)
        assert h["max_tilt_deg"] < 1.0 and h["tipping_share"] < 0.05
