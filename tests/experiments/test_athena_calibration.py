"""The ATHENA calibration study's machinery (experiments/athena_calibration) on a tiny grid, and
the env settings it calibrates reaching the MuJoCo model; not the study's results."""

import gymnasium as gym
import numpy as np
import pytest

import hexapod_envs  # noqa: F401
from experiments.athena_calibration import calibration as cal


def test_factorial_takes_every_combination_and_leaves_none_at_the_default():
    grid = cal.factorial(servo_kp=[5.0, 8.0], contact_solref=[None, (0.01, 1.0)])
    assert grid == [
        {"servo_kp": 5.0},
        {"servo_kp": 5.0, "contact_solref": (0.01, 1.0)},
        {"servo_kp": 8.0},
        {"servo_kp": 8.0, "contact_solref": (0.01, 1.0)},
    ]


def test_names_are_stable_and_plausibility_reads_the_ranges():
    assert cal.candidate_name({}) == "default"
    a = cal.candidate_name({"servo_kp": 8.0, "contact_solref": (0.01, 1.0)})
    assert a == cal.candidate_name({"contact_solref": [0.01, 1], "servo_kp": 8})
    assert a == "contact_solref=(0.01, 1), servo_kp=8"
    assert cal.plausible({"servo_kp": 8.0, "contact_solref": (0.01, 1.0), "friction": 5.0})
    assert not cal.plausible({"servo_kp": 50.0})
    assert not cal.plausible({"contact_solref": (0.001, 1.0)})


def test_run_evaluates_each_candidate_once_and_tabulates_every_row(tmp_path):
    out = tmp_path / "results.jsonl"
    logged = []
    results = cal.run(cal.GRIDS["tiny"], out, seeds=range(1), steps=40, log=logged.append)
    assert len(results) == len(logged) == len(cal.GRIDS["tiny"])
    for r in results:
        assert set(r["rows"]) == set(cal.ROW_IDS)
        assert all(isinstance(row["holds"], bool) for row in r["rows"].values())
        assert r["headline_holds"] == all(r["rows"][i]["holds"] for i in cal.HEADLINE)
    again = []
    assert cal.run(cal.GRIDS["tiny"], out, seeds=range(1), steps=40, log=again.append) == results
    assert again == []  # resumed: nothing evaluated twice
    lines = cal.table(results).splitlines()
    assert len(lines) == 2 + len(results)
    assert all(line.count("|") == len(cal.ROW_IDS) + 3 for line in lines)


def _model(**kwargs):
    env = gym.make("HexapodIrregularTerrain-v0", **kwargs)
    env.reset(seed=0)
    return env.unwrapped


def test_calibrated_settings_reach_the_model_and_none_leaves_the_paper_servo():
    base = _model()
    m = base.model
    assert np.allclose(m.actuator_forcerange[base._act_ids], [-1.89, 1.89])
    assert not np.any(m.actuator_delay)
    env = _model(
        servo_torque_limit=1.5,
        servo_armature=0.004,
        servo_delay=0.01,
        robot_friction=0.6,
        contact_solref=(0.01, 0.8),
        contact_solimp=(0.95, 0.99, 0.001, 0.5, 2.0),
    )
    m = env.model
    act = env._act_ids
    assert np.allclose(m.actuator_forcerange[act], [-1.5, 1.5])
    assert np.allclose(m.actuator_delay[act], 0.01)
    assert np.all(m.actuator_history[act, 0] * env.settings.physics_dt > 0.01)
    foot = m.geom(env.handles.foot_geoms[0]).id
    assert m.geom_friction[foot, 0] == pytest.approx(0.6)
    assert np.allclose(m.geom_solref[foot], [0.01, 0.8])
    assert np.allclose(m.geom_solimp[foot], [0.95, 0.99, 0.001, 0.5, 2.0])
    dofs = m.jnt_dofadr[m.actuator_trnid[act, 0]]
    assert np.allclose(m.dof_armature[dofs], 0.004)


def test_a_delayed_servo_starts_from_the_standing_targets():
    """The target history is filled with the standing posture at reset, so the robot stands
    after the settle phase as it does without latency."""
    heights = [_model(terrain="flat", servo_delay=d).sensors.cog()[2] for d in (0.0, 0.02)]
    assert heights[1] == pytest.approx(heights[0], abs=1e-4)  # 4 mm lower without it


def test_validate_reports_the_ramp_changes_and_the_bed_intervals():
    v = cal.validate({"contact_solref": [0.01, 1.0]}, ramp_seeds=range(1), beds=range(2), steps=100)
    assert v["name"] == "contact_solref=(0.01, 1)"
    assert set(v["ramp_change_pct"]) == set(cal.RAMP_METRICS)
    for controller in cal.CONTROLLERS:
        assert v["ramp_medians"][controller]["height"] > 0.02
    for metric in ("pitch_rate", "roll_rate"):
        estimate, *interval = v["blocks_change_interval"][metric]
        assert np.isfinite(estimate) and len(interval) == 2  # 2 beds: the interval may be nan
    assert 0 <= v["posture_beds_touched"] <= 2
