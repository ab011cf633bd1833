"""The record of a training env's settings (agents/pipeline/env_settings.py): what counts as a
difference, how it is worded, and the warning when a run is resumed on a changed env."""

from pathlib import Path

import gymnasium as gym
import yaml

from agents.pipeline.env_settings import (
    describe,
    differences,
    read_settings,
    resolved_settings,
    write_settings,
)
from agents.pipeline.training import _warn_if_settings_changed

ROOT = Path(__file__).resolve().parents[1]

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
    env = gym.make("HexapodIrregularTerrain-v0", terrain="blocks")
    settings = resolved_settings(env)
    assert settings["terrain"] == "blocks" and settings["reward"]["rate_weight"] > 0
    write_settings(tmp_path, settings)
    assert read_settings(tmp_path) == settings
    assert differences(read_settings(tmp_path), settings) == {}
    assert read_settings(tmp_path / "elsewhere") is None


def test_envs_without_typed_settings_record_nothing(tmp_path):
    env = gym.make("CartPole-v1")
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


def test_every_shipped_agent_records_the_env_it_was_trained_on_and_the_code_still_builds_it():
    """A default changed in the code (a physics step, a servo gain) fails here for every shipped
    agent trained on the former one, instead of silently evaluating it on another env."""
    models = sorted(p.parent for p in (ROOT / "models").glob("*/*/model.zip"))
    assert len(models) >= 10
    for model_dir in models:
        recorded = read_settings(model_dir)
        assert recorded is not None, f"{model_dir} has no env_settings.yaml"
        config = yaml.safe_load((model_dir / "config.yaml").read_text())["env"]
        now = resolved_settings(gym.make(config["id"], **config["kwargs"]))
        assert differences(recorded, now) == {}, (model_dir, describe(differences(recorded, now)))
