"""Hybrid runs through train.py and evaluate.py: the resolved config records the hybrid, a run
directory loads as a hybrid with no extra argument, training starts exactly at the analytical
controller, and the run's evaluation log gives a learning curve."""

import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import yaml
from helpers.paths import REPO
from helpers.stewart_hybrid_runs import STEWART, TINY, train

from agents.hybrid import HybridPolicy
from agents.pipeline.cli import evaluate_main, train_main
from agents.pipeline.learning_curve import load_learning_curve
from agents.ppo import PPOPolicy


def evaluate(
    out: Path, *policies: str, env_kwargs=None, env="HexapodStewartTilt-v0", steps: int = 250
) -> int:
    envs = json.dumps([{"id": env, "kwargs": env_kwargs or {}}])
    argv = ["--episodes", "2", "--max-episode-steps", str(steps), "--output-dir", str(out)]
    argv += ["--no-progress", "--set", f"envs={envs}", "--policies", *policies]
    return evaluate_main(argv)


def reset_to_untrained(run: Path) -> None:
    """Zero the action net of every saved model of `run` again (an untrained hybrid; the
    learning rate must be > 0, so training cannot be frozen by the config)."""
    from agents.hybrid import zero_init_action_net
    from agents.run_files.model_files import load_ppo, ppo_custom_objects
    from agents.run_files.train_config import load_train_config

    config = load_train_config(data=yaml.safe_load((run / "config.yaml").read_text()))
    env = gym.make("HexapodStewartTilt-v0")
    box = gym.spaces.Box(-1.0, 1.0, env.action_space.shape, env.action_space.dtype)
    objects = ppo_custom_objects(config.policy.policy_kwargs(), env.observation_space, box)
    for model_zip in run.glob("**/model.zip"):
        model = load_ppo(model_zip, objects)
        zero_init_action_net(model)
        model.save(model_zip)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("hybrid_runs")
    frozen = train(tmp, "frozen")
    reset_to_untrained(frozen)
    return {"learning": train(tmp, "learning"), "frozen": frozen}


def test_resolved_config_records_the_hybrid(runs):
    for sub in ("", "best", "final"):
        config = yaml.safe_load((runs["learning"] / sub / "config.yaml").read_text())
        assert config["hybrid"]["mode"] == "residual"
        assert config["hybrid"]["scale"] == 0.05


def test_run_dir_loads_as_a_hybrid_policy(runs):
    env = gym.make("HexapodStewartTilt-v0")
    policy = PPOPolicy.load(runs["learning"], env)
    assert isinstance(policy, HybridPolicy)
    assert policy.core.settings.scale == 0.05
    obs, _ = env.reset(seed=0)
    policy.reset()
    action = policy(obs)
    assert action.shape == env.action_space.shape and env.action_space.contains(action)


def test_untrained_hybrid_is_the_analytical_controller_in_evaluate(runs, tmp_path):
    """Zero action mean (an untrained hybrid): evaluate.py's ppo:<run dir> gives exactly
    the analytical controller's episodes (same seeds), with no extra argument. The episodes run
    into the recovery (from 290 steps on at this tilt rate), where the analytical controller's
    differ from the zero action's."""
    frozen = f"ppo:{runs['frozen']}"
    fast_tilt = {"scenario": "climb", "tilt_rate_deg": 4.0}
    code = evaluate(tmp_path / "rep", "analytical", "zero", frozen, env_kwargs=fast_tilt, steps=340)
    assert code == 0
    metrics = json.loads((tmp_path / "rep" / "metrics.json").read_text())
    policies = metrics["envs"]["HexapodStewartTilt-v0"]["policies"]
    hybrid = policies[frozen]["episodes"]
    assert hybrid == policies["analytical"]["episodes"]
    assert hybrid != policies["zero"]["episodes"]
    assert len(hybrid) == 2


def test_a_new_hybrid_model_starts_at_the_analytical_controller():
    """train.py's model (`new_model`) has a zero action net when the hybrid section asks for it,
    so that its step 0 is exactly the analytical controller; SB3's initialisation otherwise."""
    import torch
    from stable_baselines3.common.vec_env import DummyVecEnv

    from agents.pipeline.training import new_model
    from agents.run_files.train_config import load_train_config

    venv = DummyVecEnv([lambda: gym.make("HexapodStewartTilt-v0")])
    for zero in (True, False):
        option = f"hybrid.zero_init_action_net={str(zero).lower()}"
        net = new_model(load_train_config(STEWART, [*TINY, option]), venv).policy.action_net
        weights = torch.cat([p.detach().ravel() for p in net.parameters()])
        assert bool((weights == 0).all()) is zero


def test_evaluate_runs_a_hybrid_in_its_trained_action_mode(tmp_path):
    """The cliff hybrid trains in the residual mode with residual_scale 2: evaluate.py builds
    that env for it (the suite's env keeps the defaults), and a direct load into an env in
    another action mode is refused with both modes named."""
    run = train(tmp_path, "cliff", config=str(REPO / "configs" / "cliff_walk_hybrid.yaml"))
    assert evaluate(tmp_path / "rep", "zero", f"ppo:{run}", env="HexapodCliffWalk-v0") == 0
    metrics = json.loads((tmp_path / "rep" / "metrics.json").read_text())
    assert metrics["envs"]["HexapodCliffWalk-v0"]["policies"][f"ppo:{run}"]["episodes"]
    env = gym.make("HexapodCliffWalk-v0", action_mode="joint")
    with pytest.raises(ValueError, match="action_mode='residual' but the env has action_mode"):
        PPOPolicy.load(run, env)


def test_training_writes_a_learning_curve(runs):
    curve = load_learning_curve(runs["learning"])
    # step 0 is the initial policy (here: the analytical controller), then every eval.freq
    np.testing.assert_array_equal(curve.timesteps, [0, 128, 256])
    assert curve.returns.shape == (3, 2) and curve.successes.shape == (3, 2)
    assert set(np.unique(curve.successes)) <= {0.0, 1.0}
    rows = curve.rows()
    assert [r["timesteps"] for r in rows] == [0, 128, 256]
    assert all(0.0 <= r["success_rate"] <= 1.0 for r in rows)


def test_missing_learning_curve_is_a_clear_error(tmp_path):
    with pytest.raises(ValueError, match="has no evaluations.npz"):
        load_learning_curve(tmp_path)


def test_a_damaged_learning_curve_is_a_clear_error_and_short_successes_are_left_out(tmp_path):
    """SB3 logs successes only where the episodes report them: a successes array without a
    row per evaluation is left out; rows of different lengths or a missing array are a
    damaged log, said as such (the report and the sweep summary then leave the run out)."""
    log = tmp_path / "evaluations.npz"
    np.savez(
        log,
        timesteps=[0, 1, 2],
        results=np.ones((3, 2)),
        ep_lengths=np.ones((3, 2)),
        successes=np.ones((2, 2)),
    )
    curve = load_learning_curve(tmp_path)
    assert curve.successes is None and [r["success_rate"] for r in curve.rows()] == [None] * 3
    np.savez(log, timesteps=[0, 1, 2], results=np.ones((2, 2)), ep_lengths=np.ones((2, 2)))
    with pytest.raises(ValueError, match="is damaged: 3 evaluations, but returns of shape"):
        load_learning_curve(tmp_path)
    np.savez(log, timesteps=[0])
    with pytest.raises(ValueError, match="evaluations.npz is damaged"):
        load_learning_curve(tmp_path)
    np.savez(log, timesteps=[0, 1], results=np.ones((2, 2)), ep_lengths=np.ones((2, 2)))
    log.write_bytes(log.read_bytes()[:200])  # cut short, as a kill during a write leaves it
    with pytest.raises(ValueError, match="evaluations.npz is damaged"):
        load_learning_curve(tmp_path)


def test_resume_keeps_the_hybrid_and_refuses_to_change_it(tmp_path, capsys):
    run = train(tmp_path, "resumed", "checkpoint.freq=128")
    assert train_main(["--resume", str(run), "--set", "hybrid.scale=0.2"]) == 2
    assert "cannot change 'hybrid' when resuming" in capsys.readouterr().err
    # The evaluation log's rows hold eval.n_episodes episodes each: kept, log untouched.
    log = (run / "evaluations.npz").read_bytes()
    same_tasks = yaml.safe_load((run / "config.yaml").read_text())["eval"]["same_tasks"]
    for override in ("eval.n_episodes=3", f"eval.same_tasks={str(not same_tasks).lower()}"):
        argv = ["--resume", str(run), "--set", override, "--set", "train.total_timesteps=384"]
        assert train_main(argv) == 2
        assert "when resuming" in capsys.readouterr().err
    assert (run / "evaluations.npz").read_bytes() == log
    assert train_main(["--resume", str(run), "--set", "train.total_timesteps=384"]) == 0
    config = yaml.safe_load((run / "final" / "config.yaml").read_text())
    assert config["hybrid"]["scale"] == 0.05
    assert isinstance(PPOPolicy.load(run, gym.make("HexapodStewartTilt-v0")), HybridPolicy)
