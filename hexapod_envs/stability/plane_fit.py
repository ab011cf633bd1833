"""Least-squares ground plane z = a x + b y + c through foot contact points (Zhang et al. 2024
§4.2)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hexapod_envs.stability import _compiled


@dataclass(frozen=True)
class Plane:
    """A non-vertical plane z = a x + b y + c.

    Attributes:
        a, b: slopes dz/dx, dz/dy [-].
        c: height at x = y = 0 [m].
        normal: (3,) unit normal (-a, -b, 1)/sqrt(a² + b² + 1), pointing up (z > 0).
        point: (3,) a point on the plane (the centroid of the fitted points' x, y, on the plane).
    """

    a: float
    b: float
    c: float
    normal: np.ndarray
    point: np.ndarray

    @classmethod
    def from_coefficients(cls, a: float, b: float, c: float, x0: float = 0.0, y0: float = 0.0):
        """The plane z = a x + b y + c, with ``point`` above (x0, y0)."""
        s = 1.0 / math.sqrt(a * a + b * b + 1.0)
        return cls(
            a=float(a),
            b=float(b),
            c=float(c),
            normal=np.array([-a * s, -b * s, s]),
            point=np.array([x0, y0, a * x0 + b * y0 + c]),
        )

    def height_at(self, x, y):
        """Plane height z [m] at (x, y); scalars or broadcastable arrays."""
        return self.a * np.asarray(x, dtype=float) + self.b * np.asarray(y, dtype=float) + self.c

    def distance(self, p):
        """Signed distance [m] of point(s) ``p`` ((3,) or (n, 3)) to the plane, > 0 above it."""
        return (np.asarray(p, dtype=float) - self.point) @ self.normal

    def project(self, p) -> np.ndarray:
        """Orthogonal projection of point(s) ``p`` ((3,) or (n, 3)) onto the plane."""
        p = np.asarray(p, dtype=float)
        return p - np.multiply.outer(self.distance(p), self.normal)

    @property
    def inclination_rad(self) -> float:
        """Angle [rad] between the plane and the horizontal."""
        return math.acos(min(1.0, float(self.normal[2])))


def fit_plane(points) -> Plane:
    """Linear least-squares plane z = a x + b y + c through ``points`` (k, 3), k >= 3.

    Minimises the vertical residuals sum (a x_i + b y_i + c - z_i)², as Zhang et al. 2024 does for
    the
    terrain under the feet; solved from the centred 2x2 normal equations (exact for points on a
    plane, well conditioned for feet metres away from the origin).

    Raises:
        ValueError: fewer than 3 points, points whose (x, y) are collinear or coincident (a
            vertical or undetermined plane), malformed or non-finite input.
    """
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must be an array of shape (k, 3), got shape {pts.shape}")
    k = pts.shape[0]
    if k < 3:
        raise ValueError(f"fitting a plane needs at least 3 points, got {k}")
    status, coefficients, normal, point = _compiled.fit_plane(pts)
    if status == _compiled.NOT_FINITE:
        raise ValueError("points contains NaN or infinite values")
    if status != _compiled.OK:
        raise ValueError(
            f"the {k} points' (x, y) are collinear or coincident: z = a x + b y + c is undetermined"
        )
    a, b, c = coefficients.tolist()
    return Plane(a=a, b=b, c=c, normal=normal, point=point)


def plane_normal(points: np.ndarray) -> np.ndarray | None:
    """The unit normal of `fit_plane` for a float64 (k, 3) array with k >= 3, or None where
    `fit_plane` raises (collinear, coincident or non-finite points).

    For callers that fit a plane every control period and need only its normal (the tipping
    recovery's force distribution): the same kernel and numbers, without the input checks and
    the `Plane` object, which in that loop cost more than the fit.
    """
    status, _, normal, _ = _compiled.fit_plane(points)
    return normal if status == _compiled.OK else None
