"""Rewards that rank like the success metric, on each env's paper scenario.

Episodes (seed 0, full length) of the reference motion (zero action), the analytical controller,
the uniform random policy, and a constant destabilising action that makes the robot tip over
(found by trying constant +-1 patterns; named per scenario below). Where a ranking does not hold
today the test is an xfail whose reason gives the measured returns and the cause.
"""

from functools import cache

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401  (registers the env ids)
from agents.policy import RandomPolicy, ZeroPolicy
from agents.registry import analytical_policy

SCENARIOS = {
    # name: (env id, kwargs of the paper scenario)
    "cliff": ("HexapodCliffWalk-v0", {}),
    "stewart_climb": ("HexapodStewartTilt-v0", {"scenario": "climb"}),
    "stewart_descend": ("HexapodStewartTilt-v0", {"scenario": "descend"}),
    "stewart_side": ("HexapodStewartTilt-v0", {"scenario": "side"}),
    # The robot cannot tip at the registered tip_over_angle_deg=60 (no constant or random action
    # rolls the torso that far); 30 deg still lets the reference and the controller walk upright.
    "ramp": ("HexapodIrregularTerrain-v0", {"tip_over_angle_deg": 30.0}),
    "blocks": ("HexapodIrregularTerrain-v0", {"terrain": "blocks", "tip_over_angle_deg": 30.0}),
    "ditch": ("HexapodDitchCrossing-v0", {}),
}


def _split(n: int, first: float) -> np.ndarray:
    """First half of the action `first`, second half `-first` (legs of one side vs the other)."""
    action = np.full(n, -first)
    action[: n // 2] = first
    return action


TIPPING_ACTIONS = {
    "cliff": lambda n: -np.ones(n),  # all joints to the low end of their residual
    "stewart_climb": lambda n: _split(n, 1.0),
    "stewart_descend": lambda n: _split(n, 1.0),
    "stewart_side": lambda n: _split(n, 1.0),
    "ramp": lambda n: _split(n, 1.0),
    "blocks": lambda n: _split(n, 1.0),
    "ditch": lambda n: _split(n, 1.0),
}


class ConstantPolicy:
    def __init__(self, action: np.ndarray):
        self.action = action.astype(np.float32)

    def reset(self) -> None:
        pass

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        return self.action


@cache
def episode(scenario: str, policy: str) -> dict:
    """Return, length, tipped and success of one seed-0 episode of `policy` on `scenario`."""
    env_id, kwargs = SCENARIOS[scenario]
    env = gym.make(env_id, **kwargs)
    n = env.action_space.shape[0]
    make = {
        "zero": lambda: ZeroPolicy(env.action_space),
        "analytical": lambda: analytical_policy(env),
        "random": lambda: RandomPolicy(env.action_space, seed=0),
        "tipping": lambda: ConstantPolicy(TIPPING_ACTIONS[scenario](n)),
        "standing_plus": lambda: ConstantPolicy(np.ones(n)),
    }[policy]
    pol = make()
    obs, _ = env.reset(seed=0)
    pol.reset()
    total, steps = 0.0, 0
    while True:
        obs, reward, terminated, truncated, info = env.step(pol(obs))
        total += float(reward)
        steps += 1
        if terminated or truncated:
            env.close()
            return {
                "return": total,
                "length": steps,
                "tipped": bool(info["is_tipped_over"]),
                "success": bool(info["is_success"]),
            }


BLOCKS_XFAIL = (
    "on the blocks the steadiness costs of walking exceed the tip-over penalty (50): tipping at "
    "step 100 returns -117, the reference gait's full episode -419 and the paper controller's "
    "-744 (in the default residual mode its targets are clipped on 39% of the steps; in the "
    "joint mode it returns 146.5). Fix in the env as for the early tip-over: a tip-over penalty "
    "of at least the remaining steps' bounded cost."
)


@pytest.mark.parametrize(
    "scenario",
    [
        pytest.param(s, marks=pytest.mark.xfail(strict=True, reason=BLOCKS_XFAIL))
        if s == "blocks"
        else s
        for s in SCENARIOS
    ],
)
def test_tip_over_returns_less_than_the_reference_and_the_controller(scenario):
    tipped = episode(scenario, "tipping")
    assert tipped["tipped"], f"{scenario}: the destabilising action did not tip ({tipped})"
    assert tipped["return"] < episode(scenario, "zero")["return"]
    analytical = episode(scenario, "analytical")
    assert not analytical["tipped"]
    assert tipped["return"] < analytical["return"]


@pytest.mark.parametrize("scenario", list(SCENARIOS))
def test_analytical_controller_returns_more_than_random_actions(scenario):
    assert episode(scenario, "analytical")["return"] > episode(scenario, "random")["return"]


EARLY_TIP_XFAIL = (
    "per-step costs are unbounded against a fixed tip-over penalty, so ending the episode by "
    "tipping pays more than flailing upright. Measured (seed 0): cliff tip-over 452 vs random "
    "upright -2611; ramp (tip at 30 deg) tip-over -67 at step 62 vs random upright -3084; blocks "
    "tip-over -117 at step 100 vs random upright -2107. Fix in "
    "the envs: bound each step's cost and make the tip-over penalty at least the cost of the "
    "remaining steps, e.g. tip_over = -(P + remaining_steps x max per-step cost)."
)


@pytest.mark.parametrize(
    "scenario",
    [
        pytest.param(s, marks=pytest.mark.xfail(strict=True, reason=EARLY_TIP_XFAIL))
        for s in ("cliff", "ramp", "blocks")
    ],
)
def test_tipping_never_pays_more_than_staying_up_with_random_actions(scenario):
    """The random policy stays up on these scenarios; tipping over must still pay less."""
    random = episode(scenario, "random")
    assert not random["tipped"]
    assert episode(scenario, "tipping")["return"] < random["return"]


@pytest.mark.xfail(
    strict=True,
    reason="the ditch's per-step stability reward pays a robot that never crosses: constant "
    "+1 stands for the full 1500 steps (302.1, no success) vs the reference crossing in 1017 "
    "steps (276.4, success). Fix in the env: a success bonus of at least the stability reward "
    "of the remaining steps, or the stability term only while progressing.",
)
def test_not_crossing_the_ditch_pays_less_than_crossing():
    standing = episode("ditch", "standing_plus")
    crossing = episode("ditch", "zero")
    assert crossing["success"] and not standing["success"]
    assert standing["return"] < crossing["return"]
