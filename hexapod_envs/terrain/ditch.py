"""Flat ground with a ditch across the walking direction (Li et al. 2018 §7, Fig. 13).

The robot walks along +x. The ground is flat (top at z = 0) except for x in
[start_x, start_x + width], where a flat-bottomed ditch with vertical walls drops to z = -depth.
Built from three boxes so that the walls are real vertical faces a foot or a leg can hit.
"""

from __future__ import annotations

import math

import mujoco

from ..checks import check_number
from .flat import ground_geom_kwargs

DITCH_GEOMS: tuple[str, ...] = ("ground", "ditch_floor", "ground_far")
"""Geom names created by `add_ditch`: the near ground, the ditch bottom, the far ground."""


def add_ditch(
    spec: mujoco.MjSpec,
    start_x: float = 0.6,
    width: float = 0.35,
    depth: float = 0.14,
    friction: float = 1.0,
    length: float = 20.0,
    half_width_y: float = 5.0,
    thickness: float = 0.5,
) -> None:
    """Add ground with a ditch to `spec.worldbody`.

    Args:
        start_x: x of the near edge of the ditch [m].
        width: ditch width along x [m] (paper: 0.35).
        depth: ditch depth below the ground [m] (paper: 0.14).
        friction: sliding friction coefficient of all three surfaces.
        length: total ground length along x, centred on the ditch [m].
        half_width_y: half-extent of the ground along y [m].
        thickness: thickness of the boxes below their top faces [m].
    """
    values = {
        "width": width,
        "depth": depth,
        "length": length,
        "half_width_y": half_width_y,
        "thickness": thickness,
        "friction": friction,
    }
    for name, value in values.items():
        check_number(f"ditch {name}", value, strict=True)
    if not math.isfinite(start_x):
        raise ValueError(f"ditch start_x must be finite, got {start_x}")
    if length <= width:
        raise ValueError(f"ditch length {length} m must exceed its width {width} m")
    kw = ground_geom_kwargs(friction)
    box = mujoco.mjtGeom.mjGEOM_BOX
    end_x = start_x + width
    back = start_x + width / 2 - length / 2
    front = start_x + width / 2 + length / 2
    near_half = (start_x - back) / 2
    far_half = (front - end_x) / 2
    spec.worldbody.add_geom(
        name=DITCH_GEOMS[0],
        type=box,
        size=[near_half, half_width_y, thickness / 2],
        pos=[back + near_half, 0.0, -thickness / 2],
        **kw,
    )
    floor_kw = {**kw, "rgba": [0.45, 0.4, 0.35, 1.0]}
    spec.worldbody.add_geom(
        name=DITCH_GEOMS[1],
        type=box,
        size=[width / 2, half_width_y, thickness / 2],
        pos=[start_x + width / 2, 0.0, -depth - thickness / 2],
        **floor_kw,
    )
    spec.worldbody.add_geom(
        name=DITCH_GEOMS[2],
        type=box,
        size=[far_half, half_width_y, thickness / 2],
        pos=[end_x + far_half, 0.0, -thickness / 2],
        **kw,
    )


def ditch_ground_height(x: float, start_x: float, width: float, depth: float) -> float:
    """Height of the terrain surface at `x` for `add_ditch`'s geometry [m] (walls at the edges
    count as ground)."""
    return -depth if start_x < x < start_x + width else 0.0
