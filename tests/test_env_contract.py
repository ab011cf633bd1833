"""Invariants every registered hexapod env must satisfy (DESIGN.md §5 tier b)."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env
from stable_baselines3.common.env_checker import check_env as sb3_check_env

import hexapod_envs  # noqa: F401

ENV_IDS = sorted(k for k in gym.registry if k.startswith("Hexapod"))


def test_env_ids_registered():
    assert "HexapodCliffWalk-v0" in ENV_IDS


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_gymnasium_and_sb3_checkers_pass(env_id):
    env = gym.make(env_id)
    gym_check_env(env.unwrapped, skip_render_check=True)
    sb3_check_env(env.unwrapped, warn=True)
    env.close()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_same_seed_same_trajectory(env_id):
    def rollout():
        env = gym.make(env_id)
        obs, _ = env.reset(seed=123)
        env.action_space.seed(7)
        trace = [obs]
        for _ in range(40):
            obs, reward, *_ = env.step(env.action_space.sample())
            trace.append(np.append(obs, reward))
        env.close()
        return np.concatenate(trace)

    np.testing.assert_array_equal(rollout(), rollout())


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_observation_finite_in_space_and_reward_is_sum_of_terms(env_id):
    env = gym.make(env_id)
    obs, info = env.reset(seed=1)
    structure = env.unwrapped.observation_structure
    assert {"foot_force", "fasm_margin_deg", "joint_pos", "joint_vel"} <= set(structure)
    assert max(s.stop for s in structure.values()) == env.observation_space.shape[0]
    for _ in range(30):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert env.observation_space.contains(obs) and np.all(np.isfinite(obs))
        terms = {k: v for k, v in info.items() if k.startswith("reward_")}
        assert terms and reward == pytest.approx(sum(terms.values()))
        for key in ("fasm_margin_deg", "stance_legs", "is_tipping", "is_success"):
            assert key in info
        if terminated or truncated:
            break
    env.close()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_rgb_render_headless(env_id):
    env = gym.make(env_id, render_mode="rgb_array", width=96, height=64)
    env.reset(seed=0)
    frame = env.render()
    env.close()
    assert frame.shape == (64, 96, 3) and frame.std() > 0


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_docstring_tables_name_every_observation_piece_and_reward_term(env_id):
    """The user-facing docstring (module + class) must describe what the env really returns."""
    import inspect

    env = gym.make(env_id)
    base = env.unwrapped
    doc = (inspect.getmodule(type(base)).__doc__ or "") + (type(base).__doc__ or "")
    _, info = env.reset(seed=0)
    _, _, _, _, info = env.step(env.action_space.sample())
    missing = [name for name in base.observation_structure if name not in doc]
    missing += [k for k in info if k.startswith("reward_") and k[len("reward_") :] not in doc]
    env.close()
    assert not missing, f"{env_id} docstring does not mention {missing}"
