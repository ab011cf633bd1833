"""Small-vector geometry shared by the stability measures (private).

The stability measures are evaluated every control step on 3-6 contact points. At that size the
call overhead of numpy dominates, so the hot paths here work on plain Python floats (lists of
``[x, y, z]``). Inputs are validated once on entry (shape and finiteness) and converted with
``ndarray.tolist()``.
"""

from __future__ import annotations

import math
from math import atan2

import numpy as np

# Relative tolerance for "collinear" / "degenerate" decisions, scaled by the size of the point set.
REL_TOL = 1e-12

Vec3 = tuple[float, float, float]


def as_points(points, name: str, dims: tuple[int, ...] = (3,)) -> list[list[float]]:
    """Validate a (k, d) array of finite points and return it as a list of float lists."""
    arr = np.asarray(points, dtype=float)
    if arr.ndim != 2 or arr.shape[1] not in dims:
        wanted = " or ".join(f"(k, {d})" for d in dims)
        raise ValueError(f"{name} must be an array of shape {wanted}, got shape {arr.shape}")
    rows = arr.tolist()
    if not math.isfinite(sum(arr.ravel().tolist())):
        raise ValueError(f"{name} contains NaN or infinite values")
    return rows


def as_vec3(vector, name: str) -> Vec3:
    """Validate a finite 3-vector and return it as a tuple of floats."""
    arr = np.asarray(vector, dtype=float)
    if arr.shape != (3,):
        raise ValueError(f"{name} must be a 3-vector (shape (3,)), got shape {arr.shape}")
    x, y, z = arr.tolist()
    if not math.isfinite(x + y + z):
        raise ValueError(f"{name} contains NaN or infinite values: {arr}")
    return x, y, z


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


def centred_moments(pts: list[list[float]]) -> tuple[Vec3, tuple[float, ...]]:
    """(centroid, (xx, xy, xz, yy, yz, zz)): second moments of ``pts`` about their centroid."""
    k = len(pts)
    cx = cy = cz = 0.0
    for x, y, z in pts:
        cx += x
        cy += y
        cz += z
    cx /= k
    cy /= k
    cz /= k
    xx = xy = xz = yy = yz = zz = 0.0
    for x, y, z in pts:
        dx, dy, dz = x - cx, y - cy, z - cz
        xx += dx * dx
        xy += dx * dy
        xz += dx * dz
        yy += dy * dy
        yz += dy * dz
        zz += dz * dz
    return (cx, cy, cz), (xx, xy, xz, yy, yz, zz)


def normal_and_centroid(pts: list[list[float]]) -> tuple[Vec3, Vec3]:
    """(least-squares unit normal with n_z >= 0, centroid) of ``pts``; see least_squares_normal."""
    k = len(pts)
    (cx, cy, cz), (xx, xy, xz, yy, yz, zz) = centred_moments(pts)
    det_x = yy * zz - yz * yz
    det_y = xx * zz - xz * xz
    det_z = xx * yy - xy * xy
    trace = xx + yy + zz
    if det_z >= det_x and det_z >= det_y:
        det, nx, ny, nz = det_z, xy * yz - xz * yy, xy * xz - yz * xx, det_z
    elif det_y >= det_x:
        det, nx, ny, nz = det_y, xz * yz - xy * zz, det_y, xy * xz - yz * xx
    else:
        det, nx, ny, nz = det_x, det_x, xz * yz - xy * zz, xy * yz - xz * yy
    if not det > REL_TOL * trace * trace:
        raise ValueError(
            f"the {k} points are collinear (or coincident): they span no plane and no polygon"
        )
    s = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
    if nz < 0.0:
        s = -s
    return (nx * s, ny * s, nz * s), (cx, cy, cz)


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


def project_oblique(pts: list[list[float]], up: Vec3) -> tuple[list[float], list[float]]:
    """Affine 2-D image of ``pts`` seen along ``up``, counter-clockwise preserved (cheap).

    Projects along ``up`` onto the coordinate plane most normal to it (an oblique projection:
    two multiply-adds per point). It is an orientation-preserving affine image of the orthogonal
    projection, so convex hull membership and counter-clockwise order (seen from +up) are the
    same; lengths are not (use :func:`project_2d` for distances).
    """
    ux, uy, uz = up
    ax, ay, az = abs(ux), abs(uy), abs(uz)
    if az >= ax and az >= ay:  # onto z = 0, coordinates (x, y)
        sx, sy = ux / uz, uy / uz
        xs = [p[0] - p[2] * sx for p in pts]
        ys = [p[1] - p[2] * sy for p in pts] if uz > 0.0 else [p[2] * sy - p[1] for p in pts]
    elif ax >= ay:  # onto x = 0, coordinates (y, z)
        sy, sz = uy / ux, uz / ux
        xs = [p[1] - p[0] * sy for p in pts]
        ys = [p[2] - p[0] * sz for p in pts] if ux > 0.0 else [p[0] * sz - p[2] for p in pts]
    else:  # onto y = 0, coordinates (z, x)
        sz, sx = uz / uy, ux / uy
        xs = [p[2] - p[1] * sz for p in pts]
        ys = [p[0] - p[1] * sx for p in pts] if uy > 0.0 else [p[1] * sx - p[0] for p in pts]
    return xs, ys


def hull_2d(xs: list[float], ys: list[float]) -> list[int]:
    """Strict convex hull of 2-D points, counter-clockwise, as indices into xs/ys.

    Points on an edge (collinear within a relative 1e-12 tolerance) and duplicates are dropped.
    Fewer than 3 hull vertices (fewer than 3 points, or all collinear): ValueError.

    Algorithm (fast for the 3-8 points of a legged robot): sort the points by angle around their
    centroid, which lies strictly inside the hull, giving a polygon star-shaped from it; then
    delete every vertex that is not a strict left turn until all are (Graham's scan). Hull
    vertices are never deleted, and of points on one ray from the centroid the nearer is always
    a right turn, so ties in angle need no special care.
    """
    k = len(xs)
    if k < 3:
        raise ValueError(f"a support polygon needs at least 3 points, got {k}")
    cx = sum(xs) / k
    cy = sum(ys) / k
    span = max(xs) - min(xs) + max(ys) - min(ys)
    tol = REL_TOL * span * span
    ring = sorted(range(k), key=lambda i: atan2(ys[i] - cy, xs[i] - cx))
    n = k
    i = 0
    confirmed = 0  # length of the run of checked left turns ending just before ring[i]
    while confirmed < n and n >= 3:
        a = ring[i - 1]
        b = ring[i]
        c = ring[i + 1] if i + 1 < n else ring[0]
        bx = xs[b]
        by = ys[b]
        if (bx - xs[a]) * (ys[c] - by) - (by - ys[a]) * (xs[c] - bx) > tol:
            confirmed += 1
            i = i + 1 if i + 1 < n else 0
        else:  # b is reflex, straight or a duplicate: drop it and re-check its predecessor
            del ring[i]
            n -= 1
            confirmed = max(0, min(confirmed - 1, n - 2))
            i = i - 1 if i > 0 else n - 1
    if n < 3:
        raise ValueError(
            f"the {k} points are collinear (seen from above): they do not enclose a support polygon"
        )
    return ring


def hull_3d(pts: list[list[float]], up: Vec3) -> list[int]:
    """Strict convex hull of ``pts`` seen along unit ``up``, counter-clockwise seen from above."""
    if len(pts) < 3:
        raise ValueError(f"a support polygon needs at least 3 points, got {len(pts)}")
    xs, ys = project_oblique(pts, up)
    return hull_2d(xs, ys)


def signed_distance_2d(xs: list[float], ys: list[float], hull: list[int], px: float, py: float):
    """Signed distance of (px, py) to the boundary of the ccw polygon ``hull``; > 0 inside.

    Inside: the smallest distance to an edge line. Outside: minus the Euclidean distance to the
    polygon (the nearest edge segment or vertex).
    """
    m = len(hull)
    edges = []
    d_in = math.inf
    for j in range(m):
        x0, y0 = xs[hull[j]], ys[hull[j]]
        i1 = hull[(j + 1) % m]
        ex, ey = xs[i1] - x0, ys[i1] - y0
        wx, wy = px - x0, py - y0
        edges.append((ex, ey, wx, wy))
        d_in = min(d_in, (ex * wy - ey * wx) / math.hypot(ex, ey))
    if d_in >= 0.0:
        return d_in
    d_out = math.inf
    for ex, ey, wx, wy in edges:
        t = min(1.0, max(0.0, (ex * wx + ey * wy) / (ex * ex + ey * ey)))
        d_out = min(d_out, math.hypot(wx - t * ex, wy - t * ey))
    return -d_out
