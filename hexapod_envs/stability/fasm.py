"""Force-Angle Stability Measure (FASM) of Papadopoulos & Rey, as used in Zhang et al. 2024 (eqs.
3-9).

For every edge of the support polygon the net destabilising force at the CoG and the net moment
(replaced by an equivalent force couple) are projected onto the plane normal to the edge; the
angle between that tipping force and the perpendicular from the CoG to the edge is the edge's
stability angle. It is positive while the force points inside the edge (stable), zero at the
tipping point and negative beyond it. The margin is the smallest angle over the edges.

Zhang et al. 2024's notation, for edge i with unit direction a_i (edges counter-clockwise seen from
above):

    l_i   = (I - a aᵀ)(p_{i+1} - p_G)          perpendicular from the CoG to the edge line
    f_i   = (I - a aᵀ) f_r                      force component that can tip about the edge
    n_i   = (a aᵀ) n_r                          moment component about the edge
    f_ni  = (l̂ × n_i) / ‖l_i‖                   force couple equivalent to n_i (note the ‖l‖)
    f*_i  = f_i + f_ni
    θ_i   = ±acos(f̂*·l̂), + when (l̂ × f̂*)·a > 0;  margin = min_i θ_i

f_ni is the force at the CoG whose moment about the edge equals n_i: (p_G - p) × f_ni has
a-component -(l × (l̂ × n_i))·a / ‖l‖ = a·n_r. Without the division by ‖l‖ (a bug found in public
code) the moment is scaled by the edge distance and the angle is wrong whenever n_r ≠ 0.

Implementation: f*_i lies in the plane normal to a, spanned by l̂ and t̂ = a × l̂, with
f*·l̂ = f_r·l̂ and f*·t̂ = f_r·t̂ - (a·n_r)/‖l‖ (because l̂ × a = -t̂). Hence, multiplying both by ‖l‖,

    θ_i = atan2(f_r·(a × l) - a·n_r,  f_r·l),

which equals the ±acos form with its sign rule ((l̂ × f̂*)·a = f̂*·t̂) and needs no clipping.
f_r·(a × l) - a·n_r is minus the moment of the destabilising wrench about the edge axis a, so
θ_i < 0 exactly when that wrench rolls the body over the edge.

Note on Zhang et al. 2024's printed eq. (8): it gives θ = +acos(l̂·f*) when (l̂·f*)·â < 0 and -acos
otherwise. As printed the condition multiplies a scalar by a vector (a dot where Papadopoulos &
Rey have a cross product); dropping the vector factor, it would make every angle with l̂·f* > 0
negative, i.e. call a robot standing upright unstable. This module uses Papadopoulos & Rey's rule,
+ when (l̂ × f̂*)·â > 0, with which the paper's own figures are reproduced (standing ≈ 48°,
31.41° at the tripod switch; see reports/reproduction.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hexapod_envs.stability._geometry import (
    REL_TOL,
    as_points,
    as_vec3,
    hull_3d,
    normal_and_centroid,
    unit,
)


@dataclass(frozen=True, slots=True)
class FasmResult:
    """Result of :func:`fasm`.

    Attributes:
        margin_deg: stability margin [deg] = smallest edge angle; > 0 stable, < 0 tipping.
        angles_deg: (m,) stability angle of every support-polygon edge [deg], edges in order.
        edges: (m, 2) edges of the support polygon as indices into ``feet`` as given,
            counter-clockwise seen from above; edge j runs from ``edges[j, 0]`` to ``edges[j, 1]``.
        edge: the edge attaining the margin, as ``(i, j)`` indices into ``feet`` (the tipping
            axis: the body would roll over the feet ``feet[i]``, ``feet[j]``).
        edge_index: position of ``edge`` in ``edges`` / ``angles_deg``.
        tipping_forces: (m,) magnitude of the tipping force f*_i of every edge [N] (the force
            weighting of Papadopoulos & Rey's original measure beta = theta * |f*|).
    """

    margin_deg: float
    angles_deg: np.ndarray
    edges: np.ndarray
    edge: tuple[int, int]
    edge_index: int
    tipping_forces: np.ndarray

    @property
    def margin_rad(self) -> float:
        """Stability margin [rad]."""
        return math.radians(self.margin_deg)


def fasm(feet, cog, force, moment=None, up=None) -> FasmResult:
    """Force-Angle Stability Measure of a body standing on ``feet`` (Zhang et al. 2024, eqs. 5-9).

    Args:
        feet: (k, 3) contact points [m], any order, k >= 3; their convex hull (seen from above)
            is the support polygon, points inside it or on its edges are ignored.
        cog: (3,) centre of gravity [m], same frame as ``feet``.
        force: (3,) net destabilising force on the body at the CoG [N]: gravity + external +
            inertial (-m a), i.e. minus the sum of the support forces (Zhang et al. 2024 eq. 4).
            Standing
            still under gravity only: ``m * g_vector``, e.g. ``(0, 0, -m * 9.81)``.
        moment: (3,) net destabilising moment about the CoG [N m] (gravity contributes none;
            external + inertial moments, = minus the support moments about the CoG). None: zero.
        up: the "above" direction used to find the hull and its counter-clockwise order.
            Default: normal of the least-squares plane through the feet, pointing to the side
            of the CoG. Give it explicitly when the CoG may lie in the plane of the feet.

    Returns:
        :class:`FasmResult` (margin and per-edge angles in degrees, edges as indices into
        ``feet`` as given).

    Raises:
        ValueError: fewer than 3 feet, feet collinear (seen from above), zero net force (the
            angle is undefined without a force), the CoG on the line of a support edge, or
            malformed / non-finite input. An edge whose tipping force vanishes (force along the
            edge and no moment about it) gets the angle 0 (critical) rather than an error.
    """
    pts = as_points(feet, "feet")
    k = len(pts)
    if k < 3:
        raise ValueError(f"FASM needs at least 3 feet in contact, got {k}")
    cog_v = as_vec3(cog, "cog")
    force_v = as_vec3(force, "force")
    moment_v = (0.0, 0.0, 0.0) if moment is None else as_vec3(moment, "moment")
    angles, forces, edges = _edge_angles(pts, cog_v, force_v, moment_v, up)
    margin = min(angles)
    index = angles.index(margin)
    return FasmResult(
        margin_deg=margin,
        angles_deg=np.array(angles),
        edges=np.array(edges, dtype=np.intp),
        edge=edges[index],
        edge_index=index,
        tipping_forces=np.array(forces),
    )


def _edge_angles(pts, cog, force, moment, up):
    """Per-edge angles [deg], tipping forces [N] and (i, j) edges on validated plain floats."""
    gx, gy, gz = cog
    fx, fy, fz = force
    nx, ny, nz = moment
    f_norm = math.sqrt(fx * fx + fy * fy + fz * fz)
    if f_norm == 0.0:
        raise ValueError(
            "the net destabilising force is zero, so the force angles are undefined; "
            "pass gravity + external + inertial force (e.g. (0, 0, -m*g))"
        )
    hull = _ordered_hull(pts, (gx, gy, gz), up)

    m = len(hull)
    angles = [0.0] * m
    forces = [0.0] * m
    edges = [(0, 0)] * m
    for j in range(m):
        i0 = hull[j]
        i1 = hull[j + 1] if j + 1 < m else hull[0]
        edges[j] = (i0, i1)
        p = pts[i0]
        q = pts[i1]
        ax, ay, az = q[0] - p[0], q[1] - p[1], q[2] - p[2]
        inv = 1.0 / math.sqrt(ax * ax + ay * ay + az * az)
        ax *= inv
        ay *= inv
        az *= inv
        # l = (I - a aᵀ)(p_{i+1} - p_G)
        wx, wy, wz = q[0] - gx, q[1] - gy, q[2] - gz
        t = wx * ax + wy * ay + wz * az
        lx, ly, lz = wx - t * ax, wy - t * ay, wz - t * az
        l_norm = math.sqrt(lx * lx + ly * ly + lz * lz)
        if l_norm <= REL_TOL * math.sqrt(wx * wx + wy * wy + wz * wz):
            raise ValueError(
                f"the CoG lies on the line of support edge ({i0}, {i1}); FASM is undefined there"
            )
        # Components of ‖l‖ f* along l̂ and t̂ = a × l̂.
        f_l = fx * lx + fy * ly + fz * lz
        f_t = (
            fx * (ay * lz - az * ly)
            + fy * (az * lx - ax * lz)
            + fz * (ax * ly - ay * lx)
            - (nx * ax + ny * ay + nz * az)
        )
        size = math.hypot(f_l, f_t)
        if size <= REL_TOL * (f_norm * l_norm + abs(nx * ax + ny * ay + nz * az)):
            angles[j] = 0.0  # no tipping force about this edge: critical, sign undefined
        else:
            angles[j] = math.degrees(math.atan2(f_t, f_l))
        forces[j] = size / l_norm

    return angles, forces, edges


def _ordered_hull(pts: list[list[float]], cog, up) -> list[int]:
    """Hull indices counter-clockwise seen from ``up`` (default: plane normal to the CoG side)."""
    gx, gy, gz = cog
    if up is not None:
        return hull_3d(pts, unit(as_vec3(up, "up"), "up"))
    if len(pts) == 3:
        # Triangle: the plane normal is the cross product; order so it points to the CoG side.
        p0, p1, p2 = pts
        ax, ay, az = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
        bx, by, bz = p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]
        nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
        size = ax * ax + ay * ay + az * az + bx * bx + by * by + bz * bz
        if math.sqrt(nx * nx + ny * ny + nz * nz) <= REL_TOL * size:
            raise ValueError("the 3 feet are collinear: they do not enclose a support polygon")
        side = (gx - p0[0]) * nx + (gy - p0[1]) * ny + (gz - p0[2]) * nz
        if side == 0.0:
            side = nz
        return [0, 1, 2] if side >= 0.0 else [0, 2, 1]
    (ux, uy, uz), (cx, cy, cz) = normal_and_centroid(pts)
    if (gx - cx) * ux + (gy - cy) * uy + (gz - cz) * uz < 0.0:
        ux, uy, uz = -ux, -uy, -uz
    return hull_3d(pts, (ux, uy, uz))


def fasm_from_feet(
    feet: np.ndarray, forces: np.ndarray, cog: np.ndarray, loaded: np.ndarray
) -> tuple[float, tuple[int, int] | None]:
    """FASM [deg] and its edge from measured foot forces, as a robot computes it online.

    `feet` (n, 3) contact points and `forces` (n, 3) ground reactions on the feet [N], in one
    frame with `cog`; `loaded` (n,) marks the feet that carry load. f_r and n_r are minus the
    measured support wrench about the CoG (Zhang et al. 2024 eq. 4). Returns (margin_deg, (i, j))
    with
    the edge as indices into `feet`, or (0, None) when the loaded feet span no support polygon
    (fewer than three, or collinear): the robot is at the tipping limit.
    """
    idx = [i for i, on in enumerate(loaded.tolist()) if on]
    if len(idx) < 3:
        return 0.0, None
    # Plain floats: at k <= 6 feet this is several times faster than numpy calls.
    all_p, all_f = feet.tolist(), forces.tolist()
    p = [all_p[i] for i in idx]
    cx, cy, cz = cog.tolist()
    fx = fy = fz = mx = my = mz = 0.0
    for i, (px, py, pz) in zip(idx, p, strict=True):
        gx, gy, gz = all_f[i]
        rx, ry, rz = px - cx, py - cy, pz - cz
        fx -= gx
        fy -= gy
        fz -= gz
        mx -= ry * gz - rz * gy
        my -= rz * gx - rx * gz
        mz -= rx * gy - ry * gx
    if not math.isfinite(fx + fy + fz + mx + my + mz + cx + cy + cz):
        raise ValueError("foot forces, feet or CoG contain NaN or infinite values")
    try:  # the inputs are plain floats already: skip fasm()'s array validation
        angles, _, edges = _edge_angles(p, (cx, cy, cz), (fx, fy, fz), (mx, my, mz), None)
    except ValueError:  # collinear feet or zero force: no polygon to stand on
        return 0.0, None
    margin = min(angles)
    i, j = edges[angles.index(margin)]
    return margin, (idx[i], idx[j])
