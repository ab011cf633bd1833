"""Zero-moment point estimated from normal foot forces, and its margin (Coelho et al. 2024, eqs.
32-33).

Coelho et al. 2024 (ATHENA) cannot use the torso acceleration in its simulator and estimates the
ZMP as
the normal-force-weighted mean of the foot positions, in the horizontal (x, y) coordinates of the
frame the feet are given in (the torso frame in the paper):

    p_ZMP = ( Σ f_n,i x_i / Σ f_n,i ,  Σ f_n,i y_i / Σ f_n,i )                        (32)
    s_ZMP = min(d_1, ..., d_e)                                                      (33)

with d_j the distance of the ZMP to edge j of the support polygon. Because (32) is a convex
combination of the loaded feet, this ZMP (really a centre of pressure) always lies in the support
polygon of the loaded feet: s_ZMP >= 0, and it measures how centred the load is rather than
predicting a tip-over.

Unloaded feet: a foot with normal force <= ``min_force`` (default 1e-6 N; negative readings,
i.e. sensor noise, included - a foot cannot pull) is not in contact. It gets no weight in (32)
and is not a vertex of the support polygon in (33). If fewer than 3 loaded feet remain, or the
loaded feet are collinear, the support polygon has no interior and the ZMP lies on it, so
``zmp_margin`` returns 0.0 (critical) instead of raising. No loaded foot at all: ValueError
(the ZMP is undefined).
"""

from __future__ import annotations

import numpy as np

from hexapod_envs.stability import _compiled
from hexapod_envs.stability._geometry import points_array

DEFAULT_MIN_FORCE = 1e-6  # [N] normal force at or below which a foot counts as unloaded


def _zmp_and_margin(feet, normal_forces, min_force: float) -> tuple[float, float, float]:
    """(ZMP x, ZMP y, margin) of validated input, from the compiled kernel
    (:func:`hexapod_envs.stability._compiled.zmp_margin`, which sums in the feet's order)."""
    pts = points_array(feet, "feet", dims=(2, 3))
    if not np.isfinite(pts).all():
        raise ValueError("feet contains NaN or infinite values")
    forces = np.asarray(normal_forces, dtype=float)
    if forces.shape != (len(pts),):
        raise ValueError(
            f"normal_forces must have shape ({len(pts)},) (one per foot), got {forces.shape}"
        )
    status, px, py, margin = _compiled.zmp_margin(pts[:, 0], pts[:, 1], forces, float(min_force))
    if status == _compiled.NOT_FINITE:
        raise ValueError("normal_forces contains NaN or infinite values")
    if status == _compiled.ZERO_FORCE:
        raise ValueError(
            f"no foot carries a normal force above min_force={min_force} N: the ZMP is undefined"
        )
    return px, py, margin


def zmp(feet, normal_forces, min_force: float = DEFAULT_MIN_FORCE) -> np.ndarray:
    """ZMP estimate of Coelho et al. 2024 eq. 32: normal-force-weighted mean of the foot (x, y) [m].

    Args:
        feet: (k, 3) or (k, 2) foot positions [m]; only x and y are used (projection along the
            frame's z axis, as in the paper).
        normal_forces: (k,) normal contact force of each foot [N].
        min_force: feet at or below this force [N] are unloaded and get no weight.

    Returns:
        (2,) array: the ZMP's x, y [m].

    Raises:
        ValueError: no loaded foot, shape mismatch, or non-finite input.
    """
    px, py, _ = _zmp_and_margin(feet, normal_forces, min_force)
    return np.array([px, py])


def zmp_margin(feet, normal_forces, min_force: float = DEFAULT_MIN_FORCE) -> float:
    """Coelho et al. 2024 eq. 33: signed distance [m] of the ZMP (eq. 32) to the loaded feet's
    polygon.

    The support polygon is the convex hull of the loaded feet's (x, y); the margin is the smallest
    distance from the ZMP to its edges, positive inside (negative outside, which eq. 32 cannot
    produce). Fewer than 3 loaded feet or collinear loaded feet: 0.0 (see module docstring).

    Args:
        feet: (k, 3) or (k, 2) foot positions [m]; only x and y are used.
        normal_forces: (k,) normal contact forces [N].
        min_force: feet at or below this force [N] are unloaded.
    """
    return _zmp_and_margin(feet, normal_forces, min_force)[2]
