"""The ditch crossing's shaping terms for stride learners, both off by default: ``foothold`` (feet
landing near a ditch edge, measured) and ``landing`` (a decided stride's planned landings near
an edge, charged on the step that decides it)."""

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from agents.upu_stride import ClearStridePolicy
from hexapod_envs.robots.upu.params import PLATFORM_LEGS

STRIDE_ENV = dict(
    task_distribution="train", stride_action=True, residual_limb_m=0.0, residual_leg_m=0.0
)
ZERO = np.zeros(10, dtype=np.float32)


def _episode(env, policy, seed: int):
    """Run one episode; per step: the foothold term and the feet that landed with their x [m]."""
    return [(info["reward_foothold"], landed_x) for info, landed_x, _ in _steps(env, policy, seed)]


def _steps(env, policy, seed: int):
    """Run one episode; per step: the info, the x of the feet that landed [m] and the platform
    step decided by the step (None if none)."""
    base = env.unwrapped
    obs, _ = env.reset(seed=seed)
    loaded = base._loaded.copy()
    steps = []
    while True:
        decided = len(base.online_gait.steps)
        obs, _, terminated, truncated, info = env.step(policy(obs))
        landed = base._loaded & ~loaded
        loaded = base._loaded.copy()
        step = base.online_gait.steps[-1] if len(base.online_gait.steps) > decided else None
        steps.append((info, base.data.xpos[base._foot_body[landed], 0], step))
        if terminated or truncated:
            return steps


def _expected(base, feet_x: np.ndarray, weight: float) -> float:
    """The term from its definition: -weight x sum of clip(1 - gap / band, 0, 1)."""
    ditch = base.ditch
    gap = np.minimum(np.abs(feet_x - ditch.start_x), np.abs(feet_x - ditch.end_x))
    band = base.params.foot_radius + base.gait_settings.edge_clearance
    return -weight * float(np.clip(1.0 - gap / band, 0.0, 1.0).sum())


def test_foothold_term_is_zero_by_default():
    env = gym.make("HexapodDitchCrossing-v1", **STRIDE_ENV)
    steps = _episode(env, lambda obs: ZERO, seed=3)
    assert all(term == 0.0 for term, _ in steps)
    assert sum(len(x) for _, x in steps) > 0  # feet did land


def test_foothold_term_charges_each_landing_by_its_distance_to_an_edge():
    env = gym.make("HexapodDitchCrossing-v1", **STRIDE_ENV, foothold_weight=20.0)
    base = env.unwrapped
    steps = _episode(env, lambda obs: ZERO, seed=3)  # full strides: feet land at the edges
    for term, feet_x in steps:
        assert term == pytest.approx(_expected(base, feet_x, 20.0), abs=1e-9)
    charged = [term for term, _ in steps if term < 0.0]
    assert len(charged) >= 2
    # The stride rule lands its feet clear of the edges: it pays far less than full strides.
    rule = ClearStridePolicy(env)
    rule_total = sum(term for term, _ in _episode(env, rule, seed=3))
    assert rule_total > 0.2 * sum(charged)


def test_foothold_term_is_zero_on_flat_ground():
    env = gym.make("HexapodDitchCrossing-v1", **STRIDE_ENV, foothold_weight=20.0, terrain="flat")
    steps = _episode(env, lambda obs: ZERO, seed=0)
    assert all(term == 0.0 for term, _ in steps)
    assert sum(len(x) for _, x in steps) > 0  # feet did land


def _expected_landing(base, step, weight: float) -> float:
    """The landing term from its definition: -weight x sum over the moving feet of
    clip(1 - clear / band, 0, 1), clear the planned landing's distance to the nearer edge (this
    ditch is shallow enough to stand in)."""
    p, ditch = base.params, base.ditch
    assert ditch.depth <= p.leg_extend
    feet = step.end_x + np.array([p.foot_offset(leg)[0] for leg in PLATFORM_LEGS[step.moving]])
    gap = np.minimum(np.abs(feet - ditch.start_x), np.abs(feet - ditch.end_x))
    band = p.foot_radius + base.gait_settings.edge_clearance
    return -weight * float(np.clip(1.0 - gap / band, 0.0, 1.0).sum())


def test_landing_term_is_zero_by_default():
    env = gym.make("HexapodDitchCrossing-v1", **STRIDE_ENV)
    steps = _steps(env, lambda obs: ZERO, seed=3)
    assert all(info["reward_landing"] == 0.0 for info, _, _ in steps)
    assert sum(step is not None for _, _, step in steps) >= 10  # strides were decided


def test_landing_term_charges_each_decided_stride_by_its_planned_footholds():
    env = gym.make("HexapodDitchCrossing-v1", **STRIDE_ENV, landing_weight=20.0)
    base = env.unwrapped
    steps = _steps(env, lambda obs: ZERO, seed=3)  # full strides: some land at the edges
    for info, _, step in steps:
        expected = 0.0 if step is None else _expected_landing(base, step, 20.0)
        assert info["reward_landing"] == pytest.approx(expected, abs=1e-9)
    assert sum(info["reward_landing"] < 0.0 for info, _, _ in steps) >= 2
    # The clear-stride rule's strides land every foot at least the band from an edge.
    rule = ClearStridePolicy(env)
    rule_steps = _steps(env, rule, seed=3)
    assert all(info["reward_landing"] == 0.0 for info, _, _ in rule_steps)
    assert rule_steps[-1][0]["is_success"]


def test_landing_term_is_zero_on_flat_ground():
    env = gym.make("HexapodDitchCrossing-v1", **STRIDE_ENV, landing_weight=20.0, terrain="flat")
    steps = _steps(env, lambda obs: ZERO, seed=0)
    assert all(info["reward_landing"] == 0.0 for info, _, _ in steps)
