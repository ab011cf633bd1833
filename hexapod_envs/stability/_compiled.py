"""Compiled kernels of the stability measures (private; numba, no MuJoCo).

The stability measures run every control step on 3-6 contact points. At that size a Python or
numpy implementation spends nearly all its time in interpreter and call overhead (FASM took 8 µs
for 3 feet and 17 µs for 6 as plain-float Python, against ~1 µs of arithmetic), so the hot paths
live here as ``numba.njit`` functions on float64 arrays. They are compiled on first use and the
machine code is cached on disk (``cache=True``; numba picks a writable cache directory, or
``NUMBA_CACHE_DIR``), so later processes load them in milliseconds. ``NUMBA_DISABLE_JIT=1`` runs
the same functions as plain Python, for debugging.

Kernels do not raise: they return a status code and the callers in :mod:`._geometry` and
:mod:`.fasm` turn it into a ValueError with a message naming the problem. The arithmetic is
written out in the order of the Python it replaced, so results are unchanged to the bit (numba
does not reassociate or fuse floating-point operations without ``fastmath``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

REL_TOL = 1e-12
"""Relative tolerance for "collinear" / "degenerate" decisions, scaled by the point set's size."""

# Status codes of the kernels (see the callers for the messages).
OK = 0
ZERO_FORCE = 1
TRIANGLE_COLLINEAR = 2  # three feet on a line
NO_PLANE = 3  # k > 3 points on a line or coincident: no least-squares plane
HULL_COLLINEAR = 4  # collinear seen from above
COG_ON_EDGE = 5
NOT_FINITE = 6
ZERO_UP = 7
TOO_FEW = 8  # fewer than 3 (loaded) feet


@njit(cache=True)
def centred_moments(pts):
    """(centroid (3,), (xx, xy, xz, yy, yz, zz) (6,)): second moments of (k, 3) ``pts``."""
    k = pts.shape[0]
    cx = cy = cz = 0.0
    for i in range(k):
        cx += pts[i, 0]
        cy += pts[i, 1]
        cz += pts[i, 2]
    cx /= k
    cy /= k
    cz /= k
    xx = xy = xz = yy = yz = zz = 0.0
    for i in range(k):
        dx, dy, dz = pts[i, 0] - cx, pts[i, 1] - cy, pts[i, 2] - cz
        xx += dx * dx
        xy += dx * dy
        xz += dx * dz
        yy += dy * dy
        yz += dy * dz
        zz += dz * dz
    return np.array((cx, cy, cz)), np.array((xx, xy, xz, yy, yz, zz))


@njit(cache=True)
def fit_plane(pts):
    """Least-squares z = a x + b y + c through (k, 3) ``pts`` (see .plane_fit.fit_plane).

    Returns (status, (a, b, c) (3,), unit up-normal (3,), point above the centroid (3,));
    status NOT_FINITE, or NO_PLANE when the points' (x, y) are collinear or coincident.
    """
    zero = np.zeros(3)
    if not finite(pts.ravel()):
        return NOT_FINITE, zero, zero, zero
    centroid, mom = centred_moments(pts)
    x0, y0, z0 = centroid[0], centroid[1], centroid[2]
    sxx, sxy, sxz, syy, syz = mom[0], mom[1], mom[2], mom[3], mom[4]
    det = sxx * syy - sxy * sxy
    if not det > REL_TOL * (sxx + syy) ** 2:
        return NO_PLANE, zero, zero, zero
    a = (sxz * syy - sxy * syz) / det
    b = (sxx * syz - sxy * sxz) / det
    c = z0 - a * x0 - b * y0
    s = 1.0 / math.sqrt(a * a + b * b + 1.0)
    return (
        OK,
        np.array((a, b, c)),
        np.array((-a * s, -b * s, s)),
        np.array((x0, y0, a * x0 + b * y0 + c)),
    )


@njit(cache=True)
def plane_normal(pts):
    """(unit normal (3,) with n_z >= 0, centroid (3,), ok) of the least-squares plane.

    Regression along the best-conditioned axis: for a plane that is not steep this is the
    z = a x + b y + c fit; near-vertical point sets regress x or y instead, so any non-collinear
    set has a normal. ok is False for collinear or coincident points.
    """
    centroid, mom = centred_moments(pts)
    xx, xy, xz, yy, yz, zz = mom[0], mom[1], mom[2], mom[3], mom[4], mom[5]
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
        return np.zeros(3), centroid, False
    s = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
    if nz < 0.0:
        s = -s
    return np.array((nx * s, ny * s, nz * s)), centroid, True


@njit(cache=True)
def project_oblique(pts, up):
    """Affine 2-D image (xs, ys) of (k, 3) ``pts`` seen along unit ``up``, ccw preserved.

    Projects along ``up`` onto the coordinate plane most normal to it (two multiply-adds per
    point): an orientation-preserving affine image of the orthogonal projection, so hull
    membership and counter-clockwise order seen from +up are kept; lengths are not.
    """
    k = pts.shape[0]
    xs = np.empty(k)
    ys = np.empty(k)
    ux, uy, uz = up[0], up[1], up[2]
    ax, ay, az = abs(ux), abs(uy), abs(uz)
    if az >= ax and az >= ay:  # onto z = 0, coordinates (x, y)
        sx, sy = ux / uz, uy / uz
        for i in range(k):
            xs[i] = pts[i, 0] - pts[i, 2] * sx
            ys[i] = pts[i, 1] - pts[i, 2] * sy if uz > 0.0 else pts[i, 2] * sy - pts[i, 1]
    elif ax >= ay:  # onto x = 0, coordinates (y, z)
        sy, sz = uy / ux, uz / ux
        for i in range(k):
            xs[i] = pts[i, 1] - pts[i, 0] * sy
            ys[i] = pts[i, 2] - pts[i, 0] * sz if ux > 0.0 else pts[i, 0] * sz - pts[i, 2]
    else:  # onto y = 0, coordinates (z, x)
        sz, sx = uz / uy, ux / uy
        for i in range(k):
            xs[i] = pts[i, 2] - pts[i, 1] * sz
            ys[i] = pts[i, 0] - pts[i, 1] * sx if uy > 0.0 else pts[i, 1] * sx - pts[i, 0]
    return xs, ys


@njit(cache=True)
def hull_2d(xs, ys):
    """Strict convex hull of 2-D points, counter-clockwise, as indices (fewer than 3: collinear).

    Sort the points by angle around their centroid (strictly inside the hull; a stable
    insertion sort, fastest for the 3-8 points of a legged robot), giving a polygon star-shaped
    from it; then delete every vertex that is not a strict left turn until all are (Graham's
    scan). Points on an edge (within a relative 1e-12) and duplicates are dropped. Hull vertices
    are never deleted, and of points on one ray from the centroid the nearer is always a right
    turn, so ties in angle need no special care.
    """
    k = xs.shape[0]
    cx = 0.0
    cy = 0.0
    for i in range(k):
        cx += xs[i]
        cy += ys[i]
    cx /= k
    cy /= k
    span = xs.max() - xs.min() + ys.max() - ys.min()
    tol = REL_TOL * span * span
    angle = np.empty(k)
    for i in range(k):
        angle[i] = math.atan2(ys[i] - cy, xs[i] - cx)
    ring = np.arange(k)
    for i in range(1, k):
        j = i
        while j > 0 and angle[ring[j - 1]] > angle[ring[j]]:
            ring[j - 1], ring[j] = ring[j], ring[j - 1]
            j -= 1
    n = k
    i = 0
    confirmed = 0  # length of the run of checked left turns ending just before ring[i]
    while confirmed < n and n >= 3:
        a = ring[i - 1] if i > 0 else ring[n - 1]
        b = ring[i]
        c = ring[i + 1] if i + 1 < n else ring[0]
        bx = xs[b]
        by = ys[b]
        if (bx - xs[a]) * (ys[c] - by) - (by - ys[a]) * (xs[c] - bx) > tol:
            confirmed += 1
            i = i + 1 if i + 1 < n else 0
        else:  # b is reflex, straight or a duplicate: drop it and re-check its predecessor
            for j in range(i, n - 1):
                ring[j] = ring[j + 1]
            n -= 1
            confirmed = max(0, min(confirmed - 1, n - 2))
            i = i - 1 if i > 0 else n - 1
    return ring[:n].copy()


@njit(cache=True)
def hull_up(pts, up):
    """Strict convex hull of (k, 3) ``pts`` seen along unit ``up``, ccw from above."""
    xs, ys = project_oblique(pts, up)
    return hull_2d(xs, ys)


@njit(cache=True)
def _ordered_hull(pts, cog, up, has_up):
    """(hull indices ccw seen from ``up``, else from the feet plane's CoG side; status)."""
    k = pts.shape[0]
    gx, gy, gz = cog[0], cog[1], cog[2]
    if has_up:
        ux, uy, uz = up[0], up[1], up[2]
        un = math.sqrt(ux * ux + uy * uy + uz * uz)
        if un == 0.0:
            return np.empty(0, dtype=np.int64), ZERO_UP
        ring = hull_up(pts, np.array((ux / un, uy / un, uz / un)))
    elif k == 3:
        # Triangle: the plane normal is the cross product; order so it points to the CoG side.
        ax, ay, az = pts[1, 0] - pts[0, 0], pts[1, 1] - pts[0, 1], pts[1, 2] - pts[0, 2]
        bx, by, bz = pts[2, 0] - pts[0, 0], pts[2, 1] - pts[0, 1], pts[2, 2] - pts[0, 2]
        nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
        size = ax * ax + ay * ay + az * az + bx * bx + by * by + bz * bz
        if math.sqrt(nx * nx + ny * ny + nz * nz) <= REL_TOL * size:
            return np.empty(0, dtype=np.int64), TRIANGLE_COLLINEAR
        side = (gx - pts[0, 0]) * nx + (gy - pts[0, 1]) * ny + (gz - pts[0, 2]) * nz
        if side == 0.0:
            side = nz
        ring = np.array((0, 1, 2)) if side >= 0.0 else np.array((0, 2, 1))
    else:
        normal, centroid, ok = plane_normal(pts)
        if not ok:
            return np.empty(0, dtype=np.int64), NO_PLANE
        side = (
            (gx - centroid[0]) * normal[0]
            + (gy - centroid[1]) * normal[1]
            + (gz - centroid[2]) * normal[2]
        )
        ring = hull_up(pts, -normal if side < 0.0 else normal)
    if ring.shape[0] < 3:
        return ring, HULL_COLLINEAR
    return ring, OK


@njit(cache=True)
def finite(values) -> bool:
    """True when every entry is finite (a finite sum proves it: NaN and ±inf propagate)."""
    total = 0.0
    for v in values:
        total += v
    return math.isfinite(total)


@njit(cache=True)
def fasm_edges(pts, cog, force, moment, up, has_up):
    """FASM per support-polygon edge (see :mod:`.fasm` for the formulas).

    Returns (status, angles [deg] (m,), tipping forces [N] (m,), edges (m, 2), index of the
    smallest angle). With status COG_ON_EDGE the index is the offending edge's; NOT_FINITE
    comes with the index of the bad input (0 feet, 1 cog, 2 force, 3 moment, 4 up).
    """
    empty = np.empty(0)
    no_edges = np.empty((0, 2), dtype=np.int64)
    bad = -1
    if not finite(pts.ravel()):
        bad = 0
    elif not finite(cog):
        bad = 1
    elif not finite(force):
        bad = 2
    elif not finite(moment):
        bad = 3
    elif has_up and not finite(up):
        bad = 4
    if bad >= 0:
        return NOT_FINITE, empty, empty, no_edges, bad
    gx, gy, gz = cog[0], cog[1], cog[2]
    fx, fy, fz = force[0], force[1], force[2]
    nx, ny, nz = moment[0], moment[1], moment[2]
    f_norm = math.sqrt(fx * fx + fy * fy + fz * fz)
    if f_norm == 0.0:
        return ZERO_FORCE, empty, empty, no_edges, 0
    hull, status = _ordered_hull(pts, cog, up, has_up)
    if status != OK:
        return status, empty, empty, no_edges, 0

    m = hull.shape[0]
    angles = np.empty(m)
    forces = np.empty(m)
    edges = np.empty((m, 2), dtype=np.int64)
    best = 0
    for j in range(m):
        i0 = hull[j]
        i1 = hull[j + 1] if j + 1 < m else hull[0]
        edges[j, 0] = i0
        edges[j, 1] = i1
        ax, ay, az = pts[i1, 0] - pts[i0, 0], pts[i1, 1] - pts[i0, 1], pts[i1, 2] - pts[i0, 2]
        inv = 1.0 / math.sqrt(ax * ax + ay * ay + az * az)
        ax *= inv
        ay *= inv
        az *= inv
        # l = (I - a aᵀ)(p_{i+1} - p_G)
        wx, wy, wz = pts[i1, 0] - gx, pts[i1, 1] - gy, pts[i1, 2] - gz
        t = wx * ax + wy * ay + wz * az
        lx, ly, lz = wx - t * ax, wy - t * ay, wz - t * az
        l_norm = math.sqrt(lx * lx + ly * ly + lz * lz)
        if l_norm <= REL_TOL * math.sqrt(wx * wx + wy * wy + wz * wz):
            return COG_ON_EDGE, empty, empty, edges[: j + 1], j
        # Components of ‖l‖ f* along l̂ and t̂ = a × l̂.
        f_l = fx * lx + fy * ly + fz * lz
        n_a = nx * ax + ny * ay + nz * az
        f_t = fx * (ay * lz - az * ly) + fy * (az * lx - ax * lz) + fz * (ax * ly - ay * lx) - n_a
        size = math.hypot(f_l, f_t)
        if size <= REL_TOL * (f_norm * l_norm + abs(n_a)):
            angles[j] = 0.0  # no tipping force about this edge: critical, sign undefined
        else:
            angles[j] = math.degrees(math.atan2(f_t, f_l))
        forces[j] = size / l_norm
        if angles[j] < angles[best]:
            best = j
    return OK, angles, forces, edges, best


@njit(cache=True)
def fasm_from_feet(feet, reactions, cog, loaded):
    """(status, margin [deg], i, j) of the FASM from measured foot reactions (see .fasm)."""
    n = feet.shape[0]
    count = 0
    for i in range(n):
        if loaded[i]:
            count += 1
    if count < 3:
        return TOO_FEW, 0.0, -1, -1
    idx = np.empty(count, dtype=np.int64)
    pts = np.empty((count, 3))
    count = 0
    cx, cy, cz = cog[0], cog[1], cog[2]
    fx = fy = fz = mx = my = mz = 0.0
    for i in range(n):
        if loaded[i]:
            idx[count] = i
            px, py, pz = feet[i, 0], feet[i, 1], feet[i, 2]
            pts[count, 0], pts[count, 1], pts[count, 2] = px, py, pz
            count += 1
            gx, gy, gz = reactions[i, 0], reactions[i, 1], reactions[i, 2]
            rx, ry, rz = px - cx, py - cy, pz - cz
            fx -= gx
            fy -= gy
            fz -= gz
            mx -= ry * gz - rz * gy
            my -= rz * gx - rx * gz
            mz -= rx * gy - ry * gx
    if not math.isfinite(fx + fy + fz + mx + my + mz + cx + cy + cz):
        return NOT_FINITE, 0.0, -1, -1
    status, angles, _, edges, best = fasm_edges(
        pts, cog, np.array((fx, fy, fz)), np.array((mx, my, mz)), cog, False
    )
    if status != OK:  # collinear feet or zero force: no polygon to stand on
        return status, 0.0, -1, -1
    return OK, angles[best], idx[edges[best, 0]], idx[edges[best, 1]]


_VELTKAMP = 134217729.0  # 2**27 + 1


@njit(cache=True)
def _split(x):
    t = x * _VELTKAMP
    hi = t - (t - x)
    return hi, x - hi


@njit(cache=True)
def _exact_product(x, y):
    """(x y rounded, its rounding error) exactly: Dekker's product, what fma(x, y, -x y) gives."""
    z = x * y
    xh, xl = _split(x)
    yh, yl = _split(y)
    return z, ((xh * yh - z) + xh * yl + xl * yh) + xl * yl


@njit(cache=True)
def _fast_two_sum(a, b):
    """(a + b rounded, its rounding error) for |a| >= |b|."""
    s = a + b
    return s, (a - s) + b


@njit(cache=True)
def cpython_hypot(x, y):
    """CPython 3.11's ``math.hypot(x, y)`` to the bit (its vector_norm: lossless power-of-two
    scaling, exact squares, compensated sum and one differential correction of the root; for a
    subnormal larger value, division by it and a plain compensated sum, as 3.11 does)."""
    ax, ay = abs(x), abs(y)
    if math.isinf(ax) or math.isinf(ay):
        return math.inf
    if math.isnan(ax) or math.isnan(ay):
        return math.nan
    largest = max(ax, ay)
    if largest == 0.0:
        return largest
    _, exponent = math.frexp(largest)
    if exponent < -1023:  # subnormal: 2**-exponent would overflow
        csum, frac = 1.0, 0.0
        for value in (ax, ay):
            v = value / largest
            v = v * v
            before = csum
            csum += v
            frac += (before - csum) + v
        return largest * math.sqrt(csum - 1.0 + frac)
    scale = math.ldexp(1.0, -exponent)
    csum, frac1, frac2 = 1.0, 0.0, 0.0
    for value in (ax, ay):
        v = value * scale
        hi, lo = _exact_product(v, v)
        csum, err = _fast_two_sum(csum, hi)
        frac1 += lo
        frac2 += err
    h = math.sqrt(csum - 1.0 + (frac1 + frac2))
    hi, lo = _exact_product(-h, h)
    csum, err = _fast_two_sum(csum, hi)
    frac1 += lo
    frac2 += err
    h += (csum - 1.0 + (frac1 + frac2)) / (2.0 * h)
    return h / scale


@njit(cache=True)
def signed_distance_2d(xs, ys, hull, px, py):
    """Signed distance of (px, py) to the boundary of the ccw polygon ``hull`` (indices into
    xs / ys); > 0 inside: the smallest distance to an edge line. Outside: minus the distance to
    the polygon (nearest edge segment or vertex). Python's ``min`` / ``max`` semantics and
    CPython's ``math.hypot`` (:func:`cpython_hypot`), so the result is the former Python's."""
    m = hull.shape[0]
    edges = np.empty((m, 4))  # per edge: its vector (ex, ey), (px, py) from its start (wx, wy)
    d_in = math.inf
    for j in range(m):
        x0, y0 = xs[hull[j]], ys[hull[j]]
        i1 = hull[j + 1] if j + 1 < m else hull[0]
        ex, ey = xs[i1] - x0, ys[i1] - y0
        wx, wy = px - x0, py - y0
        edges[j, 0], edges[j, 1], edges[j, 2], edges[j, 3] = ex, ey, wx, wy
        d = (ex * wy - ey * wx) / cpython_hypot(ex, ey)
        if d < d_in:
            d_in = d
    if d_in >= 0.0:
        return d_in
    d_out = math.inf
    for j in range(m):
        ex, ey, wx, wy = edges[j, 0], edges[j, 1], edges[j, 2], edges[j, 3]
        t = (ex * wx + ey * wy) / (ex * ex + ey * ey)
        t = t if t > 0.0 else 0.0
        t = t if t < 1.0 else 1.0
        d = cpython_hypot(wx - t * ex, wy - t * ey)
        if d < d_out:
            d_out = d
    return -d_out


@njit(cache=True)
def hull_distance(xs, ys, px, py):
    """Signed distance of (px, py) to the convex hull of the points (xs, ys) (see
    :func:`signed_distance_2d`); 0 when the points lie on a line: no polygon."""
    hull = hull_2d(xs, ys)
    if hull.shape[0] < 3:
        return 0.0
    return signed_distance_2d(xs, ys, hull, px, py)


@njit(cache=True)
def zmp_margin(xs, ys, forces, min_force):
    """(status, ZMP x, ZMP y, margin) of Coelho et al. 2024 eqs. (32)-(33) (see
    :func:`hexapod_envs.stability.zmp.zmp_margin`): the feet with force > ``min_force`` [N] weigh
    their (x, y) [m] by it, summed in index order as Python's ``sum``; the margin is the ZMP's
    signed distance to their hull, 0 with fewer than 3 of them, on a line, or within a relative
    1e-12 of an edge. Status NOT_FINITE for non-finite forces, ZERO_FORCE if no foot is loaded."""
    total = 0.0
    count = 0
    for f in forces:
        total += f
        count += f > min_force
    if not math.isfinite(total):
        return NOT_FINITE, 0.0, 0.0, 0.0
    if count == 0:
        return ZERO_FORCE, 0.0, 0.0, 0.0
    lx, ly = np.empty(count), np.empty(count)
    total = sx = sy = 0.0
    count = 0
    for i in range(forces.shape[0]):
        f = forces[i]
        if f > min_force:
            lx[count], ly[count] = xs[i], ys[i]
            total += f
            sx += xs[i] * f
            sy += ys[i] * f
            count += 1
    px, py = sx / total, sy / total
    if count < 3:
        return OK, px, py, 0.0
    margin = hull_distance(lx, ly, px, py)
    span = max(lx.max() - lx.min(), ly.max() - ly.min())
    return OK, px, py, (0.0 if abs(margin) <= REL_TOL * span else margin)
