"""Teaching a gains policy with the look-ahead (experiments.gains_lookahead.distill, its script)."""

from __future__ import annotations

import dataclasses

import gymnasium as gym
import numpy as np
import pytest
import torch

import hexapod_envs  # noqa: F401
from agents.pipeline.envs import EnvSpec
from agents.run_files.env_settings import read_settings
from experiments.gains_lookahead import distill_gains
from experiments.gains_lookahead.distill import (
    Demonstrations,
    demonstrate,
    fit_actor,
    fit_choice,
    interpolated_cost,
    lattice_costs,
)
from experiments.gains_lookahead.lookahead import CycleCost, gain_grid

CONFIG = "configs/irregular_terrain_gains_blocks_scan.yaml"


def test_interpolation_is_exact_on_the_lattice_linear_between_and_flat_beyond():
    levels = [0.2, 0.5, 0.8]
    rng = np.random.default_rng(0)
    lattice = torch.as_tensor(rng.uniform(size=(1, 3, 3, 3)))
    for i, g in enumerate(gain_grid(levels)):
        z, a, b = np.unravel_index(i, (3, 3, 3))
        value = interpolated_cost(lattice, torch.tensor([g], dtype=torch.float64), levels)
        assert float(value) == pytest.approx(float(lattice[0, z, a, b]), abs=1e-12)
    # halfway along k_α between (0.2, 0.2, 0.8) and (0.2, 0.5, 0.8)
    mid = interpolated_cost(lattice, torch.tensor([[0.2, 0.35, 0.8]], dtype=torch.float64), levels)
    assert float(mid) == pytest.approx(float(lattice[0, 0, :2, 2].mean()), abs=1e-12)
    beyond = interpolated_cost(lattice, torch.tensor([[1.0, 0.0, 0.9]]), levels)
    assert float(beyond) == pytest.approx(float(lattice[0, 2, 0, 2]), abs=1e-12)
    gains = torch.tensor([[0.3, 0.6, 0.4]], dtype=torch.float64, requires_grad=True)
    interpolated_cost(lattice, gains, levels).sum().backward()
    assert torch.all(torch.isfinite(gains.grad)) and torch.any(gains.grad != 0)
    with pytest.raises(ValueError, match="evenly spaced"):
        interpolated_cost(lattice, gains, [0.2, 0.3, 0.8])


def _synthetic(n: int = 400, seed: int = 0) -> Demonstrations:
    """Observation feature 0 says which k_z level is cheapest (0.2 when negative, else 0.8)."""
    rng = np.random.default_rng(seed)
    levels = np.array([0.2, 0.5, 0.8])
    grid = np.array(gain_grid(levels))
    candidates = np.vstack([grid, [0.6, 0.4, 0.4]])
    obs = rng.normal(size=(n, 4)).astype(np.float32)
    best_kz = np.where(obs[:, :1] < 0, 0.2, 0.8)
    pitch = np.abs(candidates[None, :, 0] - best_kz) + 0.01 * rng.uniform(size=(n, len(candidates)))
    zero, inf = np.zeros_like(pitch), np.full_like(pitch, np.inf)
    outcomes = np.stack([pitch, np.full_like(pitch, 0.1), zero, inf], axis=-1)
    reference = np.array([0.6, 0.4, 0.4])
    return Demonstrations(obs, outcomes, candidates, levels, reference, np.arange(n) // 20, n * 50)


def test_fit_actor_learns_the_state_dependent_choice_and_keeps_the_best_epoch():
    from stable_baselines3.common.policies import ActorCriticPolicy

    demos = _synthetic()
    torch.manual_seed(0)  # the actor's initial weights: otherwise whatever ran before draws them
    policy = ActorCriticPolicy(
        gym.spaces.Box(-np.inf, np.inf, (4,), np.float32),
        gym.spaces.Box(-1.0, 1.0, (3,), np.float32),
        lr_schedule=lambda _: 1e-3,
        net_arch=[32],
    )
    validation = demos.beds >= 16
    result = fit_actor(policy, demos.observations, demos, 1.0, validation, epochs=60)
    assert result.history[0][0] == 0 and len(result.history) == 61
    assert result.best_cost == min(v for _, _, v in result.history)
    # the teacher knows every row's cheapest; a constant cannot follow feature 0; the student can
    excess = result.best_cost - result.teacher_cost
    assert 0 < excess < 0.5 * (result.best_constant_cost - result.teacher_cost)
    assert result.best_cost < result.reference_cost
    with torch.no_grad():
        mean = policy.get_distribution(torch.as_tensor(demos.observations)).distribution.mean
    k_z = np.clip(0.6 + mean[:, 0].clamp(-1, 1).numpy(), 0, 1)
    sign = demos.observations[:, 0] < 0
    assert np.median(k_z[sign]) < 0.35 and np.median(k_z[~sign]) > 0.65
    # the optimum lies on the lattice's edge; the edge term keeps the actor from drifting beyond
    low, high = np.percentile(k_z, [10, 90])
    assert low > 0.15 and high < 0.85
    with pytest.raises(ValueError, match="training and validation"):
        fit_actor(policy, demos.observations, demos, 1.0, demos.beds >= 0)


def test_demonstrations_record_every_candidate_and_the_teachers_budget(tmp_path):
    spec = EnvSpec(
        "HexapodIrregularTerrain-v0",
        {
            "task_distribution": "train",
            "terrain": "blocks",
            "action_mode": "gains",
            "gait_ground_search": "always",
            "terrain_scan": True,
        },
        max_episode_steps=90,
    )
    demos = demonstrate(spec, 3, [0.2, 0.8])
    n = len(demos.beds)
    assert n >= 2 and np.all(demos.beds == 3)
    assert demos.candidates.shape == (9, 3) and tuple(demos.candidates[-1]) == (0.6, 0.4, 0.4)
    assert demos.observations.shape == (
        n,
        gym.make(spec.id, **spec.kwargs).observation_space.shape[0],
    )
    assert demos.outcomes.shape == (n, 9, 4) and np.all(demos.outcomes[..., :2] > 0)
    assert np.all((demos.outcomes[..., 3] > 0.0) & (demos.outcomes[..., 3] < 0.1))  # clearance [m]
    # every candidate is played for a whole cycle on top of the episode's 90 steps
    assert demos.env_steps > 90 + 9 * 20 * n
    assert lattice_costs(demos, CycleCost()).shape == (n, 2, 2, 2)
    demos.save(tmp_path / "d.npz")
    back = Demonstrations.load(tmp_path / "d.npz")
    np.testing.assert_array_equal(back.outcomes, demos.outcomes)
    assert back.env_steps == demos.env_steps
    both = Demonstrations.concatenate([demos, back])
    assert len(both.beds) == 2 * n and both.env_steps == 2 * demos.env_steps
    other = Demonstrations(**{**vars(demos), "candidates": demos.candidates + 0.1})
    with pytest.raises(ValueError, match="different candidate sets"):
        Demonstrations.concatenate([demos, other])
    np.savez(tmp_path / "bad.npz", observations=demos.observations)
    with pytest.raises(ValueError, match="not a demonstrations file"):
        Demonstrations.load(tmp_path / "bad.npz")


def _script(command: str, demos, *options: str) -> None:
    """Run the study script's `command` on the blocks config with the demonstrations `demos`
    (``collect``: written there; the other commands: read from there)."""
    where = "--out" if command == "collect" else "--demos"
    distill_gains.main([command, "--config", CONFIG, where, str(demos), *options])


@pytest.fixture(scope="module")
def collected(tmp_path_factory):
    """Demonstrations of two short episodes on the 2-level lattice, collected by the script."""
    demos = tmp_path_factory.mktemp("distill") / "demos.npz"
    options = "--set env.max_episode_steps=70 --episodes 2 --levels 0.2 0.8"
    _script("collect", demos, *options.split())
    return demos


def test_script_fits_a_model_that_the_evaluation_loads_and_runs(collected, tmp_path):
    from agents.ppo import PPOPolicy

    model_dir = tmp_path / "model"
    options = "--epochs 3 --validation-fraction 0.5"
    _script("fit", collected, *options.split(), "--out", str(model_dir))
    recorded = read_settings(model_dir)  # the evaluation compares it with the env it runs on
    assert recorded["terrain"] == "blocks" and recorded["terrain_scan"] is True
    env = gym.make(
        "HexapodIrregularTerrain-v0",
        terrain="blocks",
        action_mode="gains",
        gait_ground_search="always",
        terrain_scan=True,
        task_distribution="test",
    )
    policy = PPOPolicy.load(model_dir, env)
    obs, _ = env.reset(seed=0)
    policy.reset()
    action = policy(obs)
    assert action.shape == (3,) and np.all((action >= 0.0) & (action <= 1.0))


def test_script_draws_the_learning_curve_over_training_beds(collected, capsys):
    options = "--epochs 2 --validation-fraction 0.5 --fractions 1 --seeds 1"
    _script("curve", collected, *options.split())
    assert "1 training beds: held-out cost" in capsys.readouterr().out


def test_script_chooses_among_the_candidates_and_names_bad_arguments(collected, tmp_path, capsys):
    # two more beds (the same rows relabelled) so that test, validation and training each get one
    loaded = Demonstrations.load(collected)
    four = tmp_path / "four.npz"
    relabelled = dataclasses.replace(loaded, beds=loaded.beds + 2)
    Demonstrations.concatenate([loaded, relabelled]).save(four)
    options = "--beds 3 --seeds 1 --epochs 2 --drop terrain_scan"
    _script("choose", four, "--test-beds", "1", *options.split())
    assert "2 beds" not in (out := capsys.readouterr().out)
    assert "3 beds (a fifth for early stopping): test cost" in out and "oracle" in out
    with pytest.raises(ValueError, match="--beds \\[1\\]: each needs at least 2"):
        _script("choose", four, "--test-beds", "1", "--beds", "1")
    with pytest.raises(ValueError, match="not observation pieces; valid: .*terrain_scan"):
        _script("choose", four, "--test-beds", "1", "--drop", "terrain")
    with pytest.raises(ValueError, match="--test-beds 3: .* 4 beds, and at least two"):
        _script("choose", four, "--test-beds", "3")
    with pytest.raises(ValueError, match="wide observations.*--set"):
        _script("choose", four, "--test-beds", "1", "--set", "env.kwargs.foot_scan=true")


def test_fit_choice_predicts_the_state_dependent_choice_and_else_keeps_the_best_fixed_one():
    demos = _synthetic()
    beds = demos.beds
    train, validation, test = beds < 12, (beds >= 12) & (beds < 16), beds >= 16
    result = fit_choice(demos.observations, demos, train, validation, test)
    # every fixed k_z is 0.2 or more from the cheapest on a share of the rows; the student
    # follows feature 0
    fixed = min(result.best_constant_cost, result.reference_cost)
    assert result.cost < result.oracle_cost + 0.05 < fixed - 0.2
    assert result.departed > 0.3 and result.margin < np.inf  # the default is wrong on ~half
    # without feature 0 nothing predicts the cheapest: the student is a fixed setting
    blind = fit_choice(np.zeros_like(demos.observations), demos, train, validation, test)
    assert blind.cost == pytest.approx(blind.best_constant_cost, abs=0.01)
    assert blind.cost > result.cost + 0.2
    with pytest.raises(ValueError, match="training, validation and test"):
        fit_choice(demos.observations, demos, beds < 0, validation, test)


def test_ground_deviation_features_match_the_controllers_estimate_at_each_cycle_start():
    """The features recomputed from the observation the posture controller saw when it began
    a cycle's first phase agree with its estimate (its commands' horizontal feet aside). On
    the blocks the ground search waits for the landing feet, so the phases begin with four to
    six feet down, where the stance tripod decides which plane counts."""
    from experiments.gains_lookahead.distill import ground_deviation_features

    env = gym.make("HexapodIrregularTerrain-v0", terrain="blocks", action_mode="gains")
    base = env.unwrapped
    obs, _ = env.reset(seed=3)
    rows, estimates, contacts, began = [], [], [], -1
    for _ in range(600):
        seen = obs
        obs, _, terminated, truncated, _ = env.step(np.array([0.6, 0.4, 0.4], np.float32))
        estimate = base.controller.last_estimate
        if estimate is not None and estimate.phase_index != began:
            began = estimate.phase_index
            if began % 2 == 0:  # a cycle's first phase, begun on the sensors of `seen`
                rows.append(seen)
                estimates.append((estimate.delta_pitch, estimate.delta_roll, estimate.delta_z))
                contacts.append(len(estimate.contact_legs))
        if terminated or truncated:
            break
    features = ground_deviation_features(
        np.array(rows), base.observation_structure, base.controller
    )
    estimates = np.array(estimates)
    assert len(rows) >= 8 and sum(n >= 5 for n in contacts) >= 4
    assert np.abs(estimates[:, :2]).max() > 0.01  # the blocks tilt the plane
    assert np.abs(features[:, 2] - estimates[:, 2]).max() < 1e-6  # the same height reading
    assert np.abs(features[:, :2] - estimates[:, :2]).max() < 0.003  # rad, horizontal feet aside
    env.close()
