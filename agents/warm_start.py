"""A warm start for PPO: behaviour cloning of a teacher into the actor before PPO (kick-starting).

PPO from a zero-initialised actor starts at the zero action; where that fails and the useful
actions are rare (the ditch's strides: a few decisions an episode, each needing a stride that
keeps every foot its radius plus 20 mm from an edge), exploration may never find them in the
budget. A warm start copies a teacher first: the teacher drives ``episodes`` tasks of the
training distribution (seeded apart from training and evaluation), every (observation, action)
is kept, and the actor's mean is fitted to the teacher's actions by mean squared error, through
the observation normalisation PPO starts with (the VecNormalize statistics start from the
labelled observations; PPO's rollouts then keep updating them, so the clone's inputs drift as
training goes on, even while the actor is unchanged). The log standard deviation and the critic
are left as configured; PPO starts from the clone, and its step-0 evaluation is the clone's.

An action value that the env reads only on some steps (`HexapodEnv.action_read_flags`, such as
the ditch's stride) is fitted on those steps only; each action value's error is averaged over
its own steps, so a value read on 1 step of 51 weighs as much as one read on every step.

Teachers (``warm_start.teacher``): ``analytical``, the env's registered controller
(`agents.registry`) on the env as configured (in a residual action mode a controller's
commands beyond the residual's range are clipped, see `agents.registry.ANALYTICAL_ENV_KWARGS`;
in DAgger rounds a controller with a gait clock or a plan labels states it did not drive
into); ``clear_stride``, the ditch's stride rule (`agents.upu_stride.ClearStridePolicy`), a
function of the observation. A config turns it on with a ``warm_start`` section
(docs/training.md).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np

from .registry import load_factory

TEACHERS: dict[str, str] = {
    "analytical": "agents.registry:analytical_policy",
    "clear_stride": "agents.upu_stride:ClearStridePolicy",
}
"""Teacher name -> ``module:factory`` taking the env and returning a `Policy`."""

SEED_OFFSET = 20_000
"""The teacher's tasks are seeded from the training seed plus this, apart from training's and
evaluation's (`agents.pipeline.training.EVAL_SEED_OFFSET`)."""


@dataclasses.dataclass
class WarmStartSettings:
    """How a run is warm-started: which teacher, how many of its episodes, how long a fit."""

    teacher: str = "analytical"
    episodes: int = 40
    """Teacher episodes on the training distribution (each a fresh task)."""
    epochs: int = 100
    """Passes over the teacher's (observation, action) pairs."""
    learning_rate: float = 1e-3
    """Adam's step size for the actor."""
    batch_size: int = 256
    dagger_rounds: int = 0
    """Rounds of DAgger (Ross et al. 2011) after the first fit: the clone drives ``episodes``
    fresh tasks, the teacher labels every step, and the actor is fitted again on all pairs."""
    critic_steps: int = 0
    """PPO's first env steps that update the critic only (`agents.pipeline.callbacks.
    CriticFirst`): the actor stays the clone until the value function has learnt its returns."""

    def __post_init__(self):
        if self.teacher not in TEACHERS:
            raise ValueError(
                f"warm_start.teacher must be one of {sorted(TEACHERS)}, got {self.teacher!r}"
            )
        for name, least in (
            ("episodes", 1),
            ("epochs", 1),
            ("batch_size", 1),
            ("dagger_rounds", 0),
            ("critic_steps", 0),
        ):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < least:
                raise ValueError(f"warm_start.{name} must be an integer >= {least}, got {value!r}")
        rate = self.learning_rate
        if isinstance(rate, bool) or not isinstance(rate, int | float) or not 0 < rate < np.inf:
            raise ValueError(f"warm_start.learning_rate must be a number > 0, got {rate!r}")


@dataclasses.dataclass
class TeacherData:
    """Episodes labelled by the teacher: raw observations, its actions (clipped to the action
    space), which action values each step's env read (1) or ignored (0), and how many of the
    episodes (driven by the teacher or by the clone) succeeded."""

    observations: np.ndarray
    actions: np.ndarray
    read: np.ndarray
    successes: int
    episodes: int

    def __add__(self, other: TeacherData) -> TeacherData:
        return TeacherData(
            np.concatenate([self.observations, other.observations]),
            np.concatenate([self.actions, other.actions]),
            np.concatenate([self.read, other.read]),
            self.successes + other.successes,
            self.episodes + other.episodes,
        )


def teacher_data(
    make_env: Callable[[], gym.Env],
    teacher: str,
    episodes: int,
    seed: int,
    driver: Callable[[np.ndarray], np.ndarray] | None = None,
) -> TeacherData:
    """Run ``episodes`` fresh tasks of ``make_env()`` (seeds ``seed``, ``seed + 1``, ...) driven
    by `teacher`, or by `driver` (DAgger) with the teacher asked at every step all the same, and
    keep every step's observation and the teacher's action."""
    env = make_env()
    try:
        policy = load_factory(TEACHERS[teacher])(env)
        space = env.action_space
        flags = env.unwrapped.action_read_flags
        observations, actions, successes = [], [], 0
        for episode in range(episodes):
            obs, _ = env.reset(seed=seed + episode)
            policy.reset()
            done, info = False, {}
            while not done:
                label = np.clip(np.asarray(policy(obs), dtype=np.float64), space.low, space.high)
                observations.append(obs)
                actions.append(label)
                action = label if driver is None else driver(obs)
                obs, _, terminated, truncated, info = env.step(action)
                done = terminated or truncated
            successes += bool(info.get("is_success", False))
    finally:
        env.close()
    observations, actions = np.array(observations), np.array(actions)
    read = np.ones_like(actions)
    for action_index, flag in flags.items():
        read[:, action_index] = observations[:, flag] > 0.5
    return TeacherData(observations, actions, read, successes, episodes)


def fit_actor(
    policy: Any,
    observations: np.ndarray,
    actions: np.ndarray,
    read: np.ndarray,
    settings: WarmStartSettings,
    seed: int,
) -> float:
    """Fit the actor's mean of an SB3 `ActorCriticPolicy` to `actions` at `observations` (as the
    policy sees them: normalised) by mean squared error over the values read; returns the last
    epoch's loss (in action units squared, averaged over the action values)."""
    import torch

    generator = torch.Generator().manual_seed(seed)
    x, y, w = (
        torch.as_tensor(a, dtype=torch.float32, device=policy.device)
        for a in (observations, actions, read)
    )
    actor = [
        *policy.pi_features_extractor.parameters(),
        *policy.mlp_extractor.policy_net.parameters(),
        *policy.action_net.parameters(),
    ]
    optimiser = torch.optim.Adam(actor, lr=settings.learning_rate)
    policy.set_training_mode(True)
    loss_value = float("nan")
    for _ in range(settings.epochs):
        losses = []
        order = torch.randperm(len(x), generator=generator).to(policy.device)
        for batch in order.split(settings.batch_size):
            mean = policy.get_distribution(x[batch]).distribution.mean
            weights = w[batch]
            per_value = (weights * (mean - y[batch]) ** 2).sum(dim=0)
            counted = weights.sum(dim=0)
            loss = (per_value[counted > 0] / counted[counted > 0]).mean()
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            losses.append(loss.item())
        loss_value = float(np.mean(losses))
    policy.set_training_mode(False)
    return loss_value


def warm_start(
    model: Any,
    venv: Any,
    make_env: Callable[[], gym.Env],
    settings: WarmStartSettings,
    seed: int,
    log: Callable[[str], Any] = lambda line: None,
) -> dict[str, Any]:
    """Clone the teacher into `model`'s actor (module docstring), then run the DAgger rounds.
    `venv` is the model's training vec env: a VecNormalize on it takes its observation
    statistics from the labelled observations first. `log` gets a line after each fit. Returns
    what to record with the run."""
    normalize = getattr(venv, "norm_obs", False)

    def as_seen(observations: np.ndarray) -> np.ndarray:
        return venv.normalize_obs(observations) if normalize else observations

    def clone(observation: np.ndarray) -> np.ndarray:
        return model.policy.predict(as_seen(observation), deterministic=True)[0]

    first = seed + SEED_OFFSET
    data = new = teacher_data(make_env, settings.teacher, settings.episodes, first)
    rounds = []
    for round_ in range(settings.dagger_rounds + 1):
        if round_ > 0:
            start = first + round_ * settings.episodes
            new = teacher_data(make_env, settings.teacher, settings.episodes, start, clone)
            rounds.append({"round": round_, "clone_successes": new.successes})
            data = data + new
        if normalize:
            venv.obs_rms.update(new.observations)
        loss = fit_actor(
            model.policy, as_seen(data.observations), data.actions, data.read, settings, seed
        )
        driver = "the teacher" if round_ == 0 else "the clone"
        log(
            f"round {round_}: {driver} succeeded in {new.successes} of {new.episodes}; "
            f"fitted on {len(data.actions)} pairs, loss {loss:.3g}"
        )
    return {
        **dataclasses.asdict(settings),
        "teacher_successes": data.successes - sum(r["clone_successes"] for r in rounds),
        "teacher_episodes": settings.episodes,
        "dagger": rounds,
        "pairs": int(len(data.actions)),
        "pairs_read": [int(n) for n in data.read.sum(axis=0)],
        "final_loss": loss,
        "normalisation_from_teacher": bool(normalize),
    }
