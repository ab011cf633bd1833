"""Does a benchmark task need feedback? The baselines a ``-v1`` task must defeat, measured.

On the benchmark's test tasks (`hexapod_envs.benchmark.BENCHMARK_SEEDS`) of one env id this runs
the analytical controller, the zero action (the paper's motion without feedback), uniformly
random actions, an open-loop replay of the controller's actions (each task gets the sequence the
controller produced on the next task) and a search over constant actions (fixed action vectors:
every entry at one bound, the mean of the analytical controller's actions, and seeded random
vectors), and reports per policy the success rate, tip-overs, the median of the episodes'
largest tilt and of their share of time tipping, and the mean return (the env's reward summed
over the episode: a reward that ranks policies as success does gives the analytical controller
the highest). docs/benchmark.md states the targets: the analytical controller succeeds on
40-85 % of the test tasks, the zero action on at most 40 %, random actions on at most 10 %, and
neither the open-loop replay nor any constant action reaches the analytical controller.

`scripts/benchmark_headroom.py` prints the table for every ``-v1`` env; the tests run it on a few
tasks.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

import gymnasium as gym
import numpy as np

from hexapod_envs import info_keys as keys

from ..policy import Policy, RandomPolicy, ZeroPolicy, episode_infos
from ..registry import ANALYTICAL_ENV_KWARGS, analytical_factory


@dataclass(frozen=True)
class Episode:
    """One episode's outcome and safety figures."""

    seed: int
    success: bool
    tipped_over: bool
    max_tilt_deg: float
    tipping_share: float
    difficulty: float
    episode_return: float
    """The env's reward summed over the episode."""


@dataclass
class Baseline:
    """One policy's episodes on the tasks."""

    name: str
    episodes: list[Episode] = field(default_factory=list)

    @property
    def success_rate(self) -> float:
        return float(np.mean([e.success for e in self.episodes]))

    @property
    def tip_over_rate(self) -> float:
        return float(np.mean([e.tipped_over for e in self.episodes]))

    @property
    def mean_return(self) -> float:
        return float(np.mean([e.episode_return for e in self.episodes]))

    def median(self, figure: str) -> float:
        return float(np.median([getattr(e, figure) for e in self.episodes]))


class ConstantPolicy:
    """Always the same action vector."""

    def __init__(self, action: np.ndarray):
        self.action = np.asarray(action, dtype=np.float32)

    def reset(self) -> None:
        pass

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        return self.action.copy()


class _Recording:
    """A policy that keeps the actions it returns, one list per episode (for the mean action
    and the open-loop replay)."""

    def __init__(self, policy: Policy):
        self.policy, self.episodes = policy, []

    def reset(self) -> None:
        self.policy.reset()
        self.episodes.append([])

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        action = self.policy(observation)
        self.episodes[-1].append(np.asarray(action))
        return action


class ReplayPolicy:
    """Open loop: episode k replays the recorded action sequence k, holding its last action
    once the sequence runs out."""

    def __init__(self, sequences: list[list[np.ndarray]]):
        self.sequences, self._episode, self._step = sequences, -1, 0

    def reset(self) -> None:
        self._episode, self._step = self._episode + 1, 0

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        actions = self.sequences[self._episode % len(self.sequences)]
        action = actions[min(self._step, len(actions) - 1)]
        self._step += 1
        return action.copy()


def run_baseline(
    env_id: str,
    name: str,
    make_policy: Callable[[gym.Env], Policy],
    seeds: Iterable[int],
    env_kwargs: dict | None = None,
    distribution: str = "test",
) -> Baseline:
    """Episodes of `make_policy(env)` from ``reset(seed=s)`` for s in `seeds`."""
    env = gym.make(env_id, task_distribution=distribution, **(env_kwargs or {}))
    env = gym.wrappers.RecordEpisodeStatistics(env)  # the return, in the last info's "episode"
    policy, result = make_policy(env), Baseline(name)
    try:
        for seed in seeds:
            if isinstance(policy, RandomPolicy):
                policy.seed = int(seed)
            info = episode_infos(env, policy, seed=int(seed))[-1]
            result.episodes.append(
                Episode(
                    seed=int(seed),
                    success=bool(info[keys.IS_SUCCESS]),
                    tipped_over=bool(info[keys.IS_TIPPED_OVER]),
                    max_tilt_deg=float(info[keys.MAX_TILT_DEG]),
                    tipping_share=float(info[keys.TIPPING_SHARE]),
                    difficulty=float(info[keys.TASK].get("difficulty", np.nan)),
                    episode_return=float(info["episode"]["r"]),
                )
            )
    finally:
        env.close()
    return result


def constant_actions(shape: tuple[int, ...], mean_analytical: np.ndarray | None, n_random: int):
    """The constant actions searched: every entry at -1, at +1, the mean of the analytical
    controller's actions (if given, in the env's default action mode) and `n_random` seeded
    uniform vectors; name -> action."""
    candidates = {"all -1": -np.ones(shape), "all +1": np.ones(shape)}
    if mean_analytical is not None:
        candidates["analytical mean"] = np.clip(mean_analytical, -1.0, 1.0)
    rng = np.random.default_rng(0)
    for k in range(n_random):
        candidates[f"uniform #{k}"] = rng.uniform(-1.0, 1.0, shape)
    return candidates


def headroom(env_id: str, seeds: Iterable[int], n_random_constants: int = 4) -> list[Baseline]:
    """The analytical controller, zero, random, the open-loop replay of the controller's actions
    (each task gets the action sequence the controller produced on the next one) and the best
    constant action on `seeds` (test tasks) of `env_id`; the best constant is named
    ``constant (<which>)``."""
    seeds = list(seeds)
    recorder: list[_Recording] = []

    def analytical(env: gym.Env) -> Policy:
        recorder.append(_Recording(analytical_factory(env_id)(env)))
        return recorder[-1]

    reference_kwargs = ANALYTICAL_ENV_KWARGS.get(env_id, {})
    rows = [run_baseline(env_id, "analytical", analytical, seeds, reference_kwargs)]
    rows.append(run_baseline(env_id, "zero", lambda env: ZeroPolicy(env.action_space), seeds))
    rows.append(run_baseline(env_id, "random", lambda env: RandomPolicy(env.action_space), seeds))
    # Open loop: on each task, the actions the controller took on the next task (in its mode).
    recorded = recorder[0].episodes
    shifted = recorded[1:] + recorded[:1]
    replay = run_baseline(
        env_id, "open-loop replay", lambda env: ReplayPolicy(shifted), seeds, reference_kwargs
    )
    rows.append(replay)
    # The analytical controller's mean action is a constant action only in the mode it runs in.
    same_mode = not reference_kwargs.get("action_mode")
    mean = np.mean([a for ep in recorded for a in ep], axis=0) if same_mode else None
    env = gym.make(env_id)
    shape = env.action_space.shape  # the default action mode's
    env.close()
    best = None
    for which, action in constant_actions(shape, mean, n_random_constants).items():
        row = run_baseline(env_id, f"constant ({which})", _constant(action), seeds)
        if best is None or row.success_rate > best.success_rate:
            best = row
    rows.append(best)
    return rows


def _constant(action: np.ndarray) -> Callable[[gym.Env], Policy]:
    return lambda env: ConstantPolicy(action)


def format_table(env_id: str, rows: list[Baseline]) -> str:
    """A Markdown table: policy, success, tip-overs, median max tilt, median share tipping, mean
    return."""
    lines = [
        f"### {env_id} ({len(rows[0].episodes)} test tasks)",
        "",
        "| policy | success | tip-over | max tilt, median [deg] | time tipping, median "
        "| return, mean |",
        "|---|---|---|---|---|---|",
    ]
    for row in rows:
        lines.append(
            f"| {row.name} | {row.success_rate:.0%} | {row.tip_over_rate:.0%} | "
            f"{row.median('max_tilt_deg'):.1f} | {row.median('tipping_share'):.0%} | "
            f"{row.mean_return:.0f} |"
        )
    return "\n".join(lines)
