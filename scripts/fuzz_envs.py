"""Fuzz every env x action mode x task distribution with uniform random, bang-bang and bound
actions; count exceptions, non-finite observations/rewards and unstable steps.

Not a CI test (it takes minutes): run it by hand after changing an env, e.g.
    PYTHONPATH=$PWD nice -n 10 python scripts/fuzz_envs.py --steps 20000
    python scripts/fuzz_envs.py --envs HexapodCliffWalk-v1 HexapodStewartTilt-v1 \
        HexapodIrregularTerrain-v1 HexapodDitchCrossing-v1 --distributions train test \
        --steps 55600   # the v1 benchmark's 1 M steps
Prints one line per combination and a total; exits 1 if any exception or non-finite value.
"""

from __future__ import annotations

import argparse
import sys
import time
import traceback

import gymnasium as gym
import numpy as np

import hexapod_envs  # noqa: F401

ACTION_MODES = {
    "HexapodCliffWalk-v0": ("joint", "residual"),
    "HexapodStewartTilt-v0": ("joint", "residual"),
    "HexapodIrregularTerrain-v0": ("residual", "joint", "gains"),
    "HexapodDitchCrossing-v0": ("residual", "joint"),
}
ACTION_MODES.update({env_id.replace("-v0", "-v1"): m for env_id, m in ACTION_MODES.items()})
DISTRIBUTIONS = ("paper", "train", "test")


def actions(space, rng: np.random.Generator, step: int) -> np.ndarray:
    """Uniform random, bang-bang (each entry at a bound) and all-at-one-bound in turns."""
    kind = (step // 50) % 3
    if kind == 0:
        return rng.uniform(space.low, space.high)
    if kind == 1:
        return np.where(rng.random(space.shape) < 0.5, space.low, space.high)
    return space.high.copy() if (step // 150) % 2 else space.low.copy()


def fuzz(env_id: str, mode: str, dist: str, steps: int, seed: int) -> dict:
    env = gym.make(env_id, action_mode=mode, task_distribution=dist)
    rng = np.random.default_rng(seed)
    counts = dict(steps=0, episodes=0, exceptions=0, nonfinite=0, unstable=0, tipped=0)
    episode = 0
    obs, _ = env.reset(seed=seed)
    while counts["steps"] < steps:
        try:
            obs, reward, terminated, truncated, info = env.step(
                actions(env.action_space, rng, counts["steps"])
            )
        except Exception:  # noqa: BLE001 - counted and printed, the fuzz goes on
            counts["exceptions"] += 1
            traceback.print_exc()
            terminated = truncated = True
            info, reward = {}, 0.0
        counts["steps"] += 1
        if not (np.all(np.isfinite(obs)) and np.isfinite(reward)):
            counts["nonfinite"] += 1
        counts["unstable"] += bool(info.get("sim_unstable"))
        if terminated or truncated:
            counts["tipped"] += bool(info.get("is_tipped_over"))
            counts["episodes"] += 1
            episode += 1
            obs, _ = env.reset(seed=seed + episode)
    env.close()
    return counts


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=20000, help="steps per combination")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--envs", nargs="*", default=list(ACTION_MODES), choices=ACTION_MODES)
    parser.add_argument("--distributions", nargs="*", default=DISTRIBUTIONS, choices=DISTRIBUTIONS)
    args = parser.parse_args()
    total = dict(steps=0, exceptions=0, nonfinite=0, unstable=0)
    for env_id in args.envs:
        for mode in ACTION_MODES[env_id]:
            for dist in args.distributions:
                t0 = time.perf_counter()
                c = fuzz(env_id, mode, dist, args.steps, args.seed)
                dt = time.perf_counter() - t0
                print(f"{env_id} {mode:8s} {dist:5s} {c} {c['steps'] / dt:.0f} steps/s", flush=True)
                for k in total:
                    total[k] += c[k]
    print("total", total, flush=True)
    return 1 if total["exceptions"] or total["nonfinite"] else 0


if __name__ == "__main__":
    sys.exit(main())
