"""experiments/ditch_planner/settings_scan.py: a setting's action means that setting, and the
scan runs the planner through the planner knobs' path."""

import numpy as np
import pytest

from agents.knobs import PLANNER_KNOB_RANGES, knob_values
from agents.plan_knobs import resolved_settings
from experiments.ditch_planner import settings_scan
from hexapod_envs.robots.upu.gait_plan import GaitSettings
from hexapod_envs.robots.upu.params import UpuParams


def test_a_setting_round_trips_through_the_knob_action():
    default = resolved_settings(GaitSettings(), UpuParams())
    names = tuple(PLANNER_KNOB_RANGES)
    for text in ("", "min_margin=0.02", "edge_clearance=0.005,max_stride=0.12,lift=0.1"):
        values = settings_scan.parse_setting(text)
        action = settings_scan.action_for(values, default, names)
        assert np.all(np.abs(action) <= 1)
        expected = {n: values.get(n, getattr(default, n)) for n in names}
        assert knob_values(default, names, action, PLANNER_KNOB_RANGES) == pytest.approx(expected)
    with pytest.raises(SystemExit, match="knobs"):
        settings_scan.parse_setting("margin=0.02")
    with pytest.raises(SystemExit, match="outside the knob's range"):
        settings_scan.parse_setting("min_margin=0.05")


def test_the_scan_compares_settings_on_the_same_tasks():
    """Test ditch 11 has a plan with the env's 10 mm margin but none with 20 mm: the scan falls
    back to the env's settings there, and the two runs are the same episode."""
    results, tilts = settings_scan.scan("test", range(11, 12), ["", "min_margin=0.02"])
    assert results[""][11] in ("S", "T", "F")
    assert results["min_margin=0.02"][11] == results[""][11] + "*"
    assert tilts["min_margin=0.02"][11] == tilts[""][11] > 0  # the same episode
    line = settings_scan.summary("min_margin=0.02", results["min_margin=0.02"], results[""])
    assert "1 fallbacks" in line and "wins [], losses []" in line


def test_the_summary_compares_the_largest_tilt_where_both_settings_cross():
    outcomes = {1: "S", 2: "S", 3: "T", 4: "S"}
    reference = {1: "S", 2: "S", 3: "S", 4: "F"}
    tilt, reference_tilt = {1: 0.3, 2: 0.6, 3: 12.0, 4: 0.4}, {1: 0.4, 2: 0.4, 3: 0.4, 4: 0.1}
    line = settings_scan.summary("min_margin=0.02", outcomes, reference, tilt, reference_tilt)
    assert "wins [4], losses [3]" in line
    assert "largest tilt lower on 1 of the 2 tasks both cross, median change +0.050 deg" in line
