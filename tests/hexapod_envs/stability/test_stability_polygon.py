"""Support polygon (strict convex hull seen from above) and static stability margin."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hexapod_envs.stability import static_stability_margin, support_polygon

SQUARE = np.array([[1.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [-1.0, -1.0, 0.0], [1.0, -1.0, 0.0]])


def signed_area(xy: np.ndarray) -> float:
    """Shoelace area of a closed polygon; > 0 when counter-clockwise."""
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def check_strict_hull(xy: np.ndarray, hull: np.ndarray) -> None:
    """A ccw strict convex hull: strictly convex vertices, every point inside or on it."""
    poly = xy[hull]
    m = len(poly)
    assert m >= 3
    assert signed_area(poly) > 0.0
    for j in range(m):
        o, a, b = poly[j - 1], poly[j], poly[(j + 1) % m]
        turn = (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
        assert turn > 1e-9, "a hull vertex is not strictly convex"
        edge = b - a
        cross = edge[0] * (xy[:, 1] - a[1]) - edge[1] * (xy[:, 0] - a[0])
        assert np.all(cross >= -1e-9 * np.linalg.norm(edge)), "a point lies outside the hull"


def test_square_in_any_order_is_counter_clockwise_from_above():
    rng = np.random.default_rng(0)
    for _ in range(10):
        pts = SQUARE[rng.permutation(4)]
        hull = support_polygon(pts)
        assert sorted(hull.tolist()) == [0, 1, 2, 3]
        assert signed_area(pts[hull, :2]) == pytest.approx(4.0)
        # Seen from below the order reverses.
        assert signed_area(pts[support_polygon(pts, up=(0, 0, -1)), :2]) == pytest.approx(-4.0)


def test_middle_feet_on_the_edges_interior_points_and_duplicates_are_dropped():
    pts = np.array(
        [
            [2.4, 1.9, -1.75],
            [0.0, 1.9, -1.75],  # on the left edge
            [-2.4, 1.9, -1.75],
            [2.4, -1.9, -1.75],
            [0.0, -1.9, -1.75],  # on the right edge
            [-2.4, -1.9, -1.75],
            [0.3, 0.2, -1.75],  # inside
            [2.4, 1.9, -1.75],  # duplicate of 0
        ]
    )
    hull = support_polygon(pts)
    assert len(hull) == 4
    assert {tuple(p) for p in pts[hull, :2].tolist()} == {
        (2.4, 1.9),
        (-2.4, 1.9),
        (-2.4, -1.9),
        (2.4, -1.9),
    }
    assert not {1, 4, 6} & set(hull.tolist())


def test_random_point_sets_give_strict_hulls():
    rng = np.random.default_rng(1)
    for trial in range(300):
        k = int(rng.integers(3, 10))
        # Odd trials: a small integer grid, with many collinear points and duplicates.
        grid = rng.integers(0, 3, size=(k, 2)).astype(float)
        xy = grid if trial % 2 else rng.normal(size=(k, 2))
        pts = np.column_stack([xy, rng.normal(scale=0.01, size=k)])
        try:
            hull = support_polygon(pts, up=(0.0, 0.0, 1.0))
        except ValueError as err:
            assert "collinear" in str(err)
            centred = xy - xy.mean(axis=0)
            assert np.linalg.matrix_rank(centred, tol=1e-9) < 2
            continue
        check_strict_hull(xy, hull)


def test_tilted_and_vertical_point_sets_use_their_own_plane():
    rng = np.random.default_rng(2)
    xy = rng.normal(size=(6, 2))
    flat = np.column_stack([xy, np.zeros(6)])
    expected = support_polygon(flat)
    # A vertical wall x = 0: the default normal is ±x, the hull the same set of points.
    wall = flat[:, [2, 0, 1]]
    assert sorted(support_polygon(wall).tolist()) == sorted(expected.tolist())
    # A steep plane through the points (60 deg): same hull as the flat set.
    c, s = math.cos(math.radians(60)), math.sin(math.radians(60))
    steep = flat @ np.array([[1, 0, 0], [0, c, s], [0, -s, c]]).T
    hull = support_polygon(steep)
    assert sorted(hull.tolist()) == sorted(expected.tolist())
    check_strict_hull(xy, hull)  # ccw seen from the plane normal with z > 0


@pytest.mark.parametrize(
    ("points", "message"),
    [
        (SQUARE[:2], "at least 3"),
        ([[0, 0, 0], [1, 2, 3], [2, 4, 6], [3, 6, 9]], "collinear"),
        ([[1, 1, 1]] * 4, "collinear"),
        ([[0, 0], [1, 0], [0, 1]], "shape"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, math.inf]], "infinite"),
    ],
)
def test_support_polygon_errors(points, message):
    with pytest.raises(ValueError, match=message):
        support_polygon(points)


def test_points_collinear_seen_from_the_given_up_are_an_error():
    with pytest.raises(ValueError, match="collinear"):
        support_polygon(SQUARE, up=(1.0, 0.0, 0.0))  # the square seen edge-on
    with pytest.raises(ValueError, match="non-zero"):
        support_polygon(SQUARE, up=(0.0, 0.0, 0.0))


# ----------------------------------------------------------------------------- static margin


@pytest.mark.parametrize(
    ("cog_xy", "expected"),
    [
        ((0.0, 0.0), 1.0),
        ((0.3, 0.1), 0.7),
        ((-0.2, -0.9), 0.1),
        ((1.0, 0.5), 0.0),
        ((1.5, 0.5), -0.5),  # outside one edge
        ((1.3, 1.4), -0.5),  # outside a corner: distance to the vertex (0.3, 0.4)
    ],
)
def test_static_margin_of_a_square(cog_xy, expected):
    margin = static_stability_margin(SQUARE, [*cog_xy, 0.8])
    assert margin == pytest.approx(expected, abs=1e-12)


@pytest.mark.parametrize("phi_deg", [0.0, 10.0, 30.0, 60.0])
def test_static_margin_with_tilted_gravity(phi_deg):
    """Gravity tilted by phi toward +x moves the CoG projection by h tan(phi) in the plane
    normal to gravity, whose x-axis is foreshortened by cos(phi): margin = (1 - h tan phi) cos phi
    to the front edge, and the side edges stay 1 m away."""
    h = 0.8
    phi = math.radians(phi_deg)
    gravity = (math.sin(phi), 0.0, -math.cos(phi))
    margin = static_stability_margin(SQUARE, [0.0, 0.0, h], gravity=gravity)
    expected = min((1.0 - h * math.tan(phi)) * math.cos(phi), 1.0)
    assert margin == pytest.approx(expected, abs=1e-12)
    assert (margin < 0.0) == (h * math.tan(phi) > 1.0)


def test_static_margin_of_the_hexapod_and_gravity_magnitude_is_irrelevant():
    feet = np.array(
        [[x, y, -1.75] for x, y in [(2.4, 1.9), (0, 1.9), (-2.4, 1.9), (2.4, -1.9), (0, -1.9)]]
        + [[-2.4, -1.9, -1.75]]
    )
    assert static_stability_margin(feet, np.zeros(3)) == pytest.approx(1.9)
    assert static_stability_margin(feet, np.zeros(3), gravity=(0, 0, -9.81)) == pytest.approx(1.9)
    tripod = feet[[0, 2, 4]]
    dist = abs(-2.4 * -3.8 - 1.9 * 2.4) / math.hypot(2.4, 3.8)
    assert static_stability_margin(tripod, np.zeros(3)) == pytest.approx(dist)


def test_static_margin_errors():
    with pytest.raises(ValueError, match="gravity must be a non-zero"):
        static_stability_margin(SQUARE, [0, 0, 1], gravity=(0, 0, 0))
    with pytest.raises(ValueError, match="collinear"):
        static_stability_margin(SQUARE, [0, 0, 1], gravity=(0, 1, 0))
    with pytest.raises(ValueError, match="cog must be a 3-vector"):
        static_stability_margin(SQUARE, [0, 0])


def test_stability_package_imports_only_numpy_numba_and_the_standard_library():
    """The stability measures must stay usable without MuJoCo (pure math, docs/architecture.md,
    Layers; numba only compiles the hot loops)."""
    import ast
    import pathlib
    import sys

    import hexapod_envs.stability as stability

    allowed = {"numpy", "numba", "hexapod_envs", *sys.stdlib_module_names}
    for path in pathlib.Path(stability.__file__).parent.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = [node.module or ""]
            else:
                continue
            for name in names:
                assert name.split(".")[0] in allowed, f"{path.name} imports {name}"
                if name.startswith("hexapod_envs"):
                    assert name.startswith("hexapod_envs.stability"), f"{path.name}: {name}"


def _python_signed_distance(xs, ys, hull, px, py):
    """The former plain-Python signed_distance_2d (CPython's math.hypot, min and max)."""
    m = len(hull)
    edges = []
    d_in = math.inf
    for j in range(m):
        x0, y0 = xs[hull[j]], ys[hull[j]]
        i1 = hull[(j + 1) % m]
        ex, ey = xs[i1] - x0, ys[i1] - y0
        wx, wy = px - x0, py - y0
        edges.append((ex, ey, wx, wy))
        d_in = min(d_in, (ex * wy - ey * wx) / math.hypot(ex, ey))
    if d_in >= 0.0:
        return d_in
    d_out = math.inf
    for ex, ey, wx, wy in edges:
        t = min(1.0, max(0.0, (ex * wx + ey * wy) / (ex * ex + ey * ey)))
        d_out = min(d_out, math.hypot(wx - t * ex, wy - t * ey))
    return -d_out


def test_compiled_signed_distance_is_the_python_one_to_the_bit():
    """Inside and outside points of random polygons (the compiled kernel uses CPython's hypot
    algorithm; libm's hypot would differ in the last bit now and then)."""
    from hexapod_envs.stability._geometry import hull_2d, signed_distance_2d

    rng = np.random.default_rng(11)
    inside = outside = 0
    for _ in range(3000):
        k = int(rng.integers(3, 7))
        xs, ys = rng.normal(size=k).tolist(), rng.normal(size=k).tolist()
        hull = hull_2d(xs, ys)
        px, py = rng.normal(size=2).tolist()
        expected = _python_signed_distance(xs, ys, hull, px, py)
        assert signed_distance_2d(xs, ys, hull, px, py) == expected
        inside += expected > 0
        outside += expected < 0
    assert inside > 300 and outside > 300
