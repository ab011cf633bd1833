"""How much per-gait-cycle posture gains can gain over the paper's fixed gains, without learning.

A gains policy (HexapodIrregularTerrain-v0's ``action_mode="gains"``, e.g. a run of
``configs/irregular_terrain_gains_blocks.yaml``) picks (k_z, k_α, k_β) of Coelho et al.
2024's posture controller once per gait cycle. Two measurements show what such choices can
achieve on a task distribution:

- **fixed gains**: every setting of a grid held for whole episodes (a constant policy, which
  PPO can represent);
- **look-ahead**: at every cycle start the env is copied and each candidate setting is played
  for one cycle on its own copy; the one with the lowest `CycleCost` (by default pitch-rate
  RMS + roll-rate RMS [rad/s] + 1 per torso-contact step) is applied. It sees the terrain the
  cycle will meet (the default observation does not carry it) and the cycle's outcome, so it
  shows what a greedy per-cycle choice can reach; it is not a bound on policies that plan over
  several cycles. A contact step costs 1 rad/s by default, more than any rate difference
  between settings (0.01-0.1 rad/s), as the training reward ranks them. (Allowing only
  candidates with no more contact steps than the reference in the same cycle, instead, let the
  choices of one cycle cause contacts in the next ones.)

**Foresight or hindsight?** The simulator is deterministic, so the exact look-ahead picks the
setting whose *realised* cycle was cheapest. If the cycles' costs hung on details of the state
no sensor resolves, that pick would exploit the chaos of the contacts rather than foresee the
terrain, and no policy could learn it. ``Lookahead(state_noise=σ, samples=K)`` tells the two
apart: it plays every candidate on K copies whose joint and body velocities carry an error
drawn from N(0, σ²) (the same K errors for every candidate) and picks the lowest mean cost,
while the real env goes on from the exact state. What it keeps of the exact look-ahead's
advantage is foresight that a state known to σ supports. ``position_noise=σ_p`` also shifts
each copy's robot horizontally by an error drawn from N(0, σ_p²) per axis: where it stands
relative to the blocks known only to σ_p. The stance feet move with it, so a shift can start a
copy with a foot pressed into a block's face or off its edge: such a copy measures how much
the cycle hangs on the exact footing, not only an error of the terrain map.

The figures are those the evaluation reports for gains (the pooled medians of the per-cycle
pitch- and roll-rate RMS, ``info["cycle_stats"]``; torso-contact steps, successes).
"""

from __future__ import annotations

import copy
import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import NamedTuple

import gymnasium as gym
import numpy as np

Gains = tuple[float, float, float]
Chooser = Callable[[gym.Env, np.ndarray], Gains]
"""Returns the gains for the cycle about to start in the given env (its last observation
given)."""


class StateError(NamedTuple):
    """An error put into a look-ahead copy's state."""

    velocity: np.ndarray
    """(nv,) added to ``qvel`` [m/s, rad/s]."""
    position: np.ndarray
    """(2,) added to the robot's horizontal position [m]."""


class CycleOutcome(NamedTuple):
    """One gait cycle played with one gain setting."""

    pitch_rate_rms: float
    """[rad/s]"""
    roll_rate_rms: float
    """[rad/s]"""
    contact_steps: int
    """Control steps with torso-terrain contact."""
    min_clearance: float = float("inf")
    """Smallest torso footprint clearance of the cycle [m] (the env's
    ``torso_footprint_clearance``; inf for an env without one)."""
    steps: int = 0
    """Control steps simulated (what the look-ahead spends of an env-step budget)."""


def gains_env(terrain: str = "blocks", **kwargs) -> gym.Env:
    """The env these measurements run on: HexapodIrregularTerrain-v0's held-out ``test`` beds
    of `terrain` in the "gains" action mode, the gait searching for ground at every touch-down
    (as the evaluation of the gains agents does); `kwargs` go to gym.make."""
    return gym.make(
        "HexapodIrregularTerrain-v0",
        task_distribution="test",
        terrain=terrain,
        gait_ground_search="always",
        action_mode="gains",
        **kwargs,
    )


def gain_grid(levels: Sequence[float]) -> list[Gains]:
    """Every (k_z, k_α, k_β) with each gain in ``levels``."""
    return [tuple(float(v) for v in g) for g in itertools.product(levels, repeat=3)]


def play_cycle(env: gym.Env, gains: Gains, error: StateError | None = None) -> CycleOutcome:
    """Play one gait cycle with ``gains`` on a copy of ``env`` (at a cycle start; ``env`` is
    left as it was), from the copy's state plus ``error``."""
    twin = copy.deepcopy(env)
    base = twin.unwrapped
    if error is not None:
        base.data.qvel += error.velocity
        root = base.model.jnt_qposadr[base.model.joint("root").id]  # the free joint's x, y
        base.data.qpos[root : root + 2] += error.position
    action = np.asarray(gains, dtype=twin.action_space.dtype)
    clearance = getattr(base, "torso_footprint_clearance", lambda: float("inf"))
    pitch_sq = roll_sq = 0.0
    steps = contacts = 0
    lowest = float("inf")
    while True:
        _, _, terminated, truncated, info = twin.step(action)
        pitch_sq += info["pitch_rate"] ** 2
        roll_sq += info["roll_rate"] ** 2
        contacts += bool(info["torso_contact"])
        lowest = min(lowest, clearance())
        steps += 1
        if terminated or truncated or base.gains_due:
            break
    twin.close()
    pitch, roll = float(np.sqrt(pitch_sq / steps)), float(np.sqrt(roll_sq / steps))
    return CycleOutcome(pitch, roll, contacts, lowest, steps)


SCORED = 4
"""The leading `CycleOutcome` fields a `CycleCost` reads."""


@dataclass(frozen=True)
class CycleCost:
    """What the look-ahead minimises over one cycle [rad/s]: pitch-rate RMS + roll-rate RMS
    + `contact` per torso-contact step + `clearance` per metre by which the torso's footprint
    clearance fell below `margin` [m].

    The clearance term (off by default) warns densely where contacts are rare: on training
    block beds the paper's gains touched in 1 of 1242 cycles, while their footprint clearance
    fell below 3 cm in 13 of 208 (10 beds); on 6 taller held-out beds every one of 928 contact
    steps fell in a cycle whose footprint clearance dropped below 1 cm."""

    contact: float = 1.0
    clearance: float = 0.0
    """[rad/s per m]"""
    margin: float = 0.0
    """[m]"""

    def __call__(self, outcome: CycleOutcome) -> float:
        return float(self.of_rows(np.asarray(outcome[:SCORED], dtype=np.float64)))

    def of_rows(self, outcomes: np.ndarray) -> np.ndarray:
        """Costs of outcome rows (..., 4): pitch-, roll-rate RMS, contact steps, clearance."""
        o = outcomes
        shortfall = np.maximum(0.0, self.margin - o[..., 3])
        return o[..., 0] + o[..., 1] + self.contact * o[..., 2] + self.clearance * shortfall


DEFAULT_COST = CycleCost()


@dataclass(frozen=True)
class Fixed:
    """The same gains every cycle."""

    gains: Gains

    def __call__(self, env: gym.Env, observation: np.ndarray | None = None) -> Gains:
        return self.gains


@dataclass(frozen=True)
class Lookahead:
    """The look-ahead choice (module docstring) over ``candidates`` (the first of equal cost)."""

    candidates: tuple[Gains, ...]
    cost: CycleCost = DEFAULT_COST
    state_noise: float = 0.0
    """σ of the copies' velocity error [m/s, rad/s]."""
    position_noise: float = 0.0
    """σ of the copies' horizontal position error per axis [m] (both 0: the exact
    look-ahead)."""
    samples: int = 1
    """Copies per candidate whose mean cost is compared (with noise)."""
    seed: int = 0
    """Seed of the errors (drawn per cycle from the seed and the env's clock)."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "candidates", tuple(dict.fromkeys(self.candidates)))
        if not self.candidates:
            raise ValueError("Lookahead needs at least one candidate setting")
        if not (self.state_noise >= 0.0 and self.position_noise >= 0.0 and self.samples >= 1):
            raise ValueError(
                "need state_noise >= 0, position_noise >= 0 and samples >= 1, got "
                f"{self.state_noise}, {self.position_noise}, {self.samples}"
            )

    @property
    def noisy(self) -> bool:
        """Whether the copies carry state errors (False: the exact look-ahead)."""
        return self.state_noise > 0.0 or self.position_noise > 0.0

    def state_errors(self, env: gym.Env) -> list[StateError | None]:
        """The cycle's state errors, one per copy ([None]: the exact look-ahead)."""
        if not self.noisy:
            return [None]
        base = env.unwrapped
        tick = round(base.data.time * 1e6)  # [µs]: a different draw every cycle
        rng = np.random.default_rng([self.seed, tick])
        velocity = rng.normal(0.0, self.state_noise, (self.samples, base.model.nv))
        position = rng.normal(0.0, self.position_noise, (self.samples, 2))
        return [StateError(v, p) for v, p in zip(velocity, position, strict=True)]

    def outcomes(self, env: gym.Env) -> list[list[CycleOutcome]]:
        """Every candidate's coming cycle on each copy: [candidate][copy], in `candidates`
        order (one copy, the exact one, without noise)."""
        errors = self.state_errors(env)
        return [[play_cycle(env, g, e) for e in errors] for g in self.candidates]

    def choose(self, outcomes: Sequence[Sequence[CycleOutcome]]) -> Gains:
        """The candidate of lowest mean cost over its copies (the first of equal cost)."""
        costs = [float(np.mean([self.cost(o) for o in copies])) for copies in outcomes]
        return self.candidates[costs.index(min(costs))]

    def __call__(self, env: gym.Env, observation: np.ndarray | None = None) -> Gains:
        return self.choose(self.outcomes(env))


def run_episode(env: gym.Env, seed: int, choose: Chooser) -> dict:
    """One episode in the "gains" action mode, ``choose`` asked at every cycle start.

    Returns the per-cycle pitch- and roll-rate RMS lists, torso-contact steps, success and the
    episode's control steps."""
    base = env.unwrapped
    if getattr(base, "action_mode", None) != "gains":
        raise ValueError("run_episode needs HexapodIrregularTerrain-v0 with action_mode='gains'")
    observation, _ = env.reset(seed=seed)
    pitch, roll = [], []
    action = np.asarray(base.reference_gains, dtype=env.action_space.dtype)
    steps = 0
    while True:
        if base.gains_due:
            action = np.asarray(choose(env, observation), dtype=env.action_space.dtype)
        observation, _, terminated, truncated, info = env.step(action)
        steps += 1
        stats = info.get("cycle_stats")
        if stats is not None:
            pitch.append(stats["pitch_rate_rms"])
            roll.append(stats["roll_rate_rms"])
        if terminated or truncated:
            break
    return {
        "pitch_rate_rms": pitch,
        "roll_rate_rms": roll,
        "contact_steps": int(info["torso_collisions"]),
        "success": bool(info["is_success"]),
        "steps": steps,
    }


def summarize(episodes: list[dict]) -> dict:
    """Pooled medians over all cycles of all episodes, summed contacts, successes."""
    pitch = [v for e in episodes for v in e["pitch_rate_rms"]]
    roll = [v for e in episodes for v in e["roll_rate_rms"]]
    return {
        "pitch_rate_median": float(np.median(pitch)),
        "roll_rate_median": float(np.median(roll)),
        "contact_steps": sum(e["contact_steps"] for e in episodes),
        "successes": sum(e["success"] for e in episodes),
        "episodes": len(episodes),
        "cycles": len(pitch),
    }


def beats(row: dict, reference: dict) -> bool:
    """Lower pitch- and roll-rate medians than ``reference`` with no more contact steps (the
    gains target of the learned agents)."""
    return (
        row["pitch_rate_median"] < reference["pitch_rate_median"]
        and row["roll_rate_median"] < reference["roll_rate_median"]
        and row["contact_steps"] <= reference["contact_steps"]
    )
