"""A model's step-0 policy rebuilt from the model (agents.run_files.step0) and the paired check
against it (scripts/check_step0.py)."""

import hashlib
import json
import sys

import gymnasium as gym
import numpy as np
import pytest
from helpers.cliff_ppo_runs import TINY, train
from helpers.paths import REPO

from agents.ppo import PPOPolicy
from agents.run_files.configtools import dump_yaml, load_yaml
from agents.run_files.errors import UserError
from agents.run_files.step0 import STEP0_KIND, write_step0_model

sys.path.insert(0, str(REPO / "scripts"))
import check_step0  # noqa: E402


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    """The final model of a tiny zero-initialised residual PPO run on the cliff walk, trained
    with a learning rate large enough to move its action layer off zero."""
    tmp = tmp_path_factory.mktemp("step0")
    assert train(tmp, "tiny", overrides=[*TINY, "ppo.learning_rate=0.01"]) == 0
    return tmp / "tiny" / "final"


def _actions(path, seed=3, steps=20):
    env = gym.make("HexapodCliffWalk-v0", max_episode_steps=100)
    policy = PPOPolicy.load(path, env)
    obs, _ = env.reset(seed=seed)
    actions = []
    for _ in range(steps):
        actions.append(policy(obs))
        obs, *_ = env.step(actions[-1])
    env.close()
    return np.array(actions)


def _digest(directory):
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in directory.iterdir()}


def test_step0_model_acts_exactly_like_the_zero_initialised_start(model, tmp_path):
    before = _digest(model)
    step0 = write_step0_model(model, tmp_path / "step0")
    assert np.abs(_actions(model)).max() > 1e-4  # training moved the actor
    assert np.array_equal(_actions(step0), np.zeros((20, 18)))
    meta = json.loads((step0 / "meta.json").read_text())
    assert meta["kind"] == STEP0_KIND and meta["num_timesteps"] == 0
    assert not any(key.startswith("eval_") for key in meta)
    assert _digest(model) == before  # the trained model's files are untouched


def test_a_model_trained_without_zero_init_has_no_rebuildable_step0(model, tmp_path):
    copy = tmp_path / "model"
    copy.mkdir()
    for path in model.iterdir():
        (copy / path.name).write_bytes(path.read_bytes())
    config = load_yaml(copy / "config.yaml")
    config["policy"]["zero_init_action_net"] = False
    (copy / "config.yaml").write_text(dump_yaml(config))
    with pytest.raises(UserError, match="zero-initialised"):
        write_step0_model(copy, tmp_path / "step0")


def test_check_step0_reports_the_paired_success_difference(model, tmp_path, capsys):
    out_dir = tmp_path / "out"
    argv = [str(model), "--episodes", "2", "--output-dir", str(out_dir)]
    assert check_step0.main(argv) == 0
    line = [text for text in capsys.readouterr().out.splitlines() if text.startswith(f"{model} ")]
    assert "HexapodCliffWalk-v0: step 0 " in line[-1] and "/2 successes" in line[-1]
    assert "return" in line[-1] and line[-1].rsplit(": ", 1)[1] == record_verdict(out_dir, model)
    record = json.loads((out_dir / "summary.json").read_text())[str(model)]["train"]
    assert record["tasks"] == 2 and record["seeds"] == [1000, 1001]
    assert record["model_sha256"] == hashlib.sha256((model / "model.zip").read_bytes()).hexdigest()
    (report,) = [path for path in out_dir.iterdir() if path.is_dir()]
    suite = load_yaml(report / "suite.yaml")
    assert suite["envs"][0]["kwargs"]["task_distribution"] == "train"
    assert suite["references"] == [f"ppo:{report / 'step0_model'}"]
    assert (report / "report" / "report.md").is_file()
    assert not (report / "step0_model").exists()  # rebuilt on demand, not kept


def record_verdict(out_dir, model):
    return json.loads((out_dir / "summary.json").read_text())[str(model)]["train"]["verdict"]


def test_a_missing_or_renamed_model_is_a_clear_error(model, tmp_path, capsys):
    assert check_step0.main([str(tmp_path / "nothing"), "--output-dir", str(tmp_path)]) == 2
    assert "no PPO model" in capsys.readouterr().err
    renamed = tmp_path / "renamed"
    renamed.mkdir()
    for path in model.iterdir():
        (renamed / path.name.replace("model.zip", "other.zip")).write_bytes(path.read_bytes())
    with pytest.raises(UserError, match="give the model's directory"):
        write_step0_model(renamed / "other.zip", tmp_path / "step0")


def test_verdict_takes_the_return_only_where_success_does_not_separate():
    def comparison(challenger, baseline, interval, resolved):
        return dict(
            challenger_value=challenger,
            baseline_value=baseline,
            interval=interval,
            resolved=resolved,
        )

    better_return = comparison(110.0, 100.0, [2.0, 18.0], True)
    flat_return = comparison(100.0, 100.0, [-5.0, 5.0], False)
    assert check_step0.verdict(comparison(0.6, 0.4, [0.1, 0.3], True), flat_return).startswith(
        "beats its step 0 (success)"
    )
    tie = comparison(0.5, 0.5, [-0.1, 0.1], False)
    assert "(return" in check_step0.verdict(tie, better_return)
    assert check_step0.verdict(tie, flat_return) == "does not beat its step 0"
    fewer = comparison(0.48, 0.5, [-0.06, 0.0], False)
    assert check_step0.verdict(fewer, better_return) == "does not beat its step 0"


def test_an_evaluation_suite_can_keep_the_hard_part_of_a_distribution(tmp_path):
    """``min_task_difficulty`` of a suite env: every evaluated task is at least that difficult,
    the same tasks for every policy (the check of a model trained on the hard part)."""
    from agents.pipeline.cli import evaluate_main

    suite = {
        "envs": [
            {
                "id": "HexapodIrregularTerrain-v1",
                "kwargs": {"task_distribution": "train"},
                "min_task_difficulty": 0.6,
            }
        ],
        "policies": ["zero", "random"],
        "episodes": 3,
        "max_episode_steps": 5,
        "output_dir": str(tmp_path / "report"),
    }
    (tmp_path / "suite.yaml").write_text(dump_yaml(suite))
    assert evaluate_main(["--config", str(tmp_path / "suite.yaml"), "--no-progress"]) == 0
    metrics = json.loads((tmp_path / "report" / "metrics.json").read_text())
    runs = metrics["envs"]["HexapodIrregularTerrain-v1"]["policies"]
    tasks = {name: [e["task"] for e in run["episodes"]] for name, run in runs.items()}
    assert all(t["difficulty"] >= 0.6 for t in tasks["zero"]) and tasks["zero"] == tasks["random"]
