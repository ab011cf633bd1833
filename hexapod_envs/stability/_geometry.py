"""Small-vector geometry shared by the stability measures (private).

The stability measures are evaluated every control step on 3-6 contact points. At that size the
call overhead of numpy dominates, so the small helpers here work on plain Python floats (lists
of ``[x, y, z]``) and the hull and plane fit call the compiled kernels of :mod:`._compiled`.
Inputs are validated once on entry (shape and finiteness).
"""

from __future__ import annotations

import math

import numpy as np

from hexapod_envs.stability import _compiled

Vec3 = tuple[float, float, float]


def points_array(points, name: str, dims: tuple[int, ...] = (3,)) -> np.ndarray:
    """``points`` as a (k, d) float array (d in ``dims``), else a ValueError naming ``name``."""
    arr = np.asarray(points, dtype=float)
    if arr.ndim != 2 or arr.shape[1] not in dims:
        wanted = " or ".join(f"(k, {d})" for d in dims)
        raise ValueError(f"{name} must be an array of shape {wanted}, got shape {arr.shape}")
    return arr


def as_points(points, name: str, dims: tuple[int, ...] = (3,)) -> list[list[float]]:
    """Validate a (k, d) array of finite points and return it as a list of float lists."""
    arr = points_array(points, name, dims)
    rows = arr.tolist()
    if not math.isfinite(sum(arr.ravel().tolist())):
        raise ValueError(f"{name} contains NaN or infinite values")
    return rows


def vec3_array(vector, name: str) -> np.ndarray:
    """``vector`` as a (3,) float array, else a ValueError naming ``name``."""
    arr = np.asarray(vector, dtype=float)
    if arr.shape != (3,):
        raise ValueError(f"{name} must be a 3-vector (shape (3,)), got shape {arr.shape}")
    return arr


def as_vec3(vector, name: str) -> Vec3:
    """Validate a finite 3-vector and return it as a tuple of floats."""
    arr = vec3_array(vector, name)
    x, y, z = arr.tolist()
    if not math.isfinite(x + y + z):
        raise ValueError(f"{name} contains NaN or infinite values: {arr}")
    return x, y, z


def hull_collinear_message(k: int) -> str:
    """The error of ``k`` points whose hull seen from above is no polygon."""
    return f"the {k} points are collinear (seen from above): they do not enclose a support polygon"


def no_plane_message(k: int) -> str:
    """The error of ``k`` points (k > 3) without a least-squares plane."""
    return f"the {k} points are collinear (or coincident): they span no plane and no polygon"


def unit(v: Vec3, name: str) -> Vec3:
    """Return v / |v|; a zero vector is a ValueError naming ``name``."""
    x, y, z = v
    n = math.sqrt(x * x + y * y + z * z)
    if n == 0.0:
        raise ValueError(f"{name} must be a non-zero vector")
    return x / n, y / n, z / n


def least_squares_normal(pts: list[list[float]]) -> Vec3:
    """Unit normal of the least-squares plane through ``pts`` (k >= 3), oriented with n_z >= 0.

    Regression along the best-conditioned axis (for a plane that is not steep this is exactly the
    z = a x + b y + c fit of :func:`fit_plane`; for near-vertical point sets it regresses x or y
    instead, so any non-collinear set has a normal). Collinear or coincident points: ValueError.
    """
    return normal_and_centroid(pts)[0]


def normal_and_centroid(pts) -> tuple[Vec3, Vec3]:
    """(least-squares unit normal with n_z >= 0, centroid) of ``pts``; see least_squares_normal."""
    normal, centroid, ok = _compiled.plane_normal(np.asarray(pts, dtype=float))
    if not ok:
        raise ValueError(no_plane_message(len(pts)))
    return tuple(normal.tolist()), tuple(centroid.tolist())


def plane_basis(up: Vec3) -> tuple[Vec3, Vec3]:
    """Orthonormal e1, e2 spanning the plane normal to unit ``up`` with e1 x e2 = up.

    Counter-clockwise in (e1, e2) coordinates is then counter-clockwise seen from above (from +up).
    """
    ux, uy, uz = up
    # Helper axis: the world axis least aligned with up.
    if abs(ux) <= abs(uy) and abs(ux) <= abs(uz):
        hx, hy, hz = 1.0, 0.0, 0.0
    elif abs(uy) <= abs(uz):
        hx, hy, hz = 0.0, 1.0, 0.0
    else:
        hx, hy, hz = 0.0, 0.0, 1.0
    t = hx * ux + hy * uy + hz * uz
    e1 = unit((hx - t * ux, hy - t * uy, hz - t * uz), "basis vector")
    ax, ay, az = e1
    e2 = (uy * az - uz * ay, uz * ax - ux * az, ux * ay - uy * ax)
    return e1, e2


def project_2d(pts: list[list[float]], up: Vec3) -> tuple[list[float], list[float]]:
    """Coordinates of ``pts`` in the plane normal to ``up`` (a projection along ``up``)."""
    (ax, ay, az), (bx, by, bz) = plane_basis(up)
    xs = [p[0] * ax + p[1] * ay + p[2] * az for p in pts]
    ys = [p[0] * bx + p[1] * by + p[2] * bz for p in pts]
    return xs, ys


def hull_2d(xs, ys) -> list[int]:
    """Strict convex hull of 2-D points, counter-clockwise, as indices into xs/ys.

    Points on an edge (collinear within a relative 1e-12 tolerance) and duplicates are dropped.
    Fewer than 3 hull vertices (fewer than 3 points, or all collinear): ValueError. The
    algorithm is :func:`hexapod_envs.stability._compiled.hull_2d`'s.
    """
    _check_count(len(xs))
    ring = _compiled.hull_2d(np.asarray(xs, dtype=float), np.asarray(ys, dtype=float))
    return _checked_ring(ring, len(xs))


def hull_3d(pts, up: Vec3) -> list[int]:
    """Strict convex hull of (k, 3) ``pts`` seen along unit ``up``, counter-clockwise from above."""
    _check_count(len(pts))
    ring = _compiled.hull_up(np.asarray(pts, dtype=float), np.asarray(up, dtype=float))
    return _checked_ring(ring, len(pts))


def _check_count(k: int) -> None:
    if k < 3:
        raise ValueError(f"a support polygon needs at least 3 points, got {k}")


def _checked_ring(ring: np.ndarray, k: int) -> list[int]:
    """The hull kernel's ``ring`` as a list, or a ValueError when it is not a polygon."""
    if len(ring) < 3:
        raise ValueError(hull_collinear_message(k))
    return ring.tolist()


def signed_distance_2d(xs: list[float], ys: list[float], hull: list[int], px: float, py: float):
    """Signed distance of (px, py) to the boundary of the ccw polygon ``hull``; > 0 inside.

    Inside: the smallest distance to an edge line. Outside: minus the Euclidean distance to the
    polygon (the nearest edge segment or vertex). See
    :func:`hexapod_envs.stability._compiled.signed_distance_2d`.
    """
    return _compiled.signed_distance_2d(
        np.asarray(xs, dtype=float),
        np.asarray(ys, dtype=float),
        np.asarray(hull, dtype=np.int64),
        float(px),
        float(py),
    )
