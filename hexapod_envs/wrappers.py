"""Gymnasium wrappers: one decision per gait cycle or per episode, and stability-rule penalties.

`GainsPerCycle`: HexapodIrregularTerrain's "gains" mode reads its action once per gait cycle
(40 control steps at the defaults) and ignores it in between, so a learner that acts at every
step sees 39 actions without consequence for each one that counts, and a per-step reward whose
effect shows up over the whole cycle. The wrapper makes one wrapped step of each gait cycle: the
action is held until the env reads the next one, and the rewards of the cycle's steps are
summed. It is the semi-MDP of "one decision per gait cycle" (the paper's gains are per cycle too).
The env reads the gains at the first control step of a cycle; when the cycle starts with waits
for the stance feet to touch the ground (ground search), the gains are read on the first wait,
the search already runs with them, and the waits belong to that cycle's wrapped step.

With ``baseline_action`` the wrapper also plays each cycle a second time, on a copy of the env
taken at the cycle start, with that action held (e.g. the zero residual: the paper's gains), and
returns the difference of the two rewards: what the chosen action gained over the baseline on the
same terrain, from the same state (common random numbers). On a block bed the terrain under the
feet moves a cycle's reward far more than the gains do, so the plain reward ranks gain settings
only at noise level; the difference cancels the terrain and leaves the gains' effect.

The ditch crossing's stride action (``stride_action=True``) with the residuals off
(``residual_limb_m=0``, ``residual_leg_m=0``) is read the same way, once per platform step (its
first control step, `stride_due`), so the wrapper makes one step of each platform step there:
the learner chooses each stride, and its reward is the platform step's sum (~51 control steps).

A policy trained through it acts identically without it: the env reads the action only at the
cycle starts, and the wrapped env returns exactly the observation that the unwrapped env returns
before each cycle start. Evaluation (which needs every step's info for its metrics) therefore
runs the policy on the unwrapped env at every step.

`GainsPerEpisode`: one wrapped step per episode, the action held over every gait cycle: the
contextual bandit of "one setting per terrain", for knobs whose best value hardly changes within
an episode (ATHENA's body height: the height control reaches a new reference over several
cycles, so per-cycle rewards credit little of it). The step's reward is the episode's outcome.

`StrideChoices`: the ditch crossing's stride action as a choice among a few stride values (a
`gymnasium.spaces.Discrete` action), the residuals off. A Gaussian policy that starts at the full
stride moves its mean by small steps, and on the way to a stride that clears an edge it meets
strides that land a foot on it; a categorical policy weighs each value apart.
`StrideClearances` appends where each choice would land the moving feet.

`StabilityRulePenalty`: per-step penalties that mirror a ``-v1`` success rule's bounds on the
time spent tipping and the largest tilt (and, on the cliff walk, its pace), for learners that
act at every step.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from functools import partial
from typing import Any, Literal, get_args

import gymnasium as gym
import numpy as np

from . import info_keys as keys


class GainsPerCycle(gym.Wrapper):
    """One step per gait cycle of a "gains"-mode env, or per platform step of the ditch
    crossing's stride action with the residuals off (see the module docstring).

    ``step`` returns the last control step's observation, termination, truncation and info, with
    the reward and the info's reward terms (``reward_<term>``) summed over the cycle's control
    steps (with ``baseline_action`` below, the terms stay the chosen action's sums);
    ``info["cycle_steps"]`` is how many control steps it ran (a cycle's, with the ground-search
    waits at its start on the irregular terrain; fewer when the episode ended inside the
    cycle).

    With ``baseline_action`` (an action of the wrapped env) the reward is that sum minus the sum
    over as many control steps (fewer if it ends first) of a copy of the wrapped env taken before
    the cycle and driven with the baseline action; ``info["cycle_reward"]`` and
    ``info["baseline_reward"]`` hold both sums and ``info["baseline_steps"]`` the copy's steps
    (which count as simulated env steps: the cycle is simulated twice)."""

    def __init__(self, env: gym.Env, baseline_action: Any = None):
        super().__init__(env)
        self.baseline_action = None
        if baseline_action is not None:
            self.baseline_action = np.asarray(baseline_action, dtype=env.action_space.dtype)
            if not env.action_space.contains(self.baseline_action):
                raise ValueError(
                    f"baseline_action {baseline_action!r} is not in the action space "
                    f"{env.action_space}"
                )
        self._due = _decision_due(env, type(self).__name__)

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        twin = None if self.baseline_action is None else copy.deepcopy(self.env)
        base = self.env.unwrapped
        (obs, _, terminated, truncated, info), total, steps = _play(
            self.env, action, lambda _: getattr(base, self._due)
        )
        info["cycle_steps"] = steps
        if twin is None:
            return obs, total, terminated, truncated, info
        _, baseline, baseline_steps = _play(twin, self.baseline_action, lambda n: n >= steps)
        twin.close()
        info.update(cycle_reward=total, baseline_reward=baseline, baseline_steps=baseline_steps)
        return obs, total - baseline, terminated, truncated, info


def _play(env: gym.Env, action: Any, done: Callable[[int], bool]) -> tuple[tuple, float, int]:
    """Step ``env`` with ``action`` until the episode ends or ``done(steps so far)``; returns
    the last step's result (its info's reward terms, ``reward_<term>``, replaced by their sums
    over the steps), the summed reward and the number of steps."""
    total, steps, terms = 0.0, 0, {}
    while True:
        obs, reward, terminated, truncated, info = env.step(action)
        total += float(reward)
        steps += 1
        for key, value in info.items():
            if key.startswith(keys.REWARD_PREFIX):
                terms[key] = terms.get(key, 0.0) + float(value)
        if terminated or truncated or done(steps):
            return (obs, reward, terminated, truncated, {**info, **terms}), total, steps


EpisodeReward = Literal["success", "stable_success", "margin_success", "return"]
"""The rewards of a decision that spans an episode (`episode_reward`)."""
EPISODE_REWARDS: tuple[str, ...] = get_args(EpisodeReward)


def episode_reward(
    kind: str,
    info: dict[str, Any],
    episode_return: float,
    tilt_bound_deg: float | None = None,
    margin_scale_m: float | None = None,
) -> float:
    """The reward of a decision whose consequence is a whole episode.

    - ``"success"``: 1.0 when the episode meets the env's success rule (``info["is_success"]``
      of its last step), else 0.0.
    - ``"stable_success"``: a success graded by how far its largest tilt stayed from the success
      rule's bound: ``1 - info["max_tilt_deg"] / tilt_bound_deg`` for a success (in [0, 1]; the
      rule holds the tilt within the bound), 0.0 for a failure. Among settings that all
      succeed, it prefers the steadier one, which the 0/1 success cannot tell apart.
    - ``"margin_success"``: a success graded by how close the episode came to tipping on the
      robot's own stability criterion, the static margin (the ditch crossing):
      ``1 + clip(info["min_static_margin_m"] / margin_scale_m, 0, 1)`` for a success (in
      [1, 2]), 0.0 for a failure. A success outweighs any margin; among successes it prefers
      the one whose smallest margin was larger.
    - ``"return"``: `episode_return`, the env's rewards summed over what it decided.

    `tilt_bound_deg` is the env's ``success_max_tilt_deg`` and `margin_scale_m` the env's
    support inradius (`episode_reward_of` reads both), needed by "stable_success" and
    "margin_success" only.
    """
    _check_episode_reward(kind)
    if kind == "return":
        return episode_return
    success = float(bool(info.get("is_success", False)))
    if kind == "success" or not success:
        return success
    if kind == "margin_success":
        if margin_scale_m is None:
            raise ValueError('episode reward "margin_success" needs the margin scale [m]')
        return 1.0 + min(max(info["min_static_margin_m"] / margin_scale_m, 0.0), 1.0)
    if tilt_bound_deg is None:
        raise ValueError('episode reward "stable_success" needs the success rule\'s tilt bound')
    return max(1.0 - info["max_tilt_deg"] / tilt_bound_deg, 0.0)


def episode_reward_of(env: gym.Env, kind: str) -> Callable[[dict[str, Any], float], float]:
    """`episode_reward` of kind `kind` on `env`, checked once (`tilt_bound`'s and
    `margin_scale`'s errors): ``rule(info, episode_return)``."""
    return partial(
        episode_reward,
        kind,
        tilt_bound_deg=tilt_bound(env, kind),
        margin_scale_m=margin_scale(env, kind),
    )


def _check_episode_reward(kind: str) -> None:
    if kind not in EPISODE_REWARDS:
        raise ValueError(f"the episode reward must be one of {EPISODE_REWARDS}, got {kind!r}")


def tilt_bound(env: gym.Env, kind: str) -> float | None:
    """The success rule's tilt bound [deg] of `env` (``success_max_tilt_deg``) where the episode
    reward `kind` needs it; a ValueError that names the valid choices when `kind` is unknown,
    or is "stable_success" on an env whose success rule bounds no tilt (the -v0 ids)."""
    _check_episode_reward(kind)
    if kind != "stable_success":
        return None
    bound = _rule_setting(env, "success_max_tilt_deg")
    if bound is None:
        raise ValueError(
            'the episode reward "stable_success" grades a success by the success rule\'s tilt '
            f"bound, and {_env_name(env)} has none "
            '(the -v1 ids have one); use "success" or "return"'
        )
    return float(bound)


def margin_scale(env: gym.Env, kind: str) -> float | None:
    """The scale [m] of "margin_success" on `env`: the inradius of its support polygon (the
    scale of the env's own stability reward term); a ValueError where `kind` is
    "margin_success" and `env` has no static margin (only the ditch crossing's robot is judged
    by one)."""
    _check_episode_reward(kind)
    if kind != "margin_success":
        return None
    scale = getattr(env.unwrapped, "inradius", None)
    if scale is None:
        raise ValueError(
            'the episode reward "margin_success" grades a success by the smallest static margin '
            f"(info['min_static_margin_m']), and {_env_name(env)} has none (the ditch "
            'crossing has); use "success" or "return"'
        )
    return float(scale)


def _rule_setting(env: gym.Env, name: str) -> Any:
    """The success-rule setting `name` of `env` (None where the env has none: the -v0 ids)."""
    return getattr(getattr(env.unwrapped, "settings", None), name, None)


def _env_name(env: gym.Env) -> str:
    return env.spec.id if env.spec else type(env.unwrapped).__name__


class GainsPerEpisode(gym.Wrapper):
    """One step per episode of a "gains"-mode env (see the module docstring): ``step(action)``
    holds `action` until the episode ends and returns its last observation, info (its reward
    terms, ``reward_<term>``, summed over the episode) and ``terminated=True`` (the episode is
    the decision's whole consequence: nothing to bootstrap), with ``info["episode_steps"]`` the
    control steps it ran and ``info["episode_truncated"]`` whether the env's time limit ended
    it.

    The reward is `episode_reward` of kind `reward` ("success", "stable_success" or
    "return")."""

    def __init__(self, env: gym.Env, reward: str = "success"):
        super().__init__(env)
        self._reward = episode_reward_of(env, reward)
        _require_gains_mode(env, type(self).__name__)
        if not _has_time_limit(env):
            raise ValueError(
                "GainsPerEpisode plays each episode to its end, so the env needs a time limit: "
                "make it with gym.make (the registered limit, or max_episode_steps=N) or wrap it "
                "in gymnasium.wrappers.TimeLimit"
            )
        self.reward = reward

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        (obs, _, _, truncated, info), total, steps = _play(self.env, action, lambda _: False)
        info.update(episode_steps=steps, episode_truncated=truncated)
        return obs, self._reward(info, total), True, False, info


def _has_time_limit(env: gym.Env) -> bool:
    """A `gymnasium.wrappers.TimeLimit` among `env`'s wrappers."""
    while isinstance(env, gym.Wrapper):
        if isinstance(env, gym.wrappers.TimeLimit):
            return True
        env = env.env
    return False


def _decision_due(env: gym.Env, wrapper: str) -> str:
    """The name of the property of `env.unwrapped` that says whether its next step reads its
    action, for an env that reads it once per gait cycle and ignores it in between: ATHENA's
    "gains" mode (``gains_due``), or the ditch crossing's stride action with the residuals off
    (``stride_due``: once per platform step). A name rather than a bound check, so that a deep
    copy of the wrapper asks its own env. ValueError for any other env or mode, naming what
    would do."""
    base = env.unwrapped
    if getattr(base, "stride_action", False):
        if np.any(base.residual_gain):
            raise ValueError(
                f"{wrapper} on the ditch crossing's stride action needs residual_limb_m=0 and "
                "residual_leg_m=0: the residuals are read at every step, so a policy acting "
                "once per platform step would act differently on the plain env (got "
                f"{base.settings.residual_limb_m} and {base.settings.residual_leg_m})"
            )
        return "stride_due"
    envs = (
        "HexapodIrregularTerrain-* with action_mode='gains', or HexapodDitchCrossing-* with "
        "stride_action=True and the residuals off"
    )
    _require_gains_mode(env, wrapper, envs)
    return "gains_due"


def _require_gains_mode(
    env: gym.Env, wrapper: str, envs: str = "a gains action mode (HexapodIrregularTerrain-*)"
) -> None:
    """ValueError unless `env` is in a gains action mode (which reads its action per cycle);
    `envs` names the envs the wrapper takes."""
    base = env.unwrapped
    if not hasattr(type(base), "gains_due"):
        raise ValueError(f"{wrapper} needs an env with {envs}, got {type(base).__name__}")
    if getattr(base, "action_mode", None) != "gains":
        raise ValueError(
            f"{wrapper} needs action_mode='gains', got {base.action_mode!r}; the other "
            "modes read their action at every step"
        )


class StrideChoices(gym.ActionWrapper):
    """The ditch crossing's stride action (``stride_action=True``, residuals off) as
    ``Discrete(len(values))``: action k sets the stride value ``values[k]`` (0: the full stride,
    -0.5: half of it; `OnlineGait.stride_for`) and the nine residuals, whose range is 0, to 0.

    Action 0 is the first value; put the zero action's (0.0, full strides) first so that a
    policy with equal preferences (an untrained one, acting deterministically) walks the zero
    action. Like the env, the wrapped env reads the choice only on a platform step's first
    control step. A ValueError names the problem for another env, residuals that are not off,
    or values outside [-1, 0] or repeated."""

    def __init__(self, env: gym.Env, values: Any):
        super().__init__(env)
        base = _stride_env(env, "StrideChoices")
        if len(base.inert_actions) != env.action_space.shape[0] - 1:
            raise ValueError(
                "StrideChoices sets only the stride value; it needs residual_limb_m=0 and "
                f"residual_leg_m=0 (got {base.settings.residual_limb_m} and "
                f"{base.settings.residual_leg_m})"
            )
        self.values = _stride_values(values, "StrideChoices")
        (self.stride_index,) = base.action_read_flags
        self.action_space = gym.spaces.Discrete(self.values.size)

    def action(self, action: Any) -> np.ndarray:
        choice = int(np.asarray(action).reshape(()))
        if not 0 <= choice < self.values.size:
            raise ValueError(f"stride choice {choice} is not in 0..{self.values.size - 1}")
        full = np.zeros(self.env.action_space.shape, dtype=self.env.action_space.dtype)
        full[self.stride_index] = self.values[choice]
        return full


class StrideClearances(gym.ObservationWrapper):
    """The ditch crossing's observation (``stride_action=True``) with one value appended per
    stride value in `values`: where the next platform step, taking that stride, lands the moving
    platform's worst-placed foot, as its clearance from the nearer ditch edge less the clear
    band [m] (>= 0: every foot clear; `hexapod_envs.robots.upu.stride_clearance`), clipped to
    +-`bound`.

    The values are a function of the observation (``ditch_ahead``, ``stride_decision``) and the
    robot's constants, the geometry the clear-stride rule computes; they let a learner of
    `StrideChoices` weigh each choice by where it lands instead of from the edges' positions,
    which do not extrapolate to ditches wider or farther than those it trained on. A ValueError
    names the problem for another env or bad values."""

    def __init__(self, env: gym.Env, values: Any, bound: float = 0.3):
        super().__init__(env)
        base = _stride_env(env, "StrideClearances")
        from .robots.upu.stride_clearance import StrideClearance

        self.values = _stride_values(values, "StrideClearances")
        if not bound > 0:
            raise ValueError(f"StrideClearances needs a bound > 0 [m], got {bound!r}")
        self.bound = float(bound)
        self.geometry = StrideClearance.of(base.params, base.gait_settings)
        slices = base.observation_layout.slices
        self._ahead, self._decision = slices["ditch_ahead"], slices["stride_decision"]
        space = env.observation_space
        low = np.concatenate([space.low, np.full(self.values.size, -self.bound)])
        high = np.concatenate([space.high, np.full(self.values.size, self.bound)])
        self.observation_space = gym.spaces.Box(low, high, dtype=space.dtype)

    def clearances(self, observation: np.ndarray) -> np.ndarray:
        """Each stride value's clearance less the band [m], clipped to +-`bound`."""
        upper_next = observation[self._decision][0] > 0.5
        _, clear = self.geometry.candidates(observation[self._ahead], upper_next, self.values)
        return np.clip(clear - self.geometry.band, -self.bound, self.bound)

    def observation(self, observation: np.ndarray) -> np.ndarray:
        extra = self.clearances(observation).astype(observation.dtype)
        return np.concatenate([observation, extra])


def _stride_env(env: gym.Env, wrapper: str) -> Any:
    """The ditch crossing under `env`, which must have the stride action."""
    base = env.unwrapped
    if not getattr(base, "stride_action", False):
        raise ValueError(
            f"{wrapper} needs HexapodDitchCrossing-* with stride_action=True, got {_env_name(env)}"
        )
    return base


def _stride_values(values: Any, wrapper: str) -> np.ndarray:
    """`values` as stride values: at least 2, distinct, in [-1, 0]."""
    values = np.asarray(values, dtype=np.float64)
    if values.ndim != 1 or values.size < 2:
        raise ValueError(f"{wrapper} needs a list of at least 2 values, got {values!r}")
    if not (np.all(np.isfinite(values)) and np.all((values >= -1.0) & (values <= 0.0))):
        raise ValueError(
            f"stride values must lie in [-1, 0] (0: the full stride), got {values.tolist()}"
        )
    if np.unique(values).size != values.size:
        raise ValueError(f"stride values must differ, got {values.tolist()}")
    return values


class StabilityRulePenalty(gym.Wrapper):
    """Per-step reward terms that mirror the stability part of a ``-v1`` success rule, for
    learners that act at every step.

    The ``-v1`` success rules bound the share of the episode spent tipping (the FASM below the
    robot's ξ) and the episode's largest tilt, but the envs' rewards pay neither: a residual
    policy that lifts ATHENA's torso off the blocks earns more return while it leans past the
    25° bound and tips for a third of the episode, failing every task. Three terms, each in
    ``info`` beside the env's own, close that gap:

    - ``reward_rule_tipping`` = -`weight` on every step with ``info["is_tipping"]``, where the
      rule bounds the time spent tipping (``success_max_tipping_share``; the Stewart tilt's does
      not, since on a platform tilted to 40° every stance is below ξ after the recovery, and
      there the term stays 0);
    - ``reward_rule_tilt`` = -`weight` on every step whose tilt exceeds the success rule's bound
      (``success_max_tilt_deg``): from then on the episode can no longer succeed;
    - ``reward_rule_early_landing`` = -`weight` on every step from a lifted foot's landing before
      the robot first tipped (``info["early_landing"]``), where the rule keeps the lifted tripod
      in swing until then (``swing_until_tipping``, the Stewart tilt's): standing on all six feet
      from the start would otherwise earn the most return and fail every task.

    With `progress_weight` > 0 a fourth term mirrors the rule's progress part on the walking
    heavy-duty envs (the cliff walk): ``reward_rule_progress`` = -`progress_weight` on every
    step with ``info["behind_pace"]``, the CoG short of ``min_progress`` of the reference gait's
    distance so far. A policy that can stop the gait (``clock_action``) otherwise earns the most
    return by stopping early, safe and short of the distance the rule asks for.

    Choose `weight` against the env's alive term (what an upright step earns) so that a tipping
    step costs a visible share of it. A ValueError names the problem for an env without the
    bound (the -v0 ids) or without a pace (for `progress_weight`), or a weight that is not a
    number >= 0 (`weight` > 0).
    """

    def __init__(self, env: gym.Env, weight: float, progress_weight: float = 0.0):
        super().__init__(env)
        if not (np.isfinite(weight) and weight > 0):
            raise ValueError(f"the stability-rule penalty weight must be > 0, got {weight}")
        if not (np.isfinite(progress_weight) and progress_weight >= 0):
            raise ValueError(
                f"the progress-rule penalty weight must be a number >= 0, got {progress_weight}"
            )
        self.progress_weight = float(progress_weight)
        paced = getattr(env.unwrapped, "walks", False) and _rule_setting(env, "min_progress")
        if self.progress_weight and not paced:
            raise ValueError(
                f"{_env_name(env)} has no pace (min_progress) for the progress-rule penalty to "
                "mirror; the walking heavy-duty envs (HexapodCliffWalk-*) have one"
            )
        bound = _rule_setting(env, "success_max_tilt_deg")
        if bound is None:
            raise ValueError(
                f"{_env_name(env)} has no success tilt bound (success_max_tilt_deg) for the "
                "stability-rule penalty to mirror; the -v1 ids have one"
            )
        self.weight, self.tilt_bound_deg = float(weight), float(bound)
        self.bounds_tipping = _rule_setting(env, "success_max_tipping_share") is not None
        self.bounds_swing = bool(_rule_setting(env, "swing_until_tipping"))

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        is_tipping = self.bounds_tipping and bool(info.get(keys.IS_TIPPING, False))
        tipping = -self.weight * float(is_tipping)
        tilt = -self.weight * float(info.get(keys.TILT_DEG, 0.0) > self.tilt_bound_deg)
        early = self.bounds_swing and bool(info.get("early_landing", False))
        landing = -self.weight * float(early)
        terms = {"rule_tipping": tipping, "rule_tilt": tilt, "rule_early_landing": landing}
        if self.progress_weight:
            behind = bool(info.get("behind_pace", False))
            terms["rule_progress"] = -self.progress_weight * float(behind)
        info = {**info, **{keys.REWARD_PREFIX + name: v for name, v in terms.items()}}
        return obs, sum(terms.values(), float(reward)), terminated, truncated, info
