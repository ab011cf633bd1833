"""Normalised energy stability margin (NESM) of Hirose et al., in metres."""

from __future__ import annotations

import math

import numpy as np

from hexapod_envs.stability._geometry import as_points, as_vec3, hull_3d, unit


def nesm_per_edge(feet, cog, gravity=(0.0, 0.0, -1.0)) -> tuple[np.ndarray, np.ndarray]:
    """NESM of every support-polygon edge: signed CoG height rise [m] to tip over that edge.

    For edge i (a line through two feet, unit direction a, possibly inclined), rotating the body
    about it moves the CoG on a circle of radius r = distance(CoG, edge line) centred at c, the
    CoG's foot point on the line. The highest point of that circle is c + r u⊥/|u⊥|, where u is
    "up" (= -gravity) and u⊥ = u - (u·a)a, |u⊥| = cos(psi), psi the edge's inclination. So

        h_i = (c - p_G)·u + r cos(psi)                  (= |R|(1 - cos theta) cos psi, Hirose)

    is the height the CoG must rise before it lies vertically above the edge and the body tips.
    h_i is made negative when the CoG's projection along gravity lies outside the edge (the body
    is already past the tipping point; -h_i is then the rise needed to bring it back), so the
    margin is continuous and changes sign at the edge.

    Args:
        feet: (k, 3) contact points [m], any order, k >= 3.
        cog: (3,) centre of gravity [m].
        gravity: (3,) gravity direction (only the direction is used).

    Returns:
        ``(heights, edges)``: (m,) signed rise per edge [m] and (m, 2) edges as indices into
        ``feet``, counter-clockwise seen from above (from -gravity).

    Raises:
        ValueError: fewer than 3 feet, feet collinear seen along gravity, zero gravity,
            malformed or non-finite input.
    """
    pts = as_points(feet, "feet")
    gx, gy, gz = as_vec3(cog, "cog")
    dx, dy, dz = unit(as_vec3(gravity, "gravity"), "gravity")
    ux, uy, uz = -dx, -dy, -dz
    hull = hull_3d(pts, (ux, uy, uz))
    m = len(hull)
    heights = [0.0] * m
    edges = [(0, 0)] * m
    for j in range(m):
        i0, i1 = hull[j], hull[(j + 1) % m]
        edges[j] = (i0, i1)
        p, q = pts[i0], pts[i1]
        ax, ay, az = q[0] - p[0], q[1] - p[1], q[2] - p[2]
        inv = 1.0 / math.sqrt(ax * ax + ay * ay + az * az)
        ax, ay, az = ax * inv, ay * inv, az * inv
        # c - p_G = (p - p_G) - ((p - p_G)·a) a
        wx, wy, wz = p[0] - gx, p[1] - gy, p[2] - gz
        t = wx * ax + wy * ay + wz * az
        cx, cy, cz = wx - t * ax, wy - t * ay, wz - t * az
        radius = math.sqrt(cx * cx + cy * cy + cz * cz)
        ua = ux * ax + uy * ay + uz * az
        cos_psi = math.sqrt(max(0.0, 1.0 - ua * ua))
        rise = cx * ux + cy * uy + cz * uz + radius * cos_psi
        # Inside the edge (seen from above) when (a × (p_G - p))·u > 0, i.e. (a × w)·u < 0.
        side = (ay * wz - az * wy) * ux + (az * wx - ax * wz) * uy + (ax * wy - ay * wx) * uz
        heights[j] = -rise if side > 0.0 else rise
    return np.array(heights), np.array(edges, dtype=np.intp)


def nesm(feet, cog, gravity=(0.0, 0.0, -1.0)) -> float:
    """Hirose's normalised energy stability margin [m]: the smallest CoG rise to tip over.

    The minimum over the support-polygon edges of :func:`nesm_per_edge`: how far the CoG must be
    lifted (against gravity) by rotating the body about an edge until it lies vertically above
    that edge. Positive inside the support polygon (seen along gravity), negative outside.
    NESM = ESM / (m g). See :func:`nesm_per_edge` for arguments and errors.
    """
    heights, _ = nesm_per_edge(feet, cog, gravity)
    return float(heights.min())
