"""Does a gait cycle on the blocks depend on blocks the feet do not already stand among?

At the first cycle starts of test beds walked with the paper's gains, each cycle is played twice
on copies of the env (`lookahead.play_cycle`): as it is, and with every block that
no foot stands on or comes within `FOOT_CLEARANCE` (plus the shift) of moved horizontally by a
shift. Identical outcomes mean the cycle met only the blocks around the feet: what decides
the cheapest gains of one cycle is then where the feet stand among those blocks, not the terrain
further ahead (docs/results.md, "Why not on the blocks").

Findings (dated): README.md beside this script.

Run: python experiments/gains_lookahead/gains_footing_probe.py [--beds 5] [--cycles 4]
"""

from __future__ import annotations

import argparse
import copy
import sys
from pathlib import Path

import gymnasium as gym
import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
import hexapod_envs  # noqa: E402, F401
from agents.athena_policy import PAPER_GAINS  # noqa: E402
from experiments.gains_lookahead.lookahead import gains_env, play_cycle  # noqa: E402

FOOT_CLEARANCE = 0.03
"""[m] A block stays put when a foot lies within this distance (plus the shift) of its
footprint."""
SHIFTS = ((0.03, 0.0), (-0.03, 0.03))
"""[m] Horizontal shifts of the far blocks."""
SETTINGS = (PAPER_GAINS["blocks"], (0.2, 0.8, 0.8))
"""Gain settings (k_z, k_α, k_β) played at every cycle start."""


def shift_far_blocks(env: gym.Env, shift: np.ndarray) -> int:
    """Move, in ``env``'s model, every block no foot stands on or near by ``shift`` (x, y) [m];
    returns how many moved. For an env copy: its model is changed."""
    base = env.unwrapped
    feet = base.sensors.foot_positions()[:, :2]
    reach = FOOT_CLEARANCE + float(np.abs(shift).max())
    moved = 0
    for name in base.terrain_info.geom_names:
        geom = base.model.geom(name)
        if geom.type[0] != mujoco.mjtGeom.mjGEOM_BOX:
            continue  # the ground plane
        if (np.abs(feet - geom.pos[:2]) < geom.size[:2] + reach).all(axis=1).any():
            continue
        geom.pos[:2] += shift
        moved += 1
    return moved


def probe(beds: int, cycles: int, make_env=gains_env) -> tuple[int, int]:
    """(cycles unchanged, cycles played) over the first `cycles` cycle starts of `beds` beds."""
    unchanged = played = 0
    for seed in range(beds):
        env = make_env()
        env.reset(seed=seed)
        paper = np.asarray(PAPER_GAINS["blocks"], dtype=env.action_space.dtype)
        starts = 0
        while starts < cycles:
            _, _, terminated, truncated, _ = env.step(paper)
            if terminated or truncated:
                break
            if not env.unwrapped.gains_due:
                continue
            starts += 1
            as_is = {gains: play_cycle(env, gains) for gains in SETTINGS}
            for shift in SHIFTS:
                twin = copy.deepcopy(env)  # play_cycle plays copies of it: one shift serves all
                shift_far_blocks(twin, np.asarray(shift))
                for gains in SETTINGS:
                    unchanged += play_cycle(twin, gains) == as_is[gains]
                    played += 1
        env.close()
    return unchanged, played


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--beds", type=int, default=5)
    parser.add_argument("--cycles", type=int, default=4, help="cycle starts per bed")
    args = parser.parse_args(argv)
    unchanged, played = probe(args.beds, args.cycles)
    print(f"cycles unchanged when the blocks away from the feet move: {unchanged} of {played}")


if __name__ == "__main__":
    main()
