"""Support polygon: the convex hull of the contact points, seen from above."""

from __future__ import annotations

import numpy as np

from hexapod_envs.stability._geometry import as_points, as_vec3, hull_3d, least_squares_normal, unit


def support_polygon(points, up=None) -> np.ndarray:
    """Indices of the strict convex hull of ``points``, counter-clockwise seen from above.

    Args:
        points: (k, 3) contact points [m], any order, k >= 3.
        up: the "above" direction (any non-zero 3-vector; the points are projected along it).
            Default: the unit normal of the least-squares plane through the points, oriented
            with a non-negative z component.

    Returns:
        (m,) integer indices into ``points`` (m >= 3) forming the hull, counter-clockwise seen
        from +up. Points lying on a hull edge (collinear within a relative 1e-12 tolerance) and
        duplicates are dropped, so e.g. the middle feet of a hexapod standing in a rectangle are
        not vertices.

    Raises:
        ValueError: fewer than 3 points, all points collinear (seen from above), non-finite
            input, or a zero ``up``.
    """
    pts = as_points(points, "points")
    if len(pts) < 3:
        raise ValueError(f"a support polygon needs at least 3 points, got {len(pts)}")
    up_vec = least_squares_normal(pts) if up is None else unit(as_vec3(up, "up"), "up")
    return np.array(hull_3d(pts, up_vec), dtype=np.intp)
