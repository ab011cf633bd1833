"""train.py / evaluate.py end to end with tiny budgets (DummyVecEnv, short episodes), plus the
bad-input paths: clear one-line errors on stderr and a non-zero exit code."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import yaml
from helpers.cliff_ppo_runs import CONFIG, TINY, evaluate, meta, train
from helpers.paths import REPO

from agents.pipeline import callbacks
from agents.pipeline.cli import default_headless_gl, evaluate_main, train_main
from agents.ppo import PPOPolicy
from agents.run_files.env_settings import read_settings, resolved_settings


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """A tiny training run (1024 steps) resumed to 1536 steps."""
    tmp = tmp_path_factory.mktemp("runs")
    assert train(tmp, "tiny") == 0
    run_dir = tmp / "tiny"
    first = {
        "final_steps": meta(run_dir / "final")["num_timesteps"],
        "events": sorted((run_dir / "tb").glob("events.out.tfevents.*")),
    }
    assert train_main(["--resume", str(run_dir), "--set", "train.total_timesteps=1536"]) == 0
    return run_dir, first


def test_run_dir_holds_model_config_command_vecnormalize_and_tensorboard(run):
    run_dir, first = run
    assert first["final_steps"] == 1024 and first["events"]
    for model_dir in (run_dir / "final", run_dir / "best", *(run_dir / "checkpoints").iterdir()):
        for name in (
            "model.zip",
            "vecnormalize.npz",
            "config.yaml",
            "env_settings.yaml",
            "command.txt",
            "meta.json",
        ):
            assert (model_dir / name).is_file(), model_dir / name
    config = yaml.safe_load((run_dir / "final" / "config.yaml").read_text())
    assert config["env"]["id"] == "HexapodCliffWalk-v0" and config["ppo"]["n_steps"] == 256
    assert "--run-name tiny" in (run_dir / "command.txt").read_text().splitlines()[0]
    assert "train.py" in (run_dir / "best" / "command.txt").read_text()


def test_tensorboard_has_fasm_success_and_reward_term_scalars(run):
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    acc = EventAccumulator(str(run[0] / "tb"))
    acc.Reload()
    tags = set(acc.Tags()["scalars"])
    expected = {
        "hexapod/fasm_min_deg",
        "hexapod/fasm_mean_deg",
        "hexapod/time_below_xi_s",
        "hexapod/success_rate",
        "reward_terms/reward_forward",
        "reward_terms/reward_stability",
        "eval/fasm_min_deg",
        "eval/mean_reward",
        "rollout/ep_rew_mean",
    }
    assert expected <= tags, expected - tags
    steps = [e.step for e in acc.Scalars("hexapod/fasm_min_deg")]
    assert max(steps) == 1536  # the resumed part logs into the same directory


def test_resume_continues_in_the_same_run_dir(run):
    run_dir, first = run
    assert meta(run_dir / "final")["num_timesteps"] == 1536
    assert (run_dir / "checkpoints" / "step_000000001536").is_dir()
    commands = (run_dir / "command.txt").read_text().splitlines()
    assert len(commands) == 2 and "--resume" in commands[1]
    assert yaml.safe_load((run_dir / "config.yaml").read_text())["train"]["total_timesteps"] == 1536
    assert len(list((run_dir / "tb").glob("events.out.tfevents.*"))) >= len(first["events"])
    assert not [p for p in run_dir.parent.iterdir() if p.name != "tiny"]


def test_resume_refuses_a_finished_budget_and_env_changes(run, capsys):
    run_dir = str(run[0])
    assert train_main(["--resume", run_dir]) == 2
    assert "already trained to 1536 steps" in capsys.readouterr().err
    assert train_main(["--resume", run_dir, "--set", "env.id=HexapodStewartTilt-v0"]) == 2
    assert "cannot change 'env' when resuming" in capsys.readouterr().err


def test_the_evaluation_log_and_best_are_in_place_before_the_after_eval_callback(tmp_path):
    """A sweep's after-eval callback reports to Ray Tune, which may end the trial right there:
    the evaluation it reports is already in evaluations.npz and best/ by then."""
    from stable_baselines3.common.callbacks import BaseCallback

    from agents.pipeline.learning_curve import load_learning_curve
    from agents.pipeline.training import start_training
    from agents.run_files.configtools import load_yaml
    from agents.run_files.train_config import load_train_config

    seen = []

    class Check(BaseCallback):
        def _on_step(self) -> bool:
            run = tmp_path / "r"
            seen.append(
                (int(load_learning_curve(run).timesteps[-1]), meta(run / "best")["num_timesteps"])
            )
            return True

    # eval.select: success keeps best/ through our callback (SB3's own saving, for "reward",
    # already ran before the after-eval callback)
    config = load_train_config(data=load_yaml(CONFIG), overrides=[*TINY, "eval.select=success"])
    start_training(config, tmp_path, "r", after_eval=Check())
    assert [logged for logged, _ in seen] == [0, 512, 1024]  # each callback sees its own row
    assert seen[0][1] == 0  # and best/ already holds the step-0 policy at the first one
    assert not list((tmp_path / "r").glob(".evaluations.partial*"))


def test_ctrl_c_saves_a_checkpoint_and_exits_130(tmp_path, monkeypatch, capsys):
    calls = {"n": 0}

    def interrupt(self):
        calls["n"] += 1
        if calls["n"] == 300:
            raise KeyboardInterrupt
        return True

    monkeypatch.setattr(callbacks.EpisodeStatsCallback, "_on_step", interrupt)
    assert train(tmp_path, "stop", overrides=[*TINY, "eval.freq=0"]) == 130
    saved = meta(tmp_path / "stop" / "checkpoints" / "step_000000000300")
    assert saved["kind"] == "interrupt" and saved["num_timesteps"] == 300
    assert "python train.py --resume" in capsys.readouterr().err


def test_a_resumed_run_evaluates_at_the_steps_of_an_uninterrupted_one(tmp_path, monkeypatch):
    """Interrupted at 300 steps, between evaluations: the resumed part evaluates at 512, 768
    and 1024 (multiples of eval.freq), not 256 steps after the restart."""
    calls = {"n": 0}
    original = callbacks.EpisodeStatsCallback._on_step

    def interrupt(self):
        calls["n"] += 1
        if calls["n"] == 300:
            raise KeyboardInterrupt
        return original(self)

    monkeypatch.setattr(callbacks.EpisodeStatsCallback, "_on_step", interrupt)
    assert train(tmp_path, "cut", overrides=[*TINY, "eval.freq=256"]) == 130
    monkeypatch.undo()
    assert train_main(["--resume", str(tmp_path / "cut")]) == 0
    timesteps = np.load(tmp_path / "cut" / "evaluations.npz")["timesteps"]
    assert timesteps.tolist() == [0, 256, 512, 768, 1024]


def test_existing_run_dir_is_not_overwritten_without_force(run, capsys):
    run_dir = run[0]
    before = meta(run_dir / "final")
    assert train(run_dir.parent, "tiny") == 2
    assert "already exists; pass --force" in capsys.readouterr().err
    assert meta(run_dir / "final") == before
    # --force replaces an earlier run only, not a directory without a run's config.yaml
    (run_dir.parent / "notes").mkdir()
    (run_dir.parent / "notes" / "todo.txt").write_text("keep")
    assert train(run_dir.parent, "notes", "--force") == 2
    assert "is not an earlier run directory" in capsys.readouterr().err
    assert (run_dir.parent / "notes" / "todo.txt").is_file()


def test_config_typo_lists_valid_keys(tmp_path, capsys):
    assert train(tmp_path, "x", overrides=["ppo.n_step=8"]) == 2
    err = capsys.readouterr().err
    assert "unknown key 'ppo.n_step'" in err and "n_steps" in err and "batch_size" in err
    assert not (tmp_path / "x").exists()


def test_env_id_typo_lists_registered_hexapod_ids(tmp_path, capsys):
    assert train(tmp_path, "x", overrides=["env.id=HexapodCliffWallk-v0"]) == 2
    err = capsys.readouterr().err
    assert "unknown env id 'HexapodCliffWallk-v0'" in err
    assert "registered Hexapod env ids: HexapodCliffWalk-v0" in err


def test_cli_user_errors_have_no_traceback(tmp_path):
    result = subprocess.run(
        [sys.executable, "train.py", "--config", CONFIG, "--set", "env.id=NoSuchEnv-v0"],
        cwd=REPO,
        capture_output=True,
        text=True,
    )
    assert result.returncode == 2
    assert result.stderr.startswith("train.py: error: unknown env id 'NoSuchEnv-v0'")
    assert "Traceback" not in result.stderr


# --- evaluate.py ---------------------------------------------------------------------------------
def test_evaluate_smoke_writes_json_markdown_and_html_rows(run, tmp_path, capsys):
    ppo = f"ppo:{run[0]}"
    assert evaluate(tmp_path / "rep", "analytical", "zero", "random", ppo) == 0
    out = tmp_path / "rep"
    metrics = json.loads((out / "metrics.json").read_text())
    policies = metrics["envs"]["HexapodCliffWalk-v0"]["policies"]
    assert list(policies) == ["analytical", "zero", "random", ppo]
    for entry in policies.values():
        assert [e["seed"] for e in entry["episodes"]] == [0, 1]
        assert all(e["episode_length"] == 60 for e in entry["episodes"])
        assert entry["aggregate"]["fasm_min_deg"]["n"] == 2
    md, page = (out / "report.md").read_text(), (out / "report.html").read_text()
    alias = Path(run[0]).name  # the report's short name of ppo:<run dir>
    for name in ("analytical", "zero", "random", alias):
        assert f"| {name} |" in md and f"<td>{name}</td>" in page
    assert f"- `{alias}` vs the analytical controller (`analytical`): success" in md
    assert f"`{alias}`: {run[0]}" in md  # the sources name the path
    assert "data:image/png;base64," in page and "<img" in page
    assert metrics["envs"]["HexapodCliffWalk-v0"]["comparisons"]
    assert metrics["references"] == ["analytical", "zero"]  # the defaults: the suite names none


def test_identical_seeds_give_identical_episodes_across_policies(tmp_path):
    """Before the cliff, analytical (joint mode, its own env) and zero (the reference gait in the
    default residual mode) walk the same gait: same seeds, same tasks, the same episodes up to
    the joint mode's rounding of the gait's targets."""
    extra = ("--config", "configs/evaluate_v0_shipped.yaml")
    extra += ("--set", "envs=[{id: HexapodCliffWalk-v0, kwargs: {task_distribution: train}}]")
    assert evaluate(tmp_path / "rep", "analytical", "zero", extra=extra) == 0
    metrics = json.loads((tmp_path / "rep" / "metrics.json").read_text())
    policies = metrics["envs"]["HexapodCliffWalk-v0"]["policies"]
    analytical, zero = policies["analytical"]["episodes"], policies["zero"]["episodes"]
    assert [e["task"] for e in analytical] == [e["task"] for e in zero]
    assert analytical[0]["task"] != analytical[1]["task"]  # sampled per seed
    for a, z in zip(analytical, zero, strict=True):
        assert a["episode_return"] == pytest.approx(z["episode_return"], rel=1e-4)
        assert a["distance_m"] == pytest.approx(z["distance_m"], abs=1e-4)


def test_a_sampling_ppo_policy_repeats_an_episode_whatever_ran_before(run):
    """With deterministic=False an episode's actions come from its own seed (`seed_episode`,
    which the evaluation calls before each episode), not from the episodes run before it."""
    from agents.pipeline.episode import EpisodeAccumulator
    from agents.pipeline.evaluation import run_episode

    env = gym.make("HexapodCliffWalk-v0", max_episode_steps=30)
    policy = PPOPolicy.load(run[0] / "final", env, deterministic=False)

    def episode_return(seed: int) -> float:
        return run_episode(env, policy, seed, EpisodeAccumulator(None)).episode_return

    first = episode_return(1)
    episode_return(0)
    assert episode_return(1) == first
    assert episode_return(2) != first


def test_run_records_every_setting_of_its_training_env(run):
    """Defaults included: a later change of a default must be visible against the record."""
    run_dir, _ = run
    config = yaml.safe_load((run_dir / "config.yaml").read_text())
    env = gym.make("HexapodCliffWalk-v0", **config["env"]["kwargs"])
    expected = resolved_settings(env)
    assert "physics_dt" not in config["env"]["kwargs"] and expected["physics_dt"] == 0.002
    for directory in (run_dir, run_dir / "final", run_dir / "best"):
        assert read_settings(directory) == expected


def test_evaluation_warns_when_a_setting_differs_from_the_training_env(run, tmp_path):
    """A default changed since the training (here the physics step) is named in the report;
    the held-out task distribution is not a mismatch."""
    model = tmp_path / "model"
    shutil.copytree(run[0] / "final", model)
    assert evaluate(tmp_path / "same", f"ppo:{model}") == 0
    assert "set up otherwise" not in (tmp_path / "same" / "report.md").read_text()
    settings = read_settings(model)
    settings["physics_dt"] = 0.001
    settings["reward"]["forward_weight"] = 3.0
    (model / "env_settings.yaml").write_text(yaml.safe_dump(settings))
    assert evaluate(tmp_path / "changed", f"ppo:{model}") == 0
    md = (tmp_path / "changed" / "report.md").read_text()
    assert (
        f"- **warning:** HexapodCliffWalk-v0: ppo:{model} was trained on an env set up otherwise "
        "than evaluated here (setting: trained -> evaluated): physics_dt: 0.001 -> 0.002; reward "
        "terms (change returns only): reward.forward_weight: 3.0 -> 1.0"
    ) in md
    # other reward scales alone change no action (every policy is scored with the evaluated
    # env's reward): a note of the report, not a warning
    settings["physics_dt"] = 0.002
    (model / "env_settings.yaml").write_text(yaml.safe_dump(settings))
    assert evaluate(tmp_path / "reward", f"ppo:{model}") == 0
    md = (tmp_path / "reward" / "report.md").read_text()
    assert "## Warnings" not in md and "## Notes" in md
    note = f"HexapodCliffWalk-v0: ppo:{model} was trained on an env"
    assert f"- **note:** {note}" in md
    metrics = json.loads((tmp_path / "reward" / "metrics.json").read_text())
    assert not metrics["warnings"] and metrics["notes"][0].startswith(note)


def test_a_model_template_found_for_one_env_of_two_is_a_note(run, tmp_path, capsys):
    models = tmp_path / "models"
    shutil.copytree(run[0] / "final", models / "HexapodCliffWalk-v0")
    argv = ["--episodes", "1", "--max-episode-steps", "5", "--no-progress"]
    argv += ["--output-dir", str(tmp_path / "rep"), "--set", "missing_models=skip"]
    argv += ["--set", "envs=[HexapodCliffWalk-v0, HexapodStewartTilt-v0]"]
    argv += ["--set", f"policies=[zero, 'ppo:{models}/{{env_id}}']"]
    assert evaluate_main(argv) == 0
    note = (
        f"ppo:{models}/{{env_id}} runs on HexapodCliffWalk-v0 only: no model at "
        f"{models}/{{env_id}} for HexapodStewartTilt-v0"
    )
    metrics = json.loads((tmp_path / "rep" / "metrics.json").read_text())
    assert metrics["notes"] == [note] and not metrics["warnings"]
    assert f"- **note:** {note}" in (tmp_path / "rep" / "report.md").read_text()
    assert f"note: {note}" in capsys.readouterr().err


def test_a_model_without_the_settings_record_is_checked_by_its_kwargs(run, tmp_path):
    """Older runs (and envs of other packages) have no env_settings.yaml: the evaluation then
    compares the kwargs of the model's config with the suite's."""
    model = tmp_path / "old"
    shutil.copytree(run[0] / "final", model)
    (model / "env_settings.yaml").unlink()
    config = yaml.safe_load((model / "config.yaml").read_text())
    config["env"]["kwargs"]["forward_weight"] = 2.0
    (model / "config.yaml").write_text(yaml.safe_dump(config))
    assert evaluate(tmp_path / "rep", f"ppo:{model}") == 0
    md = (tmp_path / "rep" / "report.md").read_text()
    assert f"ppo:{model} was trained with other env kwargs than evaluated here" in md
    assert "forward_weight: 2.0 -> None" in md


def test_missing_model_path_is_a_clear_error(tmp_path, capsys):
    assert evaluate(tmp_path / "rep", "analytical", f"ppo:{tmp_path / 'nope'}") == 2
    assert f"no PPO model at {tmp_path / 'nope'}" in capsys.readouterr().err


def test_model_for_another_env_is_refused(run, tmp_path, capsys):
    fake = tmp_path / "other"
    fake.mkdir()
    final = run[0] / "final"
    for name in ("model.zip", "vecnormalize.npz"):
        (fake / name).write_bytes((final / name).read_bytes())
    config = yaml.safe_load((final / "config.yaml").read_text())
    config["env"]["id"] = "HexapodStewartTilt-v0"
    (fake / "config.yaml").write_text(yaml.safe_dump(config))
    assert evaluate(tmp_path / "rep", f"ppo:{fake}") == 2
    err = capsys.readouterr().err
    assert "was trained on another env (HexapodStewartTilt-v0), not HexapodCliffWalk-v0" in err


def test_shipped_model_of_another_env_is_named_before_its_env_kwargs_are_used(tmp_path, capsys):
    """The irregular-terrain agent's trained settings (gait_ground_search) would be an unknown
    keyword of the cliff walk: the error names the env it was trained on instead."""
    policy = "ppo:models/HexapodIrregularTerrain-v0/ppo"
    assert evaluate(tmp_path / "rep", policy) == 2
    err = capsys.readouterr().err
    assert "was trained on another env (HexapodIrregularTerrain-v0), not HexapodCliffWalk-v0" in err
    assert "unknown keyword" not in err


def test_the_default_report_is_replaced_on_a_second_run_other_reports_need_force(
    tmp_path, monkeypatch, capsys
):
    """Without --output-dir the default suite writes reports/default (relative to the working
    directory), and running it again replaces that report; another existing directory, or a
    reports/default that holds no report, is refused without --force."""
    monkeypatch.chdir(tmp_path)
    argv = ["--envs", "HexapodCliffWalk-v0", "--policies", "zero", "--episodes", "1"]
    argv += ["--max-episode-steps", "5", "--no-progress"]
    for _ in range(2):
        assert evaluate_main(argv) == 0
    assert (tmp_path / "reports" / "default" / "metrics.json").is_file()
    # a -v0 id is no part of the default suite (the v1 benchmark): the title says no more
    title = (tmp_path / "reports" / "default" / "report.md").read_text().splitlines()[0]
    assert title.startswith("# Hexapod policy evaluation") and "v1" not in title
    listed = [a if a != "HexapodCliffWalk-v0" else "HexapodCliffWalk-v1" for a in argv]
    for extra, expected in (
        (listed, "# Hexapod benchmark v1"),
        ([*argv, "--set", "title=Mine"], "# Mine"),
    ):
        assert evaluate_main([*extra, "--output-dir", "titled", "--force"]) == 0
        assert (tmp_path / "titled" / "report.md").read_text().startswith(expected)
    assert evaluate_main([*argv, "--output-dir", "reports/default"]) == 0  # the same directory
    assert evaluate_main([*argv, "--output-dir", "mine"]) == 0
    capsys.readouterr()
    assert evaluate_main([*argv, "--output-dir", "mine"]) == 2
    assert "report directory mine already exists; pass --force" in capsys.readouterr().err
    assert evaluate_main([*argv, "--output-dir", "mine", "--force"]) == 0
    shutil.rmtree(tmp_path / "reports" / "default")
    (tmp_path / "reports" / "default").mkdir()
    (tmp_path / "reports" / "default" / "notes.txt").write_text("not a report")
    assert evaluate_main(argv) == 2
    assert (tmp_path / "reports" / "default" / "notes.txt").is_file()


def test_an_interrupted_evaluation_keeps_the_earlier_report(tmp_path, monkeypatch):
    """The report is written beside the output directory and swapped in when it is complete:
    a run stopped half-way (Ctrl-C) leaves the earlier report as it was, and no partial one."""
    from agents.pipeline import evaluation

    argv = ["--envs", "HexapodCliffWalk-v0", "--policies", "zero", "--episodes", "1"]
    argv += ["--max-episode-steps", "5", "--no-progress", "--output-dir", str(tmp_path / "rep")]
    assert evaluate_main(argv) == 0
    before = (tmp_path / "rep" / "metrics.json").read_bytes()

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(evaluation, "run_episode", interrupted)
    with pytest.raises(KeyboardInterrupt):
        evaluate_main([*argv, "--force"])
    assert (tmp_path / "rep" / "metrics.json").read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rep"]


def test_force_replaces_only_an_earlier_report_never_other_files(tmp_path, monkeypatch, capsys):
    """--force empties a directory only if it holds an earlier report, and never the working
    directory or one above it: a mistyped --output-dir must not delete a user's files."""
    monkeypatch.chdir(tmp_path)
    argv = ["--envs", "HexapodCliffWalk-v0", "--policies", "zero", "--episodes", "1"]
    argv += ["--max-episode-steps", "5", "--no-progress", "--force"]
    precious = tmp_path / "precious"
    (precious / "sub").mkdir(parents=True)
    (precious / "sub" / "data.csv").write_text("1,2")
    assert evaluate_main([*argv, "--output-dir", "precious"]) == 2
    assert "is not an earlier report directory" in capsys.readouterr().err
    assert (precious / "sub" / "data.csv").is_file()
    for parent in (".", ".."):
        assert evaluate_main([*argv, "--output-dir", parent]) == 2
        assert "is the working directory or above it" in capsys.readouterr().err
    (tmp_path / "notes.csv").write_text("1,2")
    assert evaluate_main([*argv, "--output-dir", "notes.csv"]) == 2
    assert "exists and is not a directory" in capsys.readouterr().err
    assert (precious / "sub" / "data.csv").is_file() and (tmp_path / "notes.csv").is_file()
    # a symbolic link to an earlier report: the report replaces the directory it points to
    assert evaluate_main([*argv, "--output-dir", "rep"]) == 0
    (tmp_path / "link").symlink_to(tmp_path / "rep")
    assert evaluate_main([*argv, "--output-dir", "link"]) == 0
    assert (tmp_path / "link").is_symlink() and (tmp_path / "link" / "metrics.json").is_file()


def test_missing_shipped_model_is_skipped_with_a_warning_in_the_report(tmp_path):
    models = tmp_path / "models"
    argv = ["--envs", "HexapodCliffWalk-v0", "--episodes", "1", "--max-episode-steps", "20"]
    argv += ["--output-dir", str(tmp_path / "rep"), "--no-progress"]
    argv += ["--set", f"policies=[analytical, 'ppo:{models}/{{env_id}}']"]
    argv += ["--set", "missing_models=skip"]
    assert evaluate_main(argv) == 0
    md = (tmp_path / "rep" / "report.md").read_text()
    assert f"**warning:** HexapodCliffWalk-v0: skipped ppo:{models}/{{env_id}}" in md
    assert f"no model at {models}/HexapodCliffWalk-v0" in md
    assert "| analytical |" in md


def test_a_per_env_model_that_exists_for_some_envs_is_one_note():
    from types import SimpleNamespace

    from agents.pipeline.evaluation import _skip_lines

    name, why = "ppo:models/{env_id}/gains", "no model at ..."
    results = [
        SimpleNamespace(env_id="A-v0", runs={"zero": 0}),
        SimpleNamespace(env_id="B-v0", runs={"zero": 0, name: 0}),
        SimpleNamespace(env_id="C-v0", runs={"zero": 0}),
    ]
    skipped = {name: [("A-v0", why), ("C-v0", why)]}
    note = f"{name} runs on B-v0 only: no model at models/{{env_id}}/gains for A-v0, C-v0"
    assert _skip_lines(skipped, results) == ([], [note])  # expected: a note
    results[1].runs.pop(name)  # found nowhere: a warning per env, with the reason
    skipped[name].insert(1, ("B-v0", why))
    warnings = [f"{e}-v0: skipped {name} - {why}" for e in "ABC"]
    assert _skip_lines(skipped, results) == (warnings, [])


def test_unknown_env_id_and_existing_report_dir(tmp_path, capsys):
    assert evaluate_main(["--envs", "HexapodClifWalk-v0", "--output-dir", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "unknown env id 'HexapodClifWalk-v0'" in err and "HexapodCliffWalk-v0" in err
    (tmp_path / "rep").mkdir()
    (tmp_path / "rep" / "report.md").write_text("keep me")
    assert evaluate(tmp_path / "rep", "zero") == 2
    assert "already exists; pass --force" in capsys.readouterr().err
    assert (tmp_path / "rep" / "report.md").read_text() == "keep me"


class ToyEnv(gym.Env):
    """A 1-D env that fills every evaluation hook: declared per-step metrics and episode_metrics."""

    evaluation_metrics = {
        "height_m": {"reduce": "min", "better": "higher", "description": "lowest torso height"},
        "recovery_time_s": {"reduce": "episode", "better": "lower"},
    }
    control_dt = 0.1

    def __init__(self):
        self.observation_space = gym.spaces.Box(-10.0, 10.0, (1,))
        self.action_space = gym.spaces.Box(-1.0, 1.0, (1,))

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.x, self.k = 0.0, 0
        return np.array([self.x], dtype=np.float32), {}

    def step(self, action):
        self.x += float(action[0]) * 0.1
        self.k += 1
        info = {
            "fasm_margin_deg": 30.0 - 20.0 * abs(self.x),
            "reward_move": float(action[0]),
            "height_m": 0.5 - 0.01 * self.k,
            "is_success": True,
            "distance": self.x,
            "episode_metrics": {
                "recovery_time_s": 0.1 * self.k,
                "adjustment_leg": "RR" if self.x >= 0 else "LM",
                "cycle_rms": [abs(self.x), 2 * abs(self.x)],
            },
        }
        obs = np.array([self.x], dtype=np.float32)
        return obs, float(action[0]), False, False, info


def test_env_specific_metrics_reach_metrics_json_and_report(tmp_path):
    gym.register("PipelineToy-v0", entry_point=ToyEnv, max_episode_steps=10)
    argv = ["--envs", "PipelineToy-v0", "--episodes", "2", "--no-progress"]
    argv += ["--output-dir", str(tmp_path / "rep"), "--set", "missing_models=skip"]
    argv += ["--set", "policies=[analytical, zero, random]"]
    assert evaluate_main(argv) == 0
    metrics = json.loads((tmp_path / "rep" / "metrics.json").read_text())
    env = metrics["envs"]["PipelineToy-v0"]
    assert list(env["policies"]) == ["zero", "random"]
    zero = env["policies"]["zero"]
    assert zero["episodes"][0]["specifics"]["height_m"] == pytest.approx(0.4)
    assert zero["episodes"][0]["duration_s"] == pytest.approx(1.0)
    specifics = zero["aggregate"]["specifics"]
    assert specifics["recovery_time_s"]["mean"] == pytest.approx(1.0)
    assert specifics["adjustment_leg"]["counts"] == {"RR": 2}
    assert specifics["cycle_rms"]["pooled"] and specifics["cycle_rms"]["n"] == 4
    md = (tmp_path / "rep" / "report.md").read_text()
    assert "skipped analytical - no analytical controller registered" in md
    assert "### Env-specific metrics" in md and "height_m (lowest torso height)" in md
    assert "figures/PipelineToy-v0_specific.png" in md


def test_zero_initialised_action_net_starts_at_the_reference_and_is_evaluated_at_step_0(tmp_path):
    """policy.zero_init_action_net: the untrained policy is the zero action (the reference gait
    in the residual mode), and the learning curve starts with its evaluation at step 0."""
    extra = [*TINY, "train.total_timesteps=256", "policy.zero_init_action_net=true"]
    extra += ["eval.freq=256", "eval.n_episodes=1", "ppo.learning_rate=1e-12"]
    assert train(tmp_path, "zero", overrides=extra) == 0
    env = gym.make("HexapodCliffWalk-v0")
    policy = PPOPolicy.load(tmp_path / "zero" / "final", env)
    obs, _ = env.reset(seed=0)
    np.testing.assert_allclose(policy(obs), np.zeros(18), atol=1e-6)
    with np.load(tmp_path / "zero" / "evaluations.npz") as log:
        assert list(log["timesteps"]) == [0, 256]


def test_same_tasks_evaluations_score_every_checkpoint_on_the_same_tasks(tmp_path):
    """eval.same_tasks reseeds the evaluation env: with a nearly frozen policy every evaluation
    repeats the first (without it, each evaluation draws new tasks); eval.select=success keeps
    best/ by success rate, then return, and writes both to its meta.json. A learning rate of
    1e-12 still moves the zero-initialised action net by about 1e-12, which the physics may
    carry into the returns' eighth digit, hence the relative tolerance."""
    extra = [*TINY, "train.total_timesteps=512", "policy.zero_init_action_net=true"]
    extra += ["eval.freq=256", "eval.n_episodes=2", "ppo.learning_rate=1e-12"]
    extra += ["env.kwargs={task_distribution: train}"]
    logs = {}
    for same in (True, False):
        name = f"same_{same}"
        both = [f"eval.same_tasks={str(same).lower()}", "eval.select=success"]
        assert train(tmp_path, name, overrides=[*extra, *both]) == 0
        with np.load(tmp_path / name / "evaluations.npz") as log:
            logs[same] = log["results"]
            if same:
                steps, successes = log["timesteps"], log["successes"].mean(axis=1)
    assert logs[True].shape == (3, 2)
    np.testing.assert_allclose(logs[True][1:], np.repeat(logs[True][:1], 2, axis=0), rtol=1e-6)
    assert not np.allclose(logs[False][0], logs[False][1], rtol=1e-6)
    # best/: the most successes, then the highest mean return (the first of equals)
    ranks = list(zip(successes, logs[True].mean(axis=1), strict=True))
    chosen = max(range(len(ranks)), key=lambda i: (ranks[i], -i))
    best = meta(tmp_path / "same_True" / "best")
    assert best["num_timesteps"] == steps[chosen] and "eval_success_rate" in best
    assert best["eval_success_rate"] == pytest.approx(float(successes[chosen]))
    assert best["eval_mean_reward"] == pytest.approx(float(logs[True][chosen].mean()))


def test_each_policy_is_evaluated_in_the_action_mode_it_was_built_for(run):
    from agents.pipeline.evaluation import policy_env_kwargs

    assert policy_env_kwargs("analytical", "HexapodCliffWalk-v0") == {"action_mode": "joint"}
    assert policy_env_kwargs("analytical", "HexapodStewartTilt-v0") == {}
    assert policy_env_kwargs("zero", "HexapodCliffWalk-v0") == {}
    trained = policy_env_kwargs(f"ppo:{run[0]}", "HexapodCliffWalk-v0")
    assert trained == {"action_mode": "residual", "residual_scale": 0.25}


def test_a_run_is_evaluated_with_the_observation_it_was_trained_on(monkeypatch):
    """terrain_scan shapes the observation: it comes from the run, not from the suite."""
    from agents.pipeline.evaluation import policy_env_kwargs
    from agents.run_files import artifacts

    class Run:
        def __init__(self, kwargs):
            self.kwargs = kwargs

        def training_config(self):
            return {"env": {"kwargs": self.kwargs}}

    scan = {"terrain": "blocks", "action_mode": "gains", "terrain_scan": True}
    monkeypatch.setattr(artifacts, "find_model", lambda path: Run(scan))
    env_id = "HexapodIrregularTerrain-v0"
    assert policy_env_kwargs("ppo:x", env_id, {"terrain": "ramp"}) == {
        "action_mode": "gains",
        "terrain_scan": True,
    }
    monkeypatch.setattr(artifacts, "find_model", lambda path: Run({"action_mode": "gains"}))
    assert policy_env_kwargs("ppo:x", env_id, {"terrain_scan": True}) == {
        "action_mode": "gains",
        "terrain_scan": False,
    }


def test_a_run_is_evaluated_with_the_actions_it_was_trained_on(monkeypatch):
    """clock_action adds an action: a run trained with it is evaluated with it."""
    from agents.pipeline.evaluation import policy_env_kwargs
    from agents.run_files import artifacts

    class Run:
        def training_config(self):
            return {"env": {"kwargs": {"residual_scale": 0.1, "clock_action": True}}}

    monkeypatch.setattr(artifacts, "find_model", lambda path: Run())
    kwargs = policy_env_kwargs("ppo:x", "HexapodCliffWalk-v1")
    assert kwargs == {"residual_scale": 0.1, "clock_action": True}
    with gym.make("HexapodCliffWalk-v1", **kwargs) as env:
        assert env.action_space.shape == (19,)


def test_reward_exclude_takes_the_named_terms_out_of_the_reward():
    """env.reward_exclude: the learner's reward is the env's minus those info terms; a term the
    env does not report is an error at the first step."""
    from agents.pipeline.envs import EnvSpec
    from agents.run_files.errors import UserError

    plain = EnvSpec("HexapodCliffWalk-v0", gym_packages=["hexapod_envs"]).make()
    spec = EnvSpec("HexapodCliffWalk-v0", gym_packages=["hexapod_envs"], reward_exclude=["alive"])
    without = spec.make()
    for env in (plain, without):
        env.reset(seed=0)
    for _ in range(3):
        _, r0, *_, info = plain.step(np.zeros(18))
        _, r1, *_ = without.step(np.zeros(18))
        assert info["reward_alive"] > 0
        assert r1 == pytest.approx(r0 - info["reward_alive"])
    bad = EnvSpec("HexapodCliffWalk-v0", gym_packages=["hexapod_envs"], reward_exclude=["alivee"])
    env = bad.make()
    env.reset(seed=0)
    with pytest.raises(UserError, match="reward_alivee"):
        env.step(np.zeros(18))


def test_a_misspelt_reward_exclude_stops_training_before_the_run_folder(tmp_path, capsys):
    assert train(tmp_path, "x", overrides=[*TINY, "env.reward_exclude=[alivee]"]) == 2
    assert "reward_alivee" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


def test_a_settings_note_names_the_model_of_its_env_not_the_template(run, tmp_path):
    """``ppo:models/{env_id}/...`` differing from its training env is told per env, with the
    path of the model that differs (the report must not show an unexpanded template)."""
    models = tmp_path / "models"
    shutil.copytree(run[0] / "final", models / "HexapodCliffWalk-v0")
    settings = read_settings(models / "HexapodCliffWalk-v0")
    settings["reward"]["forward_weight"] = 3.0
    (models / "HexapodCliffWalk-v0" / "env_settings.yaml").write_text(yaml.safe_dump(settings))
    assert evaluate(tmp_path / "rep", f"ppo:{models}/{{env_id}}") == 0
    metrics = json.loads((tmp_path / "rep" / "metrics.json").read_text())
    expected = f"HexapodCliffWalk-v0: ppo:{models}/HexapodCliffWalk-v0 was trained on an env"
    assert [n for n in metrics["notes"] if n.startswith(expected)]
    assert f"- **note:** {expected}" in (tmp_path / "rep" / "report.md").read_text()


def test_same_task_evaluations_log_the_change_since_step_0():
    """With the same tasks at every evaluation, the success rate and mean return are logged as
    changes against the run's first evaluation (step 0)."""
    from agents.pipeline.callbacks import StatsEvalCallback

    class Logger:
        def __init__(self):
            self.values = {}

        def record(self, key, value):
            self.values[key] = value

    callback = StatsEvalCallback.__new__(StatsEvalCallback)
    callback.evaluations_timesteps = [0, 256, 512]
    callback.evaluations_successes = [[1, 0, 0, 0], [1, 1, 0, 0], [1, 1, 1, 0]]
    callback.evaluations_results = [[10.0, 0.0], [10.0, 2.0], [12.0, 4.0]]
    logger = Logger()
    callback.model = type("Model", (), {"logger": logger})()
    callback._log_change_since_start()
    assert logger.values["eval/success_change_since_start"] == pytest.approx(0.5)
    assert logger.values["eval/return_change_since_start"] == pytest.approx(3.0)


@pytest.mark.parametrize(
    "env_id",
    [
        "HexapodCliffWalk-v1",
        "HexapodStewartTilt-v1",
        "HexapodIrregularTerrain-v1",
        "HexapodDitchCrossing-v1",
    ],
)
def test_every_switch_that_shapes_the_spaces_is_a_policy_setting(env_id):
    """A run is evaluated with the POLICY_SETTINGS it was trained with; an on/off setting that
    changes the action or observation space but is missing there would be evaluated with the
    suite's default, and the model would not fit the env."""
    import dataclasses

    from agents.env_kwargs import POLICY_SETTINGS

    with gym.make(env_id) as env:
        base = env.unwrapped
        spaces = (env.action_space.shape, env.observation_space.shape)
        switches = [
            f.name
            for f in dataclasses.fields(base.settings)
            if getattr(base.settings, f.name) is False
        ]
    assert switches  # the envs have such switches (the scans, the extra actions)
    shaping = []
    for name in switches:
        try:
            made = gym.make(env_id, **{name: True})
        except ValueError:  # needs other settings too (e.g. a walking scenario)
            continue
        with made:
            if (made.action_space.shape, made.observation_space.shape) != spaces:
                shaping.append(name)
    assert shaping and not set(shaping) - set(POLICY_SETTINGS), shaping


@pytest.mark.parametrize(
    ("already", "egl", "expected"),
    [(None, "libEGL.so.1", "egl"), (None, None, None), ("osmesa", "libEGL.so.1", "osmesa")],
)
def test_headless_gl_defaults_to_egl_only_where_libegl_exists(monkeypatch, already, egl, expected):
    """hexapod-evaluate sets MUJOCO_GL=egl for its frames, but not where libEGL is missing (MuJoCo
    could not even be imported then) nor over the user's own choice."""
    import ctypes.util

    monkeypatch.delenv("MUJOCO_GL", raising=False)
    if already is not None:
        monkeypatch.setenv("MUJOCO_GL", already)
    monkeypatch.setattr(ctypes.util, "find_library", lambda name: egl if name == "EGL" else None)
    default_headless_gl()
    assert os.environ.get("MUJOCO_GL") == expected
