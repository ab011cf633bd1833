"""What the analytical controller's successes on HexapodCliffWalk-v1 amount to: stopping.

Three policies on the tasks of a distribution, each task's outcome printed:

- ``analytical``: the paper's judgment and recovery (`GaitWithRecoveryPolicy`, joint mode, as the
  benchmark runs it): it walks the reference gait until the FASM falls below ξ_f, then puts the
  adjustment leg down and holds the recovered stance.
- ``hold``: the reference gait, held where it is (`clock_action`: the gait's clock stopped)
  from the first step the FASM falls below ξ_f. No recovery step: what stopping alone gives.
- ``sensed_hold``: the same hold from the sensors of the current step alone (no memory, as a
  per-step policy without a recurrent state acts): hold while the FASM is below ξ_f or a leg
  the gait's phase puts in stance carries no load. Held over the void, a leg stays unloaded,
  so the hold lasts.

If ``hold`` and ``sensed_hold`` succeed where the controller does, the cliff's success rule
asks for a stop at the edge, and a per-step policy with the clock action can express it
(`configs/cliff_walk_v1_ppo_clock.yaml`, docs/results.md).

    python experiments/cliff_stop/stop_rules.py --distribution train --seeds 1000 1020 \
        [--policies analytical hold sensed_hold] [--json out.json]
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import gymnasium as gym
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # run as a script from anywhere

import hexapod_envs  # noqa: E402, F401  (registers the ids)
from agents.policy import ObservationReader  # noqa: E402
from agents.registry import ANALYTICAL_ENV_KWARGS, analytical_factory  # noqa: E402
from agents.tripod_gait import TripodGaitPolicy  # noqa: E402
from experiments import rule_studies  # noqa: E402
from hexapod_envs.robots.heavy_duty import LEG_NAMES  # noqa: E402

ENV_ID = "HexapodCliffWalk-v1"
POLICIES = ("analytical", "hold", "sensed_hold")
STANCE_MARGIN = 0.02
"""Share of the cycle after touch-down (and before lift-off) in which a stance leg may still be
unloaded: the foot takes a few control steps to carry its share."""


class HoldAtTipping:
    """Zero residuals; the gait's clock stopped for good once the FASM falls below ξ_f (or,
    with `sensed`, on every step the sensors show tipping or an unloaded stance leg)."""

    def __init__(self, env: gym.Env, sensed: bool):
        base = env.unwrapped
        self.read = ObservationReader(base.task_description.observation_structure)
        self.threshold = base.tipping_threshold_deg
        self.reference = TripodGaitPolicy(env)  # reads the gait clock's phase
        self.sensed = sensed
        self.action = np.zeros(env.action_space.shape, dtype=np.float32)
        self.held = False

    def reset(self) -> None:
        self.held = False

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        o = self.read(observation)
        walking = o["gait_phase"][2] > 0.5
        tipping = walking and o["fasm_margin_deg"][0] < self.threshold
        if self.sensed:
            self.held = walking and (tipping or self._unloaded_stance_leg(observation, o))
        else:
            self.held = self.held or tipping
        self.action[-1] = -1.0 if self.held else 0.0
        return self.action.copy()

    def _unloaded_stance_leg(self, observation: np.ndarray, o: dict) -> bool:
        gait = self.reference.gait
        phase = self.reference.phase(observation)
        duty = gait.gait.duty_factor
        for k, leg in enumerate(LEG_NAMES):
            leg_phase = gait.leg_phase_at(leg, phase)
            if STANCE_MARGIN < leg_phase < duty - STANCE_MARGIN and o["foot_contact"][k] < 0.5:
                return True
        return False


def make(policy: str, distribution: str) -> tuple[gym.Env, Callable]:
    """The env and the policy of `policy` (one of `POLICIES`)."""
    if policy not in POLICIES:
        raise ValueError(f"unknown policy {policy!r}; policies: {list(POLICIES)}")
    if policy == "analytical":
        env = gym.make(ENV_ID, task_distribution=distribution, **ANALYTICAL_ENV_KWARGS[ENV_ID])
        return env, analytical_factory(ENV_ID)(env)
    env = gym.make(ENV_ID, task_distribution=distribution, clock_action=True)
    return env, HoldAtTipping(env, sensed=policy == "sensed_hold")


def run(policy: str, distribution: str, seeds: range) -> list[dict]:
    """Each task's outcome: success, tip-over, largest tilt, share below ξ_f, distance [m]."""
    return rule_studies.play(*make(policy, distribution), seeds, _row)


def _row(seed: int, info: dict) -> dict:
    return {
        **rule_studies.outcome(seed, info),
        "tipping_share": float(info["tipping_share"]),
        "distance_m": float(info["distance"]),
        "cliff_x": float(info["task"]["cliff_x"]),
    }


def _summary(rows: list[dict]) -> str:
    distances = " ".join(f"{r['distance_m']:.2f}" for r in rows)
    return f"{rule_studies.counts(rows)}; distances {distances}"


def main(argv: list[str] | None = None) -> dict[str, list[dict]]:
    description = __doc__.split("\n\n")[0]
    return rule_studies.main(description, POLICIES, run, _summary, (1000, 1020), "train", argv)


if __name__ == "__main__":
    main()
