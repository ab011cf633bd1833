"""Irregular terrain of Coelho et al. 2024 (Section 5.1, Fig. 9): a 10 degree ramp and a test bed
of blocks.

Both pieces add static box geoms to `spec.worldbody` (collision convention of
`hexapod_envs.terrain.flat`: terrain geoms only receive contacts) and, by default, a ground plane
at z = 0 so that the robot starts on flat ground at the origin. They return a small frozen
dataclass describing what was built, including `surface_height(x, y)`, the true terrain height,
for privileged evaluation quantities (e.g. the torso's true clearance) in `info`.
"""

from __future__ import annotations

import bisect
import functools
import math
from dataclasses import dataclass

import mujoco
import numpy as np

from ..checks import check_number
from .flat import ground_geom_kwargs

PAPER_FRICTION = 0.9
"""Kinetic friction coefficient of Coelho et al. 2024's simulations (Section 5.1)."""

_RAMP_RGBA = [0.62, 0.55, 0.45, 1.0]


@dataclass(frozen=True)
class Ramp:
    """A ramp built by `add_ramp`: flat approach, slope from `start_x` over a horizontal run of
    `length`, then a flat top of `top_length`; all `width` wide around `y_center` (m, rad)."""

    start_x: float
    length: float
    slope: float
    top_length: float
    width: float
    y_center: float
    geom_names: tuple[str, ...]

    @property
    def top_height(self) -> float:
        """Height of the flat top above the approach, m."""
        return self.length * math.tan(self.slope)

    def surface_height(self, x: float | np.ndarray, y: float | np.ndarray = 0.0) -> np.ndarray:
        """True ground height (m) at world (x, y); 0 off the ramp's footprint."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        rise = np.clip(x - self.start_x, 0.0, self.length) * math.tan(self.slope)
        end = self.start_x + self.length + self.top_length
        on = (np.abs(y - self.y_center) <= self.width / 2) & (x >= self.start_x) & (x <= end)
        return np.where(on, rise, 0.0)

    def height_at(self, x: float, y: float) -> float:
        """`surface_height` at one point, on plain floats (cheap enough for every env step), m."""
        end = self.start_x + self.length + self.top_length
        if abs(y - self.y_center) > self.width / 2 or not self.start_x <= x <= end:
            return 0.0
        return min(x - self.start_x, self.length) * math.tan(self.slope)


@dataclass(frozen=True)
class BlockField:
    """A grid of boxes built by `add_blocks`: block (i, j) spans x_edges[i:i+2] x y_edges[j:j+2]
    and rises from z = 0 to heights[i, j] (m)."""

    x_edges: np.ndarray
    y_edges: np.ndarray
    heights: np.ndarray
    geom_names: tuple[str, ...]

    def surface_height(self, x: float | np.ndarray, y: float | np.ndarray) -> np.ndarray:
        """True ground height (m) at world (x, y): the block's top, 0 outside the field."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        i = np.searchsorted(self.x_edges, x, side="right") - 1
        j = np.searchsorted(self.y_edges, y, side="right") - 1
        inside = (i >= 0) & (i < len(self.x_edges) - 1) & (j >= 0) & (j < len(self.y_edges) - 1)
        ii, jj = np.where(inside, i, 0), np.where(inside, j, 0)
        return np.where(inside, self.heights[ii, jj], 0.0)

    def height_at(self, x: float, y: float) -> float:
        """`surface_height` at one point, on plain floats (cheap enough for every env step), m."""
        xe, ye = self._edges
        i, j = bisect.bisect_right(xe, x) - 1, bisect.bisect_right(ye, y) - 1
        if 0 <= i < len(xe) - 1 and 0 <= j < len(ye) - 1:
            return self._height_rows[i][j]
        return 0.0

    @functools.cached_property
    def _edges(self) -> tuple[list[float], list[float]]:
        return self.x_edges.tolist(), self.y_edges.tolist()

    @functools.cached_property
    def _height_rows(self) -> list[list[float]]:
        return self.heights.tolist()


def add_ramp(
    spec: mujoco.MjSpec,
    slope_deg: float = 10.0,
    start_x: float = 0.5,
    length: float = 1.5,
    top_length: float = 0.5,
    width: float = 1.0,
    y_center: float = 0.0,
    friction: float = PAPER_FRICTION,
    with_ground: bool = True,
    thickness: float = 0.05,
    name: str = "ramp",
) -> Ramp:
    """Add a ramp rising along +x (Coelho et al. 2024: 10 degrees) with a flat approach before
    `start_x`.

    [slope_deg: degrees, in (0, 45]; start_x, length (horizontal run), top_length, width, y_center,
    thickness (of the sloped slab): m]. With `with_ground` a plane `{name}_ground` at z = 0 forms
    the approach; leave it out when another piece already provides the ground.
    """
    if not 0.0 < slope_deg <= 45.0:
        raise ValueError(f"slope_deg must be in (0, 45] degrees, got {slope_deg}")
    for label, value in (("length", length), ("width", width), ("thickness", thickness)):
        check_number(label, value, strict=True)
    check_number("top_length", top_length)
    slope = math.radians(slope_deg)
    kwargs = ground_geom_kwargs(friction)
    names = []
    if with_ground:
        _add_ground(spec, f"{name}_ground", friction)
        names.append(f"{name}_ground")

    # Sloped slab: its top face runs from (start_x, 0) to (start_x + length, top height).
    run = length / math.cos(slope)
    mid_top = np.array([start_x + length / 2, y_center, length * math.tan(slope) / 2])
    normal = np.array([-math.sin(slope), 0.0, math.cos(slope)])
    spec.worldbody.add_geom(
        name=f"{name}_slope",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[run / 2, width / 2, thickness / 2],
        pos=(mid_top - normal * thickness / 2).tolist(),
        quat=[math.cos(-slope / 2), 0.0, math.sin(-slope / 2), 0.0],  # pitch the slab up by slope
        **{**kwargs, "rgba": _RAMP_RGBA},
    )
    names.append(f"{name}_slope")
    if top_length > 0:
        height = length * math.tan(slope)
        spec.worldbody.add_geom(
            name=f"{name}_top",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[top_length / 2, width / 2, height / 2],
            pos=[start_x + length + top_length / 2, y_center, height / 2],
            **{**kwargs, "rgba": _RAMP_RGBA},
        )
        names.append(f"{name}_top")
    return Ramp(start_x, length, slope, top_length, width, y_center, tuple(names))


def add_blocks(
    spec: mujoco.MjSpec,
    rng: np.random.Generator,
    height_range: tuple[float, float] = (0.04, 0.13),
    block_size: tuple[float, float] = (0.1, 0.1),
    region: tuple[tuple[float, float], tuple[float, float]] = ((0.4, 2.0), (-0.5, 0.5)),
    friction: float = PAPER_FRICTION,
    with_ground: bool = True,
    name: str = "blocks",
) -> BlockField:
    """Add a test bed of boxes with heights drawn uniformly from `height_range` (Coelho et al. 2024:
    0.04-0.13 m) by `rng`, so the same generator state gives the same terrain.

    [block_size: (x, y) of one block, m; region: ((x_min, x_max), (y_min, y_max)), m]. The region
    is split into round(extent / block_size) blocks per axis, so the blocks may be slightly
    resized to tile it exactly. Heights are drawn in row-major (x, then y) order.
    """
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    low, high = (float(v) for v in height_range)
    if not 0.0 <= low <= high:
        raise ValueError(f"height_range must satisfy 0 <= low <= high, got {height_range}")
    if min(block_size) <= 0:
        raise ValueError(f"block_size must be positive, got {block_size}")
    (x0, x1), (y0, y1) = region
    if not (x1 > x0 and y1 > y0):
        raise ValueError(
            f"region must be ((x_min, x_max), (y_min, y_max)) with max > min, got {region}"
        )
    nx = max(1, round((x1 - x0) / block_size[0]))
    ny = max(1, round((y1 - y0) / block_size[1]))
    x_edges, y_edges = np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1)
    heights = rng.uniform(low, high, size=(nx, ny))

    kwargs = ground_geom_kwargs(friction)
    names = []
    if with_ground:
        _add_ground(spec, f"{name}_ground", friction)
        names.append(f"{name}_ground")
    for i in range(nx):
        for j in range(ny):
            h = float(heights[i, j])
            if h <= 0.0:
                continue
            shade = 0.45 + 0.4 * (h - low) / (high - low) if high > low else 0.65
            geom = f"{name}_{i}_{j}"
            spec.worldbody.add_geom(
                name=geom,
                type=mujoco.mjtGeom.mjGEOM_BOX,
                size=[(x_edges[i + 1] - x_edges[i]) / 2, (y_edges[j + 1] - y_edges[j]) / 2, h / 2],
                pos=[(x_edges[i] + x_edges[i + 1]) / 2, (y_edges[j] + y_edges[j + 1]) / 2, h / 2],
                **{**kwargs, "rgba": [shade, 0.5, 0.35, 1.0]},
            )
            names.append(geom)
    return BlockField(x_edges, y_edges, heights, tuple(names))


def _add_ground(spec: mujoco.MjSpec, name: str, friction: float) -> None:
    spec.worldbody.add_geom(
        name=name,
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[50.0, 50.0, 0.1],
        **ground_geom_kwargs(friction),
    )
