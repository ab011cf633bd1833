"""Rewards that rank like the success metric, on each env's paper scenario.

Episodes (seed 0, full length) of the reference motion (zero action), the analytical controller,
the uniform random policy, and a constant destabilising action that makes the robot tip over
(found by trying constant +-1 patterns; named per scenario below). Each env bounds its per-step
terms and pays their bound as an ``alive`` term while the robot is up (and the ditch pays the
remaining steps' bound on success), so these rankings hold by construction: they fail if a new or
re-weighted term breaks a bound.
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


@pytest.mark.parametrize("scenario", list(SCENARIOS))
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


@pytest.mark.parametrize("scenario", ["cliff", "ramp", "blocks"])
def test_tipping_never_pays_more_than_staying_up_with_random_actions(scenario):
    """The random policy stays up on these scenarios; tipping over must still pay less."""
    random = episode(scenario, "random")
    assert not random["tipped"]
    assert episode(scenario, "tipping")["return"] < random["return"]


def test_not_crossing_the_ditch_pays_less_than_crossing():
    standing = episode("ditch", "standing_plus")
    crossing = episode("ditch", "zero")
    assert crossing["success"] and not standing["success"]
    assert standing["return"] < crossing["return"]


@pytest.mark.parametrize(
    "env_id", ["HexapodCliffWalk-v0", "HexapodIrregularTerrain-v0", "HexapodDitchCrossing-v0"]
)
def test_every_upright_step_of_random_actions_earns_at_least_zero(env_id):
    """The alive term covers the bounded costs: no step of a robot that is up is negative."""
    env = gym.make(env_id)
    obs, _ = env.reset(seed=1)
    env.action_space.seed(1)
    for _ in range(200):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        if terminated or truncated:
            break
        assert reward >= -1e-9, {k: v for k, v in info.items() if k.startswith("reward_")}
    env.close()


def _worst_heavy_duty(env):
    env._prev_cog_x = float(env._cog[0]) + 5.0  # walking backwards far beyond the clip
    env._fasm_deg = -90.0
    env._power = 1e12


def _worst_athena(env):
    env._prev_cog_x = float(env._cog[0]) + 5.0
    env._gyro = np.array([100.0, 100.0, 0.0])
    env._height = env.reference_height + 1.0
    env._touched = True


def _worst_ditch(env):
    env._prev_cog_x = float(env._cog[0]) + 5.0
    env._static_margin = -10.0
    env._power = 1e12


@pytest.mark.parametrize(
    ("env_id", "worst"),
    [
        ("HexapodCliffWalk-v0", _worst_heavy_duty),
        ("HexapodStewartTilt-v0", _worst_heavy_duty),
        ("HexapodIrregularTerrain-v0", _worst_athena),
        ("HexapodDitchCrossing-v0", _worst_ditch),
    ],
)
def test_the_alive_term_pays_exactly_the_worst_step_of_an_upright_robot(env_id, worst):
    """Every bounded term at its worst at once (backwards beyond the speed clip, the margin or
    steadiness at its floor, the effort cap, a torso contact): the costs sum to minus the
    ``alive`` term, so no step of a robot that is up is negative and the bound is not loose."""
    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    worst(env)
    terms = env._reward_terms(tipped=False)
    costs = sum(v for k, v in terms.items() if k != "alive")
    assert terms["alive"] == pytest.approx(env.step_cost_bound()) and terms["alive"] > 0
    assert costs == pytest.approx(-terms["alive"], rel=1e-9)


@pytest.mark.parametrize("cap", [1.0, 1.5])
def test_the_forward_term_counts_speed_up_to_its_cap(cap):
    env = gym.make("HexapodCliffWalk-v0", reward={"forward_cap": cap}).unwrapped
    env.reset(seed=0)
    v_ref = env.gait.gait.body_speed
    env._prev_cog_x = float(env._cog[0]) - 2.0 * v_ref * env.control_dt  # twice the reference
    assert env._reward_terms(tipped=False)["forward"] == pytest.approx(cap)
