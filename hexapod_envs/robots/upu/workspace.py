"""Workspace of the 3-UPU mechanism by the limit-boundary search of Li et al. 2018 §4.2 (Fig. 3).

The flow chart: (1) take the structure parameters; (2) define a search box of reference-point
positions; (3) for every point solve the inverse kinematics (eq. 6), the Hooke angles
(eqs. 10-11) and compare with the limits (eq. 9 and ±pi/4); (4) the accepted points are the
workspace. We evaluate the whole grid at once with numpy and also return the boundary: accepted
points with at least one rejected 6-neighbour, labelled with the limit that the neighbour breaks
(the paper's "top and bottom surfaces" are limb-length limits, the "surrounding surfaces"
Hooke-joint limits). Pure numpy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kinematics import LIMIT_NAMES, limit_margins
from .params import UpuParams, check_platform


@dataclass(frozen=True)
class WorkspaceResult:
    """Grid search result. Positions follow `kinematics` (upper in lower frame by default)."""

    xs: np.ndarray
    """(nx,) grid x values [m]."""
    ys: np.ndarray
    """(ny,) grid y values [m]."""
    zs: np.ndarray
    """(nz,) grid z values [m]."""
    inside: np.ndarray
    """(nx, ny, nz) bool: the point respects every limit."""
    boundary_points: np.ndarray
    """(k, 3) accepted points next to a rejected one [m]."""
    boundary_limit: np.ndarray
    """(k,) str: the limit (one of `LIMIT_NAMES`) a rejected neighbour of each point breaks."""
    moving: str
    """'upper' or 'lower': whose centre the positions describe."""
    touches_search_box: bool
    """True if accepted points lie on the faces of the search box (the box was too small)."""

    @property
    def points(self) -> np.ndarray:
        """(n, 3) all accepted grid points [m]."""
        gx, gy, gz = np.meshgrid(self.xs, self.ys, self.zs, indexing="ij")
        return np.stack([gx[self.inside], gy[self.inside], gz[self.inside]], axis=-1)

    @property
    def volume(self) -> float:
        """Accepted grid cells times the cell volume [m^3]."""
        cell = _spacing(self.xs) * _spacing(self.ys) * _spacing(self.zs)
        return float(self.inside.sum()) * cell

    def extent(self) -> dict[str, tuple[float, float]]:
        """Min and max of each coordinate over the accepted points [m]."""
        pts = self.points
        if len(pts) == 0:
            raise ValueError("the workspace search found no reachable point")
        return {ax: (float(pts[:, i].min()), float(pts[:, i].max())) for i, ax in enumerate("xyz")}


def _spacing(values: np.ndarray) -> float:
    return float(values[1] - values[0]) if len(values) > 1 else 0.0


def _axis(bounds, step: float, name: str) -> np.ndarray:
    lo, hi = (float(b) for b in bounds)
    if not lo < hi:
        raise ValueError(f"{name} must be (low, high) with low < high [m], got {bounds}")
    n = int(round((hi - lo) / step)) + 1
    return np.linspace(lo, hi, max(n, 2))


def search_workspace(
    params: UpuParams,
    x_range: tuple[float, float] = (-0.35, 0.35),
    y_range: tuple[float, float] = (-0.35, 0.35),
    z_range: tuple[float, float] = (0.20, 0.48),
    step: float = 0.005,
    moving: str = "upper",
) -> WorkspaceResult:
    """Limit-boundary search (§4.2) over a regular grid with spacing `step` [m].

    For moving='lower' give the ranges of the lower centre in the upper frame (e.g. a negative
    z_range); that workspace is the point reflection of the upper one (see `kinematics`).
    No tolerance is applied: a point is inside only if every limit holds exactly.
    """
    check_platform(moving, "moving")
    if not step > 0:
        raise ValueError(f"step must be > 0 m, got {step}")
    xs = _axis(x_range, step, "x_range")
    ys = _axis(y_range, step, "y_range")
    zs = _axis(z_range, step, "z_range")
    if len(xs) * len(ys) * len(zs) > 5_000_000:
        raise ValueError(
            f"search grid of {len(xs)}x{len(ys)}x{len(zs)} points is too large; "
            "increase step or shrink the ranges"
        )
    grid = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1)
    margins = limit_margins(grid, params, moving)  # (nx, ny, nz, 3 limbs, 4 limits)
    violated = np.any(margins < 0, axis=-2)  # (nx, ny, nz, 4): limit broken by some limb
    inside = ~np.any(violated, axis=-1)
    first_violation = np.argmax(violated, axis=-1)

    boundary = np.zeros_like(inside)
    label = np.full(inside.shape, -1, dtype=int)
    for axis in range(3):
        for shift in (1, -1):
            neighbour_inside = np.roll(inside, shift, axis=axis)
            neighbour_label = np.roll(first_violation, shift, axis=axis)
            # np.roll wraps around: the wrapped slice has no real neighbour.
            edge = [slice(None)] * 3
            edge[axis] = 0 if shift == 1 else -1
            neighbour_inside[tuple(edge)] = True
            hit = inside & ~neighbour_inside
            label = np.where(hit & (label < 0), neighbour_label, label)
            boundary |= hit
    faces = np.zeros_like(inside)
    for axis in range(3):
        idx = [slice(None)] * 3
        for end in (0, -1):
            idx[axis] = end
            faces[tuple(idx)] = True
    touches = bool(np.any(inside & faces))
    names = np.array(LIMIT_NAMES)
    return WorkspaceResult(
        xs=xs,
        ys=ys,
        zs=zs,
        inside=inside,
        boundary_points=grid[boundary],
        boundary_limit=names[label[boundary]],
        moving=moving,
        touches_search_box=touches,
    )
