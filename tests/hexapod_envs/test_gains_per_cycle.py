"""GainsPerCycle: one learner step per gait cycle of the irregular terrain's "gains" mode."""

import gymnasium as gym
import numpy as np
import pytest
from helpers.paths import REPO

import hexapod_envs  # noqa: F401  (registers the env ids)
from hexapod_envs.wrappers import GainsPerCycle

ENV_ID = "HexapodIrregularTerrain-v0"
GAINS = {"action_mode": "gains", "task_distribution": "train", "max_episode_steps": 200}


def _policy(obs: np.ndarray) -> np.ndarray:
    """Gains that depend on the observation, so that a shifted decision would change them."""
    return np.clip(0.5 + 0.4 * np.tanh(obs[:3]), 0.0, 1.0).astype(np.float32)


def _run(env: gym.Env, seed: int) -> tuple[np.ndarray, float, list[int]]:
    obs, _ = env.reset(seed=seed)
    total, cycle_steps = 0.0, []
    while True:
        obs, reward, terminated, truncated, info = env.step(_policy(obs))
        total += reward
        cycle_steps.append(info.get("cycle_steps", 1))
        if terminated or truncated:
            return obs, total, cycle_steps


def test_a_policy_acts_the_same_per_cycle_and_per_step():
    """The env reads the gains only at cycle starts, and the wrapper hands the policy exactly the
    observation before each cycle start: same trajectory, same summed reward."""
    wrapped = GainsPerCycle(gym.make(ENV_ID, **GAINS))
    plain = gym.make(ENV_ID, **GAINS)
    obs_w, return_w, cycle_steps = _run(wrapped, seed=4)
    obs_p, return_p, _ = _run(plain, seed=4)
    np.testing.assert_array_equal(obs_w, obs_p)
    assert return_w == pytest.approx(return_p, rel=1e-12)
    ticks = wrapped.unwrapped.controller.ticks_per_cycle
    assert sum(cycle_steps) == 200
    # A cycle's steps (plus ground-search waits at the next cycle start, if any).
    assert min(cycle_steps[:-1]) >= ticks
    assert len(cycle_steps) == pytest.approx(200 / ticks, abs=1)


def test_a_cycles_info_sums_the_reward_terms_of_its_control_steps():
    """The reward terms in a cycle's info are the sums over its control steps (training logs
    each episode's terms from them), not the last step's values."""

    def term_totals(env: gym.Env) -> dict[str, float]:
        obs, _ = env.reset(seed=4)
        totals: dict[str, float] = {}
        while True:
            obs, _, terminated, truncated, info = env.step(_policy(obs))
            for key in (k for k in info if k.startswith("reward_")):
                totals[key] = totals.get(key, 0.0) + info[key]
            if terminated or truncated:
                return totals

    per_cycle = term_totals(GainsPerCycle(gym.make(ENV_ID, **GAINS)))
    per_step = term_totals(gym.make(ENV_ID, **GAINS))
    assert per_cycle.keys() == per_step.keys() and len(per_step) >= 3
    for key, total in per_step.items():
        assert per_cycle[key] == pytest.approx(total, rel=1e-9, abs=1e-9), key


def test_the_gains_read_at_a_cycle_start_are_the_decision():
    """Changing the action between cycle starts changes nothing; at a cycle start it does."""
    env = gym.make(ENV_ID, **GAINS).unwrapped
    env.reset(seed=0)
    assert env.gains_due
    env.step(np.array([0.2, 0.3, 0.4], dtype=np.float32))
    assert not env.gains_due
    env.step(np.array([1.0, 1.0, 1.0], dtype=np.float32))
    assert env.controller.gains == pytest.approx((0.2, 0.3, 0.4))


def test_other_action_modes_and_envs_are_refused_by_name():
    with pytest.raises(ValueError, match="action_mode='gains'.*'residual'"):
        GainsPerCycle(gym.make(ENV_ID))
    with pytest.raises(ValueError, match="action_mode='gains'.*CliffWalkEnv"):
        GainsPerCycle(gym.make("HexapodCliffWalk-v0"))


def test_env_spec_decision_builds_the_wrapper_and_names_bad_values():
    from agents.pipeline.envs import EnvSpec
    from agents.run_files.errors import UserError

    spec = EnvSpec(ENV_ID, dict(GAINS), gym_packages=["hexapod_envs"], decision="gait_cycle")
    env = spec.make()
    env.reset(seed=0)
    assert env.step(np.zeros(3, dtype=np.float32))[-1]["cycle_steps"] >= 1
    with pytest.raises(UserError, match="gait_cycle.*action_mode='gains'"):
        EnvSpec(ENV_ID, gym_packages=["hexapod_envs"], decision="gait_cycle").make()
    with pytest.raises(UserError, match="'step', 'gait_cycle' or 'episode', got 'cycle'"):
        EnvSpec(ENV_ID, dict(GAINS), gym_packages=["hexapod_envs"], decision="cycle").make()


def test_a_baseline_cycle_is_replayed_from_the_same_state_and_subtracted():
    """With baseline_action the reward is the cycle's reward minus that of the same cycle played
    with the baseline action from the same state; the real trajectory is unchanged."""
    paper = np.array([0.6, 0.4, 0.4], dtype=np.float32)
    other = np.array([0.9, 0.1, 0.7], dtype=np.float32)
    env = GainsPerCycle(gym.make(ENV_ID, **GAINS), baseline_action=paper)
    env.reset(seed=2)
    _, reward, _, _, info = env.step(paper)
    assert reward == 0.0 and info["baseline_steps"] == info["cycle_steps"]
    obs, reward, _, _, info = env.step(other)
    assert reward == info["cycle_reward"] - info["baseline_reward"] != 0.0

    # The same two cycles without a baseline: same observation, same cycle reward.
    plain = GainsPerCycle(gym.make(ENV_ID, **GAINS))
    plain.reset(seed=2)
    plain.step(paper)
    obs_plain, reward_plain, _, _, info_plain = plain.step(other)
    np.testing.assert_array_equal(obs, obs_plain)
    assert (info["cycle_reward"], info["cycle_steps"]) == (reward_plain, info_plain["cycle_steps"])
    # The baseline: the paper's gains from the state after the first cycle, as many steps.
    replay = GainsPerCycle(gym.make(ENV_ID, **GAINS))
    replay.reset(seed=2)
    replay.step(paper)
    baseline = sum(float(replay.env.step(paper)[1]) for _ in range(info["baseline_steps"]))
    assert info["baseline_reward"] == baseline


def test_baseline_settings_are_checked_by_name():
    from agents.pipeline.envs import EnvSpec
    from agents.run_files.errors import UserError

    with pytest.raises(ValueError, match="baseline_action .* is not in the action space"):
        GainsPerCycle(gym.make(ENV_ID, **GAINS), baseline_action=[2.0, 0.0, 0.0])
    spec = EnvSpec(ENV_ID, dict(GAINS), gym_packages=["hexapod_envs"], cycle_baseline="zero")
    with pytest.raises(UserError, match="'none' or 'zero_action', got 'zero'"):
        spec.make()
    spec = EnvSpec(ENV_ID, dict(GAINS), gym_packages=["hexapod_envs"], cycle_baseline="zero_action")
    with pytest.raises(UserError, match="cycle_baseline needs env.decision: gait_cycle"):
        spec.make()
    spec.decision = "gait_cycle"
    env = spec.make()
    env.reset(seed=0)
    assert env.step(np.zeros(3, dtype=np.float32))[1] == 0.0  # the zero action is the baseline


def test_learning_curve_unit_follows_the_run_config(tmp_path):
    from agents.pipeline.learning_curve import load_learning_curve

    np.savez(
        tmp_path / "evaluations.npz",
        timesteps=np.array([0, 10]),
        results=np.zeros((2, 1)),
        ep_lengths=np.ones((2, 1)),
    )
    assert load_learning_curve(tmp_path).unit == "env steps"
    (tmp_path / "config.yaml").write_text("env: {id: X, decision: gait_cycle}\n")
    assert load_learning_curve(tmp_path).unit == "gait cycles"


def test_a_gait_cycle_run_trains_per_cycle_and_evaluates_per_step(tmp_path):
    """train.py with env.decision=gait_cycle: the learner's steps are gait cycles (64 of them,
    far more than 64 env steps), the evaluations play whole episodes of env steps, and the saved
    model plays the env at every step, as evaluate.py does."""

    from agents.pipeline.cli import train_main
    from agents.ppo import PPOPolicy

    config = REPO / "configs" / "irregular_terrain_gains.yaml"
    overrides = [
        "ppo.n_steps=32",
        "ppo.batch_size=32",
        "ppo.n_epochs=1",
        "policy.pi=[16]",
        "policy.vf=[16]",
        "train.total_timesteps=64",
        "env.max_episode_steps=120",
        "eval.freq=64",
        "eval.n_episodes=1",
        "checkpoint.freq=64",
        "logging.progress_bar=false",
    ]
    argv = ["--config", str(config), "--output-dir", str(tmp_path), "--run-name", "cycles"]
    assert train_main([*argv, *[a for o in overrides for a in ("--set", o)]]) == 0
    run = tmp_path / "cycles"
    with np.load(run / "evaluations.npz") as log:
        assert list(log["timesteps"]) == [0, 64]
        assert (log["ep_lengths"] == 120).all()  # env steps, not gait cycles
    from agents.pipeline.learning_curve import load_learning_curve

    assert load_learning_curve(run).unit == "gait cycles"
    # The learner's episodes (SB3's rollout/ep_len_mean, from the Monitor of the training env)
    # are 120 env steps long but count a few gait cycles; learning per env step, none of them
    # would even have ended within the 64 learner steps.
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    (events,) = (run / "tb").rglob("events.out.tfevents.*")
    log = EventAccumulator(str(events))
    log.Reload()
    assert "rollout/ep_len_mean" in log.Tags()["scalars"]
    lengths = [e.value for e in log.Scalars("rollout/ep_len_mean")]
    assert lengths and max(lengths) <= 120 / _ticks_per_cycle() + 1
    # the env settings it was trained with (the config's; evaluate.py sets them the same way)
    env = gym.make(
        ENV_ID, action_mode="gains", task_distribution="test", gait_ground_search="always"
    )
    policy = PPOPolicy.load(run / "final", env)
    obs, _ = env.reset(seed=0)
    gains = policy(obs)
    assert gains.shape == (3,) and ((gains >= 0.0) & (gains <= 1.0)).all()


def _ticks_per_cycle() -> int:
    """Control steps per gait cycle of the irregular terrain's default gait."""
    env = gym.make(ENV_ID, action_mode="gains")
    ticks = env.unwrapped.ticks_per_cycle
    env.close()
    return ticks


def test_learning_curves_of_gait_cycle_runs_get_their_own_row(tmp_path):
    """Runs counted in env steps and in gait cycles are not drawn on one x axis."""
    import io
    from types import SimpleNamespace

    import matplotlib.image

    from agents.pipeline.figures import learning_curves

    runs = {}
    for name, decision in (("steps", "step"), ("cycles", "gait_cycle")):
        run = tmp_path / name
        run.mkdir()
        np.savez(
            run / "evaluations.npz",
            timesteps=np.array([0, 10]),
            results=np.zeros((2, 1)),
            ep_lengths=np.ones((2, 1)),
        )
        (run / "config.yaml").write_text(f"env: {{id: X, decision: {decision}}}\n")
        runs[name] = SimpleNamespace(model_dir=run)

    def height(names):
        result = SimpleNamespace(runs={n: runs[n] for n in names}, label=lambda n: n)
        return matplotlib.image.imread(io.BytesIO(learning_curves(result))).shape[0]

    assert height(["steps", "cycles"]) > 1.8 * height(["steps"])
    assert height(["cycles"]) == height(["steps"])
