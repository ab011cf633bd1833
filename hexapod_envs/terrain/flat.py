"""Flat ground: one large plane at z = 0."""

from __future__ import annotations

import mujoco

GROUND_CONTYPE = 0
GROUND_CONAFFINITY = 1
"""Terrain geoms only receive contacts (conaffinity 1); robot geoms that should touch the ground
set contype 1 and conaffinity 0, so robot parts never collide with each other."""


def ground_geom_kwargs(friction: float) -> dict:
    """Common attributes of every terrain geom [friction: sliding coefficient]."""
    return {
        "contype": GROUND_CONTYPE,
        "conaffinity": GROUND_CONAFFINITY,
        "friction": [friction, 0.005, 0.0001],
        "condim": 3,
        "rgba": [0.55, 0.6, 0.55, 1.0],
    }


def add_flat(spec: mujoco.MjSpec, friction: float = 1.0, size: float = 100.0) -> None:
    """Add an infinite-looking ground plane at z = 0 [size: half-extent shown, m]."""
    spec.worldbody.add_geom(
        name="ground",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[size, size, 0.1],
        **ground_geom_kwargs(friction),
    )
