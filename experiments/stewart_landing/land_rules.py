"""What a recovery on HexapodStewartTilt-v1 needs: setting the lifted tripod down in time.

Policies on the tasks of a distribution, each task's outcome printed:

- ``analytical``: the paper's judgment and recovery (`TippingRecoveryPolicy`, as the benchmark
  runs it): once the FASM falls below ξ_f it chooses one adjustment leg, a foothold reached
  outward (the safety factor ρ) and a swing time, and distributes the foot forces.
- ``zero``: the hold posture, never landing (the benchmark's zero action).
- ``land``: the env's landing action (`landing_action`) at 1 from the first step the FASM falls
  below ξ_f, zero residuals: every lifted foot straight down where it is, no foothold choice.
- ``sensed_land``: the same from the sensors of the current step alone (no memory, as a per-step
  policy without a recurrent state acts): land while the FASM is below ξ_f or more than three
  feet touch the platform.

If ``sensed_land`` succeeds, a per-step policy with the landing action can express a recovery
(`configs/stewart_tilt_v1_ppo_landing.yaml`, docs/results.md).

    python experiments/stewart_landing/land_rules.py --distribution test --seeds 0 50 \
        [--policies analytical zero land sensed_land] [--json out.json]
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
from experiments import rule_studies  # noqa: E402

ENV_ID = "HexapodStewartTilt-v1"
POLICIES = ("analytical", "zero", "land", "sensed_land")
RESIDUAL_SCALE = 0.01
"""The residual scale of the landing env (the training config's; the residuals stay 0 here)."""


class LandAtTipping:
    """Zero residuals; the landing action at 1 for good once the FASM falls below ξ_f (or, with
    `sensed`, on every step the FASM is below ξ_f or more than three feet touch down), else -1.
    `land=False` never lands (the zero action)."""

    def __init__(self, env: gym.Env, sensed: bool = False, land: bool = True):
        base = env.unwrapped
        self.read = ObservationReader(base.task_description.observation_structure)
        self.threshold = base.tipping_threshold_deg
        self.sensed, self.land = sensed, land
        self.action = np.zeros(env.action_space.shape, dtype=np.float32)
        self.landing = False

    def reset(self) -> None:
        self.landing = False

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        o = self.read(observation)
        tipping = o["fasm_margin_deg"][0] < self.threshold
        if self.sensed:
            self.landing = tipping or o["foot_contact"].sum() > 3.5
        else:
            self.landing = self.landing or tipping
        self.action[-1] = 1.0 if (self.land and self.landing) else -1.0
        return self.action.copy()


def make(policy: str, distribution: str) -> tuple[gym.Env, Callable]:
    """The env and the policy of `policy` (one of `POLICIES`)."""
    if policy not in POLICIES:
        raise ValueError(f"unknown policy {policy!r}; policies: {list(POLICIES)}")
    if policy == "analytical":
        kwargs = ANALYTICAL_ENV_KWARGS.get(ENV_ID, {})
        env = gym.make(ENV_ID, task_distribution=distribution, **kwargs)
        return env, analytical_factory(ENV_ID)(env)
    env = gym.make(
        ENV_ID, task_distribution=distribution, landing_action=True, residual_scale=RESIDUAL_SCALE
    )
    return env, LandAtTipping(env, sensed=policy == "sensed_land", land=policy != "zero")


def run(policy: str, distribution: str, seeds: range) -> list[dict]:
    """Each task's outcome: success, tip-over, early landing, largest lean [deg], tilt rate."""
    return rule_studies.play(*make(policy, distribution), seeds, _row)


def _row(seed: int, info: dict) -> dict:
    return {
        **rule_studies.outcome(seed, info),
        "early_landing": bool(info["early_landing"]),
        "scenario": str(info["task"]["scenario"]),
        "tilt_rate_deg": float(info["task"]["tilt_rate_deg"]),
    }


def _summary(rows: list[dict]) -> str:
    landings = sum(r["early_landing"] for r in rows)
    return f"{rule_studies.counts(rows)}, {landings} early landings"


def main(argv: list[str] | None = None) -> dict[str, list[dict]]:
    description = __doc__.split("\n\n")[0]
    return rule_studies.main(description, POLICIES, run, _summary, (0, 50), "test", argv)


if __name__ == "__main__":
    main()
