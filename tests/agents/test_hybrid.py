"""Hybrid policies (agents/hybrid.py): a zero residual is the analytical controller, exactly, in
the action modes the shipped configs use; the safety override and its hysteresis."""

import gymnasium as gym
import numpy as np
import pytest
from helpers.paths import REPO

import hexapod_envs  # noqa: F401  (registers the env ids)
from agents.hybrid import HybridCore, HybridPolicy, HybridSettings, HybridWrapper
from agents.registry import analytical_policy
from agents.run_files.train_config import load_train_config

CONFIGS = REPO / "configs"
HYBRID_CONFIGS = [  # residual mode: a zero learned action is the analytical controller
    "stewart_tilt_hybrid.yaml",
    "irregular_terrain_hybrid.yaml",
    "irregular_terrain_gains.yaml",
    "ditch_crossing_hybrid.yaml",
]


def config_env(name: str) -> gym.Env:
    config = load_train_config(CONFIGS / name)
    return gym.make(config.env.id, **config.env.kwargs)


def analytical_episode(env: gym.Env, seed: int) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Observations and actions of one full episode of the analytical controller on its own."""
    policy = analytical_policy(env)
    obs, _ = env.reset(seed=seed)
    policy.reset()
    observations, actions = [obs], []
    while True:
        action = policy(obs)
        obs, _, terminated, truncated, _ = env.step(action)
        observations.append(obs)
        actions.append(np.asarray(action))
        if terminated or truncated:
            return observations, actions


@pytest.mark.parametrize("name", HYBRID_CONFIGS)
def test_zero_residual_reproduces_the_analytical_controller(name):
    """Full episode, same seed: identical observations at every step, and the analytical actions
    lie inside the action space (the controller has full authority in the config's mode)."""
    env = config_env(name)
    expected, actions = analytical_episode(env, seed=1)
    space = env.action_space
    assert all(np.all(a >= space.low) and np.all(a <= space.high) for a in actions)

    wrapped = HybridWrapper(config_env(name), load_train_config(CONFIGS / name).hybrid)
    obs, _ = wrapped.reset(seed=1)
    observed = [obs]
    zero = np.zeros(wrapped.action_space.shape, dtype=wrapped.action_space.dtype)
    for _ in range(len(expected) - 1):
        obs, _, terminated, truncated, info = wrapped.step(zero)
        observed.append(obs)
        assert info["safety_override"] is False
    assert terminated or truncated
    assert len(observed) == len(expected)
    for step, (a, b) in enumerate(zip(expected, observed, strict=True)):
        np.testing.assert_array_equal(a, b, err_msg=f"{name}: step {step}")


def test_cliff_safety_filter_walks_the_reference_and_hands_over_to_the_recovery():
    """configs/cliff_walk_hybrid.yaml (safety mode): with a zero learned action the env action
    is the reference gait (zero) while the recovery is not in control, the recovery's action
    while it is; it takes control when the observed FASM falls below ξ_f and hands back once
    it is at ξ_f + the release margin again. On the paper's cliff both hand-overs happen and
    the robot does not tip."""
    name = "cliff_walk_hybrid.yaml"
    settings = load_train_config(CONFIGS / name).hybrid
    assert settings.mode == "safety"
    env = config_env(name)
    core = HybridCore(
        env,
        HybridSettings(
            mode="safety", scale=settings.scale, release_margin_deg=settings.release_margin_deg
        ),
    )
    fasm_at = env.unwrapped.observation_structure["fasm_margin_deg"]
    xi, release = core.threshold_deg, core.threshold_deg + settings.release_margin_deg
    obs, _ = env.reset(seed=0)
    core.reset()
    recovery, computed = core.base, []
    core.base = lambda o: computed.append(np.asarray(recovery(o), dtype=np.float32)) or computed[-1]
    overrides = releases = 0
    in_control = False
    while True:
        fasm = float(obs[fasm_at][0])
        expected = fasm < release if in_control else fasm < xi
        releases += in_control and not expected
        action, override = core(obs, np.zeros(18, dtype=np.float32))
        assert override == expected, (fasm, in_control)
        in_control = override
        if override:
            overrides += 1
            np.testing.assert_array_equal(action, np.clip(computed[-1], -1.0, 1.0))
        else:
            np.testing.assert_array_equal(action, np.zeros(18))
        obs, _, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            break
    assert overrides > 0 and releases > 0 and not info["is_tipped_over"]


def test_controller_is_reset_at_every_env_reset():
    """Two episodes in a row through the wrapper equal two fresh analytical episodes."""
    env = config_env("stewart_tilt_hybrid.yaml")
    wrapped = HybridWrapper(env, HybridSettings())
    zero = np.zeros(wrapped.action_space.shape, dtype=np.float32)
    for seed in (3, 4):
        expected, _ = analytical_episode(config_env("stewart_tilt_hybrid.yaml"), seed)
        obs, _ = wrapped.reset(seed=seed)
        for _ in expected[1:]:
            obs, *_ = wrapped.step(zero)
        np.testing.assert_array_equal(obs, expected[-1])


def test_residual_adds_scale_times_action_and_clips_to_the_space():
    """env action = clip(analytical + scale x learned), with an analytical action that is not
    zero (the cliff controller's residual is zero until a recovery, so a stand-in acts)."""
    env = config_env("cliff_walk_hybrid.yaml")
    base = ScriptedBase(0.3, env.action_space.shape)
    core = HybridCore(env, HybridSettings(scale=0.05), base=base)
    obs, _ = env.reset(seed=0)
    core.reset()
    learned = np.linspace(-1, 1, 18).astype(np.float32)
    action, override = core(obs, learned)
    np.testing.assert_allclose(action, np.clip(0.3 + 0.05 * learned, -1, 1), atol=1e-6)
    assert not override and base.calls == 1 and base.resets == 1
    big, _ = HybridCore(env, HybridSettings(scale=10.0), base=base)(obs, np.ones(18))
    np.testing.assert_array_equal(big, env.action_space.high)  # 0.3 + 10 clipped
    # One scale per dimension: 0 keeps a dimension at the analytical action.
    scales = [0.0] * 17 + [0.5]
    per_dim, _ = HybridCore(env, HybridSettings(scale=scales), base=base)(obs, learned)
    np.testing.assert_allclose(per_dim, np.r_[np.full(17, 0.3), 0.3 + 0.5], atol=1e-6)
    with pytest.raises(ValueError, match="hybrid scale has 2 values, one per action dimension"):
        HybridCore(env, HybridSettings(scale=[0.1, 0.2]), base=base)


class ScriptedBase:
    """A stand-in analytical controller returning a constant action; counts its calls."""

    def __init__(self, value: float, shape: tuple[int, ...]):
        self.action = np.full(shape, value, dtype=np.float32)
        self.calls = self.resets = 0

    def reset(self):
        self.resets += 1

    def __call__(self, observation):
        self.calls += 1
        return self.action.copy()


def fasm_obs(env: gym.Env, fasm: float) -> np.ndarray:
    obs = np.zeros(env.observation_space.shape, dtype=np.float32)
    obs[env.unwrapped.observation_structure["fasm_margin_deg"]] = fasm
    return obs


def test_safety_override_with_hysteresis():
    """Below ξ the analytical action applies; it keeps control until FASM >= ξ + margin; the
    controller is stepped every step, also while the learned policy acts."""
    env = config_env("stewart_tilt_hybrid.yaml")
    base = ScriptedBase(0.5, env.action_space.shape)
    settings = HybridSettings(mode="safety", scale=1.0, release_margin_deg=5.0)
    core = HybridCore(env, settings, base=base)
    assert core.threshold_deg == getattr(env.unwrapped, "tipping_threshold_deg", 20.0)
    learned = np.full(env.action_space.shape, -0.25, dtype=np.float32)
    expected = []
    for fasm in (30.0, 21.0, 19.9, 22.0, 24.9, 25.0, 19.0, 40.0):
        action, override = core(fasm_obs(env, fasm), learned)
        expected.append(override)
        np.testing.assert_array_equal(action, base.action if override else learned)
    assert expected == [False, False, True, True, True, False, True, False]
    assert base.calls == 8


def test_residual_mode_safety_filter_drops_the_residual_below_threshold():
    env = config_env("stewart_tilt_hybrid.yaml")
    base = ScriptedBase(0.1, env.action_space.shape)
    core = HybridCore(env, HybridSettings(scale=0.5, safety_filter=True), base=base)
    ones = np.ones(env.action_space.shape, dtype=np.float32)
    high, override = core(fasm_obs(env, 35.0), ones)
    np.testing.assert_allclose(high, 0.6)
    assert not override
    low, override = core(fasm_obs(env, 5.0), ones)
    np.testing.assert_allclose(low, 0.1)
    assert override
    plain = HybridCore(env, HybridSettings(scale=0.5), base=ScriptedBase(0.1, ones.shape))
    assert plain(fasm_obs(env, 5.0), ones)[1] is False  # no filter: never overrides


def test_threshold_comes_from_the_env_or_the_settings():
    env = gym.make("HexapodIrregularTerrain-v0", action_mode="joint")
    assert HybridCore(env, HybridSettings()).threshold_deg == env.unwrapped.tipping_threshold_deg
    assert HybridCore(env, HybridSettings(threshold_deg=12.5)).threshold_deg == 12.5


def test_wrapper_records_the_override_in_info_on_a_real_tilt():
    """Safety mode on the Stewart tilt with the reference hold as the learned action: the
    recovery takes over when the margin falls below ξ, as info["safety_override"] shows."""
    env = gym.make("HexapodStewartTilt-v0", scenario="side")
    wrapped = HybridWrapper(env, HybridSettings(mode="safety", scale=1.0))
    wrapped.reset(seed=0)
    zero = np.zeros(wrapped.action_space.shape, dtype=np.float32)
    overrides, tipped = [], False
    while True:
        _, _, terminated, truncated, info = wrapped.step(zero)
        overrides.append(info["safety_override"])
        tipped = tipped or bool(info.get("is_tipped_over"))
        if terminated or truncated:
            break
    assert not overrides[0] and any(overrides)
    assert not tipped

    env.reset(seed=0)  # the same episode without the safety fallback tips over
    while True:
        _, _, terminated, truncated, info = env.step(zero)
        if terminated or truncated:
            break
    assert info["is_tipped_over"]


def test_policy_combines_a_learned_policy_like_the_wrapper():
    """Over an episode into the recovery (whose actions are not zero, from step 308 on this
    task), the policy's action is the analytical controller's plus scale x the learned one."""
    env = config_env("stewart_tilt_hybrid.yaml")
    learned = ScriptedBase(0.3, env.action_space.shape)
    policy = HybridPolicy(learned, env, HybridSettings(scale=0.05))
    obs, _ = env.reset(seed=2)
    policy.reset()
    reference = analytical_policy(env)
    reference.reset()
    recovering = 0
    for _ in range(340):
        base = reference(obs)
        action = policy(obs)
        np.testing.assert_allclose(action, np.clip(base + 0.015, -1, 1), atol=1e-6)
        recovering += bool(np.any(base != 0))
        obs, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            break
    assert recovering > 0
    assert learned.resets == 1 and policy.last_override is False


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"mode": "blend"}, "hybrid mode must be one of"),
        ({"scale": 0.0}, "hybrid scale must be a finite number > 0"),
        ({"scale": float("nan")}, "hybrid scale must be a finite number > 0"),
        ({"scale": [0.0, -0.1]}, "scale per action dimension must be finite numbers >= 0"),
        ({"scale": [0.0, 0.0]}, "scale must not be 0 in every dimension"),
        ({"release_margin_deg": -1.0}, "release_margin_deg must be a finite number >= 0"),
        ({"threshold_deg": float("inf")}, "threshold_deg must be finite or None"),
    ],
)
def test_bad_settings_are_clear_errors(settings, message):
    with pytest.raises(ValueError, match=message):
        HybridSettings(**settings)


def test_env_without_analytical_controller_is_a_clear_error():
    env = gym.make("HexapodStewartTilt-v0")
    from agents import registry

    saved = registry.ANALYTICAL_POLICIES.pop("HexapodStewartTilt-v0")
    try:
        with pytest.raises(ValueError, match="no analytical controller registered"):
            HybridWrapper(env, HybridSettings())
    finally:
        registry.ANALYTICAL_POLICIES["HexapodStewartTilt-v0"] = saved


def test_override_cost_is_a_named_reward_term_of_the_overridden_steps():
    """With ξ = 90° the override acts at every step: the wrapper's reward is the env's less the
    cost, named in info; with ξ = -90° it never acts and nothing is charged."""
    rewards = {}
    for threshold, cost in ((90.0, 0.0), (90.0, 0.3), (-90.0, 0.3)):
        settings = HybridSettings(mode="safety", threshold_deg=threshold, override_cost=cost)
        wrapped = HybridWrapper(config_env("cliff_walk_hybrid.yaml"), settings)
        wrapped.reset(seed=1)
        steps = [wrapped.step(np.zeros(18, np.float32)) for _ in range(5)]
        rewards[threshold, cost] = np.array([s[1] for s in steps])
        overrides = {s[4]["safety_override"] for s in steps}
        assert overrides == {threshold > 0}
        charged = [s[4].get("reward_safety_override") for s in steps]
        assert charged == [(-cost if threshold > 0 else 0.0) if cost else None] * 5
    np.testing.assert_allclose(rewards[90.0, 0.3], rewards[90.0, 0.0] - 0.3)
    with pytest.raises(ValueError, match="override_cost needs the safety override"):
        HybridSettings(override_cost=0.1)
    with pytest.raises(ValueError, match="override_cost must be a finite number >= 0"):
        HybridSettings(mode="safety", override_cost=-1.0)


def test_a_copy_of_a_hybrid_or_its_controller_reads_the_env_it_belongs_to():
    """A deep copy of an analytical policy alone keeps reading its env (which its user resets);
    a deep copy of a wrapper holding both reads the copied env. The ditch's task description
    (read-only mappings) copies too."""
    import copy

    env = gym.make("HexapodStewartTilt-v0", task_distribution="train", action_mode="joint")
    policy = analytical_policy(env)
    obs, _ = env.reset(seed=0)
    policy.reset()
    policy(obs)
    twin = copy.deepcopy(policy)
    assert twin.env is policy.env
    for seed in range(1, 4):  # the held tripod changes from task to task
        obs, _ = env.reset(seed=seed)
        policy.reset(), twin.reset()
        np.testing.assert_array_equal(policy(obs), twin(obs))
    for name, kwargs in (("HexapodDitchCrossing-v0", {"action_mode": "joint"}), (env.spec.id, {})):
        wrapper = HybridWrapper(gym.make(name, **kwargs), HybridSettings())
        copied = copy.deepcopy(wrapper)
        assert copied.core.base.env in (copied.env, copied.unwrapped)
        assert wrapper.core.base.env in (wrapper.env, wrapper.unwrapped)


def test_the_recovery_judges_tipping_at_the_envs_threshold():
    env = gym.make("HexapodStewartTilt-v0", tipping_threshold_deg=25.0)
    assert analytical_policy(env).controller.config.threshold_deg == 25.0
    assert (
        analytical_policy(gym.make("HexapodStewartTilt-v0")).controller.config.threshold_deg == 20.0
    )


def test_a_hybrid_model_refuses_an_env_that_reads_its_action_otherwise(tmp_path):
    """A Stewart-tilt hybrid learns its action at the env's residual_scale 2: at 0.25 its actions
    would mean something else, so loading it there names the setting."""
    from helpers.stewart_hybrid_runs import train

    from agents.ppo import PPOPolicy
    from agents.run_files.errors import UserError

    model = train(tmp_path, "hybrid") / "final"
    with pytest.raises(UserError, match=r"residual_scale=2.0 but the env has residual_scale=0.25"):
        PPOPolicy.load(model, gym.make("HexapodStewartTilt-v0", residual_scale=0.25))
    PPOPolicy.load(model, gym.make("HexapodStewartTilt-v0"))
