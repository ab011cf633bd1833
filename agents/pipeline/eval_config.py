"""The evaluation suite (``configs/evaluate*.yaml``) as typed dataclasses.

Policies are strings: ``analytical`` (the env's reference controller from
`agents.registry`), ``ppo:<path>`` (model file, model directory or run directory; ``{env_id}`` in
the path is replaced by each env's id, e.g. ``ppo:models/{env_id}``), ``zero`` and ``random``.
Episode ``k`` of every policy uses seed ``seed + k``: identical seeds, hence identical terrain
and initial states, for every policy.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from ..run_files.configtools import apply_overrides, from_mapping, load_yaml
from ..run_files.errors import ConfigError
from ..run_files.train_config import DEFAULT_GYM_PACKAGES

SIMPLE_POLICIES = ("analytical", "zero", "random")
PPO_PREFIX = "ppo:"


@dataclass
class SuiteEnv:
    id: str
    kwargs: dict[str, Any] = field(default_factory=dict)
    max_episode_steps: int | None = None  # None: the registered limit
    min_task_difficulty: float | None = None
    """Only sampled tasks at least this difficult (`hexapod_envs.curriculum.MinimumDifficulty`,
    drawn through the env's ``np_random``: the same tasks for every policy); None: all."""


def _parse_envs(value: Any, where: str) -> list[SuiteEnv]:
    """A list of env ids or of ``{id, kwargs, max_episode_steps, min_task_difficulty}``
    mappings."""
    if not isinstance(value, list) or not value:
        raise ConfigError(f"{where}: expected a non-empty list of env ids or mappings")
    envs = []
    for i, item in enumerate(value):
        if isinstance(item, str):
            item = {"id": item}
        envs.append(from_mapping(SuiteEnv, item, f"{where}[{i}]"))
    ids = [env.id for env in envs]
    repeated = sorted({env_id for env_id in ids if ids.count(env_id) > 1})
    if repeated:
        raise ConfigError(
            f"{where}: {repeated} listed more than once; a report has one section per env id "
            "(its results, figures and scores are keyed by it): evaluate other settings of the "
            "same env, such as another task_distribution, in a suite of their own"
        )
    return envs


def check_policy_name(name: str, where: str = "policies") -> str:
    if name in SIMPLE_POLICIES or (name.startswith(PPO_PREFIX) and len(name) > len(PPO_PREFIX)):
        return name
    raise ConfigError(
        f"{where}: unknown policy {name!r}; valid: {', '.join(SIMPLE_POLICIES)}, ppo:<path>"
    )


def _parse_policies(value: Any, where: str) -> list[str]:
    if not isinstance(value, list) or not value:
        raise ConfigError(f"{where}: expected a non-empty list of policy names")
    names = [check_policy_name(str(v), f"{where}[{i}]") for i, v in enumerate(value)]
    if len(set(names)) != len(names):
        raise ConfigError(f"{where}: duplicate policy names in {names}")
    return names


DEFAULT_REFERENCES = ("analytical", "zero")
"""The policies every other one is compared with when a suite names no ``references``: the
analytical controller and the reference motion (those of them that ran)."""


def _parse_references(value: Any, where: str) -> list[str] | None:
    return None if value is None else _parse_policies(value, where)


DEFAULT_TITLE = "Hexapod policy evaluation"
"""A report's title where the suite gives none."""


@dataclass
class EvaluationSuite:
    envs: list[SuiteEnv] = field(metadata={"parse": _parse_envs})
    policies: list[str] = field(
        default_factory=lambda: ["analytical"], metadata={"parse": _parse_policies}
    )
    # the policies every other one is compared with, in this order (paired-bootstrap intervals
    # per metric); null: analytical and zero. E.g. [analytical, "ppo:models/{env_id}/paper_gains"]
    # compares learned gains with the paper's gains in the same action mode, like for like.
    references: list[str] | None = field(default=None, metadata={"parse": _parse_references})
    episodes: int = 5
    seed: int = 0
    max_episode_steps: int | None = None  # set: overrides every env's time limit (smoke runs)
    output_dir: str = "reports/evaluation"
    missing_models: Literal["error", "skip"] = "error"
    # skip: a ppo:<path> that does not exist, or an env without an analytical controller in
    # agents/registry.py, is left out with a warning line in the report (error: exit with it);
    # a ppo:...{env_id}... path found for some envs only is one note instead
    deterministic: bool = True  # PPO actions: the mean (true) or sampled
    trust_pickle: bool = False  # load pickled model files of older runs (runs code from them)
    frames: bool = False  # frame strip per policy (rendered with MUJOCO_GL=egl)
    frame_count: int = 6
    video_fps: float = 12.5  # --video: frames per second of simulated time (played in real time)
    frame_size: list[int] = field(default_factory=lambda: [320, 240])
    xi_f_deg: float = 20.0
    gym_packages: list[str] = field(default_factory=lambda: list(DEFAULT_GYM_PACKAGES))
    title: str = DEFAULT_TITLE

    def __post_init__(self):
        if self.episodes < 1:
            raise ValueError(f"episodes must be >= 1, got {self.episodes}")
        if self.seed < 0:
            raise ValueError(f"seed must be >= 0 (Gymnasium seeds), got {self.seed}")
        if self.frame_count < 1 or len(self.frame_size) != 2 or min(self.frame_size) < 1:
            raise ValueError(
                "frame_count must be >= 1 and frame_size [width, height] in pixels >= 1, got "
                f"{self.frame_count} and {self.frame_size}"
            )
        if not 0.0 <= self.xi_f_deg <= 90.0:  # NaN fails too
            raise ValueError(f"xi_f_deg must be in [0, 90] degrees, got {self.xi_f_deg}")
        if not 0 < self.video_fps <= 100:
            raise ValueError(f"video_fps must be in (0, 100], got {self.video_fps}")
        unknown = [r for r in self.references or () if r not in self.policies]
        if unknown:
            raise ValueError(
                f"references {unknown} are not among the policies {self.policies} (name them "
                "among the policies, or drop the suite's references with --set references=null)"
            )

    @property
    def reference_names(self) -> tuple[str, ...]:
        """The policies compared with, in order (the defaults when none are named)."""
        return DEFAULT_REFERENCES if self.references is None else tuple(self.references)

    @property
    def seeds(self) -> list[int]:
        return [self.seed + k for k in range(self.episodes)]

    def env_time_limit(self, env: SuiteEnv) -> int | None:
        """The suite-wide limit if set, else the env's own, else None (registered limit)."""
        return (
            self.max_episode_steps
            if self.max_episode_steps is not None
            else (env.max_episode_steps)
        )


def load_suite(path: str | Path, overrides: list[str] | tuple[str, ...] = ()) -> EvaluationSuite:
    return from_mapping(EvaluationSuite, apply_overrides(load_yaml(path), list(overrides)))
