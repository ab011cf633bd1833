"""Pipeline safety: model files that cannot run code, damaged files that give clear errors,
resume that falls back past a damaged checkpoint, hyperparameter ranges, interrupts that end.

The crafted files carry a pickle whose loading creates a marker file: a test fails if the marker
appears without ``--trust-pickle``."""

import base64
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import cloudpickle
import gymnasium as gym
import numpy as np
import pytest
from helpers.cliff_ppo_runs import CONFIG, TINY, evaluate, meta, sets, train
from helpers.paths import REPO

from agents.pipeline import callbacks, training
from agents.pipeline.cli import train_main
from agents.ppo import PPOPolicy
from agents.run_files.errors import UserError
from agents.run_files.model_files import NormalizationStats


class Touch:
    """Unpickling this creates `path` (stands for any code a malicious file could run)."""

    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):
        return (open, (self.path, "w"))


def serialized(obj) -> dict:
    return {":type:": "x", ":serialized:": base64.b64encode(cloudpickle.dumps(obj)).decode()}


def rewrite_zip(path: Path, edit_data=None, replace: dict | None = None) -> None:
    """Rewrite an SB3 zip: `edit_data(data)` edits its JSON, `replace` swaps whole members."""
    with zipfile.ZipFile(path) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    if edit_data is not None:
        data = json.loads(members["data"])
        edit_data(data)
        members["data"] = json.dumps(data).encode()
    members.update(replace or {})
    with zipfile.ZipFile(path, "w") as archive:
        for name, content in members.items():
            archive.writestr(name, content)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """A tiny run with checkpoints every 256 steps (256 .. 1024) and final/."""
    tmp = tmp_path_factory.mktemp("safety")
    assert train(tmp, "tiny", overrides=[*TINY, "checkpoint.freq=256"]) == 0
    return tmp / "tiny"


@pytest.fixture
def copy_run(run, tmp_path):
    def make(name="copy") -> Path:
        target = tmp_path / name
        shutil.copytree(run, target)
        return target

    return make


def model_copy(run: Path, tmp_path: Path, name: str = "model") -> Path:
    target = tmp_path / name
    shutil.copytree(run / "final", target)
    return target


# --- stats as plain arrays -----------------------------------------------------------------
def test_stats_round_trip_and_normalise_like_sb3(tmp_path):
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    venv = VecNormalize(DummyVecEnv([lambda: gym.make("Pendulum-v1")]), clip_obs=2.0)
    venv.seed(0)
    venv.reset()
    for _ in range(50):
        venv.step(np.array([venv.action_space.sample()]))
    stats = NormalizationStats.from_vec_normalize(venv)
    stats.save(tmp_path / "s.npz")
    loaded = NormalizationStats.load(tmp_path / "s.npz")
    obs = np.array([0.3, -0.9, 7.0], dtype=np.float32)
    np.testing.assert_allclose(loaded.normalize_obs(obs), venv.normalize_obs(obs), rtol=1e-6)
    fresh = VecNormalize(DummyVecEnv([lambda: gym.make("Pendulum-v1")]))
    loaded.apply_to(fresh)
    np.testing.assert_allclose(fresh.normalize_obs(obs), venv.normalize_obs(obs), rtol=1e-6)
    assert fresh.clip_obs == 2.0 and fresh.ret_rms.count == venv.ret_rms.count


def test_run_saves_statistics_without_pickle(run):
    for model_dir in (run / "final", run / "best", *(run / "checkpoints").iterdir()):
        assert (model_dir / "vecnormalize.npz").is_file()
        assert not (model_dir / "vecnormalize.pkl").exists()
        with np.load(model_dir / "vecnormalize.npz", allow_pickle=False) as data:
            assert data["obs_mean"].shape == tuple(meta(model_dir)["observation_shape"])


UNTRAINED_BY_DESIGN = {"HexapodIrregularTerrain-v0/paper_gains"}
"""Shipped models that are not learned agents: the paper's gains in a gains agent's shape, the
like-for-like reference of the gains reports (docs/results.md)."""


def test_no_shipped_agent_is_a_step_0_checkpoint():
    """A run whose best evaluation was its starting point has learned nothing to ship: every
    shipped agent's checkpoint is from after a training step."""
    from agents.run_files.artifacts import read_meta

    model_dirs = sorted(p.parent for p in (REPO / "models").glob("*/*/model.zip"))
    assert model_dirs
    for model_dir in model_dirs:
        name = f"{model_dir.parent.name}/{model_dir.name}"
        steps = read_meta(model_dir)["num_timesteps"]
        assert (steps == 0) == (name in UNTRAINED_BY_DESIGN), (name, steps)


def test_every_shipped_agent_beat_its_step_0():
    """Every shipped learned agent has a committed check against its own step-0 policy on at
    least 50 tasks (`scripts/check_step0.py`, reports/step0_check/summary.json) made with these
    very weights, and a check of it says it beats its step 0."""
    import hashlib

    summary = json.loads((REPO / "reports" / "step0_check" / "summary.json").read_text())
    for model_dir in sorted(p.parent for p in (REPO / "models").glob("*/*/model.zip")):
        name = f"{model_dir.parent.name}/{model_dir.name}"
        if name in UNTRAINED_BY_DESIGN:
            continue
        records = summary.get(f"models/{name}", {})
        assert records, f"no step-0 check of models/{name}: run scripts/check_step0.py"
        digest = hashlib.sha256((model_dir / "model.zip").read_bytes()).hexdigest()
        for record in records.values():
            assert record["model_sha256"] == digest, f"models/{name} changed since its check"
        passed = [
            r for r in records.values() if r["tasks"] >= 50 and r["verdict"].startswith("beats")
        ]
        assert passed, (name, records)


def test_shipped_models_load_without_pickle():
    """Every shipped agent (models/<env id>/<ppo|gains|knobs>/) loads without unpickling, in
    the action settings it was trained with, and acts inside the action space."""
    import yaml

    import hexapod_envs  # noqa: F401  (registers the env ids)

    model_dirs = sorted(p.parent for p in (REPO / "models").glob("*/*/model.zip"))
    assert {d.name for d in model_dirs} >= {"ppo", "gains", "knobs"}
    for model_dir in model_dirs:
        assert not list(model_dir.glob("*.pkl")), model_dir
        env_id = model_dir.parent.name
        kwargs = yaml.safe_load((model_dir / "config.yaml").read_text())["env"]["kwargs"] or {}
        env = gym.make(env_id, **kwargs)
        policy = PPOPolicy.load(model_dir, env)  # trust_pickle=False
        obs, _ = env.reset(seed=0)
        policy.reset()
        assert env.action_space.contains(np.asarray(policy(obs), dtype=np.float32)), model_dir


# --- crafted files -------------------------------------------------------------------------
def test_crafted_model_zip_runs_no_code(run, tmp_path, capsys):
    marker = tmp_path / "marker"
    model_dir = model_copy(run, tmp_path)

    def add_payloads(data):
        data["observation_space"] = serialized(Touch(marker))  # a known entry: replaced
        data["evil"] = serialized(Touch(marker))  # an unknown entry: refused

    rewrite_zip(model_dir / "model.zip", add_payloads)
    assert evaluate(tmp_path / "rep", f"ppo:{model_dir}") == 2
    err = capsys.readouterr().err
    assert "pickled entries ['evil']" in err and "--trust-pickle" in err
    assert not marker.exists()
    # the explicit opt-in is the only way the file's code runs
    assert evaluate(tmp_path / "rep2", f"ppo:{model_dir}", extra=["--trust-pickle"]) in (0, 2)
    assert marker.exists()


def test_known_pickled_entries_are_replaced_not_unpickled(run, tmp_path):
    marker = tmp_path / "marker"
    model_dir = model_copy(run, tmp_path)
    keys = ("observation_space", "policy_class", "lr_schedule", "_last_obs", "ep_info_buffer")

    def poison(data):
        for key in keys:
            data[key] = serialized(Touch(marker))

    rewrite_zip(model_dir / "model.zip", poison)
    policy = PPOPolicy.load(model_dir, gym.make("HexapodCliffWalk-v0", **_kwargs(run)))
    assert policy.model is not None and not marker.exists()


def _kwargs(run: Path) -> dict:
    import yaml

    return yaml.safe_load((run / "config.yaml").read_text())["env"]["kwargs"] or {}


def test_legacy_pickled_statistics_are_refused(run, tmp_path, capsys):
    marker = tmp_path / "marker"
    model_dir = model_copy(run, tmp_path)
    (model_dir / "vecnormalize.npz").unlink()
    (model_dir / "vecnormalize.pkl").write_bytes(cloudpickle.dumps(Touch(marker)))
    assert evaluate(tmp_path / "rep", f"ppo:{model_dir}") == 2
    err = capsys.readouterr().err
    assert "vecnormalize.pkl is a pickle file" in err and "--trust-pickle" in err
    assert not marker.exists()
    assert evaluate(tmp_path / "rep2", f"ppo:{model_dir}", extra=["--trust-pickle"]) == 2
    assert marker.exists()  # trusted: unpickled, then refused as not a VecNormalize


def test_statistics_with_object_arrays_are_refused(run, tmp_path, capsys):
    marker = tmp_path / "marker"
    model_dir = model_copy(run, tmp_path)
    good = dict(np.load(model_dir / "vecnormalize.npz"))
    good["obs_mean"] = np.array([Touch(marker)], dtype=object)
    with open(model_dir / "vecnormalize.npz", "wb") as fh:
        np.savez(fh, **good)
    assert evaluate(tmp_path / "rep", f"ppo:{model_dir}") == 2
    assert "unreadable or incomplete" in capsys.readouterr().err
    assert not marker.exists()


def test_resume_with_crafted_checkpoints_runs_no_code(copy_run, tmp_path, capsys):
    marker = tmp_path / "marker"
    run_dir = copy_run()
    for model_zip in run_dir.glob("**/model.zip"):
        rewrite_zip(model_zip, lambda data: data.update(evil=serialized(Touch(marker))))
    config_before = (run_dir / "config.yaml").read_text()
    command_before = (run_dir / "command.txt").read_text()
    argv = ["--resume", str(run_dir), "--set", "train.total_timesteps=1536"]
    assert train_main(argv) == 2
    err = capsys.readouterr().err
    assert "no loadable checkpoint" in err and "--trust-pickle" in err
    assert not marker.exists()
    # nothing was touched before a successful load
    assert (run_dir / "config.yaml").read_text() == config_before
    assert (run_dir / "command.txt").read_text() == command_before


def test_report_escapes_policy_names_and_paths(run, tmp_path):
    hostile = tmp_path / "m<script>alert(1)"
    shutil.copytree(run / "final", hostile)
    assert evaluate(tmp_path / "rep", "zero", f"ppo:{hostile}") == 0
    page = (tmp_path / "rep" / "report.html").read_text()
    assert "<script>alert(1)" not in page and "&lt;script&gt;alert(1)" in page


# --- damaged files -------------------------------------------------------------------------
def test_truncated_statistics_give_a_clear_error(run, tmp_path, capsys):
    model_dir = model_copy(run, tmp_path)
    stats = model_dir / "vecnormalize.npz"
    stats.write_bytes(stats.read_bytes()[:100])
    assert evaluate(tmp_path / "rep", f"ppo:{model_dir}") == 2
    err = capsys.readouterr().err
    assert f"normalisation statistics {stats} are unreadable" in err
    assert "Traceback" not in err


def test_corrupted_policy_weights_give_a_clear_error(run, tmp_path, capsys):
    model_dir = model_copy(run, tmp_path)
    marker = tmp_path / "marker"
    rewrite_zip(model_dir / "model.zip", replace={"policy.pth": cloudpickle.dumps(Touch(marker))})
    assert evaluate(tmp_path / "rep", f"ppo:{model_dir}") == 2
    err = capsys.readouterr().err
    assert "weights are not plain tensors" in err
    assert "weights_only=False" not in err and not marker.exists()
    rewrite_zip(model_dir / "model.zip", replace={"policy.pth": b"\x00garbage"})
    assert evaluate(tmp_path / "rep2", f"ppo:{model_dir}") == 2
    assert f"cannot load the PPO model {model_dir / 'model.zip'}" in capsys.readouterr().err


def test_resume_falls_back_past_a_damaged_newest_checkpoint(copy_run, capsys):
    run_dir = copy_run()
    newest = run_dir / "final"
    (newest / "model.zip").write_bytes(b"not a zip")
    stats = run_dir / "checkpoints" / "step_000000001024" / "vecnormalize.npz"
    stats.write_bytes(stats.read_bytes()[:50])
    # both 1024-step saves are damaged: resume goes back to the 768-step checkpoint
    assert train_main(["--resume", str(run_dir), "--set", "train.total_timesteps=1100"]) == 0
    err = capsys.readouterr().err
    assert "cannot resume from" in err and "falling back to step_000000000768" in err
    assert meta(run_dir / "final")["num_timesteps"] >= 1100
    # the evaluation at 1024 steps is made again, not appended after the first one
    timesteps = np.load(run_dir / "evaluations.npz")["timesteps"]
    assert timesteps.tolist() == [0, 512, 1024]


def test_resume_skips_half_written_checkpoints_and_ones_without_their_statistics(copy_run, capsys):
    """A folder a kill left with model.zip but no meta.json is not a checkpoint; one whose
    normalisation statistics are gone is refused (it would restart them from nothing)."""
    run_dir = copy_run()
    shutil.rmtree(run_dir / "final")
    half = run_dir / "checkpoints" / "step_000000002048"
    half.mkdir()
    shutil.copy(run_dir / "checkpoints" / "step_000000001024" / "model.zip", half)
    (run_dir / "checkpoints" / "step_000000001024" / "vecnormalize.npz").unlink()
    assert train_main(["--resume", str(run_dir), "--set", "train.total_timesteps=1100"]) == 0
    err = capsys.readouterr().err
    assert "step_000000002048" not in err
    assert "has no vecnormalize.npz" in err and "falling back to step_000000000768" in err


def test_a_model_without_its_normalisation_statistics_is_refused(run, tmp_path):
    model_dir = model_copy(run, tmp_path)
    (model_dir / "vecnormalize.npz").unlink()
    with pytest.raises(UserError, match="has no vecnormalize.npz, but its config.yaml normalises"):
        PPOPolicy.load(model_dir, gym.make("HexapodCliffWalk-v0", **_kwargs(run)))


# --- hyperparameter ranges -----------------------------------------------------------------
@pytest.mark.parametrize(
    ("override", "key"),
    [
        ("ppo.learning_rate=-1", "ppo.learning_rate"),
        ("ppo.gamma=2", "ppo.gamma"),
        ("ppo.gamma=0", "ppo.gamma"),
        ("ppo.gae_lambda=1.5", "ppo.gae_lambda"),
        ("ppo.n_epochs=0", "ppo.n_epochs"),
        ("ppo.batch_size=0", "ppo.batch_size"),
        ("ppo.n_steps=0", "ppo.n_steps"),
        ("ppo.clip_range=0", "ppo.clip_range"),
        ("ppo.clip_range_vf=-0.1", "ppo.clip_range_vf"),
        ("ppo.ent_coef=-0.01", "ppo.ent_coef"),
        ("ppo.vf_coef=.nan", "ppo.vf_coef"),
        ("ppo.max_grad_norm=0", "ppo.max_grad_norm"),
        ("ppo.target_kl=0", "ppo.target_kl"),
        ("ppo.sde_sample_freq=-2", "ppo.sde_sample_freq"),
        ("normalize.clip_observation=0", "normalize.clip_observation"),
        ("normalize.clip_reward=.inf", "normalize.clip_reward"),
        ("policy.pi=[0]", "policy.pi"),
        ("policy.log_std_init=.nan", "policy.log_std_init"),
        ("train.seed=-1", "train.seed"),
        ("eval.n_episodes=0", "eval.n_episodes"),
        ("eval.freq=-1", "eval.freq"),
        ("checkpoint.freq=-5", "checkpoint.freq"),
        ("logging.verbose=3", "logging.verbose"),
    ],
)
def test_out_of_range_hyperparameters_exit_2_and_create_nothing(tmp_path, capsys, override, key):
    assert train(tmp_path, "bad", overrides=[*TINY, override]) == 2
    err = capsys.readouterr().err
    assert f"{key} must be" in err and "Traceback" not in err
    assert not (tmp_path / "bad").exists()


def test_a_run_that_fails_to_start_leaves_no_directory(tmp_path, monkeypatch):
    def broken(*args, **kwargs):
        raise RuntimeError("cannot build the envs")

    monkeypatch.setattr(training, "_vec_envs", broken)
    with pytest.raises(RuntimeError, match="cannot build"):
        train(tmp_path, "broken")
    assert not (tmp_path / "broken").exists()


def test_an_exception_during_training_saves_a_checkpoint(tmp_path, monkeypatch, capsys):
    calls = {"n": 0}

    def fail(self):
        calls["n"] += 1
        if calls["n"] == 300:
            raise RuntimeError("simulated failure")
        return True

    monkeypatch.setattr(callbacks.EpisodeStatsCallback, "_on_step", fail)
    with pytest.raises(RuntimeError, match="simulated failure"):
        train(tmp_path, "crash", overrides=[*TINY, "eval.freq=0"])
    saved = meta(tmp_path / "crash" / "checkpoints" / "step_000000000300")
    assert saved["kind"] == "crash"
    assert "resume with: python train.py --resume" in capsys.readouterr().err


def test_policy_refuses_non_real_observations(run):
    policy = PPOPolicy.load(run, gym.make("HexapodCliffWalk-v0", **_kwargs(run)))
    with pytest.raises(UserError, match="complex"):
        policy(np.zeros(policy.model.observation_space.shape, dtype=complex))


# --- interrupts ----------------------------------------------------------------------------
def test_sigint_to_the_parent_alone_ends_training_with_a_loadable_checkpoint(tmp_path):
    """2 subprocess envs; SIGINT reaches only train.py (no process group signal)."""
    overrides = [
        *TINY,
        "vec_env.n_envs=2",
        "vec_env.type=subprocess",
        "train.total_timesteps=200000",
        "checkpoint.freq=512",
        "eval.freq=0",
    ]
    argv = [sys.executable, str(REPO / "train.py"), "--config", CONFIG]
    argv += ["--output-dir", str(tmp_path), "--run-name", "sig", *sets(overrides)]
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    proc = subprocess.Popen(argv, cwd=tmp_path, env=env, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 240
        while not list((tmp_path / "sig" / "checkpoints").glob("step_*/meta.json")):
            assert proc.poll() is None, proc.stderr.read()
            assert time.monotonic() < deadline, "training never reached its first checkpoint"
            time.sleep(0.2)
        proc.send_signal(signal.SIGINT)
        sent = time.monotonic()
        rc = proc.wait(timeout=30)
        assert time.monotonic() - sent < 30
    finally:
        if proc.poll() is None:
            proc.kill()
    err = proc.stderr.read()
    assert rc == 130, err
    assert "resume with: python train.py --resume" in err
    newest = max((tmp_path / "sig" / "checkpoints").glob("step_*"))
    assert meta(newest)["kind"] == "interrupt"  # saved on the signal, not the periodic one
    env = gym.make("HexapodCliffWalk-v0", **_kwargs(tmp_path / "sig"))
    PPOPolicy.load(newest, env)


def test_a_second_interrupt_while_saving_exits_at_once(tmp_path):
    code = (
        "import os, signal, time\n"
        "from agents.pipeline.training import _exit_on_second_interrupt\n"
        "with _exit_on_second_interrupt():\n"
        "    os.kill(os.getpid(), signal.SIGINT)\n"
        "    time.sleep(30)\n"
    )
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    start = time.monotonic()
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, timeout=60)
    assert done.returncode == 130 and time.monotonic() - start < 20
    assert b"second interrupt" in done.stderr


def test_close_vec_env_terminates_a_worker_that_does_not_answer():
    from stable_baselines3.common.vec_env import SubprocVecEnv

    venv = SubprocVecEnv([lambda: gym.make("Pendulum-v1")] * 2, start_method="fork")
    venv.reset()
    os.kill(venv.processes[0].pid, signal.SIGSTOP)  # a worker that never replies
    start = time.monotonic()
    training.close_vec_env(venv, timeout=2.0)
    assert time.monotonic() - start < 10
    assert venv.closed and not any(p.is_alive() for p in venv.processes)
