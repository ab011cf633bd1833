"""The ditch crossing's ``foothold`` reward term: feet landing near a ditch edge, off by default."""

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from agents.upu_stride import ClearStridePolicy

STRIDE_ENV = dict(
    task_distribution="train", stride_action=True, residual_limb_m=0.0, residual_leg_m=0.0
)
ZERO = np.zeros(10, dtype=np.float32)


def _episode(env, policy, seed: int):
    """Run one episode; per step: the foothold term and the feet that landed with their x [m]."""
    base = env.unwrapped
    obs, _ = env.reset(seed=seed)
    loaded = base._loaded.copy()
    steps = []
    while True:
        obs, _, terminated, truncated, info = env.step(policy(obs))
        landed = base._loaded & ~loaded
        loaded = base._loaded.copy()
        steps.append((info["reward_foothold"], base.data.xpos[base._foot_body[landed], 0]))
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
