"""Unilateral cliff of Zhang et al. 2024 §5.1: flat ground whose one side drops away ahead of the
robot.

The robot walks along +x. For x < `start_x` the ground is flat everywhere; beyond it the ground
continues only on the safe side of the line y = `edge_y` and drops by `drop` metres on the other
side ("right" means y < edge_y).
"""

from __future__ import annotations

import mujoco

from .flat import ground_geom_kwargs

CLIFF_SIDES = ("right", "left")


def add_cliff(
    spec: mujoco.MjSpec,
    start_x: float = 2.8,
    side: str = "right",
    drop: float = 3.0,
    edge_y: float = -1.0,
    friction: float = 1.0,
    length: float = 60.0,
    width: float = 30.0,
) -> None:
    """Add the cliff terrain: three boxes whose tops are at z = 0 (ground) or z = -drop (void).

    `edge_y` is measured toward the cliff side: for side="right" the edge is at y = edge_y (< 0
    puts it right of the centre line), for "left" it is mirrored to y = -edge_y.
    """
    if side not in CLIFF_SIDES:
        raise ValueError(f"cliff side must be one of {CLIFF_SIDES}, got {side!r}")
    if drop <= 0:
        raise ValueError(f"cliff drop must be > 0 m, got {drop}")
    kw = ground_geom_kwargs(friction)
    thick = 1.0
    box = mujoco.mjtGeom.mjGEOM_BOX
    back = -length / 2
    # Before the cliff: full width.
    spec.worldbody.add_geom(
        name="ground",
        type=box,
        size=[(start_x - back) / 2, width / 2, thick / 2],
        pos=[(start_x + back) / 2, 0, -thick / 2],
        **kw,
    )
    sign = 1.0 if side == "right" else -1.0
    y_edge = sign * edge_y  # world y of the edge
    far = width / 2
    # Safe side beyond the cliff start, and the void floor on the cliff side.
    safe_lo, safe_hi = (y_edge, far) if side == "right" else (-far, y_edge)
    void_lo, void_hi = (-far, y_edge) if side == "right" else (y_edge, far)
    end = length / 2
    spec.worldbody.add_geom(
        name="ground_safe",
        type=box,
        size=[(end - start_x) / 2, (safe_hi - safe_lo) / 2, thick / 2],
        pos=[(end + start_x) / 2, (safe_hi + safe_lo) / 2, -thick / 2],
        **kw,
    )
    void_kw = {**kw, "rgba": [0.35, 0.3, 0.28, 1.0]}
    spec.worldbody.add_geom(
        name="cliff_floor",
        type=box,
        size=[(end - start_x) / 2, (void_hi - void_lo) / 2, thick / 2],
        pos=[(end + start_x) / 2, (void_hi + void_lo) / 2, -drop - thick / 2],
        **void_kw,
    )
