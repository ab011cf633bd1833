"""Typed env settings: one frozen dataclass per env, built from ``gym.make(id, **kwargs)``.

Every env declares its settings as a frozen dataclass derived from `EnvSettings` (timing, settle
time, contact threshold, tipping threshold ξ, tip-over angle, reset noise, task distribution,
sensor noise, rendering), with a nested frozen `RewardScales` dataclass (`reward`). Each field is
made by one of `number`, `numbers`, `choice` or `option`, which attach the check run at
construction: a bad value raises a ValueError that names the setting and its valid range, so
nothing bad reaches the physics (a NaN gain, an infinite drop, a negative friction).

Keyword arguments build the dataclass (`EnvSettings.from_kwargs`): a reward scale may be given
flat (``gym.make(id, forward_weight=2.0)``) or nested (``reward={"forward_weight": 2.0}``);
unknown keys are a TypeError that lists the valid ones. ``env.unwrapped.settings`` holds the
result, and ``gym.make(id, **vars(env.unwrapped.settings))`` rebuilds the same env.
"""

from __future__ import annotations

import dataclasses
import math
import numbers as _numbers
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

from ..checks import check_choice, check_real, range_text, within

TASK_DISTRIBUTIONS = ("paper", "train", "test")
"""``task_distribution`` values: the paper's scenario (plus small reset noise), or task and
physical parameters sampled at every reset from the env's training or held-out test ranges."""

RENDER_MODES = ("human", "rgb_array", "depth_array")

SOLVERS = ("newton", "cg", "pgs")
"""``solver`` values: MuJoCo's constraint solvers (`hexapod_envs.envs.physics.SOLVER_IDS`)."""

RENAMED = {
    "progress_weight": "forward_weight",
}
"""Settings that were renamed (old -> new), so that an old name gets a pointed message."""


def number(
    default: Any,
    *,
    low: float | None = 0.0,
    high: float | None = None,
    strict: bool = False,
    integer: bool = False,
    optional: bool = False,
) -> Any:
    """A numeric setting: a real number (not a string, bool or complex), finite, >= `low`
    (> with `strict`; ``low=None``: any sign) and <= `high`; `integer`: an int; `optional`:
    None is allowed."""

    def check(name: str, value: Any) -> None:
        if value is None and optional:
            return
        if integer and (isinstance(value, bool) or not isinstance(value, _numbers.Integral)):
            raise ValueError(f"{name} must be an integer, got {value!r} ({type(value).__name__})")
        x = check_real(name, value, value)
        if not within(x, low, high, strict):
            raise ValueError(f"{name} must be {range_text(low, high, strict)}, got {value!r}")

    return dataclasses.field(default=default, metadata=_numeric(check, low))


def _numeric(check: Callable, low: float | None) -> dict:
    return {"check": check, "numeric": True, "signed": low is None}


def numbers(
    default: Any,
    *,
    size: int | None = None,
    low: float | None = 0.0,
    high: float | None = None,
    ordered: bool = False,
    optional: bool = False,
) -> Any:
    """A tuple of numbers (or of (low, high) pairs): each real, finite and in [`low`, `high`]
    (``low=None``: any sign); `size` entries; `ordered`: each pair has low <= high. Lists (a
    YAML config's) are stored as tuples."""

    def check(name: str, value: Any) -> None:
        if value is None and optional:
            return
        if not isinstance(value, (tuple, list)):
            raise ValueError(f"{name} must be a tuple of numbers, got {value!r}")
        if size is not None and len(value) != size:
            raise ValueError(f"{name} must have {size} entries, got {value!r}")
        items = [v for item in value for v in (item if isinstance(item, (tuple, list)) else [item])]
        for x in items:
            x = check_real(name, x, value)
            if not within(x, low, high):
                raise ValueError(
                    f"{name} entries must be {range_text(low, high, False)}, got {value!r}"
                )
        pairs = [value] if not isinstance(value[0], (tuple, list)) else value
        if ordered and any(len(p) != 2 or p[0] > p[1] for p in pairs):
            raise ValueError(f"{name} must be (low, high) with low <= high, got {value!r}")

    return dataclasses.field(default=default, metadata={**_numeric(check, low), "tuples": True})


def choice(default: Any, choices: tuple, *, optional: bool = False) -> Any:
    """A setting that takes one of `choices` (None too if `optional`)."""

    def check(name: str, value: Any) -> None:
        if not (value is None and optional):
            check_choice(name, value, choices)

    return dataclasses.field(default=default, metadata={"check": check})


def option(
    default: Any = None, *, kind: type | tuple[type, ...] | None = None, optional: bool = True
) -> Any:
    """A setting of another type (a parameter dataclass, a name): an instance of `kind` (or
    None if `optional`), checked by type; its own dataclass checks its fields."""

    def check(name: str, value: Any) -> None:
        if value is None and optional:
            return
        if kind is not None and not isinstance(value, kind):
            names = kind.__name__ if isinstance(kind, type) else [k.__name__ for k in kind]
            either = "None or " if optional else ""
            ranges = isinstance(kind, type) and issubclass(kind, TaskRanges)
            mapping = " or a mapping of the ranges to change" if ranges else ""
            raise ValueError(f"{name} must be {either}a {names}{mapping}, got {value!r}")

    if isinstance(default, (list, dict, set)):
        raise TypeError("mutable defaults are not allowed for settings")
    return dataclasses.field(default=default, metadata={"check": check})


class _Checked:
    """Runs every field's check (see `number`, `numbers`, `choice`, `option`) on construction."""

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            check: Callable | None = f.metadata.get("check")
            if check is not None:
                check(f.name, getattr(self, f.name))
            if f.metadata.get("tuples"):
                object.__setattr__(self, f.name, _as_tuples(getattr(self, f.name)))


def bounded(low: float | None = 0.0, high: float | None = None, strict: bool = False) -> Any:
    """A field of a `TaskRanges` dataclass whose numbers (a number, a (low, high) pair or a
    tuple of pairs) must lie in [`low`, `high`] (> `low` with `strict`; ``low=None``: any
    sign), as the env's plain setting of the same quantity must."""
    return dataclasses.field(metadata={"bounds": (low, high, strict)})


class TaskRanges:
    """Base of the envs' task-range dataclasses: every (low, high) pair (or tuple of pairs) must
    be finite with low <= high, every number finite, and within its field's bounds (`bounded`);
    checked on construction.

    The envs' ``train_ranges`` / ``test_ranges`` settings also take a mapping, e.g. from a YAML
    config: it replaces the named ranges of the default and keeps the others (`updated`).
    """

    def updated(self, where: str, changes: Mapping[str, Any]) -> TaskRanges:
        """A copy with the ranges in `changes` replaced (lists as tuples, as YAML gives them).
        TypeError naming unknown keys; ValueError naming a range of the wrong kind (a number,
        a (low, high) pair, a list of pairs or of names, like the default's), names outside the
        default's, or a pair with low > high."""
        valid = [f.name for f in dataclasses.fields(self)]
        unknown = sorted(set(changes) - set(valid))
        if unknown:
            raise TypeError(f"{where}: unknown range(s) {unknown}; valid: {valid}")
        new = {k: _as_tuples(v) for k, v in changes.items()}
        for key, value in new.items():
            old = getattr(self, key)
            if _shape(old) == _PAIRS and _shape(value) == _PAIR:
                value = new[key] = (value,)  # one interval
            if _shape(value) != _shape(old):
                raise ValueError(
                    f"{where}.{key} must be {_shape(old)} like the default {old!r}, got {value!r}"
                )
            if _shape(old) == _NAMES and not set(value) <= set(old):
                raise ValueError(f"{where}.{key} takes names among {old}, got {value!r}")
        try:
            return dataclasses.replace(self, **new)
        except ValueError as error:
            raise ValueError(f"{where}: {error}") from None

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = _as_tuples(getattr(self, f.name))  # lists (e.g. from YAML) as tuples
            object.__setattr__(self, f.name, value)
            if _shape(value) == _NUMBER:
                numbers = (check_real(f.name, value, value),)
            elif isinstance(value, tuple) and value and not isinstance(value[0], str):
                pairs = value if isinstance(value[0], tuple) else (value,)
                for pair in pairs:
                    ok = len(pair) == 2 and all(
                        isinstance(x, _numbers.Real) and math.isfinite(x) for x in pair
                    )
                    if not (ok and pair[0] <= pair[1]):
                        raise ValueError(
                            f"{type(self).__name__}.{f.name} must be finite (low, high) pairs "
                            f"with low <= high, got {value!r}"
                        )
                numbers = [x for pair in pairs for x in pair]
            else:  # names (checked against the default's by `updated`)
                continue
            self._check_bounds(f, numbers, value)

    def _check_bounds(self, f: dataclasses.Field, numbers: Any, value: Any) -> None:
        """ValueError naming the field and its bounds (`bounded`) when one of the `numbers` of
        its `value` lies outside them."""
        if "bounds" not in f.metadata:
            return
        low, high, strict = f.metadata["bounds"]
        for x in numbers:
            if not within(x, low, high, strict):
                raise ValueError(
                    f"{type(self).__name__}.{f.name} entries must be "
                    f"{range_text(low, high, strict)}, got {value!r}"
                )


def _shape(value: Any) -> str:
    """What kind of range `value` is: a number, a (low, high) pair, a tuple of pairs or of
    names."""
    if isinstance(value, _numbers.Real) and not isinstance(value, bool):
        return _NUMBER
    if isinstance(value, tuple) and value:
        if all(isinstance(v, str) for v in value):
            return _NAMES
        if len(value) == 2 and all(_shape(v) == _NUMBER for v in value):
            return _PAIR
        if all(isinstance(v, tuple) and _shape(v) == _PAIR for v in value):
            return _PAIRS
    return f"a {type(value).__name__}"


_NUMBER, _PAIR, _PAIRS = "a number", "a (low, high) pair", "a list of (low, high) pairs"
_NAMES = "a list of names"


def _as_tuples(value: Any) -> Any:
    """Lists (nested too) as tuples: a YAML sequence as the ranges' (low, high) pairs."""
    return tuple(_as_tuples(v) for v in value) if isinstance(value, (list, tuple)) else value


@dataclasses.dataclass(frozen=True)
class RewardScales(_Checked):
    """The weights of an env's named reward terms (every env extends it)."""

    tip_over_penalty: float = number(100.0)
    """Paid once, on the step the robot tips over."""


@dataclasses.dataclass(frozen=True)
class EnvSettings(_Checked):
    """Settings every hexapod env has. Subclasses change the defaults to their robot's."""

    reward_class: ClassVar[type[RewardScales]] = RewardScales
    """The env's reward-scales dataclass (the type of `reward`)."""

    control_dt: float = number(0.02, strict=True)
    """Control period [s] (one `step`)."""
    physics_dt: float = number(0.001, strict=True)
    """MuJoCo timestep [s]; control_dt must be a whole multiple of it."""
    integrator: str = choice("implicitfast", ("implicitfast", "implicit", "euler", "rk4"))
    """MuJoCo integrator."""
    solver: str = choice("newton", SOLVERS)
    """MuJoCo's constraint solver (Newton, conjugate gradient, projected Gauss-Seidel)."""
    solver_iterations: int | None = number(None, strict=True, integer=True, optional=True)
    """Constraint solver iterations (None: MuJoCo's default, 100)."""
    solver_ls_iterations: int | None = number(None, strict=True, integer=True, optional=True)
    """Line-search iterations of the solver (None: MuJoCo's default, 50)."""
    solver_tolerance: float | None = number(None, optional=True)
    """Constraint solver tolerance (None: MuJoCo's default, 1e-8)."""
    midphase: bool | None = choice(None, (None, False, True))
    """MuJoCo's collision midphase (bounding-volume trees that cull geom pairs before the
    narrow phase). It finds the same contacts either way (bit-identical episodes in every env),
    so only speed decides: None takes the env's measured choice (`HexapodEnv.midphase_pays`)."""
    settle_time: float = number(0.5)
    """Physics run in `reset` before the episode starts, the robot resting on its feet [s]."""
    contact_threshold: float = number(0.02, high=1.0)
    """A foot is loaded when its ground reaction exceeds this fraction of the robot's weight."""
    tipping_threshold_deg: float = number(20.0, high=90.0)
    """The robot's tipping threshold ξ on the FASM [deg] (`info["is_tipping"]` below it)."""
    tip_over_angle_deg: float = number(20.0, strict=True, high=90.0)
    """Tip-over (episode ends): the body's up axis leans more than this from vertical [deg]."""
    tip_over_margin_time: float | None = number(None, strict=True, optional=True)
    """Tip-over (episode ends) also when the FASM has stayed at or below 0 for this long [s]:
    the net force has left the support polygon and the body is rotating about its edge, past
    the point of no return once no foot can land in time (None: tilt only, the -v0 rule)."""
    success_max_tilt_deg: float | None = number(None, strict=True, high=90.0, optional=True)
    """A success also needs the episode's largest body tilt (`info["max_tilt_deg"]`) at or
    below this [deg] (None: no tilt bound, the -v0 rule)."""
    success_max_tipping_share: float | None = number(None, high=1.0, optional=True)
    """A success also needs the share of the episode's steps on which the stability criterion
    failed (`info["tipping_share"]`) at or below this (None: no bound, the -v0 rule)."""
    reset_noise_scale: float = number(0.01)
    """Size of the seed-dependent perturbation of the start state (env-specific units)."""
    task_distribution: str = choice("paper", TASK_DISTRIBUTIONS)
    """"paper" (the paper's scenario), "train" or "test" (tasks sampled at every reset)."""
    sensor_noise: float = number(0.0)
    """Relative std of Gaussian noise on the observed foot forces and IMU (0: exact)."""
    render_mode: str | None = choice(None, RENDER_MODES, optional=True)
    width: int = number(640, strict=True, integer=True)
    """Rendered image width [px]."""
    height: int = number(480, strict=True, integer=True)
    """Rendered image height [px]."""
    camera_name: str | None = option(None, kind=str)
    """Named camera to render from (None: a free camera tracking the body)."""
    reward: RewardScales = None  # type: ignore[assignment]  # the env's reward_class() if None
    """The reward terms' weights (`reward_class`)."""

    def __post_init__(self) -> None:
        if self.reward is None:
            object.__setattr__(self, "reward", self.reward_class())
        elif not isinstance(self.reward, self.reward_class):
            raise ValueError(
                f"reward must be a {self.reward_class.__name__} or a dict of its fields, got "
                f"{self.reward!r}"
            )
        super().__post_init__()

    @classmethod
    def from_kwargs(cls, owner: str, kwargs: Mapping[str, Any]) -> EnvSettings:
        """Build the settings from keyword arguments; reward scales may be given flat or as
        ``reward=`` (a dict or a `reward_class`). TypeError naming unknown keys (`owner` is
        the env's name for the message)."""
        kwargs = dict(kwargs)
        own = {f.name for f in dataclasses.fields(cls)}
        scales = {f.name for f in dataclasses.fields(cls.reward_class)}
        unknown = sorted(set(kwargs) - own - scales)
        if unknown:
            hints = [f"{k} is now {RENAMED[k]}" for k in unknown if k in RENAMED]
            hint = f" ({'; '.join(hints)})" if hints else ""
            raise TypeError(
                f"{owner} got unknown keyword argument(s) {unknown}{hint}; valid: "
                f"{sorted((own - {'reward'}) | scales)}, or reward={{...}} with the "
                "reward scales"
            )
        for f in dataclasses.fields(cls):
            if isinstance(f.default, TaskRanges) and isinstance(kwargs.get(f.name), Mapping):
                kwargs[f.name] = f.default.updated(f"{owner}: {f.name}", kwargs[f.name])
        flat = {k: kwargs.pop(k) for k in list(kwargs) if k in scales and k not in own}
        reward = kwargs.pop("reward", None)
        if isinstance(reward, Mapping):
            bad = sorted(set(reward) - scales)
            if bad:
                raise TypeError(f"{owner}: unknown reward scale(s) {bad}; valid: {sorted(scales)}")
            reward = cls.reward_class(**{**reward, **flat})
        elif reward is None:
            reward = cls.reward_class(**flat)
        elif flat and isinstance(reward, cls.reward_class):
            reward = dataclasses.replace(reward, **flat)
        return cls(**kwargs, reward=reward)

    @classmethod
    def numeric_names(cls) -> list[str]:
        """Names of the numeric settings, the reward scales included (flat names)."""
        names = [f.name for f in dataclasses.fields(cls) if f.metadata.get("numeric")]
        return names + [
            f.name for f in dataclasses.fields(cls.reward_class) if f.metadata.get("numeric")
        ]

    @classmethod
    def signed_names(cls) -> list[str]:
        """Numeric settings for which a negative value is meaningful (positions, offsets)."""
        return [n for n in cls.numeric_names() if cls._field(n).metadata.get("signed")]

    @classmethod
    def _field(cls, name: str) -> dataclasses.Field:
        for klass in (cls, cls.reward_class):
            for f in dataclasses.fields(klass):
                if f.name == name:
                    return f
        raise KeyError(name)
