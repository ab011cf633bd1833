"""experiments/stewart_landing/land_rules.py: setting the lifted tripod down once the FASM falls
below ξ_f recovers where the hold posture tips over, from memory or from the sensors."""

import pytest

from experiments.stewart_landing import land_rules


@pytest.mark.parametrize("policy", ["land", "sensed_land"])
def test_a_landing_at_the_tipping_judgment_recovers_where_the_hold_posture_tips(policy):
    """Test tasks 2 and 7 (a climb at 7.3 deg/s, an arbitrary axis at 13.8 deg/s): the hold
    posture tips over on both; landing at the judgment stands to the end, upright."""
    seeds = range(2, 8, 5)
    zero = land_rules.run("zero", "test", seeds)
    land = land_rules.run(policy, "test", seeds)
    assert all(r["tipped_over"] and not r["success"] for r in zero)
    assert all(r["success"] and not r["early_landing"] for r in land)
    assert all(r["max_tilt_deg"] < 1.0 for r in land)


def test_unknown_policies_are_named():
    with pytest.raises(ValueError, match="unknown policy 'hop'.*sensed_land"):
        land_rules.make("hop", "test")
