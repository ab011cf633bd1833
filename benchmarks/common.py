"""Shared timing helpers for the benchmark scripts (figures and ratios measured in one run)."""

from __future__ import annotations

import time

import gymnasium as gym
import mujoco
import numpy as np


def replay_step_rate(env: gym.Env, steps: int, seed: int = 0) -> tuple[float, float]:
    """(raw mj_step rate, env physics rate) over the same motion.

    The env runs `steps` zero actions from reset(seed); its controls are recorded and then
    replayed on a fresh copy of the model from the same start state with bare mj_step calls
    (one call per physics step), so both figures cover identical contact situations.
    """
    base = env.unwrapped
    substeps = getattr(base, "n_substeps", None) or getattr(base, "frame_skip", 1)
    zero = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)
    env.reset(seed=seed)
    start_state = mujoco.MjData(base.model)
    mujoco.mj_copyData(start_state, base.model, base.data)
    controls = np.empty((steps, base.model.nu))
    elapsed = 0.0
    for k in range(steps):
        t0 = time.perf_counter()
        _, _, terminated, truncated, _ = env.step(zero)
        elapsed += time.perf_counter() - t0
        controls[k] = base.data.ctrl
        if terminated or truncated:
            controls = controls[: k + 1]
            break
    n = len(controls)
    data = start_state
    t0 = time.perf_counter()
    for k in range(n):
        data.ctrl[:] = controls[k]
        for _ in range(substeps):
            mujoco.mj_step(base.model, data)
    raw = n * substeps / (time.perf_counter() - t0)
    return raw, n * substeps / elapsed


def env_vs_raw(env_id: str, steps: int = 3000, repeats: int = 3, **kwargs) -> tuple[float, float]:
    """Best of `repeats` (raw mj_step rate, env physics rate) for one env id (see replay)."""
    env = gym.make(env_id, **kwargs)
    runs = [replay_step_rate(env, steps) for _ in range(repeats)]
    env.close()
    return max(r[0] for r in runs), max(r[1] for r in runs)


def per_call_us(fn, *args, repeat: int = 20000) -> float:
    """Median time of fn(*args) in microseconds over batches of calls."""
    batches = []
    for _ in range(20):
        start = time.perf_counter()
        for _ in range(repeat // 20):
            fn(*args)
        batches.append((time.perf_counter() - start) / (repeat // 20))
    return float(np.median(batches) * 1e6)
