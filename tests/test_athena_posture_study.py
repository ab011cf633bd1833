"""Coelho et al. 2024 §5.2.3 in MuJoCo: posture control vs the "simple control" on the same seeds,
one
default episode (60 s, 30 gait cycles) per seed; the directions of the paper's results.

Measured with the default env (servo_kp 8 N·m/rad; see reports/athena_gain_sweep.md), 4 seeds:
ramp: median height +14.3 %, pitch-rate RMS -33.8 %, roll-rate RMS -16.9 % (paper +60.77,
-11.92, -35.98 %). Blocks: the non-adaptive simple controller's torso is on the blocks in 2668 of
4800 steps and it walks 1.20 m; posture control touches in 192 steps and walks 1.77 m (paper:
simple collided and walked less, posture was collision-free: not reached, see the xfail);
the ZMP margin is higher with posture control.
"""

import json

import numpy as np
import pytest

from agents.athena_study import compare, pooled

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def ramp():
    return compare("ramp", seeds=(0, 1))


@pytest.fixture(scope="module")
def blocks():
    return compare("blocks", seeds=(0, 1, 2))


def _median(result, name, metric):
    return result["summary"][name][f"{metric}_median"]


def test_ramp_runs_stay_on_the_slope_without_collisions(ramp):
    for name in ("simple", "posture"):
        assert all(len(r.cycles) >= 25 for r in ramp[name])  # all cycles counted on the slope
        assert all(r.torso_collisions == 0 and not r.tipped_over for r in ramp[name])
        assert all(r.distance > 3.0 for r in ramp[name])


def test_ramp_posture_control_holds_the_torso_higher(ramp):
    """Paper: +60.77 % median height; the simple controller sinks as its servos' sag adds up."""
    assert _median(ramp, "posture", "height") > 1.05 * _median(ramp, "simple", "height")
    # and keeps it steadier (the paper: "the interquartile range significantly reduced")
    iqr = {
        n: np.subtract(*np.percentile(pooled(ramp[n], "height"), [75, 25]))
        for n in ("simple", "posture")
    }
    assert iqr["posture"] < iqr["simple"]


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
        "Not reached: the posture controller's torso still grazes the blocks (16-139 of 1200 "
        "steps per episode on 0.1 m blocks; collision-free in 5 of 8 beds with 0.15-0.2 m "
        "blocks). Its height control holds the torso at the standing height above the one "
        "block its infrared sensor sees (bottom 0.076 m above it), and neighbouring blocks up "
        "to 0.09 m taller reach the torso's edges."
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


def _script(name):
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "scripts" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_study_and_sweep_scripts_write_their_outputs(tmp_path):
    _script("athena_posture_study").main(["--seeds", "1", "--steps", "100", "--out", str(tmp_path)])
    for name in ("athena_ramp_posture.png", "athena_blocks_posture.png"):
        assert (tmp_path / name).stat().st_size > 10_000
    numbers = json.loads((tmp_path / "athena_posture_study.json").read_text())
    for terrain in ("ramp", "blocks"):  # one change per metric, not the last loop value
        assert set(numbers[terrain]["change_pct"]) >= {"height", "pitch_rate", "roll_rate"}
    out = tmp_path / "sweep.md"
    _script("athena_gain_sweep").main(["--cycles", "1", "--out", str(out)])
    text = out.read_text()
    assert text.count("| k_z = ") == 10 and "paper's tuned (0.6, 0.4, 0.4)" in text
