"""The v1 benchmark: the ``-v1`` env ids' success and termination rules, task ranges and seeds.

A ``-v1`` id is the same env class as its ``-v0`` with the keyword defaults below (Gymnasium's
rule: new semantics, new version). What changes, per env and with the reason, is in
docs/benchmark.md; in short:

- **Termination at a physical limit**: a body tilt past the robot's engineering limit, or
  (heavy-duty robot) a FASM that has stayed at or below 0 for a second: the net force has left
  the support polygon and the body is rotating about its edge.
- **Success that means stability**: the env's goal (walk on, stand to the end, cross) with the
  episode's largest tilt (``info["max_tilt_deg"]``) and share of time tipping
  (``info["tipping_share"]``) within bounds.
- **Task ranges with a difficulty**: ``info["task"]["difficulty"]`` in [0, 1]; ``train`` spans
  easy to hard and ``test`` is at least as hard on average (held out: other seeds, and harder
  draws of the secondary parameters).

`BENCHMARK_SEEDS` are the test tasks of the benchmark: ``reset(seed=s)`` for s in it, on
``task_distribution="test"``.
"""

from __future__ import annotations

from types import MappingProxyType

from .envs.cliff_walk import CliffTaskRanges
from .envs.ditch_crossing import DitchTaskRanges
from .envs.irregular_terrain import CALIBRATED_MODEL, TerrainTaskRanges

BENCHMARK_SEEDS = range(50)
"""The benchmark's test tasks: ``env.reset(seed=s)`` on ``task_distribution="test"``."""

CLIFF_TRAIN_V1 = CliffTaskRanges(
    cliff_x=(2.8, 5.0),
    edge_y=(-1.3, -0.7),
    drop=(1.0, 5.0),
    friction=(0.6, 1.2),
    payload_mass=(0.0, 800.0),
    payload_offset=0.25,
)
"""Training cliffs, easy to hard: the edge 0.33-2.53 m ahead of the front feet, cutting
0.6-1.2 m into the outer feet's path, 1-5 m deep; friction 0.6-1.2; payload up to 800 kg."""
CLIFF_TEST_V1 = CliffTaskRanges(
    cliff_x=(2.8, 5.0),
    edge_y=(-1.0, -0.7),
    drop=(3.0, 5.0),
    friction=(0.6, 0.9),
    payload_mass=(400.0, 800.0),
    payload_offset=0.25,
)
"""Test cliffs: as near as in training, cutting deeper, deeper drops, lower friction, heavier
payload: at least as hard as training on average."""

BLOCKS_TRAIN_V1 = TerrainTaskRanges(
    slope_deg=((5.0, 15.0),),
    block_height_max=(0.06, 0.14),
    block_size=(0.20, 0.35),
    friction=(0.5, 1.1),
    servo_kp_scale=((0.7, 1.3),),
)
"""Training block beds, easy to hard: blocks up to 0.06-0.14 m high and 0.20-0.35 m wide;
friction 0.5-1.1; servo stiffness within 30 % of nominal (the slope is unused on blocks)."""
BLOCKS_TEST_V1 = TerrainTaskRanges(
    slope_deg=((8.5, 11.5),),
    block_height_max=(0.10, 0.14),
    block_size=(0.20, 0.30),
    friction=(0.5, 0.8),
    servo_kp_scale=((0.7, 0.85), (1.15, 1.3)),
)
"""Test block beds: the taller half of training's blocks, smaller, more slippery, servos far
from nominal (the soft ones rated harder, the stiff ones as nominal): harder than training on
average."""

DITCH_TEST_V1 = DitchTaskRanges(
    start_x=(0.9, 1.1), width=(0.40, 0.55), depth=(0.12, 0.15), friction=(0.5, 0.8)
)
"""Test ditches: -v0's held-out ranges with widths up to 0.55 m (training: 0.25-0.40 m)."""

V1_KWARGS = MappingProxyType(
    {
        "HexapodCliffWalk-v1": {
            "tip_over_angle_deg": 15.0,
            "tip_over_margin_time": 1.0,
            "success_max_tilt_deg": 8.0,
            "success_max_tipping_share": 0.1,
            "train_ranges": CLIFF_TRAIN_V1,
            "test_ranges": CLIFF_TEST_V1,
        },
        "HexapodStewartTilt-v1": {
            "swing_until_tipping": True,
            "success_max_tilt_deg": 2.5,
        },
        "HexapodIrregularTerrain-v1": {
            **CALIBRATED_MODEL,
            "robot_friction": 0.0,  # the contact takes the terrain's friction (MuJoCo: the larger)
            "terrain": "blocks",
            "tip_over_angle_deg": 45.0,
            "success_max_tilt_deg": 25.0,
            "success_max_tipping_share": 0.3,
            "train_ranges": BLOCKS_TRAIN_V1,
            "test_ranges": BLOCKS_TEST_V1,
        },
        "HexapodDitchCrossing-v1": {
            "reference_plan": "flat",
            "residual_limb_m": 0.05,
            "residual_leg_m": 0.16,
            "tip_over_angle_deg": 10.0,
            "success_max_tilt_deg": 2.0,
            "success_max_tipping_share": 0.02,
            "test_ranges": DITCH_TEST_V1,
        },
    }
)
"""Keyword defaults of each ``-v1`` id (docs/benchmark.md gives the reasons)."""
