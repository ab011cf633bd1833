"""Seed 002 §5.2.3 in MuJoCo: posture control vs the "simple control" on the same seeds, one
default episode (60 s, 30 gait cycles) per seed; the directions of the paper's results.

Measured with the default env (servo_kp 8 N·m/rad; see reports/athena_gain_sweep.md):
ramp, seeds 0-1: median height +13.7 %, pitch-rate RMS -33 %, roll-rate RMS -17 % (paper +60.77,
-11.92, -35.98 %). Blocks: the simple controller does not touch the blocks, the posture
controller does (xfail below, see its reason); the ZMP margin is higher with posture control.
"""

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


@pytest.mark.xfail(
    strict=False,
    reason=(
        "Not reproduced: on our block bed the simple controller never touches the blocks - its "
        "landing legs are extended until they touch (the paper's contact rule) and legs that land "
        "early push the body up, so it rides ~0.16 m above the block under its centre - while "
        "the height control (k_z = 0.6) holds the torso 0.104 m above the one block its infrared "
        "sensor sees and the torso's edges touch neighbouring blocks up to 9 cm taller."
    ),
)
def test_blocks_posture_control_avoids_the_torso_collisions_of_simple_control(blocks):
    """Paper: the simple controller's torso hit the ground, the posture controller's did not."""
    assert blocks["summary"]["simple"]["episodes_with_collision"] > 0
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
    assert "change_pct" in (tmp_path / "athena_posture_study.json").read_text()
    out = tmp_path / "sweep.md"
    _script("athena_gain_sweep").main(["--cycles", "1", "--out", str(out)])
    text = out.read_text()
    assert text.count("| k_z = ") == 10 and "paper's tuned (0.6, 0.4, 0.4)" in text
