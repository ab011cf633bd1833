"""A difficulty curriculum for the sampled tasks (``task_distribution="train"``).

Legged-robot RL commonly starts on easy terrain and raises the difficulty as the policy
succeeds (e.g. Rudin et al. 2022's terrain curriculum). `DifficultyCurriculum` does this with
the difficulty every env reports in ``info["task"]["difficulty"]`` (0 easy, 1 hard): at each
reset it draws tasks until one is at most the current `level` (rejection sampling through the
env's own ``np_random``, so a seeded run stays reproducible), and after every `window` episodes
it raises the level by `step` when the success rate of those episodes reached `promote_at`
(and lowers it by `step` below `demote_at`).

    env = DifficultyCurriculum(gym.make("HexapodCliffWalk-v1", task_distribution="train"))

`MinimumDifficulty` keeps the hard part of a distribution instead (tasks at least `minimum`):
for a learner whose settings only matter on hard tasks, such as ATHENA's body height, which pays
on tall block beds, so that its episodes carry a signal.
"""

from __future__ import annotations

import warnings

import gymnasium as gym

from .checks import check_number


class DifficultyCurriculum(gym.Wrapper):
    """Tasks no harder than `level`, raised with success (see the module docstring).

    Args:
        env: a hexapod env with ``task_distribution="train"`` (or "test").
        level: the first difficulty cap in [0, 1].
        step: how much the cap moves at a promotion or demotion.
        window: episodes per decision.
        promote_at: success rate of a window that raises the cap.
        demote_at: success rate below which the cap is lowered (0: never).
        max_draws: tasks drawn at most per reset; the last one is kept if none is under the
            cap (the env's ranges may hold no task that easy).
    """

    def __init__(
        self,
        env: gym.Env,
        level: float = 0.3,
        step: float = 0.1,
        window: int = 20,
        promote_at: float = 0.8,
        demote_at: float = 0.0,
        max_draws: int = 50,
    ):
        super().__init__(env)
        _require_sampled(env, type(self).__name__)
        check_number("level", level, high=1.0)
        check_number("step", step, high=1.0)
        if not 0.0 <= check_number("demote_at", demote_at) < promote_at <= 1.0:
            raise ValueError(
                f"need 0 <= demote_at < promote_at <= 1, got {demote_at!r}, {promote_at!r}"
            )
        if int(window) < 1 or int(max_draws) < 1:
            raise ValueError(f"window and max_draws must be >= 1, got {window!r}, {max_draws!r}")
        self.level, self.level_step = float(level), float(step)
        self.window, self.max_draws = int(window), int(max_draws)
        self.promote_at, self.demote_at = float(promote_at), float(demote_at)
        self._results: list[bool] = []
        self.warned = False
        """Whether a reset has warned that no draw met the level (said once)."""

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        obs, info = _draw(
            self, seed, options, self.max_draws, lambda d: d <= self.level, f"<= {self.level:g}"
        )
        return obs, {**info, "curriculum_level": self.level}

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        if terminated or truncated:
            self._record(bool(info.get("is_success")))
        return obs, reward, terminated, truncated, {**info, "curriculum_level": self.level}

    def _record(self, success: bool) -> None:
        self._results.append(success)
        if len(self._results) < self.window:
            return
        rate = sum(self._results) / len(self._results)
        if rate >= self.promote_at:
            self.level = min(1.0, self.level + self.level_step)
        elif rate < self.demote_at:
            self.level = max(0.0, self.level - self.level_step)
        self._results.clear()


class MinimumDifficulty(gym.Wrapper):
    """Tasks of difficulty at least `minimum` (see the module docstring): each reset draws tasks
    (through the env's own ``np_random``) until one is; after `max_draws` the last one is kept.
    ``info["task_draws"]`` counts the draws of the reset."""

    def __init__(self, env: gym.Env, minimum: float, max_draws: int = 100):
        super().__init__(env)
        _require_sampled(env, type(self).__name__)
        self.minimum = check_number("minimum", minimum, high=1.0)
        if int(max_draws) < 1:
            raise ValueError(f"max_draws must be >= 1, got {max_draws!r}")
        self.max_draws = int(max_draws)
        self.warned = False
        """Whether a reset has warned that no draw met the minimum (said once)."""

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        return _draw(
            self, seed, options, self.max_draws, lambda d: d >= self.minimum, f">= {self.minimum:g}"
        )


def _require_sampled(env: gym.Env, wrapper: str) -> None:
    if getattr(env.unwrapped, "task_distribution", None) == "paper":
        raise ValueError(
            f"{wrapper} draws sampled tasks: make the env with "
            'task_distribution="train" (or "test"), not "paper"'
        )


def _draw(wrapper: gym.Wrapper, seed, options, max_draws: int, accept, wanted: str) -> tuple:
    """Reset `env` (with `seed`, then from its ``np_random``) until ``accept(difficulty)`` or
    `max_draws` resets; the last reset's result with ``info["task_draws"]``, and
    ``info["task_accepted"]`` False (with a warning, once per wrapper) when no draw passed."""
    env = wrapper.env
    obs, info = env.reset(seed=seed, options=options)
    draws = 1
    while draws < max_draws and not accept(info["task"]["difficulty"]):
        obs, info = env.reset(options=options)  # the next task from np_random
        draws += 1
    accepted = bool(accept(info["task"]["difficulty"]))
    if not accepted and not wrapper.warned:
        wrapper.warned = True
        warnings.warn(
            f"{type(wrapper).__name__}: none of {draws} tasks drawn had a difficulty {wanted}; "
            f"the reset keeps the last (difficulty {info['task']['difficulty']:.2f}, "
            'info["task_accepted"] False). Raise max_draws, or the cap, if the ranges hold '
            "few such tasks (said once)",
            stacklevel=3,
        )
    return obs, {**info, "task_draws": draws, "task_accepted": accepted}
