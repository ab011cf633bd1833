"""experiments/physics_settings: the sweep's rows on one tiny setting (no timing assertions)."""

import math

from experiments.physics_settings.physics_settings import PhysicsSetting, sweep

SPEED_KEYS = {
    "kind",
    "robot",
    "setting",
    "env",
    "actions",
    "physics_dt",
    "substeps",
    "sim_s",
    "wall_s",
    "sim_per_wall",
    "episodes_ended",
    "unstable",
}


def test_sweep_speed_rows_have_expected_keys_and_finite_numbers():
    # ATHENA: its block bed is rebuilt at every reset, so the sweep's check that the model still
    # carries the integrator and tolerance after a reset is exercised too (it raises if not).
    setting = PhysicsSetting(1.25, "euler", tolerance=1e-6)
    rows = sweep("athena", [setting], seconds=0.2, repeats=1, fidelity=False)
    assert len(rows) == 4  # ramp and blocks, zero and random actions
    assert {(r["env"], r["actions"]) for r in rows} == {
        (t, a) for t in ("ramp", "blocks") for a in ("zero", "random")
    }
    for r in rows:
        assert set(r) == SPEED_KEYS
        assert r["kind"] == "speed" and r["robot"] == "athena" and r["setting"] == setting
        for key in ("physics_dt", "sim_s", "wall_s", "sim_per_wall"):
            assert math.isfinite(r[key]) and r[key] > 0, key
        # x1.25 of 2.5 ms (16 substeps) is not allowed (a multiple of 5 substeps): 15 substeps
        assert r["substeps"] == 15 and math.isclose(r["physics_dt"], 0.05 / 15)
        assert math.isclose(r["sim_s"], 0.2)
        assert r["unstable"] == 0


def test_athena_fidelity_includes_the_servo_dependent_reproduction_rows():
    # The ramp walk alone let a 10 ms timestep through that sags the simple controller 8.6 mm
    # more; the posture-study rows (quick: ramp seed 0, 4 block beds of 400 steps) are there
    # for that. The block rows carry a bootstrap interval and are judged by it.
    from experiments.physics_settings.physics_settings import DEFAULT, athena_fidelity

    rows = athena_fidelity(DEFAULT, quick=True)
    (sag,) = [f for f in rows if f.name.startswith("ramp, simple control")]
    assert 0.03 < sag.value < 0.12  # metres: ATHENA stands about 0.1 m high and sags on the ramp
    changes = [f for f in rows if "rate change" in f.name]
    assert len(changes) == 2
    for f in changes:
        estimate, low, high = f.value
        assert low <= estimate <= high and math.isfinite(high - low)
        assert f.compare(f.value, f.value)
        assert not f.compare((high + 1.0, low, high), f.value)
    (touched,) = [f for f in rows if "torso contact" in f.name]
    assert touched.value in range(5)


def test_finer_timesteps_for_the_convergence_check():
    # --finer compares the default with 1/2 and 1/4 of its timestep; each must be an allowed
    # one (a whole number of substeps per control period, ATHENA's a multiple of 5).
    from experiments.physics_settings.physics_settings import (
        DEFAULT,
        FINER,
        candidate_settings,
        physics_dt_for,
    )

    assert candidate_settings(quick=False, finer=True)[0] == DEFAULT
    for s in FINER:
        assert s.factor < 1.0 and s.integrator == DEFAULT.integrator
    assert math.isclose(physics_dt_for("HexapodDitchCrossing-v0", 0.25), 0.0005)
    assert math.isclose(physics_dt_for("HexapodCliffWalk-v0", 0.25), 0.0005)
    assert math.isclose(physics_dt_for("HexapodIrregularTerrain-v0", 0.25), 0.05 / 80)
    # x0.3 of 2.5 ms wants 66.7 substeps; ATHENA takes multiples of 5 only: 65 (nearer than 70)
    assert math.isclose(physics_dt_for("HexapodIrregularTerrain-v0", 0.3), 0.05 / 65)


def test_heavy_duty_rows_count_the_reference_tip_overs_on_the_test_cliffs():
    # The test-cliff row counts the episodes (seeds 0-4 in quick mode) that end in a tip-over,
    # here counted independently from the env's own termination flag.
    import gymnasium as gym
    import numpy as np

    from experiments.physics_settings.physics_settings import DEFAULT, heavy_duty_fidelity

    rows = heavy_duty_fidelity(DEFAULT, quick=True)
    assert len({r.name for r in rows}) == len(rows)
    (cliffs,) = [r for r in rows if "test tasks" in r.name]
    env = gym.make("HexapodCliffWalk-v0", task_distribution="test")
    zero = np.zeros(env.action_space.shape, env.action_space.dtype)
    tipped = 0
    for seed in range(5):
        env.reset(seed=seed)
        for _ in range(1500):
            _, _, terminated, truncated, _ = env.step(zero)
            if terminated or truncated:
                tipped += terminated
                break
    env.close()
    assert not cliffs.failed and cliffs.value == tipped
    assert cliffs.compare(tipped + 1, tipped) and not cliffs.compare(tipped + 2, tipped)
