"""HexapodStewartTilt-v0 scenarios without a controller: the held tripod tips in every case."""

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from hexapod_envs.envs.stewart_tilt import STANCES

CASES = [(s, st) for s in ("climb", "descend", "side") for st in sorted(STANCES)]
EXPECTED_EDGE = {  # the tripod edge the held robot tips about, counter-clockwise pair
    ("climb", "LF-LR-RM"): {"LR", "RM"},
    ("descend", "LF-LR-RM"): {"RM", "LF"},
    ("side", "LF-LR-RM"): {"LF", "LR"},
    ("climb", "LM-RF-RR"): {"RR", "LM"},
    ("descend", "LM-RF-RR"): {"LM", "RF"},
    ("side", "LM-RF-RR"): {"RF", "RR"},
}


@pytest.mark.slow
@pytest.mark.parametrize(("scenario", "stance"), CASES)
def test_held_tripod_tips_over_about_the_expected_edge(scenario, stance):
    env = gym.make("HexapodStewartTilt-v0", scenario=scenario, stance=stance)
    env.reset(seed=0)
    first_tipping = None
    while True:
        _, _, terminated, truncated, info = env.step(np.zeros(18))
        if info["is_tipping"] and first_tipping is None:
            first_tipping = info
        if terminated or truncated:
            break
    assert (
        first_tipping is not None
        and set(first_tipping["fasm_edge"]) == EXPECTED_EDGE[(scenario, stance)]
    )
    assert terminated and info["is_tipped_over"] and not info["is_success"]
    assert info["adjustment_leg"] is None  # nothing landed


def test_actuator_lengths_reported_and_within_stroke():
    env = gym.make("HexapodStewartTilt-v0", scenario="climb")
    env.reset(seed=0)
    for _ in range(400):
        *_, info = env.step(np.zeros(18))
    lengths = info["actuator_lengths"]
    assert lengths.shape == (6,) and np.all((lengths >= 9.0) & (lengths <= 14.0))
    assert info["platform_tilt_deg"] > 5.0
    # The lengths are the tilted platform's: its roll and pitch give the reported tilt, and a
    # tilt of this size spreads the six lengths apart (all equal when level).
    roll, pitch, _ = info["platform_rpy"]
    tilt = np.degrees(np.arccos(np.cos(roll) * np.cos(pitch)))
    assert tilt == pytest.approx(info["platform_tilt_deg"], abs=0.01)
    platform = env.unwrapped.platform
    np.testing.assert_allclose(
        lengths, platform.actuator_lengths(platform.neutral_position, info["platform_rpy"])
    )
    assert np.ptp(lengths) > 0.1


def test_unreachable_platform_pose_is_refused():
    with pytest.raises(ValueError, match="actuator"):
        gym.make("HexapodStewartTilt-v0", scenario="side", max_tilt_deg=60.0)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [({"scenario": "upside"}, "climb"), ({"stance": "LF-LM-LR"}, "LF-LR-RM")],
)
def test_bad_choices_list_the_valid_ones(kwargs, match):
    with pytest.raises(ValueError, match=match):
        gym.make("HexapodStewartTilt-v0", **kwargs)


def test_random_scenario_is_seeded():
    env = gym.make("HexapodStewartTilt-v0")
    axes = []
    for seed in (1, 1, 2):
        env.reset(seed=seed)
        axes.append(tuple(env.unwrapped.axis.round(6)))
    assert axes[0] == axes[1] != axes[2]


@pytest.mark.parametrize(
    ("rate_deg", "max_deg"), [(2.0, 38.0), (7.0, 15.0), (12.0, 8.0), (40.0, 10.0), (20.0, 20.0)]
)
def test_tilt_profile_rises_to_max_tilt_without_overshoot(rate_deg, max_deg):
    """The commanded tilt rises monotonically to max_tilt and stays there, never faster than
    the rate and with the ramps' (de)celeration, also when max_tilt is too small for the rate
    to be reached (the ramps used to overlap: 19.2 deg peak for 10 at 40 deg/s)."""
    env = gym.make(
        "HexapodStewartTilt-v0", scenario="climb", tilt_rate_deg=rate_deg, max_tilt_deg=max_deg
    ).unwrapped
    times = env.tilt_start_time + np.arange(-0.5, max_deg / rate_deg + 3.0, 1e-3)
    tilt = np.array([env.tilt_at(t) for t in times])
    rate = np.diff(tilt) / np.diff(times)
    assert np.all(rate >= -1e-12) and tilt.max() == pytest.approx(np.radians(max_deg))
    assert tilt[-1] == pytest.approx(np.radians(max_deg))
    assert rate.max() <= np.radians(rate_deg) * (1 + 1e-6)


def test_info_names_the_episodes_case_on_a_task_distribution():
    env = gym.make("HexapodStewartTilt-v0", task_distribution="train")
    scenarios = set()
    for seed in range(6):
        _, info = env.reset(seed=seed)
        assert info["scenario"] == info["task"]["scenario"]
        scenarios.add(info["scenario"])
    assert len(scenarios) > 1  # not the setting's "random" every time


def _hold_then_land(env, landing, steps, seed=1000):
    """Step `env` (landing_action) with zero residuals and landing action `landing(step)`."""
    env.reset(seed=seed)
    action = np.zeros(19, dtype=np.float32)
    infos = []
    for k in range(steps):
        action[18] = landing(k)
        infos.append(env.step(action)[4])
    return infos


def test_landing_action_at_or_below_zero_holds_the_posture_bit_for_bit():
    kwargs = {"task_distribution": "train", "residual_scale": 0.05}
    plain = gym.make("HexapodStewartTilt-v1", **kwargs)
    landing = gym.make("HexapodStewartTilt-v1", landing_action=True, **kwargs)
    assert landing.action_space.shape == (19,)
    plain.reset(seed=1000)
    expected = [plain.step(np.zeros(18, dtype=np.float32))[4] for _ in range(120)]
    got = _hold_then_land(landing, lambda k: -1.0 if k % 2 else 0.0, 120)
    np.testing.assert_array_equal([i["cog"] for i in got], [i["cog"] for i in expected])
    reference = landing.unwrapped.task_description.reference
    assert reference["landing_action"]
    changed = np.flatnonzero(reference["landed_posture"] != reference["hold_posture"])
    swing = landing.unwrapped._swing_ids
    assert {int(j) // 3 for j in changed} == set(swing)  # only the lifted legs move


def test_landing_action_one_sets_the_lifted_feet_down_and_keeps_the_robot_up():
    env = gym.make("HexapodStewartTilt-v1", landing_action=True, residual_scale=0.05)
    infos = _hold_then_land(env, lambda k: 1.0, 100, seed=0)
    assert set(infos[-1]["stance_legs"]) == set(env.unwrapped.swing) | set(env.unwrapped.stance)
    assert infos[-1]["early_landing"]  # before any tipping: the v1 rule's early landing
    assert not infos[-1]["is_success"]


def test_landing_action_needs_the_residual_mode():
    with pytest.raises(ValueError, match="landing_action.*residual action"):
        gym.make("HexapodStewartTilt-v1", landing_action=True, action_mode="joint")
