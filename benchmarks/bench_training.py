"""PPO training throughput: env steps per second including PPO updates, HexapodCliffWalk-v0 beside
Gymnasium's Ant-v5 with the same PPO settings, 1 and 2 subprocess envs, measured in one run.

Settings: the policy network and PPO hyperparameters of configs/cliff_walk_ppo.yaml with
``n_steps`` per env set so that every run collects the same number of rollouts' worth of steps
(`--steps` in total, default 4096), VecNormalize on, Monitor wrappers as in train.py. The timer
covers ``model.learn`` only (worker start-up excluded: the workers are reset and stepped once
before it, which loads the hexapod's compiled kernels). A row "env only" gives the bare
single-process stepping rate with random actions for context, a row "physics only" the bare
`mj_step` rate of the same steps (the controls replayed), and the last line the 1-env PPO rate
the hexapod would reach if its env cost nothing but that physics: the ceiling of the ratio at
the env's physics step.

Run: python benchmarks/bench_training.py [--steps 4096] [--n-steps 512]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run as a script from anywhere

from agents.pipeline.envs import EnvSpec, make_vec_env  # noqa: E402
from agents.run_files.train_config import load_train_config  # noqa: E402
from benchmarks.common import random_action_rates, verdict  # noqa: E402

ENVS = {
    "HexapodCliffWalk-v0": EnvSpec("HexapodCliffWalk-v0", gym_packages=["hexapod_envs"]),
    "Ant-v5": EnvSpec("Ant-v5"),
}

PPO_RATIO_TARGET = 1.0
"""Issue 14's target for PPO steps per second, hexapod against Ant-v5."""


def ppo_rate(spec: EnvSpec, n_envs: int, steps: int, n_steps: int, seed: int = 0) -> float:
    """Env steps per second of PPO.learn over `steps` steps with `n_envs` subprocess envs."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    config = load_train_config(ROOT / "configs" / "cliff_walk_ppo.yaml")
    ppo = config.ppo.sb3_kwargs()
    ppo["n_steps"] = max(n_steps // n_envs, 1)
    ppo["batch_size"] = min(ppo["batch_size"], ppo["n_steps"] * n_envs)
    venv = VecNormalize(make_vec_env(spec, n_envs, seed, subprocess=True), gamma=ppo["gamma"])
    model = PPO("MlpPolicy", venv, policy_kwargs=config.policy.policy_kwargs(), seed=seed, **ppo)
    _warm_up(venv)
    start = time.perf_counter()
    model.learn(steps)
    elapsed = time.perf_counter() - start
    done = model.num_timesteps
    venv.close()
    return done / elapsed


def _warm_up(venv) -> None:
    """Reset and step the workers once before the timer starts: a worker's first steps load
    its compiled kernels (about 0.4 s per process for the hexapod envs), which is start-up,
    not training. `model.learn` resets the envs again."""
    venv.reset()
    venv.step(np.array([venv.action_space.sample() for _ in range(venv.num_envs)]))


def env_only_rate(spec: EnvSpec, steps: int, seed: int = 0) -> tuple[float, float]:
    """(env steps per second, bare physics steps per second) of `random_action_rates`."""
    env = spec.make()
    try:
        return random_action_rates(env, steps, seed)
    finally:
        env.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=4096, help="env steps per measurement")
    parser.add_argument("--n-steps", type=int, default=512, help="rollout size (all envs)")
    args = parser.parse_args()

    rates: dict[tuple[str, str], float] = {}
    physics: dict[str, float] = {}
    for name, spec in ENVS.items():
        rates[(name, "env only")], physics[name] = env_only_rate(spec, args.steps)
        for n in (1, 2):
            rates[(name, f"PPO, {n} subproc")] = ppo_rate(spec, n, args.steps, args.n_steps)
            print(f"measured {name} with {n} env(s)", file=sys.stderr)

    settings = [key for key in rates if key[0] == "Ant-v5"]
    print(
        f"\n{args.steps} env steps per row; rollout {args.n_steps} steps over all envs; "
        "PPO settings of configs/cliff_walk_ppo.yaml"
    )
    print(f"{'setting':18s} {'Hexapod steps/s':>16s} {'Ant-v5 steps/s':>15s} {'hexapod/ant':>12s}")
    for _, setting in settings:
        hexapod, ant = rates[("HexapodCliffWalk-v0", setting)], rates[("Ant-v5", setting)]
        print(f"{setting:18s} {hexapod:16.0f} {ant:15.0f} {hexapod / ant:12.2f}")
    print(
        f"{'physics only':18s} {physics['HexapodCliffWalk-v0']:16.0f} {physics['Ant-v5']:15.0f}"
        f" {physics['HexapodCliffWalk-v0'] / rates[('Ant-v5', 'env only')]:12.2f}"
        "  (bare mj_step of the same steps; the ratio against Ant-v5's env)"
    )
    one = rates[("HexapodCliffWalk-v0", "PPO, 1 subproc")]
    two = rates[("HexapodCliffWalk-v0", "PPO, 2 subproc")]
    # With one env, PPO runs the env's step and its own work in turn: 1/one = env step + rest.
    # Were the hexapod env's step its bare physics and nothing else, PPO would reach `bound`.
    rest = 1 / one - 1 / rates[("HexapodCliffWalk-v0", "env only")]
    bound = 1 / (rest + 1 / physics["HexapodCliffWalk-v0"])
    ant_one = rates[("Ant-v5", "PPO, 1 subproc")]
    print(
        f"PPO, 1 subproc, if the hexapod env cost only its bare physics: {bound:.0f} steps/s, "
        f"hexapod/ant {bound / ant_one:.2f} (the ceiling of the 1-env ratio at this physics step)"
    )
    ratios = [one / ant_one, two / rates[("Ant-v5", "PPO, 2 subproc")]]
    print(
        f"issue 14's target: hexapod/ant >= {PPO_RATIO_TARGET} with 1 and with 2 envs: "
        f"{verdict(min(ratios), PPO_RATIO_TARGET)}"
    )
    cores = len(os.sched_getaffinity(0))
    print(f"Hexapod 2-env / 1-env speed-up: {two / one:.2f} ({cores} usable cores, shared)")


if __name__ == "__main__":
    main()
