"""The record of a training env's settings (agents/run_files/env_settings.py): what counts as a
difference, how it is worded, and the warning when a run is resumed on a changed env."""

from pathlib import Path

import gymnasium as gym
from helpers.paths import REPO

from agents.pipeline.training import _warn_if_settings_changed, env_spec
from agents.run_files.env_settings import (
    describe,
    differences,
    read_settings,
    resolved_settings,
    write_settings,
)
from agents.run_files.train_config import load_train_config

TRAINED = {
    "physics_dt": 0.002,
    "terrain": "ramp",
    "task_distribution": "train",
    "render_mode": None,
    "train_ranges": {"slope_deg": [[5.0, 8.5]]},
    "reward": {"rate_weight": 5.0, "forward_weight": 1.0},
}


def test_differences_name_changed_settings_and_reward_terms_apart():
    now = {
        **TRAINED,
        "physics_dt": 0.0025,
        "reward": {"rate_weight": 0.5, "forward_weight": 1.0},
    }
    found = differences(TRAINED, now)
    assert found == {"physics_dt": (0.002, 0.0025), "reward.rate_weight": (5.0, 0.5)}
    assert describe(found) == (
        "physics_dt: 0.002 -> 0.0025; reward terms (change returns only): "
        "reward.rate_weight: 5.0 -> 0.5"
    )


def test_task_distribution_ranges_and_rendering_are_no_mismatch():
    now = {
        **TRAINED,
        "task_distribution": "test",
        "render_mode": "rgb_array",
        "train_ranges": {"slope_deg": [[1.0, 2.0]]},
    }
    assert differences(TRAINED, now) == {}


def test_a_setting_added_or_removed_since_the_training_shows_against_none():
    now = {k: v for k, v in TRAINED.items() if k != "terrain"} | {"terrain_scan": False}
    assert differences(TRAINED, now) == {"terrain": ("ramp", None), "terrain_scan": (None, False)}


def test_settings_round_trip_through_the_file_exactly(tmp_path):
    with gym.make("HexapodIrregularTerrain-v0", terrain="blocks") as env:
        settings = resolved_settings(env)
    assert settings["terrain"] == "blocks" and settings["reward"]["rate_weight"] > 0
    write_settings(tmp_path, settings)
    assert read_settings(tmp_path) == settings
    assert differences(read_settings(tmp_path), settings) == {}
    assert read_settings(tmp_path / "elsewhere") is None


def test_envs_without_typed_settings_record_nothing(tmp_path):
    with gym.make("CartPole-v1") as env:
        assert resolved_settings(env) is None
    write_settings(tmp_path, None)
    assert not list(tmp_path.iterdir())


def test_resuming_on_a_changed_env_warns_with_the_differences(tmp_path, capsys):
    write_settings(tmp_path, TRAINED)
    _warn_if_settings_changed(tmp_path, TRAINED)
    assert capsys.readouterr().err == ""
    _warn_if_settings_changed(tmp_path, {**TRAINED, "physics_dt": 0.0025})
    err = capsys.readouterr().err
    assert err.startswith(f"warning: the env's settings differ from those {tmp_path} started with")
    assert "physics_dt: 0.002 -> 0.0025" in err
    # unlike an evaluation, a resumed run keeps learning: changed ranges and rewards matter
    ranges = {**TRAINED, "train_ranges": {"slope_deg": [[1.0, 2.0]]}, "render_mode": "human"}
    _warn_if_settings_changed(tmp_path, ranges)
    err = capsys.readouterr().err
    assert "train_ranges" in err and "render_mode" not in err


def test_a_model_saved_without_settings_drops_an_earlier_record(tmp_path):
    """Overwriting e.g. best/ with a model of an env without typed settings must not leave the
    previous model's settings behind."""
    from types import SimpleNamespace

    from agents.run_files.artifacts import save_model_dir

    class FakeModel(SimpleNamespace):
        def save(self, path):
            Path(path).write_bytes(b"weights")

    space = SimpleNamespace(shape=(2,))
    model = FakeModel(num_timesteps=5, observation_space=space, action_space=space)
    save_model_dir(tmp_path, model, None, {"env": {}}, "cmd", "best", env_settings=TRAINED)
    assert read_settings(tmp_path) == TRAINED
    save_model_dir(tmp_path, model, None, {"env": {}}, "cmd", "best", env_settings=None)
    assert read_settings(tmp_path) is None and (tmp_path / "meta.json").is_file()


def test_every_shipped_agent_records_the_env_it_was_trained_on_and_the_code_still_builds_it():
    """A default changed in the code (a physics step, a servo gain) fails here for every shipped
    agent trained on the former one, instead of silently evaluating it on another env."""
    models = sorted(p.parent for p in (REPO / "models").glob("*/*/model.zip"))
    assert {f"{m.parent.name}/{m.name}" for m in models} >= {
        "HexapodStewartTilt-v1/knobs",
        "HexapodIrregularTerrain-v1/knobs",
        "HexapodIrregularTerrain-v1/ppo",
        "HexapodCliffWalk-v1/ppo",
        "HexapodStewartTilt-v1/ppo",
        "HexapodDitchCrossing-v1/knobs",
        "HexapodIrregularTerrain-v0/ppo",
        "HexapodIrregularTerrain-v0/gains",
    }
    for model_dir in models:
        recorded = read_settings(model_dir)
        assert recorded is not None, f"{model_dir} has no env_settings.yaml"
        config = load_train_config(model_dir / "config.yaml")
        with env_spec(config).make() as env:
            now = resolved_settings(env)
        assert differences(recorded, now) == {}, (model_dir, describe(differences(recorded, now)))
