"""The force-distribution QP's assembly as it was before the speed-up of issue 14 (test only).

A verbatim copy of ``stability_cone``, ``tipping_force_matrices`` and ``ForceDistributor.build``
at commit 911f01b, kept so that tests/agents/tipping/test_tipping_force_distribution.py can check
that the faster assembly gives bit-identical U, f, G, h (and hence forces) on random cases. Not
used by the package. ``reference_build(distributor, feet, cog, wrench, normal)`` is the old method.
"""

from __future__ import annotations

import math

import numpy as np

from agents.tipping.force_distribution import ForceQp, StabilityCone
from hexapod_envs.stability import fit_plane, support_polygon


def _v_unit(a):
    n = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    return (a[0] / n, a[1] / n, a[2] / n)


def _v_sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _v_dot(a, b) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _v_cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def stability_cone(feet, cog, normal, cone_ratio, hull=None):
    """Old stability_cone."""
    feet = np.asarray(feet, dtype=float)
    cog_arr = np.asarray(cog, dtype=float)
    n = _v_unit(np.asarray(normal, dtype=float).tolist())
    rows = feet.tolist()
    k = len(rows)
    centre = (
        sum(r[0] for r in rows) / k,
        sum(r[1] for r in rows) / k,
        sum(r[2] for r in rows) / k,
    )
    proj = []
    for r in rows:
        h = _v_dot(_v_sub(r, centre), n)
        proj.append((r[0] - h * n[0], r[1] - h * n[1], r[2] - h * n[2]))
    if hull is None:
        hull = support_polygon(np.array(proj), up=np.array(n))
    poly = [proj[i] for i in np.asarray(hull).tolist()]
    m = len(poly)
    # Area centroid by a triangle fan (the polygon is convex).
    p0 = poly[0]
    gx = gy = gz = total = 0.0
    for j in range(1, m - 1):
        p1, p2 = poly[j], poly[j + 1]
        area = 0.5 * _v_dot(_v_cross(_v_sub(p1, p0), _v_sub(p2, p0)), n)
        total += area
        gx += area * (p0[0] + p1[0] + p2[0])
        gy += area * (p0[1] + p1[1] + p2[1])
        gz += area * (p0[2] + p1[2] + p2[2])
    g_s = (gx / (3.0 * total), gy / (3.0 * total), gz / (3.0 * total))
    # Eq. (21): distance from G_s to each edge line.
    d_min = math.inf
    for j in range(m):
        a, b = poly[j], poly[(j + 1) % m]
        e = _v_unit(_v_sub(b, a))
        w = _v_sub(a, g_s)
        t = _v_dot(w, e)
        perp = (w[0] - t * e[0], w[1] - t * e[1], w[2] - t * e[2])
        d_min = min(d_min, math.sqrt(_v_dot(perp, perp)))
    radius = cone_ratio * d_min
    ex = _v_unit((1.0 - n[0] * n[0], -n[0] * n[1], -n[0] * n[2]))
    ey = _v_cross(n, ex)
    base = [
        tuple(g_s[i] + radius * sign * v[i] for i in range(3))
        for sign, v in ((1.0, ex), (1.0, ey), (-1.0, ex), (-1.0, ey))
    ]
    c = tuple(cog_arr.tolist())
    axis = _v_sub(g_s, c)
    if _v_dot(axis, n) >= 0.0:
        raise ValueError(f"the CoG {cog_arr} is not above the support plane (normal {n})")
    tan_alpha = []
    for t_point in base:
        to_t = _v_sub(t_point, c)
        cr = _v_cross(axis, to_t)
        tan_alpha.append(math.sqrt(_v_dot(cr, cr)) / abs(_v_dot(to_t, axis)))
    g_hat = _v_unit(axis)
    eg = _v_dot(ex, g_hat)
    e1 = _v_unit((ex[0] - eg * g_hat[0], ex[1] - eg * g_hat[1], ex[2] - eg * g_hat[2]))
    e2 = _v_cross(e1, g_hat)
    r2 = 1.0 / math.sqrt(2.0)
    # faces = S_Mᵀ Qᵀ with Q = [e1 e2 -g_hat]: row j = s_1j e1 + s_2j e2 - (tan α_j/√2) g_hat.
    s12 = ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))
    faces = np.array(
        [
            [a * e1[i] + b * e2[i] - ta * r2 * g_hat[i] for i in range(3)]
            for (a, b), ta in zip(s12, tan_alpha, strict=True)
        ]
    )
    return StabilityCone(
        cog_arr.copy(),
        np.array(g_s),
        d_min,
        radius,
        np.array(base),
        np.array(tan_alpha),
        faces,
    )


def _moment_rows(rel):
    """Old _moment_rows."""
    k = len(rel)
    out = np.zeros((3, k, 3))
    x, y, z = rel[:, 0], rel[:, 1], rel[:, 2]
    out[0, :, 1], out[0, :, 2] = -z, y
    out[1, :, 0], out[1, :, 2] = z, -x
    out[2, :, 0], out[2, :, 1] = -y, x
    return out.reshape(3, 3 * k)


def tipping_force_matrices(feet, cog, edges, moment_rows=None):
    """Old tipping_force_matrices."""
    feet = np.asarray(feet, dtype=float)
    cog = np.asarray(cog, dtype=float)
    edges = np.asarray(edges)
    k = len(feet)
    if moment_rows is None:
        moment_rows = _moment_rows(feet - cog)
    rows = feet.tolist()
    c = cog.tolist()
    m = len(edges)
    aa = np.empty((m, 3, 3))
    couple = np.empty((m, 3, 3))
    for i, (e0, e1) in enumerate(edges.tolist()):
        a = _v_unit(_v_sub(rows[e1], rows[e0]))
        w = _v_sub(rows[e1], c)
        t = _v_dot(w, a)
        lv = (w[0] - t * a[0], w[1] - t * a[1], w[2] - t * a[2])
        l_norm = math.sqrt(_v_dot(lv, lv))
        if l_norm < 1e-9 * max(1.0, abs(w[0]), abs(w[1]), abs(w[2])):
            raise ValueError(f"the CoG lies on the line of support edge {(e0, e1)}")
        outer = [[a[r] * a[s] for s in range(3)] for r in range(3)]
        aa[i] = outer
        # [l̂]x (a aᵀ) / ‖l‖ = (l̂ × a) aᵀ / ‖l‖
        la = _v_cross(lv, a)
        inv = 1.0 / (l_norm * l_norm)
        couple[i] = [[la[r] * a[s] * inv for s in range(3)] for r in range(3)]
    out = couple @ moment_rows  # (m, 3, 3k)
    # + [I - a aᵀ ... I - a aᵀ], added per foot block in place (np.tile cost a copy).
    out.reshape(m, 3, k, 3)[...] += (np.eye(3) - aa)[:, :, None, :]
    return out


def _old_constants(k: int, cfg) -> dict:
    """What the old ForceDistributor.__init__ pre-built for k feet and config ``cfg``."""
    feet_idx = np.arange(k)
    foot_cols = 3 * feet_idx[:, None] + np.arange(3)
    mu = cfg.friction
    return {
        "sum": np.tile(np.eye(3), (1, k)),
        "s": np.asarray(cfg.wrench_weights, dtype=float),
        "reg": 2.0 * cfg.regularization * np.eye(3 * k),
        "pyramid": np.array([[1.0, 0.0, -mu], [-1.0, 0.0, -mu], [0.0, 1.0, -mu], [0.0, -1.0, -mu]]),
        "normal_rows": feet_idx[:, None],
        "foot_cols": foot_cols,
        "friction_rows": (k + 4 * feet_idx[:, None] + np.arange(4)).reshape(-1, 1),
        "friction_cols": np.repeat(foot_cols, 4, axis=0),
        "blocks": {"normal": slice(0, k), "friction": slice(k, 5 * k)},
    }


def reference_build(distributor, feet, cog, wrench, normal=None) -> ForceQp:
    """Old ForceDistributor.build (``distributor`` supplies n_feet and config)."""
    k, cfg = distributor.n_feet, distributor.config
    c = _old_constants(k, cfg)
    feet = np.asarray(feet, dtype=float)
    cog = np.asarray(cog, dtype=float)
    b = np.asarray(wrench, dtype=float)
    # (input validation left out: the test passes well-formed, finite input only)
    if normal is None:
        n = fit_plane(feet).normal
    else:
        n = np.array(_v_unit(np.asarray(normal, dtype=float).tolist()))

    rel = feet - cog
    moment_rows = _moment_rows(rel)  # [[P_1]x ... [P_k]x]
    a_mat = np.empty((6, 3 * k))
    a_mat[:3] = c["sum"]
    a_mat[3:] = moment_rows
    scale = max(math.sqrt(float(b[:3] @ b[:3])), k * cfg.min_normal_force, 1.0)
    b_scaled = b / scale
    sa = c["s"][:, None] * a_mat
    u_mat = 2.0 * a_mat.T @ sa + c["reg"]
    f_vec = -2.0 * sa.T @ b_scaled

    nl = n.tolist()
    t1 = (1.0 - nl[0] * nl[0], -nl[0] * nl[1], -nl[0] * nl[2])
    if math.sqrt(_v_dot(t1, t1)) < 1e-6:
        t1 = (-nl[1] * nl[0], 1.0 - nl[1] * nl[1], -nl[1] * nl[2])
    t1 = _v_unit(t1)
    t2 = _v_cross(nl, t1)
    friction_rows = c["pyramid"] @ np.array([t1, t2, nl])  # (4, 3); frame rows t1, t2, n

    cone = None
    hull = support_polygon(feet, up=n)
    edges = np.empty((len(hull), 2), dtype=np.intp)
    edges[:, 0] = hull
    edges[:-1, 1], edges[-1, 1] = hull[1:], hull[0]  # next vertex, wrapping (np.roll is slow)
    n_cone = 4 * len(edges) if cfg.stability_cone else 0
    g_mat = np.zeros((5 * k + n_cone, 3 * k))
    h_vec = np.zeros(5 * k + n_cone)
    g_mat[c["normal_rows"], c["foot_cols"]] = -n
    h_vec[:k] = -cfg.min_normal_force / scale
    g_mat[c["friction_rows"], c["friction_cols"]] = np.tile(friction_rows, (k, 1))
    if cfg.stability_cone:
        cone = stability_cone(feet, cog, n, cfg.cone_ratio, hull=hull)
        v_all = tipping_force_matrices(feet, cog, edges, moment_rows)
        # faces · f*_i <= 0 with f*_i = -V_i x.
        g_mat[5 * k :] = -(cone.faces @ v_all).reshape(-1, 3 * k)

    blocks = dict(c["blocks"])
    if cfg.stability_cone:
        blocks["stability"] = slice(5 * k, 5 * k + n_cone)
    return ForceQp(
        U=u_mat,
        f=f_vec,
        G=g_mat,
        h=h_vec,
        A=a_mat,
        b=b,
        scale=scale,
        blocks=blocks,
        edges=edges,
        cone=cone,
        normal=n,
    )
