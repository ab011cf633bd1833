"""The heavy-duty robot's envs (HexapodCliffWalk-v0, HexapodStewartTilt-v0): raw mj_step rate vs
the env's rate with substeps counted, and FASM.

Targets: env/raw >= 0.92 on every env (issue 14; Gymnasium's Ant-v5 is measured alongside for
context), FASM <= 5 / 8 us per call (3 / 6 feet). The same rates in simulated seconds per wall
second (x the model's timestep) show what the raw physics alone reaches at the robot's step;
issue 14's target for the cliff (>= 100 with random actions) is judged on a run with random
actions (env and its bare physics, `common.random_action_rates`); each env's step is profiled
piece by piece inside the loop (`common.step_profile`). ``--solver-options`` adds raw rates
under MuJoCo's other solver options (is any of them a factor of 2?). Run:
python benchmarks/bench_cliff_walk.py [--solver-options]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run as a script from anywhere

import hexapod_envs  # noqa: F401
from benchmarks.common import (
    ENV_RAW_TARGET,
    env_vs_raw,
    per_call_us,
    print_step_profile,
    random_action_rates,
    verdict,
)
from hexapod_envs.stability import fasm

SIM_RATE_TARGET = 100.0
"""Issue 14's target for the cliff walk: simulated seconds per wall second."""


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--solver-options", action="store_true", help="raw rate per solver option")
    args = parser.parse_args(argv)
    rows = (
        ("HexapodCliffWalk-v0", "HexapodCliffWalk-v0"),
        ("HexapodStewartTilt-v0", "HexapodStewartTilt-v0"),
        ("Ant-v5 (Gymnasium)", "Ant-v5"),
    )
    print(
        f"{'env':24s} {'raw mj_step/s':>14s} {'sensing last':>13s} {'env physics steps/s':>20s} "
        f"{'env/raw':>8s} {'env/sensing last':>17s} {'sim s per wall s: raw':>22s} {'env':>6s}"
    )
    env_raw = {}
    for name, env_id in rows:
        try:
            rates = env_vs_raw(env_id)
        except Exception as exc:  # pragma: no cover - Ant needs gymnasium's mujoco extras
            if env_id != "Ant-v5":
                raise
            print(f"{name} not measured: {exc}")
            continue
        dt = _timestep(env_id)
        if env_id != "Ant-v5":
            env_raw[env_id] = rates.env / rates.raw
        print(
            f"{name:24s} {rates.raw:14.0f} {rates.raw_sensing_last:13.0f} {rates.env:20.0f} "
            f"{rates.env / rates.raw:8.2f} {rates.env / rates.raw_sensing_last:17.2f} "
            f"{rates.raw * dt:22.1f} {rates.env * dt:6.1f}"
        )
    print(
        "raw: bare mj_step calls, sensors at every step; sensing last: the env's way of "
        "stepping (sensors only in a control period's last step), without the env"
    )
    with gym.make("HexapodCliffWalk-v0") as env:
        control_dt = env.unwrapped.control_dt
        steps, physics = random_action_rates(env, 3000)
    sim_rate, physics_rate = steps * control_dt, physics * control_dt
    print(
        f"random actions, 3000 steps: env {sim_rate:.1f}, bare physics {physics_rate:.1f} "
        "simulated s per wall s"
    )
    ratios = ", ".join(
        f"{env_id} {value:.3f}: {verdict(value, ENV_RAW_TARGET)}"
        for env_id, value in env_raw.items()
    )
    print(
        f"issue 14's targets: the cliff >= {SIM_RATE_TARGET:.0f} simulated s per wall s with "
        f"random actions ({sim_rate:.1f}: {verdict(sim_rate, SIM_RATE_TARGET)}); env/raw >= "
        f"{ENV_RAW_TARGET} ({ratios})"
    )

    for env_id in env_raw:
        print_step_profile(env_id)

    tripod = np.array([[2.4, 1.9, -1.75], [-2.4, 1.9, -1.75], [0.0, -1.9, -1.75]])
    six = np.array([[x, y, -1.75] for y in (1.9, -1.9) for x in (2.4, 0.0, -2.4)])
    cog, weight = np.zeros(3), np.array([0.0, 0.0, -5000 * 9.81])
    moment = np.array([100.0, -50.0, 0.0])
    print(f"FASM, 3 feet: {per_call_us(fasm, tripod, cog, weight, moment):6.1f} us per call")
    print(f"FASM, 6 feet: {per_call_us(fasm, six, cog, weight, moment):6.1f} us per call")
    if args.solver_options:
        solver_options()


def solver_options(steps: int = 4000, repeats: int = 3) -> None:
    """Raw mj_step/s of the cliff walk's model from a standing state (after 50 zero-action env
    steps), best of `repeats` rounds over all options, per MuJoCo solver option (one option
    changed at a time)."""
    import gymnasium as gym
    import mujoco

    env = gym.make("HexapodCliffWalk-v0")
    env.reset(seed=0)
    for _ in range(50):
        env.step(np.zeros(env.action_space.shape))
    model, data = env.unwrapped.model, env.unwrapped.data
    kind = mujoco.mjtState.mjSTATE_INTEGRATION
    start = np.empty(mujoco.mj_stateSize(model, kind))
    mujoco.mj_getState(model, data, start, kind)
    opt, off = model.opt, mujoco.mjtDisableBit
    options = {
        "default": {},
        "solver CG": {"solver": mujoco.mjtSolver.mjSOL_CG},
        "solver PGS": {"solver": mujoco.mjtSolver.mjSOL_PGS},
        "pyramidal cone": {"cone": mujoco.mjtCone.mjCONE_PYRAMIDAL},
        "dense Jacobian": {"jacobian": mujoco.mjtJacobian.mjJAC_DENSE},
        "sparse Jacobian": {"jacobian": mujoco.mjtJacobian.mjJAC_SPARSE},
        "no midphase": {"disableflags": opt.disableflags | off.mjDSBL_MIDPHASE},
        "no warm start": {"disableflags": opt.disableflags | off.mjDSBL_WARMSTART},
        "default, again": {},  # the spread of the timing itself
    }
    default = {name: getattr(opt, name) for change in options.values() for name in change}
    for _ in range(steps):  # warm up: the first timed loop ran 15 % slow without this
        mujoco.mj_step(model, data)
    best = dict.fromkeys(options, 0.0)
    for _ in range(repeats):  # rounds over all options, so that drifts of the machine spread
        for label, change in options.items():
            for name, value in {**default, **change}.items():
                setattr(opt, name, value)
            mujoco.mj_setState(model, data, start, kind)
            t0 = time.perf_counter()
            for _ in range(steps):
                mujoco.mj_step(model, data)
            best[label] = max(best[label], steps / (time.perf_counter() - t0))
    print(f"{'solver option':18s} {'raw mj_step/s':>14s} {'x default':>10s}")
    for label, rate in best.items():
        print(f"{label:18s} {rate:14.0f} {rate / best['default']:10.2f}")
    env.close()


def _timestep(env_id: str) -> float:
    """The env's MuJoCo timestep [s]."""
    with gym.make(env_id) as env:
        return float(env.unwrapped.model.opt.timestep)


if __name__ == "__main__":
    main()
