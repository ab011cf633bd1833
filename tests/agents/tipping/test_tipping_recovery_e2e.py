"""Zhang et al. 2024 §5.1-5.2 end to end: the tipping-recovery controller on the tilting Stewart
platform
(six cases) and on the unilateral cliff, against the same robot left to itself."""

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from agents.tipping.controller import TippingRecoveryPolicy
from agents.tipping.gait_with_recovery import GaitWithRecoveryPolicy
from agents.tripod_gait import TripodGaitPolicy

WEIGHT = 5000.0 * 9.81
PAPER_ADJUSTMENT_LEG = {  # Zhang et al. 2024 §5.2
    ("climb", "LF-LR-RM"): "RR",
    ("descend", "LF-LR-RM"): "RF",
    ("side", "LF-LR-RM"): "LM",
    ("climb", "LM-RF-RR"): "LR",
    ("descend", "LM-RF-RR"): "LF",
    ("side", "LM-RF-RR"): "RM",
}


def _held_tips(env) -> bool:
    env.reset(seed=0)
    while True:
        _, _, terminated, truncated, info = env.step(np.zeros(18))
        if terminated or truncated:
            return bool(terminated and info["is_tipped_over"])


@pytest.mark.slow
@pytest.mark.parametrize(("scenario", "stance"), sorted(PAPER_ADJUSTMENT_LEG))
def test_recovery_lands_the_papers_leg_and_the_robot_stays_up(scenario, stance):
    env = gym.make("HexapodStewartTilt-v0", scenario=scenario, stance=stance)
    assert _held_tips(env)

    policy = TippingRecoveryPolicy(env)
    obs, _ = env.reset(seed=0)
    policy.reset()
    fasm_after = None
    internal_errors = []
    while True:
        obs, _, terminated, truncated, info = env.step(policy(obs))
        d = policy.diagnostics
        landed = d["landing_time"]
        if landed is not None and fasm_after is None and info["time"] >= landed + 0.5:
            fasm_after = d["fasm_deg"]
        firm = (
            landed is not None
            and d["qp_legs"] == d["supported_legs"]
            and d["measured_forces"][:, 2].min() >= policy.config.min_normal_fraction * WEIGHT
        )
        if firm and info["time"] >= landed + 1.0:
            # Planned minus measured force, internal part: what the stiffness offsets act on,
            # which works while every support foot is firmly on the ground (near lift-off the
            # body rolls instead, e.g. the side cases beyond ~35° of platform tilt).
            assert d["qp_status"] == "optimal"
            a = policy.controller._last_qp_a
            e = (d["planned_forces"] - d["measured_forces"]).reshape(-1)
            internal_errors.append(np.linalg.norm(e - a.T @ np.linalg.solve(a @ a.T, a @ e)))
        if terminated or truncated:
            break
    leg = PAPER_ADJUSTMENT_LEG[(scenario, stance)]
    assert d["adjustment_leg"] == leg and info["adjustment_leg"] == leg
    assert d["phase"] == "supported" and d["fasm_before_landing_deg"] < 20.0
    assert fasm_after is not None and fasm_after >= 20.0
    assert truncated and not terminated and not info["is_tipped_over"]
    # The planned load sharing acts: the internal force error is small (~2 % of the weight at
    # most; without the stiffness offsets it is ~6.6 kN in the climb case).
    assert np.median(internal_errors) < 1000.0


@pytest.mark.slow
def test_gait_with_recovery_stops_at_the_cliff_instead_of_tipping():
    env = gym.make("HexapodCliffWalk-v0", action_mode="joint")
    outcomes = {}
    for name, policy in (
        ("gait", TripodGaitPolicy(env)),
        ("recovery", GaitWithRecoveryPolicy(env)),
    ):
        obs, _ = env.reset(seed=0)
        policy.reset()
        while True:
            obs, _, terminated, truncated, info = env.step(policy(obs))
            if terminated or truncated:
                break
        outcomes[name] = (terminated, info)
    assert outcomes["gait"][0] and outcomes["gait"][1]["is_tipped_over"]
    terminated, info = outcomes["recovery"]
    assert not terminated and not info["is_tipped_over"]
    d = policy.diagnostics
    # The paper's leg for the tipping edge RM-LF is RF, the leg that stepped into the void: it
    # finds no ground and the controller holds the five-leg stance.
    assert d["adjustment_leg"] == "RF" and d["phase"] == "holding"
    assert "no ground under RF" in d["failure"]
    assert info["fasm_margin_deg"] > 20.0


def test_support_feet_in_a_line_skip_the_force_distribution_instead_of_crashing(monkeypatch):
    """A learned residual can put the loaded feet on a line in (x, y): the terrain plane is then
    undetermined, and the supported phase reports degenerate geometry instead of raising (a
    hybrid training run crashed on it)."""
    import agents.tipping.controller as controller

    def no_plane(feet):  # what plane_normal returns for collinear feet
        return None

    monkeypatch.setattr(controller, "plane_normal", no_plane)
    env = gym.make("HexapodStewartTilt-v0", scenario="side")
    policy = TippingRecoveryPolicy(env)
    obs, _ = env.reset(seed=0)
    policy.reset()
    statuses = set()
    while True:
        obs, _, terminated, truncated, _ = env.step(policy(obs))
        if policy.diagnostics["phase"] == "supported":
            statuses.add(policy.diagnostics["qp_status"])
        if terminated or truncated:
            break
    assert "degenerate_geometry" in statuses


@pytest.mark.parametrize(
    ("env_id", "policy_class", "option"),
    [
        ("HexapodStewartTilt-v1", TippingRecoveryPolicy, {"landing_action": True}),
        ("HexapodCliffWalk-v1", GaitWithRecoveryPolicy, {"clock_action": True}),
    ],
)
def test_an_extra_action_gets_its_neutral_zero_and_changes_nothing(env_id, policy_class, option):
    """With a 19th action (the landing fraction, the gait clock's rate) the recovery policies
    send 0 for it and act as on the 18-action env: the same joint actions step for step."""
    runs = []
    for kwargs in ({}, option):
        env = gym.make(env_id, task_distribution="test", **kwargs)
        policy = policy_class(env)
        obs, _ = env.reset(seed=1)
        policy.reset()
        actions = []
        for _ in range(400):  # past the Stewart tilt's first tipping judgment (step 230 here)
            action = policy(obs)
            actions.append(action)
            obs, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                break
        runs.append(np.array(actions))
    plain, extra = runs
    assert extra.shape[1] == 19 and np.all(extra[:, 18] == 0.0)
    np.testing.assert_array_equal(extra[:, :18], plain)
