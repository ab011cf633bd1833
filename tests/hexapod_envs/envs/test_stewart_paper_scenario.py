"""HexapodStewartTilt-v0 as Zhang et al. 2024 §5.2 run it: `paper_scenario` and the platform that
stops once the robot tips (``stop_on_tipping``)."""

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from hexapod_envs.envs.stewart_tilt import (
    CASES,
    PAPER_FOOT_Y,
    PAPER_TILT_RATE_DEG,
    PAPER_TILT_START,
    RAMP_TIME,
    paper_scenario,
)


def _env(**kwargs):
    env = gym.make("HexapodStewartTilt-v0", scenario="climb", **kwargs)
    env.reset(seed=0)
    return env.unwrapped


def test_without_stop_on_tipping_the_tilt_is_the_schedule_even_after_tipping():
    env = _env(tilt_rate_deg=5.0)
    env._first_tipping_time = 4.0
    for t in np.linspace(0.0, 20.0, 81):
        assert env.tilt_at(t) == env.scheduled_tilt_at(t)


@pytest.mark.parametrize("stop", [3.5, 6.0])  # on the ramp up, and at the full rate
def test_platform_decelerates_at_the_ramps_rate_and_rests_once_the_robot_tips(stop):
    env = _env(tilt_rate_deg=5.0, stop_on_tipping=True)
    env._first_tipping_time = stop
    times = np.linspace(0.0, 20.0, 2001)
    tilt = np.array([env.tilt_at(t) for t in times])
    scheduled = np.array([env.scheduled_tilt_at(t) for t in times])
    before = times <= stop
    assert np.array_equal(tilt[before], scheduled[before])
    assert np.all(np.diff(tilt) >= 0.0) and np.all(tilt <= scheduled)
    rate = (env.scheduled_tilt_at(stop + 1e-4) - env.scheduled_tilt_at(stop - 1e-4)) / 2e-4
    decel = np.radians(5.0) / RAMP_TIME
    rest = env.scheduled_tilt_at(stop) + rate**2 / (2.0 * decel)
    assert tilt[-1] == pytest.approx(rest, rel=1e-6)
    assert env.tilt_at(stop + rate / decel + 0.01) == pytest.approx(rest, rel=1e-6)
    assert tilt[-1] < scheduled[-1]


def test_paper_scenario_settings_follow_the_paper_and_refuse_other_cases():
    for scenario, stance in CASES:
        kwargs = paper_scenario(scenario, stance)
        assert kwargs["stop_on_tipping"] is True
        assert kwargs["tilt_start_time"] == PAPER_TILT_START[stance]
        assert kwargs["tilt_rate_deg"] == PAPER_TILT_RATE_DEG
        assert kwargs["hold_foot_y"] == PAPER_FOOT_Y
    assert PAPER_TILT_START == {"LF-LR-RM": 7.0, "LM-RF-RR": 5.0}
    with pytest.raises(ValueError, match="climb"):
        paper_scenario("random", "LF-LR-RM")


@pytest.mark.slow
def test_held_tripod_in_the_paper_scenario_stops_the_platform_soon_after_it_tips():
    env = gym.make("HexapodStewartTilt-v0", **paper_scenario("side", "LF-LR-RM"))
    env.reset(seed=0)
    tipped_at, tilt = None, []
    for _ in range(700):  # 14 s: 7 s level, the tilt, and the stop
        _, _, terminated, _, info = env.step(np.zeros(18))
        tilt.append(info["platform_tilt_deg"])
        if tipped_at is None and info["is_tipping"]:
            tipped_at = info["time"]
        if terminated:
            break
    assert tipped_at is not None and tipped_at > PAPER_TILT_START["LF-LR-RM"]
    # 8 deg/s decelerated over 1 s adds 4 deg after the robot tips (at about 25 deg sideways);
    # then the platform rests and the held robot stays up
    assert max(tilt) < 31.0 and abs(tilt[-1] - tilt[-50]) < 0.05 and not terminated
