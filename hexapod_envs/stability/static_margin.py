"""Static stability margin (SSM): CoG projection vs support polygon, in metres."""

from __future__ import annotations

from hexapod_envs.stability._geometry import (
    as_points,
    as_vec3,
    hull_2d,
    project_2d,
    signed_distance_2d,
    unit,
)


def static_stability_margin(feet, cog, gravity=(0.0, 0.0, -1.0)) -> float:
    """Signed distance [m] from the CoG's projection along gravity to the support polygon boundary.

    Everything is projected along ``gravity`` into the plane normal to it; the support polygon is
    the convex hull of the projected feet. Inside: the smallest distance to an edge line (the
    classic SSM, McGhee & Frank). Outside: minus the distance to the polygon, so the margin is
    continuous and negative when the CoG projection has left the polygon.

    Args:
        feet: (k, 3) contact points [m], any order, k >= 3.
        cog: (3,) centre of gravity [m], same frame.
        gravity: (3,) gravity direction (any length; only the direction is used).

    Raises:
        ValueError: fewer than 3 feet, feet collinear when seen along gravity, zero gravity,
            malformed or non-finite input.
    """
    pts = as_points(feet, "feet")
    gx, gy, gz = unit(as_vec3(gravity, "gravity"), "gravity")
    cx, cy, cz = as_vec3(cog, "cog")
    xs, ys = project_2d(pts + [[cx, cy, cz]], (-gx, -gy, -gz))
    px, py = xs.pop(), ys.pop()
    return signed_distance_2d(xs, ys, hull_2d(xs, ys), px, py)
