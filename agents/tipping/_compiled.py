"""Compiled kernels of the tipping recovery's control step (private; numba).

The force-distribution QP is rebuilt every control period on 3-6 stance feet, and the supported
phase around it (sensing, desired wrench, the force error's internal part, the servo offsets)
runs every period too; as Python and small numpy calls these took most of the step's time in
interpreter overhead. These ``numba.njit`` kernels do the same arithmetic in the same order:
plain-float formulas stay plain floats (numba does not fuse multiply-adds), and the matrix
products are ``np.dot`` calls, i.e. the BLAS routines numpy's ``@`` calls (numba binds them
through scipy's BLAS). Where numpy's and scipy's BLAS give the same bits, as they do for these
small products on the machines this was measured on, U, f, G, h and the controller's actions are
unchanged to the bit (tests/agents/tipping/test_tipping_force_distribution.py checks it against the
original assembly). The 6 x 6 solve stays numpy's LAPACK call (scipy's, reached from numba, differs
in the last bit for about 6 % of systems). Compiled on first use and cached on disk,
like :mod:`hexapod_envs.stability._compiled`. Kernels return status codes; the callers raise.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from hexapod_envs.stability._compiled import centred_moments, finite, fit_plane, hull_up

OK = 0
COG_NOT_ABOVE = 1  # the CoG is not above the support plane
COG_ON_EDGE = 2  # the CoG lies on a support edge's line
HULL_COLLINEAR = 3  # the feet are collinear seen along the normal
NOT_FINITE = 4  # feet, CoG or wrench contain NaN or inf
NO_PLANE = 5  # no plane fits the feet (their x, y collinear or coincident)

_INV_SQRT2 = 1.0 / math.sqrt(2.0)


@njit(cache=True)
def wrench_map(feet, cog):
    """A = [[E ... E], [[P_1]x ... [P_k]x]] (6, 3k) of eq. (17), P_j = feet[j] - cog."""
    k = feet.shape[0]
    a = np.zeros((6, 3 * k))
    for j in range(k):
        x, y, z = feet[j, 0] - cog[0], feet[j, 1] - cog[1], feet[j, 2] - cog[2]
        c = 3 * j
        a[0, c] = a[1, c + 1] = a[2, c + 2] = 1.0
        a[3, c + 1], a[3, c + 2] = -z, y
        a[4, c], a[4, c + 2] = z, -x
        a[5, c], a[5, c + 1] = -y, x
    return a


@njit(cache=True)
def _unit3(x, y, z):
    n = math.sqrt(x * x + y * y + z * z)
    return x / n, y / n, z / n


@njit(cache=True)
def project_feet(feet, normal):
    """(feet projected onto the plane through their centroid, unit normal) for any ``normal``."""
    n0, n1, n2 = _unit3(normal[0], normal[1], normal[2])
    k = feet.shape[0]
    centroid, _ = centred_moments(feet)
    c0, c1, c2 = centroid[0], centroid[1], centroid[2]
    proj = np.empty((k, 3))
    for i in range(k):
        r0, r1, r2 = feet[i, 0], feet[i, 1], feet[i, 2]
        h = (r0 - c0) * n0 + (r1 - c1) * n1 + (r2 - c2) * n2
        proj[i, 0], proj[i, 1], proj[i, 2] = r0 - h * n0, r1 - h * n1, r2 - h * n2
    return proj, np.array((n0, n1, n2))


@njit(cache=True)
def cone_geometry(proj, cog, normal, cone_ratio, hull):
    """Eqs. (21)-(22) and (24) for feet ``proj`` already in the terrain plane (unit ``normal``).

    Returns (status, values (31,), d_min, radius) with values = G_s (3), T_1..T_4 (12),
    tan α_1..α_4 (4), pyramid faces (12); ``hull`` holds the support polygon's vertex indices
    counter-clockwise from +normal.
    """
    n0, n1, n2 = normal[0], normal[1], normal[2]
    m = hull.shape[0]
    values = np.empty(31)
    # Area centroid by a triangle fan (the polygon is convex).
    p0 = hull[0]
    x0, y0, z0 = proj[p0, 0], proj[p0, 1], proj[p0, 2]
    gx = gy = gz = total = 0.0
    for j in range(1, m - 1):
        p1, p2 = hull[j], hull[j + 1]
        x1, y1, z1 = proj[p1, 0], proj[p1, 1], proj[p1, 2]
        x2, y2, z2 = proj[p2, 0], proj[p2, 1], proj[p2, 2]
        ux, uy, uz = x1 - x0, y1 - y0, z1 - z0
        vx, vy, vz = x2 - x0, y2 - y0, z2 - z0
        area = 0.5 * (
            (uy * vz - uz * vy) * n0 + (uz * vx - ux * vz) * n1 + (ux * vy - uy * vx) * n2
        )
        total += area
        gx += area * (x0 + x1 + x2)
        gy += area * (y0 + y1 + y2)
        gz += area * (z0 + z1 + z2)
    s0, s1, s2 = gx / (3.0 * total), gy / (3.0 * total), gz / (3.0 * total)
    # Eq. (21): distance from G_s to each edge line.
    d_min = math.inf
    for j in range(m):
        pa, pb = hull[j], hull[(j + 1) % m]
        ax, ay, az = proj[pa, 0], proj[pa, 1], proj[pa, 2]
        ex, ey, ez = proj[pb, 0] - ax, proj[pb, 1] - ay, proj[pb, 2] - az
        en = math.sqrt(ex * ex + ey * ey + ez * ez)
        ex, ey, ez = ex / en, ey / en, ez / en
        wx, wy, wz = ax - s0, ay - s1, az - s2
        t = wx * ex + wy * ey + wz * ez
        px, py, pz = wx - t * ex, wy - t * ey, wz - t * ez
        d_min = min(d_min, math.sqrt(px * px + py * py + pz * pz))
    radius = cone_ratio * d_min
    ex0, ex1, ex2 = _unit3(1.0 - n0 * n0, -n0 * n1, -n0 * n2)
    ey0, ey1, ey2 = n1 * ex2 - n2 * ex1, n2 * ex0 - n0 * ex2, n0 * ex1 - n1 * ex0
    values[0], values[1], values[2] = s0, s1, s2
    # T_1..T_4 along +e_x, +e_y, -e_x, -e_y (radius * 1.0 and * -1.0, as the original).
    for j in range(4):
        r = radius * (1.0 if j < 2 else -1.0)
        d0, d1, d2 = (ex0, ex1, ex2) if j % 2 == 0 else (ey0, ey1, ey2)
        values[3 + 3 * j] = s0 + r * d0
        values[4 + 3 * j] = s1 + r * d1
        values[5 + 3 * j] = s2 + r * d2
    q0, q1, q2 = cog[0], cog[1], cog[2]
    a0, a1, a2 = s0 - q0, s1 - q1, s2 - q2  # cone axis CoG -> G_s
    if a0 * n0 + a1 * n1 + a2 * n2 >= 0.0:
        return COG_NOT_ABOVE, values, d_min, radius
    for j in range(4):
        b0, b1, b2 = values[3 + 3 * j] - q0, values[4 + 3 * j] - q1, values[5 + 3 * j] - q2
        r0, r1, r2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
        values[15 + j] = math.sqrt(r0 * r0 + r1 * r1 + r2 * r2) / abs(b0 * a0 + b1 * a1 + b2 * a2)
    h0, h1, h2 = _unit3(a0, a1, a2)  # ĝ, unit cone axis
    eg = ex0 * h0 + ex1 * h1 + ex2 * h2
    f0, f1, f2 = _unit3(ex0 - eg * h0, ex1 - eg * h1, ex2 - eg * h2)  # e_1
    e0, e1, e2 = f1 * h2 - f2 * h1, f2 * h0 - f0 * h2, f0 * h1 - f1 * h0  # e_2 = e_1 × ĝ
    # faces = S_Mᵀ Qᵀ with Q = [e1 e2 -ĝ]: row j = s_1j e_1 + s_2j e_2 - (tan α_j/√2) ĝ, with
    # (s_1j, s_2j) = (1, 0), (0, 1), (-1, 0), (0, -1) (multiplied out: zeros keep their sign).
    for j in range(4):
        u = 1.0 if j == 0 else -1.0 if j == 2 else 0.0
        v = 1.0 if j == 1 else -1.0 if j == 3 else 0.0
        tr = values[15 + j] * _INV_SQRT2
        values[19 + 3 * j] = u * f0 + v * e0 - tr * h0
        values[20 + 3 * j] = u * f1 + v * e1 - tr * h1
        values[21 + 3 * j] = u * f2 + v * e2 - tr * h2
    return OK, values, d_min, radius


@njit(cache=True)
def tipping_terms(feet, cog, edges):
    """Per support edge, I - a aᵀ and the couple term (l̂ × a) aᵀ / ‖l‖ of eq. (20).

    Returns (status, index of the offending edge, ima (m, 3, 3), couple (m, 3, 3)), from which
    :func:`tipping_products` forms V_i.
    """
    m = edges.shape[0]
    q0, q1, q2 = cog[0], cog[1], cog[2]
    ima = np.empty((m, 3, 3))
    couple = np.empty((m, 3, 3))
    for e in range(m):
        i0, i1 = edges[e, 0], edges[e, 1]
        w0, w1, w2 = feet[i1, 0], feet[i1, 1], feet[i1, 2]
        a0, a1, a2 = w0 - feet[i0, 0], w1 - feet[i0, 1], w2 - feet[i0, 2]
        an = math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
        a0, a1, a2 = a0 / an, a1 / an, a2 / an
        w0, w1, w2 = w0 - q0, w1 - q1, w2 - q2
        t = w0 * a0 + w1 * a1 + w2 * a2
        l0, l1, l2 = w0 - t * a0, w1 - t * a1, w2 - t * a2
        l_norm = math.sqrt(l0 * l0 + l1 * l1 + l2 * l2)
        if l_norm < 1e-9 * max(1.0, abs(w0), abs(w1), abs(w2)):
            return COG_ON_EDGE, e, ima, couple
        a = (a0, a1, a2)
        for r in range(3):
            for c in range(3):
                ima[e, r, c] = (1.0 if r == c else 0.0) - a[r] * a[c]  # 0.0 - v keeps +0.0
        # [l̂]x (a aᵀ) / ‖l‖ = (l̂ × a) aᵀ / ‖l‖
        x = (l1 * a2 - l2 * a1, l2 * a0 - l0 * a2, l0 * a1 - l1 * a0)
        inv = 1.0 / (l_norm * l_norm)
        for r in range(3):
            for c in range(3):
                couple[e, r, c] = x[r] * a[c] * inv
    return OK, -1, ima, couple


@njit(cache=True)
def tangent_frame(normal):
    """(3, 3) rows t_1, t_2, n: t_1 the body x axis projected on the plane of unit ``normal``
    (the y axis when x is within 1e-6 of the normal), t_2 = n × t_1."""
    n0, n1, n2 = normal[0], normal[1], normal[2]
    x, y, z = 1.0 - n0 * n0, -n0 * n1, -n0 * n2
    if math.sqrt(x * x + y * y + z * z) < 1e-6:
        x, y, z = -n1 * n0, 1.0 - n1 * n1, -n1 * n2
    x, y, z = _unit3(x, y, z)
    frame = np.empty((3, 3))
    frame[0, 0], frame[0, 1], frame[0, 2] = x, y, z
    frame[1, 0], frame[1, 1], frame[1, 2] = n1 * z - n2 * y, n2 * x - n0 * z, n0 * y - n1 * x
    frame[2, 0], frame[2, 1], frame[2, 2] = n0, n1, n2
    return frame


@njit(cache=True)
def qp_geometry(feet, cog, wrench, normal, fit_normal, cone_ratio, with_cone):
    """Everything geometric of one QP build, in one call (see ForceDistributor.build).

    Checks that ``feet``, ``cog`` and ``wrench`` are finite; ``normal`` is the terrain's unit
    up-normal, or with ``fit_normal`` the least-squares plane's through the feet (``normal`` is
    then ignored). Returns (status, detail, normal (3,), A (6, 3k), tangent frame (3, 3) (see
    :func:`tangent_frame`), hull (m,), edges (m, 2), cone values (31,), d_min, radius, ima
    (m, 3, 3), couple (m, 3, 3)); without the cone the last five are placeholders. ``detail``
    is the offending edge's index for COG_ON_EDGE.
    """
    if not (finite(feet.ravel()) and finite(cog) and finite(wrench)):
        return _failed(NOT_FINITE, feet, normal)
    if fit_normal:
        fitted, _, normal, _ = fit_plane(feet)
        if fitted != OK:
            return _failed(NO_PLANE, feet, normal)
    a_mat = wrench_map(feet, cog)
    frame = tangent_frame(normal)
    hull = hull_up(feet, np.array(_unit3(normal[0], normal[1], normal[2])))
    m = hull.shape[0]
    edges = np.empty((m, 2), dtype=np.int64)
    values = np.empty(31)
    ima = np.empty((m, 3, 3))
    couple = np.empty((m, 3, 3))
    if m < 3:
        return HULL_COLLINEAR, -1, normal, a_mat, frame, hull, edges, values, 0.0, 0.0, ima, couple
    for j in range(m):
        edges[j, 0] = hull[j]
        edges[j, 1] = hull[j + 1] if j + 1 < m else hull[0]
    if not with_cone:
        return OK, -1, normal, a_mat, frame, hull, edges, values, 0.0, 0.0, ima, couple
    proj, unit_normal = project_feet(feet, normal)
    status, values, d_min, radius = cone_geometry(proj, cog, unit_normal, cone_ratio, hull)
    if status != OK:
        return status, -1, normal, a_mat, frame, hull, edges, values, d_min, radius, ima, couple
    status, bad, ima, couple = tipping_terms(feet, cog, edges)
    return status, bad, normal, a_mat, frame, hull, edges, values, d_min, radius, ima, couple


@njit(cache=True)
def tipping_products(ima, couple, moment_rows):
    """V_e = couple_e [[P_1]x ... [P_k]x] + [I - a aᵀ ... I - a aᵀ] (m, 3, 3k) of eq. (20) for
    every edge e, from :func:`tipping_terms` and the wrench map's moment rows (3, 3k)."""
    m, k3 = couple.shape[0], moment_rows.shape[1]
    rows = np.ascontiguousarray(moment_rows)
    v_all = np.empty((m, 3, k3))
    for e in range(m):
        v = np.dot(couple[e], rows)
        for r in range(3):
            for c in range(k3):
                v[r, c] += ima[e, r, c % 3]
        v_all[e] = v
    return v_all


@njit(cache=True)
def qp_problem(
    feet,
    cog,
    wrench,
    normal,
    fit_normal,
    cone_ratio,
    with_cone,
    weights,
    unit_weights,
    reg,
    pyramid,
    min_normal_force,
):
    """One whole QP build (see ForceDistributor.build): :func:`qp_geometry` and the matrices.

    ``normal`` is made a unit vector unless ``fit_normal``. ``weights`` is S as a (6, 1)
    column (``unit_weights``: all ones), ``reg`` is 2κW (3k, 3k), ``pyramid`` the (4, 3)
    friction rows in the tangent frame. Returns (status, detail, normal, A, hull, edges, cone
    values, d_min, radius, scale, U, f, G, h); past a failed status the last five are
    placeholders. The products follow the former numpy expressions (see the
    module docstring).
    """
    if not fit_normal:  # the given normal, made a unit vector
        normal = np.array(_unit3(normal[0], normal[1], normal[2]))
    status, bad, normal, a_mat, frame, hull, edges, values, d_min, radius, ima, couple = (
        qp_geometry(feet, cog, wrench, normal, fit_normal, cone_ratio, with_cone)
    )
    k, m = feet.shape[0], hull.shape[0]
    rows = 5 * k + (4 * m if with_cone else 0)
    g_mat = np.zeros((rows, 3 * k))
    h_vec = np.zeros(rows)
    if status != OK:
        empty = np.empty((0, 0))
        return (
            *(status, bad, normal, a_mat, hull, edges, values, d_min, radius),
            *(0.0, empty, np.empty(0), g_mat, h_vec),
        )
    force = wrench[:3]
    scale = max(math.sqrt(np.dot(force, force)), k * min_normal_force, 1.0)
    sa = a_mat if unit_weights else weights * a_mat  # 1.0 * v is v exactly
    u_mat = np.dot(2.0 * a_mat.T, sa) + reg
    f_vec = np.dot(-2.0 * sa.T, wrench / scale)
    # G: per foot its normal row (-n), then its four friction rows; then 4 rows per edge.
    friction_rows = np.dot(pyramid, frame)  # frame rows t1, t2, n
    for i in range(k):
        c = 3 * i
        for j in range(3):
            g_mat[i, c + j] = -normal[j]
            for r in range(4):
                g_mat[k + 4 * i + r, c + j] = friction_rows[r, j]
        h_vec[i] = -min_normal_force / scale
    if with_cone:
        # faces · f*_e <= 0 with f*_e = -V_e x: rows -(faces @ V_e), edge by edge.
        v_all = tipping_products(ima, couple, a_mat[3:])
        faces = np.ascontiguousarray(values[19:31]).reshape(4, 3)
        for e in range(m):
            cone_rows = np.dot(faces, v_all[e])
            for r in range(4):
                for c in range(3 * k):
                    g_mat[5 * k + 4 * e + r, c] = -cone_rows[r, c]
    return (
        *(status, bad, normal, a_mat, hull, edges, values, d_min, radius),
        *(scale, u_mat, f_vec, g_mat, h_vec),
    )


@njit(cache=True)
def qp_outcome(g_mat, h_vec, x_scaled, scale, a_mat, wrench):
    """What ForceDistributor.solve_qp reports of a scaled solution: (slack of every constraint
    [N], largest violation [N], forces x (3k,) [N], their wrench A x, its residual A x - b)."""
    slack = (h_vec - np.dot(g_mat, x_scaled)) * scale
    violation = max(0.0, -slack.min())
    x = x_scaled * scale
    achieved = np.dot(a_mat, x)
    return slack, violation, x, achieved, achieved - wrench


@njit(cache=True)
def _failed(status, feet, normal):
    """qp_geometry's result for inputs it refuses: ``status`` and empty placeholders."""
    a_mat = np.zeros((6, 3 * feet.shape[0]))
    hull = np.empty(0, dtype=np.int64)
    edges = np.empty((0, 2), dtype=np.int64)
    terms = np.empty((0, 3, 3))
    return (
        status,
        -1,
        normal,
        a_mat,
        np.zeros((3, 3)),
        hull,
        edges,
        np.empty(31),
        0.0,
        0.0,
        terms,
        terms,
    )


@njit(cache=True)
def body_feet_and_cog(joints, hips, l1, consts, hip_sums):
    """(feet (6, 3), CoG (3,)) in the body frame from the (6, 3) encoder readings (see
    HeavyDutyBodyModel.feet_and_cog, which packs ``consts``: k_x, k_z, L2, the moving links'
    mass, the mass weighting the hip distance, the carriage's fixed mass moment, shank mass and
    centre, foot mass and centre, leg mass, total mass)."""
    k_x, k_z, l2, m_moving, y_mass, z_fixed, m_shank, shank_up, m_foot, foot_up, m_leg, total = (
        consts
    )
    feet = np.empty((6, 3))
    sum_x = sum_y = sum_z = 0.0
    for i in range(6):
        c, s = math.cos(joints[i, 2]), math.sin(joints[i, 2])
        x = k_x * joints[i, 0]
        d = k_z * joints[i, 1] + l2
        feet[i, 0] = hips[i, 0] + x
        feet[i, 1] = hips[i, 1] + (l1[i] * c + d * s)
        feet[i, 2] = hips[i, 2] + (l1[i] * s - d * c)
        # Mass moment of the leg's links in its (unrotated) leg plane, rotated by the swing
        # angle (the rotation is linear, so it commutes with the weighted sum).
        y = y_mass * l1[i]
        z = z_fixed + m_shank * (shank_up - d) + m_foot * (foot_up - d)
        sum_x += x
        sum_y += y * c - z * s
        sum_z += y * s + z * c
    cog = np.empty(3)
    cog[0] = (m_leg * hip_sums[0] + m_moving * sum_x) / total
    cog[1] = (m_leg * hip_sums[1] + sum_y) / total
    cog[2] = (m_leg * hip_sums[2] + sum_z) / total
    return feet, cog


@njit(cache=True)
def servo_change_for_force(joints, delta_force, legs, l1, k_z, l2, stiffness, joint_scale):
    """(n, 3) servo target changes [ΔJ_x, ΔJ_z, ΔJ_θ] that add ``delta_force`` (n, 3) to the
    feet of ``legs`` (see HeavyDutyBodyModel.target_change_for_force): Jᵀ ΔF per leg with J's
    zero entries multiplied in (as the einsum it replaces did), then -K⁻¹ and the joint scale."""
    n = legs.shape[0]
    out = np.empty((n, 3))
    for r in range(n):
        leg = legs[r]
        fx, fy, fz = delta_force[r, 0], delta_force[r, 1], delta_force[r, 2]
        c, s = math.cos(joints[leg, 2]), math.sin(joints[leg, 2])
        d = k_z * joints[leg, 1] + l2
        g_x = 1.0 * fx + 0.0 * fy + 0.0 * fz
        g_d = 0.0 * fx + s * fy + -c * fz
        g_t = 0.0 * fx + (-l1[leg] * s + d * c) * fy + (l1[leg] * c + d * s) * fz
        out[r, 0] = (-g_x / stiffness[0]) / joint_scale[0]
        out[r, 1] = (-g_d / stiffness[1]) / joint_scale[1]
        out[r, 2] = (-g_t / stiffness[2]) / joint_scale[2]
    return out


@njit(cache=True)
def force_error_system(planned, measured, a_mat):
    """The force error e = planned - measured as (3k,) [N] and the system (A Aᵀ, A e) whose
    solution y gives e's wrench part Aᵀ y (see TippingRecoveryController._supported)."""
    error = (planned - measured).ravel()
    return error, np.dot(a_mat, a_mat.T), np.dot(a_mat, error)


@njit(cache=True)
def internal_part(error, a_mat, y):
    """e - Aᵀ y: the part of the force error that leaves the support wrench unchanged."""
    return error - np.dot(a_mat.T, y)


@njit(cache=True)
def add_offsets(offsets, legs, change, gain, max_offset):
    """offsets[legs] = clip(offsets[legs] + gain change, ±max_offset), in place (the numpy
    expression's operations, without its fancy-index copies)."""
    for i in range(legs.shape[0]):
        leg = legs[i]
        for j in range(3):
            value = offsets[leg, j] + gain * change[i, j]
            offsets[leg, j] = np.minimum(np.maximum(value, -max_offset[j]), max_offset[j])


@njit(cache=True)
def offset_targets(targets, nominal, offsets, legs):
    """targets[legs] = nominal[legs] + offsets[legs], in place."""
    for i in range(legs.shape[0]):
        leg = legs[i]
        for j in range(3):
            targets[leg, j] = nominal[leg, j] + offsets[leg, j]


@njit(cache=True)
def rotation_from_quat(quat):
    """Rotation matrix (body -> world) of the quaternion (w, x, y, z) divided by its norm² (see
    `body_model.quat_to_matrix`, which checks the norm)."""
    w, x, y, z = quat[0], quat[1], quat[2], quat[3]
    s = 2.0 / (w * w + x * x + y * y + z * z)
    rot = np.empty((3, 3))
    rot[0, 0] = 1.0 - s * (y * y + z * z)
    rot[0, 1] = s * (x * y - w * z)
    rot[0, 2] = s * (x * z + w * y)
    rot[1, 0] = s * (x * y + w * z)
    rot[1, 1] = 1.0 - s * (x * x + z * z)
    rot[1, 2] = s * (y * z - w * x)
    rot[2, 0] = s * (x * z - w * y)
    rot[2, 1] = s * (y * z + w * x)
    rot[2, 2] = 1.0 - s * (x * x + y * y)
    return rot


@njit(cache=True)
def body_sensing(quat, foot_forces, contact_sq):
    """(rotation body -> world (3, 3), foot forces in the body frame (6, 3) [N], loaded (6,))
    from the IMU quaternion (w, x, y, z) and the world-frame foot forces: the arithmetic of
    ``quat_to_matrix``, ``forces_to_body`` and the controller's contact test (|f|² above
    ``contact_sq``) in one call. The caller checks the quaternion."""
    rot = rotation_from_quat(quat)
    forces = np.dot(np.ascontiguousarray(foot_forces), rot)
    loaded = np.empty(forces.shape[0], dtype=np.bool_)
    for i in range(forces.shape[0]):
        f0, f1, f2 = forces[i, 0], forces[i, 1], forces[i, 2]
        loaded[i] = f0 * f0 + f1 * f1 + f2 * f2 > contact_sq
    return rot, forces, loaded


@njit(cache=True)
def newton_euler_wrench(mass, inertia, gravity, accel, omega, omega_dot):
    """[m (a - g), I ω̇ + ω × I ω] (6,): the arithmetic of ``desired_wrench`` in one call."""
    i_omega = np.dot(inertia, omega)
    i_omega_dot = np.dot(inertia, omega_dot)
    w0, w1, w2 = omega[0], omega[1], omega[2]
    out = np.empty(6)
    for j in range(3):
        out[j] = mass * (accel[j] - gravity[j])
    out[3] = i_omega_dot[0] + (w1 * i_omega[2] - w2 * i_omega[1])
    out[4] = i_omega_dot[1] + (w2 * i_omega[0] - w0 * i_omega[2])
    out[5] = i_omega_dot[2] + (w0 * i_omega[1] - w1 * i_omega[0])
    return out
