"""experiments/ditch_reach/reach.py: the flat-ground gait whose landing legs reach until
contact plays the flat plan, and reaches only at a landing gate."""

import gymnasium as gym
import numpy as np

from experiments.ditch_reach.reach import ENV_ID, ReachingFlatGait


def test_the_reach_grows_only_while_a_landing_gate_waits_for_a_foot():
    env = gym.make(ENV_ID, task_distribution="train", action_mode="joint")
    policy = ReachingFlatGait(env, rate=0.02, freeze=False, preload=0.002)
    obs, _ = env.reset(seed=0)
    policy.reset()
    grew_at = []  # per reaching step: was it waiting at a landing ("down") gate?
    for _ in range(400):  # the flat plan's first platform steps, toward the ditch
        gate = policy.schedule.gate(policy.tick)
        before = policy.reach.copy()
        action = policy(obs)
        assert action.shape == (9,) and np.all(np.abs(action) <= 1)
        if np.any(policy.reach > before):
            grew_at.append(gate is not None and gate.state == "down")
        obs, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            break
    assert grew_at, "no landing met the ditch within 400 steps"
    assert all(grew_at) and np.max(policy.reach) <= 0.16 + 1e-9
