"""Shared timing helpers for the benchmark scripts (figures and ratios measured in one run)."""

from __future__ import annotations

import time
from typing import NamedTuple

import gymnasium as gym
import mujoco
import numpy as np

from hexapod_envs.envs.physics import step_sensing_last

ENV_RAW_TARGET = 0.92
"""Issue 14's target for env steps per wall second against bare `mj_step` over the same motion."""


def verdict(value: float, target: float) -> str:
    """'met' when `value` reaches `target` (a lower bound), else 'missed'."""
    return "met" if value >= target else "missed"


class ReplayRates(NamedTuple):
    """Physics steps per wall second over one motion (see `replay_step_rate`)."""

    raw: float
    """Bare `mj_step` calls with every sensor evaluated at every step (MuJoCo's default)."""
    raw_sensing_last: float
    """The same steps as the hexapod envs run them (`hexapod_envs.envs.physics.step_sensing_last`):
    the sensors evaluated only in the last step of a control period."""
    env: float
    """`env.step` with its substeps counted."""


def replay_step_rate(env: gym.Env, steps: int, seed: int = 0) -> ReplayRates:
    """Raw and env physics rates over the same motion.

    The env runs `steps` zero actions from reset(seed); its controls are recorded and then
    replayed twice on a copy of the start state with bare mj_step calls: one call per physics
    step with the sensors evaluated at every step (MuJoCo's default, the issues' "raw"), and
    as the env runs them (ATHENA's env senses five times per control period, the replay once),
    so all figures cover identical contact situations.
    """
    base = env.unwrapped
    substeps = _substeps(base)
    zero = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)
    env.reset(seed=seed)
    start_state = _copy(base.model, base.data)
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
    physics_steps = len(controls) * substeps
    raw = physics_steps / _replay_seconds(base, start_state, controls)
    sensing_last = physics_steps / _replay_seconds(base, start_state, controls, sensing_last=True)
    return ReplayRates(raw, sensing_last, physics_steps / elapsed)


def env_vs_raw(env_id: str, steps: int = 3000, repeats: int = 3, **kwargs) -> ReplayRates:
    """Best of `repeats` replays (`replay_step_rate`) of one env id, per figure."""
    env = gym.make(env_id, **kwargs)
    runs = [replay_step_rate(env, steps) for _ in range(repeats)]
    env.close()
    return ReplayRates(*map(max, zip(*runs, strict=True)))


def per_call_us(fn, *args, repeat: int = 20000) -> float:
    """Median time of fn(*args) in microseconds over batches of calls."""
    batches = []
    for _ in range(20):
        start = time.perf_counter()
        for _ in range(repeat // 20):
            fn(*args)
        batches.append((time.perf_counter() - start) / (repeat // 20))
    return float(np.median(batches) * 1e6)


def random_action_rates(env: gym.Env, steps: int, seed: int = 0) -> tuple[float, float]:
    """(env steps per second, the same steps' bare physics per second) with random actions.

    The physics figure replays each episode's controls from its start state as bare `mj_step`
    calls (`substeps` per env step), before the next reset can change the task's model: what
    the env's steps would cost if everything but MuJoCo's physics were free.
    """
    env.action_space.seed(seed)
    actions = [env.action_space.sample() for _ in range(steps)]
    env.reset(seed=seed)
    env.step(actions[0])  # loads the compiled kernels (start-up, not stepping)
    env.reset(seed=seed)
    base = env.unwrapped
    start_state, controls = _copy(base.model, base.data), []
    env_seconds = physics_seconds = 0.0
    for k, a in enumerate(actions):
        start = time.perf_counter()
        _, _, terminated, truncated, _ = env.step(a)
        env_seconds += time.perf_counter() - start
        controls.append(base.data.ctrl.copy())
        if terminated or truncated or k == steps - 1:
            physics_seconds += _replay_seconds(base, start_state, controls)
        if terminated or truncated:
            start = time.perf_counter()
            env.reset()
            env_seconds += time.perf_counter() - start
            start_state, controls = _copy(base.model, base.data), []
    return steps / env_seconds, steps / physics_seconds


def _copy(model: mujoco.MjModel, data: mujoco.MjData) -> mujoco.MjData:
    copy = mujoco.MjData(model)
    mujoco.mj_copyData(copy, model, data)
    return copy


def _substeps(base) -> int:
    """Physics steps per env step: the hexapod envs' `n_substeps`, Gymnasium's `frame_skip`."""
    return getattr(base, "n_substeps", None) or getattr(base, "frame_skip", 1)


def _replay_seconds(
    base, start_state: mujoco.MjData, controls, sensing_last: bool = False
) -> float:
    """Wall seconds of bare `mj_step` calls replaying `controls` (one row per env step) from
    `start_state`: every sensor at every step (MuJoCo's default, the issues' "raw"), or with
    `sensing_last` as the hexapod envs step (`step_sensing_last`)."""
    model, substeps = base.model, _substeps(base)
    data = _copy(model, start_state)
    start = time.perf_counter()
    for ctrl in controls:
        data.ctrl[:] = ctrl
        if sensing_last:
            step_sensing_last(model, data, substeps)
        else:
            for _ in range(substeps):
                mujoco.mj_step(model, data)
    return time.perf_counter() - start


STEP_PIECES = (
    "_validate_action",
    "_apply_action",
    "_simulate",
    "_measure",
    "_is_tipped_over",
    "_is_success",
    "_reward_terms",
    "_end_step",
    "_observation",
    "_info",
)
"""The hooks `HexapodEnv.step` calls, in order (`step_profile` times each)."""


def step_profile(env: gym.Env, steps: int, seed: int = 0) -> dict[str, float]:
    """Mean µs per env step of each of `STEP_PIECES`, timed inside a loop of `env.step` with
    random actions, and "rest": the step's own lines and the wrappers (the step's total minus
    the pieces).

    A piece timed alone runs on warm caches; inside the step it follows MuJoCo's physics, which
    has evicted them, and costs 2-6x as much: this is where the env's time per step goes. Each
    hook is wrapped on the env instance (two clock reads per call) and restored afterwards;
    only calls inside `env.step` count (not those of `reset`).
    """
    base = env.unwrapped
    totals = dict.fromkeys(STEP_PIECES, 0.0)
    inside = [False]

    def timed(name, method):
        def call(*args, **kwargs):
            start = time.perf_counter()
            try:
                return method(*args, **kwargs)
            finally:
                if inside[0]:
                    totals[name] += time.perf_counter() - start

        return call

    env.action_space.seed(seed)
    env.reset(seed=seed)
    for name in STEP_PIECES:
        setattr(base, name, timed(name, getattr(base, name)))
    stepping = 0.0
    try:
        for _ in range(steps):
            action = env.action_space.sample()
            inside[0] = True
            start = time.perf_counter()
            _, _, terminated, truncated, _ = env.step(action)
            stepping += time.perf_counter() - start
            inside[0] = False
            if terminated or truncated:
                env.reset()
    finally:
        for name in STEP_PIECES:
            delattr(base, name)
    profile = {name.lstrip("_"): total / steps * 1e6 for name, total in totals.items()}
    profile["rest"] = stepping / steps * 1e6 - sum(profile.values())
    return profile


def print_step_profile(env_id: str, steps: int = 2000, **kwargs) -> None:
    """One line of `step_profile` for `env_id`: µs per step of the physics (`simulate`) and of
    everything else, piece by piece."""
    with gym.make(env_id, **kwargs) as env:
        profile = step_profile(env, steps)
    physics = profile.pop("simulate")
    pieces = ", ".join(f"{name} {us:.1f}" for name, us in profile.items())
    print(
        f"{env_id} step in the loop, µs per step: physics (simulate) {physics:.1f}; the rest "
        f"{sum(profile.values()):.1f} = {pieces}"
    )
