"""The per-cycle gains measurements (experiments/gains_lookahead: lookahead, gains_ceiling)."""

from __future__ import annotations

import copy

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from agents.athena_policy import PAPER_GAINS
from experiments.gains_lookahead import gains_ceiling, gains_footing_probe
from experiments.gains_lookahead.lookahead import (
    CycleCost,
    CycleOutcome,
    Fixed,
    Lookahead,
    StateError,
    beats,
    gain_grid,
    gains_env,
    play_cycle,
    run_episode,
    summarize,
)

PAPER = PAPER_GAINS["blocks"]


def _env(steps: int = 160) -> gym.Env:
    return gains_env(max_episode_steps=steps)


def test_grid_and_the_beats_rule():
    grid = gain_grid([0.0, 1.0])
    assert len(grid) == 8 and (0.0, 0.0, 0.0) in grid and (1.0, 1.0, 1.0) in grid
    ref = {"pitch_rate_median": 0.1, "roll_rate_median": 0.1, "contact_steps": 5}
    assert beats({**ref, "pitch_rate_median": 0.09, "roll_rate_median": 0.09}, ref)
    assert not beats({**ref, "pitch_rate_median": 0.09}, ref)  # roll not lower
    assert not beats(
        {**ref, "pitch_rate_median": 0.09, "roll_rate_median": 0.09, "contact_steps": 6}, ref
    )


def test_play_cycle_leaves_the_env_as_it_was():
    env, other = _env(), _env()
    action = np.asarray(PAPER, dtype=np.float32)
    for e in (env, other):
        e.reset(seed=3)
        e.step(action)
        while not e.unwrapped.gains_due:
            e.step(action)
    outcome = play_cycle(env, (0.2, 0.2, 0.2))
    assert outcome.contact_steps >= 0 and outcome.pitch_rate_rms > 0.0
    # the torso stays a few cm above the blocks, below its standing clearance of 7 cm
    assert 0.0 < outcome.min_clearance < env.unwrapped.torso_footprint_clearance() + 0.03
    assert outcome.steps > 20
    for _ in range(30):
        a, b = env.step(action), other.step(action)
        np.testing.assert_array_equal(a[0], b[0])


def test_cycle_cost_terms():
    outcome = CycleOutcome(0.1, 0.2, 1, 0.01, steps=50)
    assert CycleCost()(outcome) == pytest.approx(1.3)
    assert CycleCost(contact=2.0)(outcome) == pytest.approx(2.3)
    # 2 cm short of a 3 cm margin at 5 rad/s per m
    assert CycleCost(clearance=5.0, margin=0.03)(outcome) == pytest.approx(1.4)
    assert CycleCost(clearance=5.0, margin=0.03)(
        outcome._replace(min_clearance=0.05)
    ) == pytest.approx(1.3)
    rows = np.array([outcome[:4], outcome._replace(contact_steps=0)[:4]])
    np.testing.assert_allclose(CycleCost(clearance=5.0, margin=0.03).of_rows(rows), [1.4, 0.4])


def test_lookahead_applies_the_cheapest_cycle():
    env = _env()
    env.reset(seed=1)
    candidates = [*gain_grid([0.2, 0.8]), PAPER]
    choice = Lookahead(tuple(candidates))(env)
    costs = {g: CycleCost()(play_cycle(env, g)) for g in candidates}
    assert costs[choice] == min(costs.values())
    # The look-ahead minimises the cost it is given: one that pays for footprint clearance
    # chooses another candidate here, the cheapest by that cost.
    clearance = CycleCost(clearance=1000.0, margin=0.5)
    chosen = Lookahead(tuple(candidates), clearance)(env)
    by_clearance = {g: clearance(play_cycle(env, g)) for g in candidates}
    assert by_clearance[chosen] == min(by_clearance.values()) and chosen != choice
    assert Lookahead((PAPER,))(env) == PAPER
    with pytest.raises(ValueError, match="at least one"):
        Lookahead(())


def test_lookahead_from_noisy_copies(monkeypatch):
    """Without noise it is the exact look-ahead; the copies' state errors are drawn per cycle
    and shared by the candidates; they change the copies' cycles, not the env."""
    env = _env()
    env.reset(seed=1)
    candidates = (*gain_grid([0.2, 0.8]), PAPER)
    exact = Lookahead(candidates)
    assert exact.state_errors(env) == [None]
    assert Lookahead(candidates, samples=3)(env) == exact(env)
    noisy = Lookahead(candidates, state_noise=1e-2, position_noise=0.005, samples=2, seed=5)
    errors = noisy.state_errors(env)
    assert len(errors) == 2 and errors[0].velocity.shape == (env.unwrapped.model.nv,)
    assert 1e-3 < float(np.std(errors[0].velocity)) < 1e-1
    assert errors[0].position.shape == (2,) and 0.0 < np.abs(errors[0].position).max() < 0.05
    np.testing.assert_array_equal(errors[1].velocity, noisy.state_errors(env)[1].velocity)
    later = copy.deepcopy(env)
    later.step(np.asarray(PAPER, dtype=np.float32))
    assert not np.array_equal(errors[0].position, noisy.state_errors(later)[0].position)
    base = env.unwrapped
    qpos, qvel = base.data.qpos.copy(), base.data.qvel.copy()
    assert play_cycle(env, PAPER, errors[0]) != play_cycle(env, PAPER)
    np.testing.assert_array_equal(base.data.qpos, qpos)
    np.testing.assert_array_equal(base.data.qvel, qvel)
    # a position error alone (no velocity error) shifts the torso by it, nothing else
    shift = StateError(np.zeros(base.model.nv), np.array([0.01, -0.02]))
    shifted = Lookahead(candidates, position_noise=0.01)
    assert shifted.state_errors(env)[0].velocity.tolist() == [0.0] * base.model.nv
    seen = {}

    def record(twin, action):
        seen["qpos"] = twin.unwrapped.data.qpos.copy()
        raise StopIteration

    with monkeypatch.context() as patch:
        patch.setattr(type(env), "step", record)
        with pytest.raises(StopIteration):
            play_cycle(env, PAPER, shift)
    moved = seen["qpos"] - qpos
    np.testing.assert_allclose(moved[:2], shift.position, rtol=0, atol=1e-15)
    assert not moved[2:].any()
    assert play_cycle(env, PAPER, shift) != play_cycle(env, PAPER)
    # the choice minimises the mean cost over the copies, which outcomes() lists per candidate
    means = {g: np.mean([CycleCost()(play_cycle(env, g, e)) for e in errors]) for g in candidates}
    assert means[noisy(env)] == min(means.values())
    played = noisy.outcomes(env)
    assert [len(copies) for copies in played] == [2] * len(candidates)
    assert noisy.choose(played) == noisy(env)
    assert [len(copies) for copies in exact.outcomes(env)] == [1] * len(candidates)
    for bad in ({"state_noise": -1.0}, {"position_noise": -1.0}, {"samples": 0}):
        with pytest.raises(ValueError, match="position_noise >= 0 and samples >= 1"):
            Lookahead(candidates, **bad)


def test_run_episode_collects_every_finished_cycle():
    env = _env()
    episode = run_episode(env, 0, Fixed(PAPER))
    # 160 steps of 50 ms hold a few 2 s gait cycles (plus ground-search waits).
    assert 2 <= len(episode["pitch_rate_rms"]) == len(episode["roll_rate_rms"]) <= 4
    again = run_episode(env, 0, Fixed(PAPER))
    assert again == episode  # same seed, same episode
    summary = summarize([episode, again])
    assert summary["cycles"] == 2 * len(episode["pitch_rate_rms"])
    with pytest.raises(ValueError, match="gains"):
        run_episode(gym.make("HexapodIrregularTerrain-v0"), 0, Fixed(PAPER))


def test_script_writes_the_table(tmp_path, monkeypatch):
    script = gains_ceiling
    monkeypatch.setattr(script, "make_env", lambda terrain: _env(120))
    script.main(["--episodes", "1", "--levels", "0.5", "--out-dir", str(tmp_path)])
    text = (tmp_path / "gains_ceiling_blocks.md").read_text()
    assert (
        "| paper (0.6, 0.4, 0.4) |" in text
        and "| look-ahead over the grid and the paper's |" in text
    )
    assert (tmp_path / "gains_ceiling_blocks.json").exists()
    script.main(
        ["--episodes", "1", "--levels", "0.5", "--no-grid", "--state-noise", "0.01"]
        + ["--position-noise", "0.02", "--samples", "1", "--out-dir", str(tmp_path)]
    )
    text = (tmp_path / "gains_foresight_blocks.md").read_text()
    assert "--no-grid --state-noise 0.01 --position-noise 0.02 --samples 1`" in text
    rows = [line for line in text.splitlines() if line.startswith("| ") and "|---" not in line]
    assert [r.split(" |")[0] for r in rows[1:]] == [
        "| paper (0.6, 0.4, 0.4)",
        "| look-ahead over the grid and the paper's",
        "| look-ahead from copies with velocity error σ = 0.01 (mean of 1)",
        "| look-ahead from copies with position error σ = 0.02 m (mean of 1)",
    ]
    # the kept column: every row but the paper's; the exact look-ahead keeps all of its lead
    assert rows[0].endswith("| kept |") and rows[2].endswith("| 100% / 100% |")
    assert all(row.count("|") == rows[0].count("|") for row in rows)


def test_footing_probe_moves_only_the_blocks_away_from_the_feet():
    probe = gains_footing_probe
    env = _env()
    env.reset(seed=0)
    base = env.unwrapped
    before = base.model.geom_pos.copy()
    twin = copy.deepcopy(env)
    moved = probe.shift_far_blocks(twin, np.array([0.05, 0.0]))
    boxes = [n for n in base.terrain_info.geom_names if n != "blocks_ground"]
    assert 0 < moved < len(boxes)
    np.testing.assert_array_equal(base.model.geom_pos, before)  # the copy's model only
    shifted = twin.unwrapped.model.geom_pos - before
    assert np.count_nonzero(shifted.any(axis=1)) == moved
    under_feet = [  # the blocks under the feet stay
        geom.id
        for geom in (base.model.geom(name) for name in boxes)
        for foot in base.sensors.foot_positions()[:, :2]
        if (np.abs(foot - geom.pos[:2]) <= geom.size[:2]).all()
    ]
    assert len(under_feet) >= 3 and not shifted[under_feet].any()
    unchanged, played = probe.probe(1, 1, make_env=lambda: _env(120))
    assert played == len(probe.SHIFTS) * len(probe.SETTINGS) and 0 <= unchanged <= played
