"""Reachable region and foothold of the adjustment leg on the fitted terrain (Zhang et al. 2024
§4.2).

Everything is in the body frame {C} (x forward, y left, z up, metres). The terrain is the
least-squares plane through the stance feet. For the adjustment leg with coxa origin B_i:

- H is B_i projected onto the plane along body z; if ‖B_iH‖ > L_max there is no reachable ground.
- The unit vector r̂_HR lies in the plane, perpendicular to body x (so the line H + s r̂_HR stays
  in the leg's plane x = x_Bi) and opposite to the ground projection of body y: R is the
  reachable extreme towards the robot's right, L towards its left (eqs. 10-12).
- A, B (front, rear) are L shifted by the horizontal joint's range K_x J_x projected onto the
  plane, C, D (rear, front) the same for R (eq. 13); the quadrilateral ABCD approximates the
  reachable region. Every length is scaled by the safety factor ρ.

Two models find R and L along the line:

- ``"paper"``: eqs. (10)-(12) as printed. R lies on the circle ‖B_iR‖ = L_max (eq. 10) unless
  the angle ∠HB_iR exceeds the swing range, in which case that angle is clamped and ‖HR‖
  recomputed (law of sines); L likewise. This treats the swing angle as the angle at B_i, i.e.
  it ignores the leg-plane offset L1. ‖HR‖ and ‖HL‖ are then scaled by ρ about H. On the
  heavy robot standing on flat ground this puts R and L of a middle leg at |y| = 1.825 m,
  inside the stance feet at 1.9 m, so this model finds no foothold outside a side tipping edge.
- ``"kinematic"`` (default): the exact extremes of the line inside the leg's reachable set of
  eq. (1) (swing angle J_θ in its range, leg length K_z J_z + L2 in its range, J_x = 0): the
  candidates are the line's intersections with the circles ‖B_iP‖ = L_max, L_min and with the
  two swing-limit rays; the reachable ones bound the interval. With L1 ≠ 0 the point H right
  under the hip may itself be out of reach (the heavy robot needs J_θ = 0.38 rad there, its
  range is ±0.35), so ρ shrinks the interval about H when H is reachable (as the paper does)
  and about the interval's midpoint otherwise.

Foothold selection (§4.2): the tipping axis runs from P'_i to P'_j, the two effective support
feet projected onto the plane, counter-clockwise seen from above, so the support polygon lies on
its left and eq. (14)'s "right side" (Θ > 0) is outside. If a boundary segment (AB, BC, CD, DA)
makes an angle below the threshold with the axis, R or L is chosen ("shorter adjustment time":
they are level with the hip); otherwise the boundary point farthest from the axis. Distances
are signed (positive on the right), so "farthest" always prefers the right side, which is the
paper's tie rule when H lies on the axis; remaining ties go to the point nearer to H (shorter
swing).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from agents.tipping.judgment import ccw_edge
from hexapod_envs.robots.heavy_duty.kinematics import (
    joints_for_foot,
    joints_from_coxa,
    within_limits,
)
from hexapod_envs.robots.heavy_duty.params import LEG_NAMES, HeavyDutyParams
from hexapod_envs.stability import Plane, fit_plane

RHO: float = 0.9
"""Safety factor ρ (0 < ρ < 1) on the reachable lengths, eqs. (11)-(13). Not given in the paper."""

AXIS_ANGLE_THRESHOLD_DEG: float = 40.0
"""Angle [deg] between a boundary segment and the tipping axis below which R or L is chosen.

Not given in the paper. All six §5.2 footholds lie level with the hip (x = x_Bi), i.e. are R or
L points; there the axes make 32.3° (diagonal edges) and 0° (side edges) with the segments BC/DA,
so the threshold lies in (32.3°, 45°) (at 45° or more the R/L branch would always apply, as every
axis makes at most 45° with the x or the y segments on flat ground)."""

ReachModel = Literal["kinematic", "paper"]
REACH_MODELS: tuple[str, ...] = ("kinematic", "paper")
BOUNDARY_POINTS: tuple[str, ...] = ("A", "B", "C", "D", "L", "R")
_SEGMENTS: tuple[tuple[str, str], ...] = (("A", "B"), ("B", "C"), ("C", "D"), ("D", "A"))
_TOL = 1e-9


@dataclass(frozen=True)
class ReachableRegion:
    """Approximate reachable region of one leg's foot on the terrain plane (body frame, m).

    Attributes:
        leg: leg name.
        status: ``"ok"`` or ``"no_reachable_ground"`` (then the points are H repeated).
        hip: B_i, the coxa-frame origin.
        lateral: unit r̂_HR (in the plane, ⊥ body x, towards the robot's right).
        hip_height: ‖B_iH‖ [m].
        points: H, R, L, A, B, C, D keyed by name (see the module docstring).
        model: the reach model used.
    """

    leg: str
    status: str
    hip: np.ndarray
    lateral: np.ndarray
    hip_height: float
    points: dict[str, np.ndarray] = field(repr=False)
    model: str

    @property
    def quadrilateral(self) -> np.ndarray:
        """(4, 3) corners A, B, C, D in boundary order."""
        return np.array([self.points[name] for name in "ABCD"])


@dataclass(frozen=True)
class FootholdChoice:
    """Target foothold of the adjustment leg (Zhang et al. 2024 §4.2).

    Attributes:
        status: ``"ok"``; ``"no_outside_foothold"`` (every reachable point lies inside the
            tipping axis, the least-inside one is returned); ``"no_reachable_ground"``
            (``foothold`` is None).
        leg: the adjustment leg.
        foothold: chosen target ^C P_tar (3,) in the body frame [m], or None.
        point: which boundary point was chosen ("A".."D", "L", "R"; "H" when the region
            collapses to H because ‖B_iH‖ = L_max), or None.
        reason: a sentence saying why.
        tipping_edge: the axis legs, counter-clockwise seen from above.
        axis_angle_deg: smallest angle between a boundary segment and the axis [deg] (nan when
            the region has no segment).
        distances: signed distance of H and every boundary point to the axis [m], > 0 outside.
        joints: [J_x, J_z, J_θ] that put the foot on ``foothold`` (None if no IK solution).
        within_joint_limits: whether ``joints`` respect the robot's joint ranges (the region is
            an approximation: on tilted ground the J_x shift also changes the leg length).
        region: the reachable region.
        plane: the fitted terrain plane.
    """

    status: str
    leg: str
    foothold: np.ndarray | None
    point: str | None
    reason: str
    tipping_edge: tuple[str, str]
    axis_angle_deg: float
    distances: dict[str, float]
    joints: np.ndarray | None
    within_joint_limits: bool
    region: ReachableRegion = field(repr=False)
    plane: Plane = field(repr=False)


def terrain_plane(stance_feet: Mapping[str, np.ndarray] | np.ndarray) -> Plane:
    """Least-squares terrain plane z = a x + b y + c through the stance feet (body frame)."""
    if isinstance(stance_feet, Mapping):
        stance_feet = np.array([np.asarray(p, float) for p in stance_feet.values()])
    return fit_plane(stance_feet)


def _check_common(leg: str, rho: float, model: str) -> None:
    if leg not in LEG_NAMES:
        raise ValueError(f"unknown leg {leg!r}; valid legs: {LEG_NAMES}")
    if not 0.0 < rho <= 1.0:
        raise ValueError(f"safety factor rho must lie in (0, 1], got {rho}")
    if model not in REACH_MODELS:
        raise ValueError(f"unknown reach model {model!r}; valid models: {REACH_MODELS}")


def _reachable_2d(y: float, z: float, l1: float, params: HeavyDutyParams) -> bool:
    """Is the point (0, y, z) of the coxa frame reachable with J_x = 0?"""
    try:
        joints = joints_from_coxa(np.array([0.0, y, z]), l1, params)
    except ValueError:
        return False
    return within_limits(joints, params, tol=1e-7)


def _kinematic_interval(
    h2: np.ndarray, u2: np.ndarray, l1: float, params: HeavyDutyParams
) -> tuple[float, float] | None:
    """Extreme reachable s of the line h2 + s u2 (leg-plane (y, z) coordinates, |u2| = 1)."""
    d_lo = params.k_z * params.j_z_range[0] + params.l2
    d_hi = params.k_z * params.j_z_range[1] + params.l2
    candidates = [0.0]
    hu = float(h2 @ u2)
    hh = float(h2 @ h2)
    for radius in (math.hypot(l1, d_hi), math.hypot(l1, d_lo)):
        disc = hu * hu - (hh - radius * radius)
        if disc >= 0.0:
            root = math.sqrt(disc)
            candidates += [-hu - root, -hu + root]
    for theta in params.j_theta_range:
        c, s = math.cos(theta), math.sin(theta)
        origin = l1 * np.array([c, s])
        w = np.array([s, -c])  # leg direction in the plane: q = L1 (c, s) + d (s, -c)
        mat = np.column_stack([u2, -w])
        if abs(np.linalg.det(mat)) > 1e-12:
            s_hit, _ = np.linalg.solve(mat, origin - h2)
            candidates.append(float(s_hit))
    reach = [s for s in candidates if _reachable_2d(*(h2 + s * u2), l1, params)]
    if not reach:
        return None
    return min(reach), max(reach)


def _paper_extent(h_dist: float, cos_beta: float, l_max: float, theta_max: float) -> float:
    """‖HR‖ of eq. (10) with the swing-angle clamp (angle at B_i limited to theta_max)."""
    cos_beta = max(-1.0, min(1.0, cos_beta))
    sin_beta = math.sqrt(1.0 - cos_beta * cos_beta)
    length = h_dist * cos_beta + math.sqrt(max(0.0, l_max**2 - (h_dist * sin_beta) ** 2))
    # Triangle with H at the origin, R on the +x axis, B_i at h_dist (cos β, sin β).
    bh = (-h_dist * cos_beta, -h_dist * sin_beta)
    br = (length - h_dist * cos_beta, -h_dist * sin_beta)
    angle_b = math.atan2(abs(bh[0] * br[1] - bh[1] * br[0]), bh[0] * br[0] + bh[1] * br[1])
    if angle_b > theta_max:
        # Law of sines with the angle at B_i clamped: ‖HR‖ / sin θ = ‖B_iH‖ / sin(π - β - θ).
        length = h_dist * math.sin(theta_max) / math.sin(math.acos(cos_beta) + theta_max)
    return length


def reachable_region(
    leg: str,
    plane: Plane,
    params: HeavyDutyParams | None = None,
    rho: float = RHO,
    model: ReachModel = "kinematic",
) -> ReachableRegion:
    """Approximate reachable region of ``leg``'s foot on ``plane`` (eqs. 10-13, body frame).

    Args:
        leg: leg name (LF..RR).
        plane: terrain plane in the body frame (e.g. :func:`terrain_plane`).
        params: robot parameters (default: the paper's robot).
        rho: safety factor ρ in (0, 1].
        model: ``"kinematic"`` (exact leg reach, default) or ``"paper"`` (eqs. 10-12 as printed).
    """
    params = params or HeavyDutyParams()
    _check_common(leg, rho, model)
    normal = np.asarray(plane.normal, float)
    hip = np.asarray(params.hip_offsets[leg], float)
    # H: hip projected along body z onto the plane (the plane is never vertical: n_z > 0).
    t = float((plane.point - hip) @ normal) / normal[2]
    h_point = hip + np.array([0.0, 0.0, t])
    h_dist = abs(t)
    lateral = np.cross([1.0, 0.0, 0.0], normal)
    lateral /= np.linalg.norm(lateral)
    l_max = params.max_leg_length

    def region(status: str, s_right: float, s_left: float, only_h: bool = False):
        right = h_point + s_right * lateral
        left = h_point + s_left * lateral
        proj = np.eye(3) - np.outer(normal, normal)
        front = rho * proj @ np.array([params.k_x * params.j_x_range[1], 0.0, 0.0])
        rear = rho * proj @ np.array([params.k_x * params.j_x_range[0], 0.0, 0.0])
        if status != "ok" or only_h:
            front = rear = np.zeros(3)
        points = {
            "H": h_point,
            "R": right,
            "L": left,
            "A": left + front,
            "B": left + rear,
            "C": right + rear,
            "D": right + front,
        }
        return ReachableRegion(leg, status, hip, lateral, h_dist, points, model)

    if t >= 0.0 or h_dist > l_max * (1.0 + _TOL):
        return region("no_reachable_ground", 0.0, 0.0)

    if model == "paper":
        if h_dist >= l_max * (1.0 - _TOL):
            return region("ok", 0.0, 0.0, only_h=True)  # ‖B_iH‖ = L_max: H is the target
        to_hip = (hip - h_point) / h_dist
        cos_beta_r = float(lateral @ to_hip)
        theta_lo, theta_hi = params.j_theta_range
        # Negative swing moves the foot towards -y (R side), positive towards +y (L side).
        hr = _paper_extent(h_dist, cos_beta_r, l_max, -theta_lo)
        hl = _paper_extent(h_dist, -cos_beta_r, l_max, theta_hi)
        return region("ok", rho * hr, -rho * hl)

    h2 = (h_point - hip)[1:]
    u2 = lateral[1:]
    interval = _kinematic_interval(h2, u2, params.signed_l1(leg), params)
    if interval is None:
        return region("no_reachable_ground", 0.0, 0.0)
    s_lo, s_hi = interval
    centre = 0.0 if s_lo - _TOL <= 0.0 <= s_hi + _TOL else 0.5 * (s_lo + s_hi)
    return region("ok", centre + rho * (s_hi - centre), centre + rho * (s_lo - centre))


def select_foothold(
    leg: str,
    stance_feet: Mapping[str, np.ndarray],
    tipping_edge: tuple[str, str],
    params: HeavyDutyParams | None = None,
    rho: float = RHO,
    angle_threshold_deg: float = AXIS_ANGLE_THRESHOLD_DEG,
    model: ReachModel = "kinematic",
    plane: Plane | None = None,
) -> FootholdChoice:
    """Target foothold of the adjustment leg ``leg`` (Zhang et al. 2024 §4.2, eq. 14).

    Args:
        leg: the adjustment leg (see :func:`agents.tipping.judgment.select_adjustment_leg`).
        stance_feet: body-frame positions [m] of the stance feet, keyed by leg (>= 3 feet, both
            tipping-edge legs among them).
        tipping_edge: the two effective support legs (either order; re-ordered
            counter-clockwise here from the geometry).
        params: robot parameters (default: the paper's robot).
        rho: safety factor ρ in (0, 1].
        angle_threshold_deg: segment-to-axis angle below which R or L is chosen [deg].
        model: reach model, see :func:`reachable_region`.
        plane: terrain plane; default: least-squares plane through ``stance_feet``.

    Returns:
        :class:`FootholdChoice`; no reachable ground is a status, not an exception.

    Raises:
        ValueError: bad leg names, an edge leg not among the stance feet, the adjustment leg in
            stance, fewer than 3 stance feet, or bad rho / model.
    """
    params = params or HeavyDutyParams()
    _check_foothold_inputs(leg, stance_feet, rho, model)
    edge = ccw_edge(*tipping_edge, tuple(stance_feet), stance_feet)
    plane = plane or terrain_plane(stance_feet)
    region = reachable_region(leg, plane, params, rho, model)
    p_i, axis = _tipping_axis(plane, stance_feet, edge)
    distances = _axis_distances(region.points, plane, p_i, axis)
    if region.status != "ok":
        return _no_ground_choice(leg, edge, distances, region, plane, params)
    angles = _segment_axis_angles(region.points, axis)
    axis_angle = min(angles.values()) if angles else math.nan
    best, why = _choose_point(
        region.points,
        distances,
        angles,
        angle_threshold_deg,
        edge_name=f"{edge[0]}-{edge[1]}",
        l_max=params.max_leg_length,
    )
    status = "ok"
    if distances[best] <= 0.0:
        status = "no_outside_foothold"
        why += "; no reachable point lies outside the axis, so the support polygon cannot grow"
    foothold = region.points[best].copy()
    joints, ok = _foothold_joints(leg, foothold, params)
    return FootholdChoice(
        status=status,
        leg=leg,
        foothold=foothold,
        point=best,
        reason=why,
        tipping_edge=edge,
        axis_angle_deg=axis_angle,
        distances=distances,
        joints=joints,
        within_joint_limits=ok,
        region=region,
        plane=plane,
    )


def _check_foothold_inputs(
    leg: str, stance_feet: Mapping[str, np.ndarray], rho: float, model: str
) -> None:
    """Raise ValueError for the inputs :func:`select_foothold` cannot use: a bad leg, rho or
    model, fewer than 3 stance feet (no terrain plane, no support polygon), or the adjustment
    leg itself among the stance feet (it is the leg being moved)."""
    _check_common(leg, rho, model)
    if len(stance_feet) < 3:
        raise ValueError(f"need at least 3 stance feet, got {sorted(stance_feet)}")
    if leg in stance_feet:
        raise ValueError(f"adjustment leg {leg} is listed among the stance feet")


def _tipping_axis(
    plane: Plane, stance_feet: Mapping[str, np.ndarray], edge: tuple[str, str]
) -> tuple[np.ndarray, np.ndarray]:
    """P'_i [m] and the unit direction P'_i -> P'_j of the tipping axis, with P'_i, P'_j the
    edge's feet projected onto ``plane`` (body frame); ``edge`` is counter-clockwise, so the
    support polygon lies on the axis's left."""
    p_i = plane.project(np.asarray(stance_feet[edge[0]], float))
    p_j = plane.project(np.asarray(stance_feet[edge[1]], float))
    return p_i, (p_j - p_i) / np.linalg.norm(p_j - p_i)


def _axis_distances(
    points: Mapping[str, np.ndarray], plane: Plane, p_i: np.ndarray, axis: np.ndarray
) -> dict[str, float]:
    """Signed distance [m] of H and every boundary point to the tipping axis through ``p_i``
    along the unit ``axis``, > 0 on its right, i.e. outside the support polygon.

    Eq. (14)'s Θ = (P'_i->X × P'_i->P'_j)·z, taken along the plane normal instead of body z so
    that it is a distance in the plane also on tilted ground.
    """
    normal = np.asarray(plane.normal, float)
    return {
        name: float(np.cross(points[name] - p_i, axis) @ normal) for name in ("H", *BOUNDARY_POINTS)
    }


def _segment_axis_angles(points: Mapping[str, np.ndarray], axis: np.ndarray) -> dict[str, float]:
    """Angle [deg, 0-90] between each boundary segment (AB, BC, CD, DA) and the unit tipping
    ``axis``, keyed "AB".."DA"; segments shorter than 1 nm (a collapsed region has no direction)
    are left out."""
    angles = {}
    for a, b in _SEGMENTS:
        seg = points[b] - points[a]
        length = np.linalg.norm(seg)
        if length > 1e-9:
            cos = min(1.0, abs(float(seg @ axis)) / length)
            angles[a + b] = math.degrees(math.acos(cos))
    return angles


def _choose_point(
    points: Mapping[str, np.ndarray],
    distances: Mapping[str, float],
    angles: Mapping[str, float],
    angle_threshold_deg: float,
    edge_name: str,
    l_max: float,
) -> tuple[str, str]:
    """§4.2's choice among the region's points, and the sentence that says why.

    A region collapsed to H (‖B_iH‖ = L_max, ``l_max`` [m]) leaves H; a boundary segment within
    ``angle_threshold_deg`` [deg] of the tipping axis (``angles``, see
    :func:`_segment_axis_angles`) leaves R or L, level with the hip (a shorter adjustment);
    otherwise every boundary point competes. Among the candidates the one farthest outside the
    axis wins (:func:`_farthest_outside`).
    """
    h_point = points["H"]
    if all(np.linalg.norm(points[n] - h_point) < 1e-9 for n in BOUNDARY_POINTS):
        return "H", (
            f"‖B_iH‖ = L_max = {l_max:.3f} m: the reachable region shrinks to H, "
            f"which is the target ({distances['H']:+.3f} m from the tipping axis {edge_name})"
        )
    axis_angle = min(angles.values()) if angles else math.nan
    if angles and axis_angle < angle_threshold_deg:
        best = _farthest_outside(points, distances, ("R", "L"))
        segment = min(angles, key=angles.get)
        return best, (
            f"segment {segment} makes {axis_angle:.1f}° (< {angle_threshold_deg:g}°) with the "
            f"tipping axis {edge_name}, so R or L is used; {best} lies "
            f"{distances[best]:+.3f} m from the axis"
        )
    best = _farthest_outside(points, distances, BOUNDARY_POINTS)
    return best, (
        f"every boundary segment makes >= {angle_threshold_deg:g}° with the tipping axis "
        f"{edge_name} ({axis_angle:.1f}° at least), so the boundary point farthest outside "
        f"the axis is used: {best} at {distances[best]:+.3f} m"
    )


def _farthest_outside(
    points: Mapping[str, np.ndarray], distances: Mapping[str, float], candidates: tuple[str, ...]
) -> str:
    """Name of the candidate point farthest outside the tipping axis: the largest signed
    distance, rounded to 1 nm so that equal distances tie; ties go to the point nearer to H (the
    shorter swing)."""
    h_point = points["H"]
    return max(
        candidates,
        key=lambda n: (round(distances[n], 9), -float(np.linalg.norm(points[n] - h_point))),
    )


def _foothold_joints(
    leg: str, foothold: np.ndarray, params: HeavyDutyParams
) -> tuple[np.ndarray | None, bool]:
    """[J_x, J_z, J_θ] that put ``leg``'s foot on ``foothold`` (body frame, m) and whether they
    lie within the joint ranges; (None, False) when no pose reaches it. The region is only an
    approximation of the reach (on tilted ground J_x also changes the leg length), hence the
    check."""
    try:
        joints = joints_for_foot(leg, foothold, params)
        return joints, within_limits(joints, params, tol=1e-7)
    except ValueError:
        return None, False


def _no_ground_choice(
    leg: str,
    edge: tuple[str, str],
    distances: dict[str, float],
    region: ReachableRegion,
    plane: Plane,
    params: HeavyDutyParams,
) -> FootholdChoice:
    """The :class:`FootholdChoice` without a foothold: the plane lies beyond the leg's reach
    (‖B_iH‖ > L_max, or no leg pose reaches it)."""
    return FootholdChoice(
        status="no_reachable_ground",
        leg=leg,
        foothold=None,
        point=None,
        reason=(
            f"no reachable ground: ‖B_iH‖ = {region.hip_height:.3f} m exceeds "
            f"L_max = {params.max_leg_length:.3f} m or no leg pose reaches the plane"
        ),
        tipping_edge=edge,
        axis_angle_deg=math.nan,
        distances=distances,
        joints=None,
        within_joint_limits=False,
        region=region,
        plane=plane,
    )
