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

from hexapod_envs.stability import _compiled
from hexapod_envs.stability._geometry import (
    hull_collinear_message,
    no_plane_message,
    points_array,
    vec3_array,
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
    pts = points_array(feet, "feet")
    k = len(pts)
    if k < 3:
        raise ValueError(f"FASM needs at least 3 feet in contact, got {k}")
    cog_v = vec3_array(cog, "cog")
    force_v = vec3_array(force, "force")
    moment_v = _NO_MOMENT if moment is None else vec3_array(moment, "moment")
    up_v = _NO_MOMENT if up is None else vec3_array(up, "up")
    status, angles, forces, edges, index = _compiled.fasm_edges(
        pts, cog_v, force_v, moment_v, up_v, up is not None
    )
    if status != _compiled.OK:
        raise ValueError(_error_message(status, index, edges, k))
    i, j = edges[index].tolist()
    return FasmResult(
        margin_deg=float(angles[index]),
        angles_deg=angles,
        edges=edges,
        edge=(i, j),
        edge_index=int(index),
        tipping_forces=forces,
    )


_NO_MOMENT = np.zeros(3)  # also the placeholder ``up`` when none is given (never written)
_INPUT_NAMES = ("feet", "cog", "force", "moment", "up")


def _error_message(status: int, index: int, edges: np.ndarray, k: int) -> str:
    """The ValueError message for a status of :func:`_compiled.fasm_edges`."""
    if status == _compiled.NOT_FINITE:
        return f"{_INPUT_NAMES[index]} contains NaN or infinite values"
    if status == _compiled.ZERO_FORCE:
        return (
            "the net destabilising force is zero, so the force angles are undefined; "
            "pass gravity + external + inertial force (e.g. (0, 0, -m*g))"
        )
    if status == _compiled.COG_ON_EDGE:
        i0, i1 = edges[index].tolist()
        return f"the CoG lies on the line of support edge ({i0}, {i1}); FASM is undefined there"
    if status == _compiled.ZERO_UP:
        return "up must be a non-zero vector"
    if status == _compiled.TRIANGLE_COLLINEAR:
        return "the 3 feet are collinear: they do not enclose a support polygon"
    if status == _compiled.NO_PLANE:
        return no_plane_message(k)
    return hull_collinear_message(k)


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
    status, margin, i, j = _compiled.fasm_from_feet(
        np.asarray(feet, dtype=float),
        np.asarray(forces, dtype=float),
        np.asarray(cog, dtype=float),
        np.asarray(loaded, dtype=bool),
    )
    if status == _compiled.OK:
        return margin, (i, j)
    if status == _compiled.NOT_FINITE:
        raise ValueError("foot forces, feet or CoG contain NaN or infinite values")
    return 0.0, None  # fewer than 3 loaded feet, collinear, or zero force: no polygon
