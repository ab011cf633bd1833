"""The 3-3 gait policy on HexapodDitchCrossing-v0 (Li et al. 2018 §6-7, Figs. 12-14).

End to end in MuJoCo: the planner's gait walks on flat ground and crosses the paper's ditch
(140 mm deep, 350 mm wide) and other ditches within the mechanism's reach with the static
stability margin d > 0 at every control step and no tip-over; ditches beyond its reach are
reported by the planner's status and not walked into.
"""

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from agents.registry import analytical_factory
from agents.upu_gait import UpuGaitPolicy
from hexapod_envs.robots.upu.gait_schedule import PHASES
from hexapod_envs.robots.upu.params import LEG_NAMES, PLATFORM_LEGS

ENV_ID = "HexapodDitchCrossing-v0"


def run_episode(seed=0, **kwargs):
    env = gym.make(ENV_ID, **kwargs)
    policy = UpuGaitPolicy(env)
    obs, info = env.reset(seed=seed)
    policy.reset()
    margins, tilts, actions = [], [], []
    terminated = truncated = False
    while not (terminated or truncated):
        action = policy(obs)
        actions.append(action)
        obs, reward, terminated, truncated, info = env.step(action)
        margins.append(info["static_margin_m"])
        tilts.append(info["tilt_deg"])
        assert not info["sim_unstable"]
    base = env.unwrapped
    feet_x = base.data.xpos[base._foot_body, 0].copy()
    env.close()
    return {
        "policy": policy,
        "info": info,
        "terminated": terminated,
        "margins": np.array(margins),
        "tilts": np.array(tilts),
        "actions": np.array(actions),
        "feet_x": feet_x,
    }


def check_crossed(result, finish_x):
    info, policy = result["info"], result["policy"]
    assert policy.status == "ok", policy.reason
    assert result["terminated"] and info["is_success"] and not info["is_tipped_over"]
    assert np.all(policy.plan.strides <= 0.16 + 1e-9)  # eq. (17)
    assert policy.plan.min_margin > 0
    # Figs. 12 and 14: the measured margin stays positive at every control step, close to
    # the planned minimum (the servos' compliance costs ~2 mm).
    assert result["margins"].min() > 0.005
    assert result["margins"].min() == pytest.approx(policy.plan.min_margin, abs=0.004)
    assert result["tilts"].max() < 2.0
    assert result["feet_x"].min() - 0.02 > finish_x  # the whole robot is past the ditch
    assert policy.waits == 0  # the feet met every contact gate on time


@pytest.mark.slow
def test_crosses_the_papers_ditch_with_default_settings():
    """Default env (residual actions): the policy plays the env's reference gait, zero action."""
    result = run_episode(seed=0)
    check_crossed(result, finish_x=0.95)
    assert np.abs(result["actions"]).max() < 1e-6
    plan = result["policy"].plan
    assert any(v > 0 for s in plan.steps for v in s.landing_extension.values())  # §7
    assert np.any(plan.strides < 0.16 - 1e-9)  # strides adapted to the ditch


@pytest.mark.slow
@pytest.mark.parametrize(
    ("width", "depth"),
    [(0.25, 0.10), (0.45, 0.15), (0.05, 0.30)],
    ids=["narrow-shallow", "wide-deep", "stepped-over"],
)
def test_crosses_other_ditches_in_joint_mode(width, depth):
    result = run_episode(seed=1, action_mode="joint", ditch_width=width, ditch_depth=depth)
    check_crossed(result, finish_x=0.6 + width)
    in_ditch = any(v > 0 for s in result["policy"].plan.steps for v in s.landing_extension.values())
    assert in_ditch == (depth <= 0.16 and width > 0.1)


@pytest.mark.slow
def test_flat_walk_keeps_a_positive_margin_at_every_step():
    result = run_episode(seed=2, terrain="flat", action_mode="joint")
    check_crossed(result, finish_x=0.95)
    assert np.allclose(result["policy"].plan.strides, 0.16)  # the paper's full stride
    assert result["info"]["distance"] == pytest.approx(1.28, abs=0.02)  # 8 cycles x 0.16 m


@pytest.mark.parametrize(
    ("width", "depth", "status"),
    [(0.35, 0.20, "too_deep"), (0.08, 0.30, "too_deep"), (0.08, 0.05, "too_wide")],
)
def test_impassable_ditch_is_reported_and_not_walked_into(width, depth, status):
    env = gym.make(ENV_ID, action_mode="joint", ditch_width=width, ditch_depth=depth)
    policy = UpuGaitPolicy(env)
    obs, info = env.reset(seed=0)
    policy.reset()
    assert policy.status == status == info["planner_status"]
    assert policy.reason == info["planner_reason"]
    for _ in range(60):
        obs, _, terminated, truncated, info = env.step(policy(obs))
        assert not (terminated or truncated)
    base = env.unwrapped
    feet_x = base.data.xpos[base._foot_body, 0]
    assert abs(info["distance"]) < 2e-3 and info["tilt_deg"] < 0.5
    assert len(info["stance_legs"]) == 6 and feet_x.max() < 0.6  # standing, clear of the ditch
    env.close()


def test_policy_waits_at_contact_gates():
    env = gym.make(ENV_ID, action_mode="joint")
    policy = UpuGaitPolicy(env)
    obs, _ = env.reset(seed=0)
    policy.reset()
    sched = policy.schedule
    gate = sched.checkpoints[0]  # before the first transfer: upper feet must be off
    assert gate.state == "off" and gate.legs == PLATFORM_LEGS["upper"]
    contact = env.unwrapped.observation_structure["foot_contact"]
    held = obs.copy()
    held[contact] = 1.0  # every foot still reports ground contact
    for _ in range(gate.tick):
        policy(held)
    assert policy.tick == gate.tick and not policy.waiting
    first = policy(held)
    second = policy(held)
    assert policy.waiting and policy.tick == gate.tick and policy.waits == 2
    np.testing.assert_array_equal(first, second)  # holding the last command
    free = obs.copy()
    free[contact] = [0.0 if leg in gate.legs else 1.0 for leg in LEG_NAMES]
    policy(free)
    assert not policy.waiting and policy.tick == gate.tick + 1
    assert sched.phase(gate.tick)[1] == PHASES[PHASES.index("unloaded") + 1]
    env.close()


def test_policy_replans_for_a_randomised_ditch_and_is_registered():
    env = gym.make(ENV_ID, ditch_width_range=(0.25, 0.45), ditch_depth_range=(0.08, 0.15))
    policy = analytical_factory(ENV_ID)(env)
    assert isinstance(policy, UpuGaitPolicy)
    for seed in (3, 4):
        policy.reset()  # before env.reset(): the policy must still plan for the new ditch
        obs, info = env.reset(seed=seed)
        policy(obs)
        assert policy.plan.ditch.width == info["ditch"]["width"]
        assert policy.plan.ditch.depth == info["ditch"]["depth"]
        assert policy.status == "ok"
    with pytest.raises(ValueError, match="HexapodDitchCrossing"):
        UpuGaitPolicy(gym.make("HexapodCliffWalk-v0"))
    env.close()


def test_policy_refuses_an_env_whose_strides_are_actions():
    env = gym.make("HexapodDitchCrossing-v1", stride_action=True)
    with pytest.raises(ValueError, match="stride_action=True takes the strides"):
        UpuGaitPolicy(env)
