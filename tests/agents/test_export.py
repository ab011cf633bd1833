"""`hexapod-export` (agents.export): the ONNX actor with the observation normalisation folded in
gives the torch policy's deterministic actions, and its model card describes the model."""

import json
import shutil

import gymnasium as gym
import numpy as np
import pytest
from helpers.paths import REPO
from helpers.stewart_hybrid_runs import train

import hexapod_envs  # noqa: F401  (registers the envs)
from agents.export import (
    _learned_part,
    card_paths,
    export_main,
    export_model,
    training_evaluations,
)
from agents.hybrid import HybridPolicy
from agents.ppo import PPOPolicy

ort = pytest.importorskip("onnxruntime")


def _recorded_observations(env, policy, steps=60, seed=3):
    """Observations of an episode driven by `policy`, then of random actions (a wider spread),
    plus scaled copies whose normalised values hit the clip of the statistics."""
    observations = []
    obs, _ = env.reset(seed=seed)
    policy.reset()
    rng = np.random.default_rng(seed)
    for step in range(steps):
        observations.append(obs)
        action = policy(obs) if step < steps // 2 else env.action_space.sample()
        obs, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            obs, _ = env.reset(seed=seed + step)
    recorded = np.array(observations, dtype=np.float64)
    extreme = recorded[:5] * rng.uniform(-50, 50, size=recorded[:5].shape)
    return np.concatenate([recorded, extreme])


def _onnx_actions(path, observations):
    session = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    (action,) = session.run(["action"], {"observation": observations})
    return action


@pytest.mark.parametrize(
    "model", ["HexapodIrregularTerrain-v0/ppo", "HexapodIrregularTerrain-v0/gains"]
)  # a plain PPO model; a hybrid one whose learned part acts once per gait cycle
def test_onnx_actions_equal_the_torch_policy(tmp_path, model):
    model_dir = REPO / "models" / model
    result = export_model(model_dir, tmp_path / "actor.onnx")
    card = result.card
    env = gym.make(card["env"]["id"], **card["env"]["kwargs"])
    try:
        policy = PPOPolicy.load(model_dir, env)
        learned = policy.learned if isinstance(policy, HybridPolicy) else policy
        assert isinstance(policy, HybridPolicy) == model.endswith("gains")
        observations = _recorded_observations(env, policy)
    finally:
        env.close()
    assert learned.stats is not None and learned.stats.norm_obs  # the test covers the folding
    expected = np.array([learned(o) for o in observations])
    actions = _onnx_actions(result.onnx, observations)
    assert actions.dtype == np.float32 and actions.shape == expected.shape
    np.testing.assert_allclose(actions, expected, rtol=0, atol=1e-5)
    assert np.ptp(expected, axis=0).max() > 0.1  # the observations move the actions
    z = np.abs(learned.stats.normalize_obs(observations))
    assert np.isclose(z, learned.stats.clip_obs).any()  # the clip of the statistics is exercised


def _report(path, rates):
    """A hexapod-evaluate metrics.json with these success rates on the Stewart tilt (-v0)."""
    policies = {
        name: {"aggregate": {"episodes": 20, "success": {"mean": rate}}}
        for name, rate in rates.items()
    }
    env = {"kwargs": {"task_distribution": "test"}, "policies": policies}
    path.mkdir()
    (path / "metrics.json").write_text(json.dumps({"envs": {"HexapodStewartTilt-v0": env}}))
    return path


def test_model_card(tmp_path):
    run = train(tmp_path, "hybrid")  # a tiny Stewart-tilt hybrid, shipped as its final model
    model_dir = run / "final"
    shutil.copy(run / "evaluations.npz", model_dir)
    out = tmp_path / "out" / "cliff.onnx"
    rates = {"analytical": 0.8, "random": 0.2, f"ppo:{model_dir}": 0.5}
    rates[f"ppo:{REPO / 'models' / 'HexapodIrregularTerrain-v0' / 'ppo'}"] = 1.0  # not this card's
    result = export_model(model_dir, out, report=_report(tmp_path / "report", rates))
    assert (result.card_json, result.card_md) == card_paths(out)
    card = json.loads(result.card_json.read_text())
    assert card == json.loads(json.dumps(result.card))
    assert card["env"]["id"] == "HexapodStewartTilt-v0" and card["env"]["version"] == 0
    layout = card["observation"]["layout"]
    assert layout[0]["start"] == 0 and layout[-1]["stop"] == card["observation"]["shape"][0]
    assert all(a["stop"] == b["start"] for a, b in zip(layout, layout[1:], strict=False))
    assert "fasm_margin_deg" in {p["name"] for p in layout}
    assert card["action"]["mode"] == "residual"  # the env's default action mode
    assert card["action"]["exported"].startswith("hybrid model: the file holds the learned actor")
    assert card["action"]["output_space"]["low"] == [-1.0] * 18
    meta = json.loads((model_dir / "meta.json").read_text())
    assert card["training"]["num_timesteps"] == meta["num_timesteps"]
    assert any("normalisation" in item for item in card["folded_in"])
    assert card["training_evaluations"]["evaluations"] > 0
    (score,) = card["benchmark"]
    assert score["env_id"] == "HexapodStewartTilt-v0" and score["success_rate"] == 0.5
    assert score["benchmark_score"] == pytest.approx(50.0)  # halfway from random to analytical
    text = result.card_md.read_text()
    for heading in ("Observation layout", "Folded into the graph", "Benchmark"):
        assert f"## {heading}" in text


def test_cli_refuses_to_overwrite_without_force(tmp_path, capsys):
    out = tmp_path / "a.onnx"
    argv = [str(REPO / "models" / "HexapodIrregularTerrain-v0" / "ppo"), "--output", str(out)]
    assert export_main(argv) == 0
    assert out.is_file() and all(p.is_file() for p in card_paths(out))
    assert export_main(argv) == 2
    assert "--force" in capsys.readouterr().err
    assert export_main([*argv, "--force"]) == 0
    assert export_main([str(tmp_path / "nothing")]) == 2
    assert "no PPO model" in capsys.readouterr().err


def test_an_unreadable_report_stops_the_export_before_any_file_is_written(tmp_path, capsys):
    out = tmp_path / "a.onnx"
    argv = [str(REPO / "models" / "HexapodIrregularTerrain-v0" / "ppo"), "--output", str(out)]
    assert export_main([*argv, "--report", str(tmp_path / "no_report")]) == 2
    assert "cannot read the report" in capsys.readouterr().err
    assert not out.exists() and not any(p.exists() for p in card_paths(out))


def test_a_gains_cards_learned_part_names_the_height_knob_when_the_env_has_it():
    env = {"decision": "gait_cycle", "kwargs": {"action_mode": "gains"}}
    plain = _learned_part({"env": env})
    assert "(k_z, k_a, k_b)" in plain and "torso-height" not in plain
    env["kwargs"]["gains_height_offset_m"] = 0.04
    knob = _learned_part({"env": env})
    assert "fourth value in [-1, 1] x 0.04 m" in knob and knob.endswith("once per gait cycle")
    env["decision"] = "episode"
    held = "chosen once per episode at its first observation and held"
    assert _learned_part({"env": env}).endswith(held)


def test_a_knobs_section_without_names_gets_the_default_knobs_on_the_card():
    part = _learned_part({"knobs": {"reward": "success"}})
    assert part.startswith("knobs model: the action is 3 values") and "rho 0.4..1.0" in part


def test_the_cards_best_evaluation_follows_the_runs_select_rule(tmp_path):
    """With ``eval.select: success`` the run's best/ is the most successful evaluation (then the
    higher return), not the highest return: the card names the same one."""
    np.savez(
        tmp_path / "evaluations.npz",
        timesteps=np.array([0, 100, 200]),
        results=np.array([[10.0, 10.0], [50.0, 30.0], [20.0, 20.0]]),
        successes=np.array([[0, 0], [0, 1], [1, 1]], dtype=bool),
        ep_lengths=np.ones((3, 2)),
    )
    assert training_evaluations(tmp_path)["best"]["timesteps"] == 100
    best = training_evaluations(tmp_path, "success")["best"]
    assert best["timesteps"] == 200 and best["success_rate"] == 1.0
    # equal success: the higher return; an exact tie: the earlier evaluation, as best/ keeps it
    np.savez(
        tmp_path / "evaluations.npz",
        timesteps=np.array([0, 100, 200, 300]),
        results=np.array([[10.0, 10.0], [20.0, 20.0], [30.0, 30.0], [30.0, 30.0]]),
        successes=np.array([[1, 0], [1, 1], [1, 1], [1, 1]], dtype=bool),
        ep_lengths=np.ones((4, 2)),
    )
    assert training_evaluations(tmp_path, "success")["best"]["timesteps"] == 200


def test_a_model_inside_a_run_reads_the_runs_evaluation_log(tmp_path):
    """Training writes evaluations.npz to the run directory, not into best/ or a checkpoint: the
    card of such a model reads the run's log; a directory that is no run gives none."""
    run = tmp_path / "run"
    for sub in ("best", "final", "checkpoints/step_000000000100"):
        (run / sub).mkdir(parents=True)
    np.savez(
        run / "evaluations.npz",
        timesteps=np.array([0, 100]),
        results=np.array([[1.0], [2.0]]),
        ep_lengths=np.ones((2, 1)),
    )
    for sub in ("best", "final", "checkpoints/step_000000000100"):
        assert training_evaluations(run / sub)["evaluations"] == 2
    (tmp_path / "loose" / "model").mkdir(parents=True)
    np.savez(
        tmp_path / "loose" / "evaluations.npz",
        timesteps=np.array([0]),
        results=np.ones((1, 1)),
        ep_lengths=np.ones((1, 1)),
    )
    assert training_evaluations(tmp_path / "loose" / "model") is None
