"""Coelho et al. 2024 §5.2.3 in MuJoCo: posture control vs the "simple control" on the same seeds,
one default episode (60 s, 30 gait cycles) per seed; the directions of the paper's results.

Measured with the default env (servo_kp 6.8 N·m/rad, calibrated to the paper's simple-control
sag; 0.25 m blocks; 2.5 ms physics step; see experiments/reproduction), 4 seeds: ramp: median
height +49.3 %, pitch-rate RMS -50.8 %, roll-rate RMS +5.5 % (paper +60.77, -11.92, -35.98 %; the
roll rate is the xfail). Blocks: the non-adaptive simple controller's torso is on the blocks in
3093 of 4800 steps; posture control touches in 5 steps (1 of 4 episodes; paper: collision-free,
see the xfail) and lowers the pitch/roll-rate RMS (-36 %, -30 %; paper +54 %, +82 %; at the
former 2 ms step +45 %, +34 %); the ZMP margin is higher with posture control. The rate changes
are not asserted: on 20 beds they are -8.0 % [-37.1, +51.2] and -21.7 % [-33.6, +19.4] (95 %
bootstrap intervals over the beds), i.e. their sign is not settled on this bed (reproduction
rows 11b/11c@seeds 0-19).

These are the -v0 defaults' results. On the calibrated robot model (`CALIBRATED_MODEL`, which the
reproduction uses) the ramp's roll rate falls by 51 % and the block-bed rates rise on seeds 0-3;
tests/experiments/test_headline_rows.py asserts those.
"""

import json

import numpy as np
import pytest

from experiments.athena_posture import (
    athena_gain_sweep,
    athena_posture_study,
    height_reference_scan,
)
from experiments.athena_posture.study import EpisodeRecord, change_interval, compare, pooled

pytestmark = pytest.mark.slow


def _beds(*per_bed_rates):
    return [
        EpisodeRecord(
            "blocks", (0.0, 0.0, 0.0), seed, cycles=[{"pitch_rate_rms": v} for v in rates]
        )
        for seed, rates in enumerate(per_bed_rates)
    ]


def test_change_interval_is_exact_when_every_bed_changes_alike_and_spreads_otherwise():
    simple = ([1.0, 2.0, 3.0], [2.0, 4.0], [10.0])
    alike = {"simple": _beds(*simple), "posture": _beds(*([1.5 * v for v in b] for b in simple))}
    assert change_interval(alike, "pitch_rate") == pytest.approx((50.0, 50.0, 50.0))
    # One bed doubles its rates, the others halve theirs: the interval spans both.
    mixed = {"simple": _beds(*simple), "posture": _beds([2.0, 4.0, 6.0], [1.0, 2.0], [5.0])}
    estimate, low, high = change_interval(mixed, "pitch_rate")
    assert estimate == pytest.approx(20.0)  # pooled medians 2.5 -> 3
    assert low < 0.0 < high and low <= estimate <= high


@pytest.fixture(scope="module")
def ramp():
    return compare("ramp", seeds=(0, 1))


@pytest.fixture(scope="module")
def blocks():
    return compare("blocks", seeds=(0, 1, 2))


def _median(result, name, metric):
    return result["summary"][name][f"{metric}_median"]


def test_ramp_runs_stay_on_the_slope_and_posture_control_keeps_the_torso_off_it(ramp):
    for name in ("simple", "posture"):
        assert all(len(r.cycles) >= 25 for r in ramp[name])  # all cycles counted on the slope
        assert not any(r.tipped_over for r in ramp[name])
    assert all(r.torso_collisions == 0 and r.distance > 3.0 for r in ramp["posture"])
    # The calibrated servos sag under the simple control until the torso drags on the slope
    # (the paper reports the sag, 0.068 m median height, not whether it touched).
    assert all(r.distance > 2.0 for r in ramp["simple"])


def test_ramp_posture_control_holds_the_torso_higher(ramp):
    """Paper: +60.77 % median height; the simple controller sinks as its servos' sag adds up."""
    assert _median(ramp, "posture", "height") > 1.05 * _median(ramp, "simple", "height")
    # and keeps it steadier (the paper: "the interquartile range significantly reduced")
    iqr = {
        n: np.subtract(*np.percentile(pooled(ramp[n], "height"), [75, 25]))
        for n in ("simple", "posture")
    }
    assert iqr["posture"] < iqr["simple"]


@pytest.mark.xfail(
    strict=True,
    reason=(
        "Not reached with the calibrated servos (kp 6.8 N m/rad): posture control's roll-rate RMS "
        "is 5.5 % above the simple control's (seeds 0-3, this test runs 0-1; paper -36 %), while "
        "the simple control's torso drags on the slope, which damps its roll. At kp 8 it was "
        "-15 %."
    ),
)
def test_ramp_posture_control_lowers_the_roll_rate(ramp):
    """Paper: -35.98 % median roll-rate RMS."""
    assert _median(ramp, "posture", "roll_rate") < _median(ramp, "simple", "roll_rate")


def test_ramp_posture_control_does_not_raise_the_pitch_rate(ramp):
    """Paper: -11.92 % median pitch-rate RMS."""
    assert _median(ramp, "posture", "pitch_rate") <= _median(ramp, "simple", "pitch_rate")


def test_blocks_simple_control_collides_and_walks_less(blocks):
    """Paper: "with the simple control, the torso collided with the ground" and the "traversed
    distance with a simple control was smaller"."""
    simple, posture = blocks["summary"]["simple"], blocks["summary"]["posture"]
    assert simple["episodes_with_collision"] == len(blocks["simple"])
    assert simple["mean_distance"] < posture["mean_distance"]


def test_blocks_posture_control_cuts_the_torso_contacts(blocks):
    simple, posture = blocks["summary"]["simple"], blocks["summary"]["posture"]
    assert posture["torso_collision_steps"] < 0.2 * simple["torso_collision_steps"]


@pytest.mark.xfail(
    strict=True,
    reason=(
        "Not reached: on the calibrated bed (0.25 m blocks) the posture controller's torso "
        "still grazes the blocks in some episodes (1 of seeds 0-3, within the 0-2 this test runs; "
        "10 of seeds 0-19; on 0.1 m blocks 4 of 4). Its height control holds the torso at the "
        "standing height above the one block its infrared sensor sees, and neighbouring blocks "
        "up to 0.09 m taller reach the torso's edges."
    ),
)
def test_blocks_posture_control_is_collision_free(blocks):
    """Paper: the posture controller's torso had a collision-free navigation."""
    assert blocks["summary"]["posture"]["episodes_with_collision"] == 0


def test_blocks_posture_control_raises_the_zmp_margin(blocks):
    """Paper (Fig. 19): the ZMP stability margin's median increases with posture control."""
    step = {n: _median(blocks, n, "zmp_margin_step") for n in ("simple", "posture")}
    assert step["posture"] > step["simple"]
    assert _median(blocks, "posture", "zmp_margin") > _median(blocks, "simple", "zmp_margin")


def test_blocks_runs_walk_and_stay_upright(blocks):
    for name in ("simple", "posture"):
        assert all(r.distance > 0.5 and not r.tipped_over for r in blocks[name])


def test_study_and_sweep_scripts_write_their_outputs(tmp_path):
    athena_posture_study.main(["--seeds", "1", "--steps", "100", "--out", str(tmp_path)])
    for name in ("athena_ramp_posture.png", "athena_blocks_posture.png"):
        assert (tmp_path / name).stat().st_size > 10_000
    numbers = json.loads((tmp_path / "athena_posture_study.json").read_text())
    for terrain in ("ramp", "blocks"):  # one change per metric, not the last loop value
        assert set(numbers[terrain]["change_pct"]) >= {"height", "pitch_rate", "roll_rate"}
    out = tmp_path / "sweep.md"
    athena_gain_sweep.main(["--cycles", "1", "--out", str(out)])
    text = out.read_text()
    assert text.count("| k_z = ") == 10 and "paper's tuned (0.6, 0.4, 0.4)" in text


def test_height_reference_scan_runs_hard_training_tasks_and_tabulates_each_offset(tmp_path, capsys):
    seeds = height_reference_scan.hard_train_seeds(2, 0.6)
    assert len(seeds) == 2 and min(seeds) >= height_reference_scan.FIRST_SEED
    out = tmp_path / "scan.json"
    argv = ["--offsets", "0", "0.02", "--tasks", "2", "--min-difficulty", "0.6"]
    height_reference_scan.main([*argv, "--max-steps", "30", "--json", str(out)])
    episodes = json.loads(out.read_text())
    assert list(episodes) == ["0.0", "0.02"]
    assert [e["seed"] for e in episodes["0.02"]] == seeds
    assert "| +0.020 | 0/2 |" in capsys.readouterr().out  # 30 steps: no episode succeeds
    with pytest.raises(SystemExit):
        height_reference_scan.main(["--offsets", "0.2"])
